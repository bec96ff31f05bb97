"""One patch of each kind at the largest edge factor the kernels allow (cltess.limits.MAX_FACTOR),
tessellated whole on a device with room for it, and checked (issue 9, item 1):

* the counts are the closed forms ((M+1)^2 vertices and 2 M^2 triangles for a quad patch,
  3M + (M-1)(M-2)/2 vertices and M^2 triangles for a triangle patch);
* every triangle index lies in 0..V-1 and every vertex is used (nothing was written past a
  buffer or left unwritten);
* every position and normal is finite.

    python bench/max_factor_limit.py --device nvidia [--kind bezier|pn]

A quad patch at M = 26754 is 716M vertices and 1.43G triangles: 46 GB of device output and as
much host memory again.  Run it on a GPU machine (bench/gpu_run.sh shows the set-up).

Measured on an NVIDIA H100 (bench/results/max_factor_limit_h100.txt): both patches exact and
complete, every index in range, every vertex used, all finite; one work-item per patch makes it
slow, 172 s (triangle) and 380 s (quad) end to end.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from cltess.limits import MAX_FACTOR
from cltess.pipeline import Tessellator
from cltess.scene import Scene, TriangleMesh


def curved_patch() -> Scene:
    points = np.array([[[i, j, (i - 1.5) ** 2 * (j - 1.5) ** 2] for i in range(4)] for j in range(4)], float)
    return Scene(np.concatenate([points, np.ones((4, 4, 1))], -1)[None], np.zeros(1, np.int32), name="curved patch")


def curved_triangle() -> Scene:
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    normals = np.array([[-1, -1, 1], [1, 0, 1], [0, 1, 1]], float)
    return Scene.from_meshes([TriangleMesh(vertices, np.array([[0, 1, 2]]), normals)], name="curved triangle")


def check(tessellator: Tessellator, kind: str) -> None:
    m = MAX_FACTOR
    scene = curved_patch() if kind == "bezier" else curved_triangle()
    expected = ((m + 1) ** 2, 2 * m * m) if kind == "bezier" else (3 * m + (m - 1) * (m - 2) // 2, m * m)
    started = time.perf_counter()
    tess = tessellator.tessellate(scene, eps=1e-30, max_factor=m)
    seconds = time.perf_counter() - started
    factors = tess.factors[0].tolist()
    print(f"{kind}: factors {factors}, {tess.num_vertices} vertices, {tess.num_triangles} triangles "
          f"in {seconds:.1f} s; stage ms {({k: round(v) for k, v in tess.stage_ms.items()})}", flush=True)
    assert (tess.num_vertices, tess.num_triangles) == expected, expected
    low, high = int(tess.triangles.min()), int(tess.triangles.max())
    assert (low, high) == (0, tess.num_vertices - 1), (low, high)
    used = np.zeros(tess.num_vertices, bool)
    for start in range(0, tess.num_triangles, 1 << 26):
        used[tess.triangles[start:start + (1 << 26)].ravel()] = True
    assert used.all(), f"{int((~used).sum())} vertices unused"
    for name in ("positions", "normals"):
        array = getattr(tess, name)
        finite = all(np.isfinite(array[start:start + (1 << 26)]).all() for start in range(0, len(array), 1 << 26))
        assert finite, name
    print(f"{kind}: ok (indices 0..V-1, every vertex used, positions and normals finite)", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", default=None)
    parser.add_argument("--kind", choices=("bezier", "pn"), action="append")
    args = parser.parse_args()
    tessellator = Tessellator(device=args.device)
    print(f"device {tessellator.device.name}, max_factor {MAX_FACTOR}", flush=True)
    for kind in args.kind or ["pn", "bezier"]:
        check(tessellator, kind)


if __name__ == "__main__":
    main()

"""Closed rational scenes far from the origin: the exact float32 weld's defects (issue 9).

For each scene moved by (o, o, o) and each eps (relative to the diagonal), tessellate and weld
exactly (tests/test_poles.py welded_edges) and print (triangles with a repeated vertex,
zero-area triangles, non-manifold edges, boundary edges, triangles); "steps" is eps in float32
steps at the offset.

    python bench/weld_far.py sphere.bpt,torus.bpt 1e3,1e5,1e6 1e-2,1e-3,1e-4 [--device pocl]
"""
import argparse
import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
from support import translated_scene  # noqa: E402
from test_poles import welded_edges  # noqa: E402


def defects(tess):
    faces, points, uses = welded_edges(tess)
    repeated = ((faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 2] == faces[:, 0])).sum()
    area = np.linalg.norm(np.cross(points[faces[:, 1]] - points[faces[:, 0]], points[faces[:, 2]] - points[faces[:, 0]]), axis=1)
    return int(repeated), int((area == 0).sum()), int((uses > 2).sum()), int((uses == 1).sum()), len(faces)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes"), parser.add_argument("offsets"), parser.add_argument("eps")
    parser.add_argument("--device", help="CLTESS_DEVICE for this run (e.g. pocl)")
    args = parser.parse_args()
    if args.device:
        os.environ["CLTESS_DEVICE"] = args.device
    from cltess.pipeline import Tessellator

    tessellator = Tessellator()
    for name in args.scenes.split(","):
        for offset in (float(x) for x in args.offsets.split(",")):
            scene, diagonal = translated_scene(ROOT / "scenes" / name, offset)
            step = float(np.spacing(np.float32(offset + 1.5)))
            for relative in (float(x) for x in args.eps.split(",")):
                eps = relative * diagonal
                print(name, offset, relative, f"steps={eps / step:.2f}", defects(tessellator.tessellate(scene, eps=eps)),
                      flush=True)


if __name__ == "__main__":
    main()

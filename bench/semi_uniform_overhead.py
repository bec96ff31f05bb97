"""Issue 11: the triangle overhead of dyadic edge levels against the transition pattern, at
equal eps: both tessellated by the pipeline (``pattern="semi_uniform"``, edge factors rounded up
to 2^p_e, p_e = min(ceil(log2 f_e), M), in stage 1).

    python bench/semi_uniform_overhead.py [--max-level 6]

SEEDS.md 1.3 expects about 2.2x for quads if log f is uniformly distributed.  The device is the
default one.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tests"))

from cltess.io import load_scene  # noqa: E402
from cltess.patterns import semi_uniform as su  # noqa: E402
from cltess.pipeline import Tessellator  # noqa: E402
from cltess.scene import Scene  # noqa: E402
from support import closed_torus_grid, genus2, icosphere, torus  # noqa: E402


def scenes():
    yield "sphere.bpt", load_scene(REPO / "scenes" / "sphere.bpt"), (1e-2, 1e-3, 1e-4)
    yield "teapot.bez", load_scene(REPO / "scenes" / "teapot.bez"), (1e-2, 1e-3)
    yield "torus grid 14x9", closed_torus_grid(np.random.default_rng(0), 14, 9, noise=0.15), (0.3, 0.1, 0.03)
    for name, mesh in (("PN icosphere(2)", icosphere(2)), ("PN torus", torus()), ("PN genus 2", genus2())):
        yield name, Scene.from_trimesh(mesh, name=name), (1e-2, 1e-3)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-level", type=int, default=su.DEFAULT_MAX_LEVEL)
    args = parser.parse_args(argv)
    tessellator = Tessellator()
    print(f"{'scene':18} {'eps':>7} {'patches':>8} {'transition':>11} {'semi-uniform':>13} {'ratio':>6}")
    for name, scene, tolerances in scenes():
        for eps in tolerances:
            transition = tessellator.tessellate(scene, eps=eps).num_triangles
            dyadic = tessellator.tessellate(scene, eps=eps, pattern="semi_uniform", max_level=args.max_level,
                                            max_factor=max(64, 1 << args.max_level)).num_triangles
            print(f"{name:18} {eps:7.0e} {scene.num_patches:8d} {transition:11d} {dyadic:13d} "
                  f"{dyadic / transition:6.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

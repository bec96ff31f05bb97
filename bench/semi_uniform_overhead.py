"""Issue 11: the triangle overhead of dyadic edge levels against today's transition pattern, at
equal eps (the same crack-free factors), before the pipeline runs the semi-uniform pattern.

    python bench/semi_uniform_overhead.py [--max-level 6]

For each scene and eps: the pipeline's final factors f_e (transition pattern, its triangle count
as emitted), then the semi-uniform records 2^p_e, p_e = min(ceil(log2 f_e), M), counted with the
pattern's closed forms (cltess/patterns/semi_uniform.py).  SEEDS.md 1.3 expects about 2.2x for
quads if log f is uniformly distributed.  Host only; the device is the default (PoCL here).
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
            tess = tessellator.tessellate(scene, eps=eps)
            bezier = scene.num_bezier
            records = su.dyadic_factors(tess.factors, args.max_level)
            dyadic = (su.counts(records[:bezier], "quad")[1].sum() + su.counts(records[bezier:], "tri")[1].sum()) // 3
            transition = len(tess.triangles)
            print(f"{name:18} {eps:7.0e} {len(records):8d} {transition:11d} {dyadic:13d} {dyadic / transition:6.2f}",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Which patch sets the worst steps of a bench/sd2_pops.py orbit, and in what state (issue 13;
docs/sd2.md section 5, "Seventh pass"): per worst step its patch, both frames' records (shape,
tip, segments, real factors, the hint's corner and phi), and in the tie zone w and lam.

    python bench/sd2_pops_worst.py TREE [--mesh icosphere] [--level-function depth] [--low 1]
                                        [--high 7] [--depth-range NEAR FAR] [--sweep 4] [--steps 4]
                                        [--top 3]

TREE: the repository whose cltess and bench/sd2_pops.py to use (this one, or a `git archive` of
another with `cltess/kernels -> ../kernels` linked).  The vertices measure of sd2_pops.py, at
--steps steps over --sweep degrees only.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("tree")
    parser.add_argument("--mesh", default="icosphere")
    parser.add_argument("--level-function", default="depth", choices=["depth", "silhouette", "bound"])
    parser.add_argument("--low", type=float, default=1.0)
    parser.add_argument("--high", type=float, default=7.0)
    parser.add_argument("--band", type=float, default=0.25)
    parser.add_argument("--depth-range", type=float, nargs=2, default=None)
    parser.add_argument("--sweep", type=float, default=4.0)
    parser.add_argument("--steps", type=int, default=4)
    parser.add_argument("--top", type=int, default=3)
    args = parser.parse_args(argv)
    sys.path.insert(0, args.tree)
    sys.path.insert(0, args.tree + "/bench")
    import sd2_pops as pops
    from cltess.backends.opencl import Tessellator
    from cltess.patterns.fractional import FIXED_ONE
    from cltess.patterns.sd2 import _Layout, sd2_hint

    def state(record) -> str:
        layout, hint = _Layout(record), sd2_hint(record)
        text = (f"{layout.shape} tip {layout.tip} segments {layout.n} factors {np.array(record[:3]) / FIXED_ONE} "
                f"hint {None if hint is None else (hint[0], hint[1] / FIXED_ONE)}")
        return text + (f" zone w {float(layout.w):.4f} lam {float(layout.lam):.4f}" if layout.zone else "")

    tessellator, scene = Tessellator(), pops.mesh(args.mesh)
    centre, radius, depth_range = pops.setting(scene)
    depth_range = depth_range if args.depth_range is None else args.depth_range
    frames, records = [], []
    for camera in pops.orbit(centre, radius, args.steps + 1, sweep_deg=args.sweep):
        scene.camera = camera
        plan = tessellator.plan(scene, **pops.frame_options(args.level_function, camera, args.low, args.high,
                                                            args.band, depth_range, 0.5))
        records.append(np.abs(plan.host_factors()))
        frames.append(tessellator.emit(plan, 0, plan.num_patches))
    worst = []
    for k in range(args.steps):
        distance, _ = pops.vertex_distance(frames[k], frames[k + 1], records[k], records[k + 1])
        worst += [(float(distance[p]), k, int(p)) for p in np.argsort(distance)[::-1][:args.top]]
    for distance, k, p in sorted(worst, reverse=True)[:2 * args.top]:
        print(f"step {k} patch {p} moves {distance:.5f}\n   before {state(records[k][p])}\n"
              f"   after  {state(records[k + 1][p])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

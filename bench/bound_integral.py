"""Request(bound="integral") and Request(bound="error-hull") against the hull bound (issue 9: the
rational scenes' measured ratio): triangles, worst measured deviation / eps and wall time, side
by side in one run (``--bounds``: which of the two).

Scenes: bench/occ_compare.py's 20 random rational patches (weights 0.2 to 5), the exact
rational torus and sphere (scenes/torus.bpt, sphere.bpt); eps 3e-2, 1e-2, 3e-3, 1e-3 of the
bounding-box diagonal.  The deviation is occ_compare.measured_deviation (float64, 28 points in
every triangle, at equal (u, v)).  Times: wall clock of ``Tessellator.plan`` + ``emit`` of the whole
scene, the best of ``--repeat`` runs after one untimed warm-up (which builds the programs and, for
"integral", the scene's majorant tables); "tables" is the wall time of making those tables once
(host, float64), which a scene pays on its first integral call only (error-hull has none: its
one-off host step, the centred nets, is in the warm-up too).

    python bench/bound_integral.py [--device pocl] [--repeat 3] [--json out.json] [--subpatch-levels 7]
                                   [--bounds integral error-hull]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from occ_compare import RELATIVE_EPS, diagonal, load_patches, measured_deviation  # noqa: E402


def run(tessellator, scene, patches, eps: float, bound: str, repeat: int) -> dict:
    tessellator.emit(*(lambda p: (p, 0, p.num_patches))(tessellator.plan(scene, eps=eps, max_factor=4096, bound=bound)))
    best = None
    for _ in range(repeat):
        start = time.perf_counter()
        plan = tessellator.plan(scene, eps=eps, max_factor=4096, bound=bound)
        tess = tessellator.emit(plan, 0, plan.num_patches)
        seconds = time.perf_counter() - start
        best = seconds if best is None else min(best, seconds)
    tris = tess.triangles.astype(np.int64)
    deviation = measured_deviation(patches, tess.positions, tess.uv, tess.patch_ids[tris[:, 0]], tris)
    prefix = bound.replace("-", "_") + "_"
    stats = {k[len(prefix):]: v for k, v in plan.stats.items() if k.startswith(prefix)}
    return {"bound": bound, "eps": eps, "triangles": int(len(tris)), "deviation": deviation,
            "ratio": deviation / eps, "seconds": best, **stats}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", help="OpenCL device (as for cltess --device)")
    parser.add_argument("--scenes", nargs="+", default=["random", "torus", "sphere"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--bounds", nargs="+", choices=("integral", "error-hull"), default=["integral", "error-hull"])
    parser.add_argument("--json", type=Path)
    parser.add_argument("--subpatch-levels", type=int,
                        help="2^this subpatches per side of the majorant tables (default: the engine's, 6)")
    args = parser.parse_args(argv)
    if args.subpatch_levels is not None:  # an experiment: the engine's constant, for this process
        import cltess.backends.opencl.integral as engine
        engine.SUBPATCH_LEVELS = args.subpatch_levels

    from cltess.backends.opencl.integral import integral_pyramids
    from cltess.pipeline import Tessellator
    from cltess.scene import Scene

    tessellator = Tessellator(device=args.device)
    print(f"device: {tessellator.device.name.strip()}\n")
    results = {"device": tessellator.device.name.strip(), "scenes": {}}
    print("| scene | eps / diag | bound | triangles | measured dev / eps | triangles / hull's | ms | hull ms "
          "| rounds | patches left at hull |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in args.scenes:
        patches = load_patches(name)
        size = diagonal(patches)
        scene = Scene(patches, np.zeros(len(patches), np.int32), name=name)
        tables = None
        if "integral" in args.bounds:
            start = time.perf_counter()
            integral_pyramids(tessellator, scene)
            tables = time.perf_counter() - start
        rows = []
        for rel in RELATIVE_EPS:
            hull = run(tessellator, scene, patches, rel * size, "hull", args.repeat)
            print(f"| {name} ({len(patches)}) | {rel:g} | hull | {hull['triangles']:,} | {hull['ratio']:.3f} | 1 | "
                  f"{hull['seconds'] * 1e3:.1f} | {hull['seconds'] * 1e3:.1f} | | |", flush=True)
            row = {"hull": hull}
            for bound in args.bounds:
                tight = row[bound] = run(tessellator, scene, patches, rel * size, bound, args.repeat)
                print(f"| {name} ({len(patches)}) | {rel:g} | {bound} | {tight['triangles']:,} | {tight['ratio']:.3f} | "
                      f"{tight['triangles'] / hull['triangles']:.3f} | {tight['seconds'] * 1e3:.1f} | "
                      f"{hull['seconds'] * 1e3:.1f} | {tight['rounds']} | {tight['at_hull']} of {tight['patches']} |",
                      flush=True)
            rows.append(row)
        results["scenes"][name] = {"diagonal": size, "tables_seconds": tables, "runs": rows}
        if tables is not None:
            print(f"| {name}: majorant tables | | integral | | | | {tables * 1e3:.0f} (once per scene) | | | |", flush=True)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()

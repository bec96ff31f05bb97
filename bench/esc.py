"""The structure of Table 1 of Hu et al., "ESC: free adaptive tessellation of Bezier surfaces"
(GRAPP 2014; /work/shared/SEEDS.md section 4.2) with cltess's ESC pattern (docs/esc.md), plus
what the paper could not show: triangles against measured error for ESC, Zheng-Sederberg factors
and uniform tessellation.

    python bench/esc.py [--device NAME] [--repeat 3] [--big 8110] [--json OUT] [--plot PNG] [--csv OUT]
    python bench/esc.py --levels [--device NAME] [--repeat 3] [--big 8110] [--json OUT]

Scenes: Teacups = 100 copies of scenes/teacup.bez on a 10 x 10 grid (translated only, 2,600
patches) and an 8,110-patch substitute for the paper's Elephants (bigguy.bez copies,
cltess.bench.scenes.bigguy_copies).  L = 3: the non-adaptive count is 288 triangles per patch.

Rows per scene:
  non-adaptive   ESC with every candidate inserted (eps 1e-9)
  high, medium   ESC at the eps (found by bisection on the triangle count) giving about 93.6 %
                 and 52 % of it, as the paper's "high" and "medium"
  ZS @ equal     the transition pattern with Zheng-Sederberg factors (cltess's default) at the
                 eps giving about the same triangle count
  uniform 12     the transition pattern with every factor 12 (12 x 12 per patch = 288 triangles)

Error: max |S(u, v) - mesh(u, v)| over order-4 barycentric samples of the triangles
(cltess.bound.worst_bound_ratio with eps = 1, so in object units), all triangles of one teacup
copy at the scene's eps for Teacups (every copy is the same mesh up to translation), every k-th
triangle of the big scene (at most --error-triangles; a sampled maximum, so a lower bound).
"dev/eps" is that deviation over the eps the row was made with.

Per-patch levels (--levels; docs/esc.md decision 5): ESC as it is (each patch tests the
candidates of its own level L_p from the Zheng-Sederberg factor, on the L = 3 lattice) against
esc.ESC_ONE_LEVEL (every patch at L = 3, one level per run, as before), at the Table 1 eps of each
scene (the "high" and "medium" of bench/RESULTS.md, issue 14) and coarser ones: triangles, the
patches' levels, the measured deviation / eps (as above), device ms of stages 1-5 (strips
included) and of stage 1 alone, medians of --repeat.

Evaluators (step 1 of issue 14): direct Bernstein, NBM-Horner and forward differencing on a
13 x 13 grid of every Teacups patch (kernels/esc/evaluate_grid.cl): kernel time (profiling, best
of --repeat) and the max error against float64 relative to the teacup's size.

Times: device milliseconds of stages 1-5 (OpenCL profiling events, their spans summed; the
read-backs to the host not included), median of --repeat runs after one warm-up, on the device
named (--device; default cltess's default device).  Forward differencing is on for the transition
rows; ESC evaluates its vertices directly (its rows are not equally spaced).
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from cltess.bench.scenes import affine, bigguy_copies, transform_patches  # noqa: E402
from cltess.bound import worst_bound_ratio  # noqa: E402
from cltess.io import load_scene  # noqa: E402
from cltess.request import Request  # noqa: E402
from cltess.scene import Scene  # noqa: E402

TIGHT = 1e-9  # an eps no candidate meets: every candidate inserted, every factor at its cap


def teacups(copies: int = 100) -> tuple[Scene, Scene]:
    """(Teacups: `copies` teacups on a grid, one teacup) - the paper's 100 x 26 = 2,600 patches."""
    cup = load_scene(REPO / "scenes" / "teacup.bez")
    side = math.ceil(math.sqrt(copies))
    chunks, ids = [], []
    for k in range(copies):
        row, col = divmod(k, side)
        chunks.append(transform_patches(cup.patches, affine(translate=(8.0 * col, 8.0 * row, 0.0))))
        ids.append(np.full(cup.num_patches, k, np.int32))
    return Scene(np.concatenate(chunks), np.concatenate(ids), name=f"Teacups ({copies} x teacup)"), cup


def plan_triangles(tessellator, scene, request) -> int:
    return tessellator.plan(scene, request).num_indices // 3


def eps_for_count(tessellator, scene, make_request, target: int, lo: float, hi: float, steps: int = 22):
    """(eps, triangles) with the count nearest `target` found by bisection of log eps in [lo, hi]
    (counts fall as eps grows: monotone for ESC, nearly so for ZS factors)."""
    best = None
    for _ in range(steps):
        mid = math.sqrt(lo * hi)
        count = plan_triangles(tessellator, scene, make_request(mid))
        if best is None or abs(count - target) < abs(best[1] - target):
            best = (mid, count)
        if count > target:
            lo = mid
        else:
            hi = mid
    return best


def deviation(scene, tess, sample_triangles: int | None) -> float:
    """Max |surface - mesh| in object units (worst_bound_ratio at eps = 1)."""
    return worst_bound_ratio(scene, tess, eps=1.0, max_triangles=sample_triangles)


def device_ms(tess) -> float:
    return sum(ms for stage, ms in tess.stage_ms.items() if stage != "total_wall")


def timed(tessellator, scene, request, repeat: int):
    """(median device ms, last Tessellation) of `repeat` runs after a warm-up."""
    run = lambda: tessellator.tessellate(scene, request)  # noqa: E731
    run()
    times, tess = [], None
    for _ in range(repeat):
        tess = run()
        times.append(device_ms(tess))
    return float(np.median(times)), tess


def esc_request(eps):
    return Request.of(eps=eps, pattern="esc", max_level=3)


def zs_request(eps):
    return Request.of(eps=eps)


def evaluators(tessellator, patches, n: int, repeat: int) -> list[dict]:
    """Device ms of the three evaluators on an n x n grid per patch (cltess/esc/evaluate.py), and
    their max error against float64 relative to the patches' size (one teacup's patches)."""
    from cltess.esc.evaluate import evaluate_grid
    from cltess.surfaces.bezier import evaluate

    t = np.linspace(0, 1, n + 1)
    u, v = np.meshgrid(t, t)
    exact = np.stack([evaluate(p, u.ravel(), v.ravel())[0] for p in patches[:26]]).reshape(-1, n + 1, n + 1, 3)
    scale = np.abs(exact).max()
    rows = []
    for method in ("direct", "nbm", "fd"):
        evaluate_grid(tessellator.queue, patches, n, method)  # build, warm up
        positions, _, seconds = evaluate_grid(tessellator.queue, patches, n, method, repeat=repeat)
        error = float(np.abs(positions[:26] - exact).max() / scale)
        rows.append({"method": method, "patches": len(patches), "points": len(patches) * (n + 1) ** 2,
                     "device_ms": seconds * 1e3, "relative_error": error})
        print(f"  {method:<7} {rows[-1]['points']:>10,} points  {seconds * 1e3:8.2f} ms  max error / size {error:.2e}",
              flush=True)
    return rows


def table(tessellator, scene, error_scene, repeat: int, sample_triangles, diagonal: float) -> list[dict]:
    """The Table 1 rows of one scene.  error_scene: the scene whose mesh the errors are measured
    on (one teacup for Teacups, the scene itself otherwise)."""
    rows = []
    full = plan_triangles(tessellator, scene, esc_request(TIGHT))
    assert full == 288 * scene.num_patches, (full, scene.num_patches)

    def row(name, request, eps, target=None):
        ms, tess = timed(tessellator, scene, request, repeat)
        measured = tess if error_scene is scene else tessellator.tessellate(error_scene, request)
        dev = deviation(error_scene, measured, sample_triangles)
        rows.append({"scene": scene.name, "row": name, "eps": eps, "triangles": len(tess.triangles),
                     "percent": 100.0 * len(tess.triangles) / full, "target_percent": target,
                     "max_dev": dev, "dev_over_eps": dev / eps if eps and eps > TIGHT else None,
                     "device_ms": ms, "patches": scene.num_patches})
        print_row(rows[-1])

    row("ESC non-adaptive", esc_request(TIGHT), None)
    for name, share in (("ESC high", 0.936), ("ESC medium", 0.52)):
        eps, _ = eps_for_count(tessellator, scene, esc_request, round(share * full), 1e-7 * diagonal, diagonal)
        row(name, esc_request(eps), eps, 100 * share)
        count = rows[-1]["triangles"]
        zs_eps, _ = eps_for_count(tessellator, scene, zs_request, count, 1e-7 * diagonal, diagonal)
        row(f"ZS @ equal ({name[4:]})", zs_request(zs_eps), zs_eps)
    row("uniform 12 (transition)", Request.of(eps=TIGHT, max_factor=12), None)
    return rows


def curves(tessellator, scene, sample_triangles, diagonal: float) -> list[dict]:
    """Triangles against measured error: ESC over eps, ZS factors over eps, uniform k x k."""
    points = []
    for eps in diagonal * np.logspace(-5.0, -1.0, 9):
        for method, request in (("ESC (L=3)", esc_request(float(eps))), ("ZS factors", zs_request(float(eps)))):
            tess = tessellator.tessellate(scene, request)
            points.append({"method": method, "eps": float(eps), "triangles": len(tess.triangles),
                           "max_dev": deviation(scene, tess, sample_triangles)})
    for k in range(1, 17):
        tess = tessellator.tessellate(scene, Request.of(eps=TIGHT, max_factor=k))
        points.append({"method": "uniform k x k", "eps": None, "k": k, "triangles": len(tess.triangles),
                       "max_dev": deviation(scene, tess, sample_triangles)})
    return points


#: The eps of the per-patch level comparison, as fractions of what Table 1 found (RESULTS.md,
#: issue 14): Teacups "high" 0.00412, "medium" 0.0142; bigguy 8,110 "high" 0.000237, "medium" 0.000747.
LEVEL_EPS = {"teacups": (0.00412, 0.0142, 0.03, 0.06), "bigguy": (0.000237, 0.000747, 0.002, 0.005)}


def stage_ms(tessellator, scene, request, repeat: int) -> tuple[float, float, object]:
    """(median device ms of stages 1-5, median ms of stage 1, last Tessellation) after a warm-up."""
    tessellator.tessellate(scene, request)
    totals, firsts, tess = [], [], None
    for _ in range(repeat):
        tess = tessellator.tessellate(scene, request)
        totals.append(device_ms(tess))
        firsts.append(tess.stage_ms["factors"])
    return float(np.median(totals)), float(np.median(firsts)), tess


STAGE_EPS = (("high", 0.00412), ("medium", 0.0142), ("non-adaptive", TIGHT))
STAGES = ("factors", "crack_free", "counts", "vertices", "indices", "strips")


def stage_rows(tessellator, scene, repeat: int) -> list[dict]:
    """ESC's stages on Teacups (--stages): counts, triangles and strips from the tables (esc, as it
    is) against the walk (esc.ESC_WALK, the build before the tables), each stage's median device
    ms of --repeat runs after a warm-up, both in this run; the same strips and triangles asserted."""
    from cltess.patterns import PATTERNS
    from cltess.patterns.esc import ESC_WALK
    PATTERNS.setdefault(ESC_WALK.name, ESC_WALK)  # not in the registry: the baseline only
    rows = []
    print(f"  {'eps':<14} {'counts':<8} {'triangles':>10} {'strip idx':>10}  " +
          " ".join(f"{s:>9}" for s in STAGES) + f" {'stages 1-5':>10}")
    for label, eps in STAGE_EPS:
        results = {}
        for counts, pattern in (("walk", ESC_WALK.name), ("table", "esc")):
            request = Request.of(eps=eps, pattern=pattern, max_level=3)
            tessellator.tessellate(scene, request)
            runs = [tessellator.tessellate(scene, request) for _ in range(repeat)]
            tess = runs[-1]
            results[counts] = tess
            ms = {s: float(np.median([r.stage_ms.get(s, 0.0) for r in runs])) for s in STAGES}
            row = {"eps": label, "counts": counts, "triangles": len(tess.triangles), "strip_indices": len(tess.strips),
                   "stage_ms": ms, "device_ms": float(np.median([device_ms(r) for r in runs]))}
            rows.append(row)
            print(f"  {label:<14} {counts:<8} {row['triangles']:>10,} {row['strip_indices']:>10,}  " +
                  " ".join(f"{ms[s]:>9.2f}" for s in STAGES) + f" {row['device_ms']:>10.2f}")
        assert np.array_equal(results["walk"].strips, results["table"].strips)
        assert np.array_equal(results["walk"].triangles, results["table"].triangles)
    return rows


def level_rows(tessellator, scene, error_scene, eps_values, repeat: int, sample_triangles) -> list[dict]:
    """Per-patch levels against one level per run at each eps (module docstring)."""
    from cltess.criteria.zheng_sederberg import zs_factors
    from cltess.esc.masks import patch_levels
    from cltess.patterns import PATTERNS
    from cltess.patterns.esc import ESC_ONE_LEVEL

    PATTERNS.setdefault(ESC_ONE_LEVEL.name, ESC_ONE_LEVEL)  # not in the registry: the baseline only
    patches = np.asarray(scene.patches, np.float64).reshape(-1, 4, 4, 4)
    points = (patches[..., :3] / patches[..., 3:]).reshape(len(patches), -1, 3)
    rows = []
    for eps in eps_values:
        tolerance = Request.of(eps=eps).tolerance_for(scene)
        bound_eps, culled = tolerance.reference(points.min(axis=1), points.max(axis=1))
        levels = np.bincount(patch_levels(zs_factors(patches, bound_eps, culled)[0], 3), minlength=4)
        for name, pattern in (("per-patch L_p", "esc"), ("one L = 3", ESC_ONE_LEVEL.name)):
            request = Request.of(eps=eps, pattern=pattern, max_level=3)
            total, first, tess = stage_ms(tessellator, scene, request, repeat)
            measured = tess if error_scene is scene else tessellator.tessellate(error_scene, request)
            dev = deviation(error_scene, measured, sample_triangles)
            rows.append({"scene": scene.name, "row": name, "eps": eps, "triangles": len(tess.triangles),
                         "levels_0_1_3": [int(levels[0]), int(levels[1]), int(levels[3])] if pattern == "esc" else None,
                         "max_dev": dev, "dev_over_eps": dev / eps, "device_ms": total, "stage1_ms": first,
                         "strip_indices": len(tess.strips)})
            r = rows[-1]
            shown = f"L_p 0/1/3: {r['levels_0_1_3']}" if r["levels_0_1_3"] else ""
            print(f"  eps {eps:<9.3g} {name:<14} tris {r['triangles']:>9,}  dev/eps {r['dev_over_eps']:6.2f}  "
                  f"device {total:8.2f} ms  stage 1 {first:6.2f} ms  {shown}", flush=True)
    return rows


def print_row(r: dict) -> None:
    eps = f"{r['eps']:.3g}" if r["eps"] else "-"
    ratio = f"{r['dev_over_eps']:.2f}" if r["dev_over_eps"] is not None else "-"
    print(f"  {r['row']:<26} eps {eps:>9}  tris {r['triangles']:>9,}  {r['percent']:6.2f} %  "
          f"max dev {r['max_dev']:.3g}  dev/eps {ratio:>6}  device {r['device_ms']:8.2f} ms", flush=True)


def plot(points, path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for method, marker in (("ESC (L=3)", "o"), ("ZS factors", "s"), ("uniform k x k", "^")):
        pts = sorted((p["triangles"], p["max_dev"]) for p in points if p["method"] == method)
        ax.loglog([t for t, _ in pts], [d for _, d in pts], marker=marker, label=method)
    ax.set_xlabel("triangles")
    ax.set_ylabel("measured max |surface - mesh| (object units)")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", default=None, help="OpenCL device (cltess devices)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--big", type=int, default=8110, help="patches of the bigguy scene (0: skip it)")
    parser.add_argument("--error-triangles", type=int, default=100_000,
                        help="the big scene's error: every k-th triangle, at most this many")
    parser.add_argument("--evaluators-only", action="store_true", help="only the evaluator timings")
    parser.add_argument("--levels", action="store_true",
                        help="only per-patch levels against one level per run (docs/esc.md decision 5)")
    parser.add_argument("--stages", action="store_true",
                        help="only ESC's stage times on Teacups, from the tables against the walk")
    parser.add_argument("--json", type=Path)
    parser.add_argument("--csv", type=Path, help="the triangles-against-error points")
    parser.add_argument("--plot", type=Path, help="PNG of triangles against error (needs matplotlib)")
    args = parser.parse_args(argv)

    from cltess.pipeline import Tessellator

    tessellator = Tessellator(args.device)
    print(f"device: {tessellator.device.name.strip()}")
    started = time.perf_counter()
    cups, cup = teacups()
    if args.stages:
        print(cups.name, cups.num_patches, "patches; device ms per stage, median of", args.repeat)
        rows = stage_rows(tessellator, cups, args.repeat)
        if args.json:
            args.json.write_text(json.dumps({"device": tessellator.device.name.strip(), "stages": rows}, indent=1))
        print(f"wall {time.perf_counter() - started:.0f} s")
        return 0
    if args.levels:
        print(cups.name, cups.num_patches, "patches; error on one teacup")
        rows = level_rows(tessellator, cups, cup, LEVEL_EPS["teacups"], args.repeat, None)
        if args.big:
            big = bigguy_copies(args.big)
            print(big.name, big.num_patches, "patches")
            rows += level_rows(tessellator, big, big, LEVEL_EPS["bigguy"], args.repeat, args.error_triangles)
        if args.json:
            args.json.write_text(json.dumps({"device": tessellator.device.name.strip(), "levels": rows}, indent=1))
        print(f"wall {time.perf_counter() - started:.0f} s")
        return 0
    print("evaluators, 13 x 13 points per patch, Teacups' 2,600 patches (best of --repeat, kernel only):")
    timings = evaluators(tessellator, cups.patches, 12, args.repeat)
    if args.evaluators_only:
        return 0
    rows = []
    print(cups.name, cups.num_patches, "patches")
    rows += table(tessellator, cups, cup, args.repeat, None, cup.diagonal)
    if args.big:
        big = bigguy_copies(args.big)
        print(big.name, big.num_patches, "patches")
        rows += table(tessellator, big, big, args.repeat, args.error_triangles, big.diagonal / math.sqrt(big.num_patches / 3570))
    points = curves(tessellator, cup, None, cup.diagonal)
    print("\ntriangles against measured error, one teacup:")
    print(f"  {'method':<16} {'eps':>9} {'k':>3} {'triangles':>10} {'max dev':>10}")
    for p in points:
        eps = f"{p['eps']:.3g}" if p["eps"] else "-"
        print(f"  {p['method']:<16} {eps:>9} {p.get('k', ''):>3} {p['triangles']:>10,} {p['max_dev']:>10.3g}")
    if args.csv:
        with open(args.csv, "w", newline="") as out:
            writer = csv.DictWriter(out, ["method", "eps", "k", "triangles", "max_dev"])
            writer.writeheader()
            writer.writerows(points)
    if args.plot:
        plot(points, args.plot, f"teacup (26 patches): triangles against measured error, {tessellator.device.name.strip()}")
    if args.json:
        args.json.write_text(json.dumps({"device": tessellator.device.name.strip(), "evaluators": timings, "rows": rows,
                                         "curve": points},
                                        indent=1))
    print(f"wall {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

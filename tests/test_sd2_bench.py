"""Smoke test of bench/sd2.py: the paper's base sizes, uniform factor 7 exactly 49 x base, and
SD-2 against the transition pattern on the same factors as in the paper (about 1.1x)."""
import numpy as np

from support import ROOT, load_script

BENCH = ROOT / "bench" / "sd2.py"


def load_bench():
    return load_script(BENCH, "bench_sd2")


def test_scenes_have_the_papers_sizes_and_a_camera():
    bench = load_bench()
    sizes = [scene.num_triangles for scene in bench.scenes()]
    assert sizes == [320, 2120, 5796] and all(scene.camera is not None for scene in bench.scenes())


def test_sphere_rows(tessellator):
    bench = load_bench()
    rows = bench.measure(tessellator, bench.scenes()[0], [5.0], repeat=1)
    by = {row["method"]: row for row in rows}
    assert by["uniform 7"]["triangles"] == 49 * 320
    sd2, stitch = by["sd2 a=5"], by["transition a=5"]
    assert 1.0 < sd2["triangles"] / stitch["triangles"] < 1.15
    assert sd2["strip_bytes"] < sd2["list_bytes"] and np.isfinite([r["ms"] for r in rows]).all()
    assert 0 < sd2["error"] < 0.01 and "| sphere-320 (320) | sd2 a=5 |" in bench.table(rows)

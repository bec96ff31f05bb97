"""Smoke tests of the benchmark suite (cltess.bench, ``cltess bench``, bench/plot.py).

They run the suite on its smallest scenes with one timed run, so that the generators, the
runner, the baselines, the tables, the JSON and the plot cannot rot; they check no speed.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyopencl as cl
import pytest

from cltess import bench
from cltess.cli import main
from cltess.reference import evaluate
from support import random_patches

REPO = Path(__file__).resolve().parents[1]


def test_pn_generators_have_the_papers_sizes_and_unit_normals():
    sizes = {"double_torus": 1_536, "elephant": 21_540, "star_field": 41_496, "model_zoo": 80_578}
    for key, size in sizes.items():
        mesh, _ = bench.SUITE[key].build()
        assert len(mesh.faces) == size == bench.PAPER_PN[key]["patches"], key
        normals = np.asarray(mesh.vertex_normals)
        assert normals.shape == mesh.vertices.shape
        np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-6)
        camera = bench.mesh_camera(mesh, closeup=key == "star_field")
        assert (camera.width, camera.height) == (1024, 768)


def test_sphere_field_is_exact_spheres_with_a_camera():
    scene = bench.sphere_field(count=8)
    assert scene.num_patches == 8 * 32 and scene.camera is not None
    assert set(np.unique(scene.object_ids)) == set(range(8))
    # every control point's image stays on its sphere: evaluate a few surface points
    points = scene.points.reshape(8, -1, 3)
    centre = (points.min(axis=1) + points.max(axis=1)) / 2
    u = np.linspace(0.1, 0.9, 5)
    for p in range(0, scene.num_patches, 37):
        position, _ = evaluate(scene.patches[p], u, u[::-1])
        radius = np.linalg.norm(position - centre[scene.object_ids[p]], axis=1)
        np.testing.assert_allclose(radius, radius[0], rtol=1e-9)


def test_numpy_baseline_matches_the_reference(rng):
    patches = random_patches(rng, 6)
    patch_ids = rng.integers(0, 6, 200)
    uv = rng.uniform(0, 1, (200, 2))
    positions, normals = bench.numpy_evaluate(patches, patch_ids, uv, chunk=64)
    for n in range(0, 200, 17):
        p, nrm = evaluate(patches[patch_ids[n]], uv[n, :1], uv[n, 1:])
        np.testing.assert_allclose(positions[n], p[0], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(normals[n], nrm[0], atol=1e-7)


def test_allocation_tracker_counts_live_buffers_and_restores_pyopencl():
    original = cl.Buffer
    context = cl.create_some_context(interactive=False)
    with bench.AllocationTracker() as tracker:
        a = cl.Buffer(context, cl.mem_flags.READ_WRITE, 1000)
        b = cl.Buffer(context, cl.mem_flags.READ_WRITE, 500)
        del a
        c = cl.Buffer(context, cl.mem_flags.READ_WRITE, 200)
    assert cl.Buffer is original
    assert tracker.peak == 1500 and tracker.total == 1700 and tracker.count == 3
    del b, c


def test_resolve_scenes():
    assert bench.resolve_scenes(["small"]) == ["tea_table", "double_torus"]
    assert bench.resolve_scenes(["spheres-closeup", "tea_table"]) == ["tea_table", "spheres_closeup"]
    assert bench.resolve_scenes([]) == list(bench.SUITE)
    with pytest.raises(ValueError, match="unknown bench scene"):
        bench.resolve_scenes(["teapot"])


@pytest.fixture(scope="module")
def small_suite():
    return bench.run_suite(["small"], repeat=1, warmup=1, progress=bench.Progress(enabled=False),
                           bandwidth_bytes=16 << 20)


def test_suite_on_the_smallest_scenes(small_suite, tmp_path):
    record = small_suite
    tea = next(s for s in record["scenes"] if s["key"] == "tea_table")
    assert tea["stats"]["patches"] == 332 and tea["stats"]["triangles"] > 10_000
    assert tea["stats"]["indices"] == 3 * tea["stats"]["triangles"]
    for variant in ("fd", "direct"):
        for stage in ("factors", "crack_free", "counts", "vertices", "indices", "offsets", "total_wall"):
            assert tea[variant][stage]["median"] >= 0, (variant, stage)
    assert tea["fd"]["total_wall"]["median"] >= tea["fd"]["device_total"]["median"] * 0.5
    assert tea["peak_device_bytes"] >= tea["output_bytes"]  # outputs live on the device at once
    assert tea["numpy"]["max_position_error_rel"] < 1e-5
    assert tea["triangles_per_s"] > 0 and 0 < tea["bandwidth_fraction"] < 1
    torus = [s for s in record["scenes"] if s["key"] == "double_torus"]
    skipped = [s for s in record["skipped"] if s["key"] == "double_torus"]
    assert len(torus) + len(skipped) == 1  # run if the pipeline takes meshes, else skipped, with why
    assert all(s["reason"] for s in skipped)
    for scene in torus:  # the PN baseline evaluates the same surface
        assert scene["numpy"]["max_position_error_rel"] < 1e-5 and scene["numpy"]["normals_off_by_0_1"] == 0

    tables = bench.format_tables(record)
    assert "Table 1" in tables and "| Tea table | 332 (332) |" in tables
    assert "(0.39, " in tables  # the paper's factors figure beside ours
    path = tmp_path / "suite.json"
    bench.write_json(record, path)
    assert json.loads(path.read_text())["scenes"][0]["key"] == "tea_table"


def test_plot(small_suite, tmp_path):
    pytest.importorskip("matplotlib")
    path = tmp_path / "suite.json"
    bench.write_json(small_suite, path)
    png = tmp_path / "plot.png"
    done = subprocess.run([sys.executable, str(REPO / "bench" / "plot.py"), str(png), f"PoCL={path}"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_bench(tmp_path, capsys):
    out = tmp_path / "b.json"
    assert main(["bench", "tea_table", "--repeat", "1", "--warmup", "0", "--no-baseline", "-q",
                 "--json", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "| Tea table |" in printed and "vertices FD" in printed
    record = json.loads(out.read_text())
    assert record["device"]["name"] and record["scenes"][0]["stats"]["patches"] == 332
    assert main(["bench", "no_such_scene"]) == 2
    assert main(["bench", "--json", str(tmp_path / "missing" / "x.json")]) == 2

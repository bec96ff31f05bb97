"""Issue 9, host side: no tracebacks on any input (item 5), no non-finite output (item 4), no
size the kernels cannot hold (item 1), bounded and named file handling (item 7), signals
(item 6).  Each refusal is checked on the command line where the user meets it: exit code,
``cltess: error: <file>: <where>: ...``, no output file and no temporary file left behind.
"""
from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from cltess import limits, reference
from cltess.cli import build_parser, main, UsageError
from cltess.device import DEVICE_ENV_VAR
from cltess.io import load_scene
from cltess.scene import Scene, SceneError

REPO = Path(__file__).resolve().parents[1]
TEAPOT = REPO / "scenes" / "teapot.bez"
FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture(autouse=True)
def no_device_env(monkeypatch):
    monkeypatch.delenv(DEVICE_ENV_VAR, raising=False)


def bpt_lines(weights: bool = False) -> list[str]:
    points = [f"{i / 3} {j / 3} {0.1 * (i - 1.5) ** 2}" + (" 1.5" if weights else "")
              for j in range(4) for i in range(4)]
    return ["1", "3 3", *points]


def bez_lines() -> list[str]:
    return ["1", ",".join(map(str, range(1, 17))), "16",
            *(f"{i},{j},{(i * j) % 3 * 0.1}" for j in range(4) for i in range(4))]


def run_cli(capsys, *argv) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


def assert_refused(code: int, err: str, fragments, expected_code: int = 2) -> None:
    assert code == expected_code, err
    assert "Traceback" not in err, err
    assert err.count("cltess: error: ") == 1, err
    for fragment in fragments:
        assert fragment in err, f"{fragment!r} not in {err!r}"


def assert_nothing_written(folder: Path) -> None:
    assert [p.name for p in folder.iterdir()] == [], "an output or temporary file was left behind"


def load_or_scene_error(path: Path):
    """load_scene's only way to fail is a SceneError naming the file."""
    try:
        return load_scene(path)
    except SceneError as error:
        assert str(error).startswith(str(path)), error
        return None


# --------------------------------------------------------------------------- item 5: tracebacks

#: Tokens worth putting where a number goes: Unicode digits and spaces, numpy-only spellings.
ODD_TOKENS = st.sampled_from(["\uff11", "\u0661.5", "1\u00a02", "1_0", "0x10", "1e", "nan", "-inf",
                              "\u2003", "1e400", "1e-400", "+", ".", "\x0c", "\x1c", "\u2028", "١٢٣",
                              "9" * 400, "1" * 5000, "0.5\u200b", "²", "½", "1d0", "--1", "1e+"])


@FUZZ
@given(line=st.integers(0, 17), column=st.integers(0, 3),
       token=st.one_of(ODD_TOKENS, st.text(max_size=12)), weights=st.booleans())
def test_bpt_with_any_token_loads_or_is_refused_by_name(tmp_path_factory, line, column, token, weights):
    lines = bpt_lines(weights)
    fields = lines[line].split()
    fields[min(column, len(fields) - 1)] = token
    lines[line] = " ".join(fields)
    path = tmp_path_factory.mktemp("bpt") / "s.bpt"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8", errors="surrogatepass") \
        if not any(0xD800 <= ord(c) <= 0xDFFF for c in token) else path.write_bytes(b"\xed\xa0\x80")
    load_or_scene_error(path)


@FUZZ
@given(line=st.integers(0, 18), column=st.integers(0, 15), token=st.one_of(ODD_TOKENS, st.text(max_size=12)))
def test_bez_with_any_token_loads_or_is_refused_by_name(tmp_path_factory, line, column, token):
    assume(not any(0xD800 <= ord(c) <= 0xDFFF for c in token))
    lines = bez_lines()
    fields = lines[line].split(",")
    fields[min(column, len(fields) - 1)] = token
    lines[line] = ",".join(fields)
    path = tmp_path_factory.mktemp("bez") / "s.bez"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    load_or_scene_error(path)


@FUZZ
@given(data=st.binary(max_size=400), suffix=st.sampled_from([".bpt", ".bez", ".json"]))
def test_any_bytes_load_or_are_refused_by_name(tmp_path_factory, data, suffix):
    path = tmp_path_factory.mktemp("bytes") / f"s{suffix}"
    path.write_bytes(data)
    load_or_scene_error(path)


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-(10**400), 10**400) | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda children: st.lists(children, max_size=5) | st.dictionaries(st.text(max_size=8), children, max_size=4),
    max_leaves=12)


def _json_slots(doc):
    """Every (container, key) of a JSON document."""
    if isinstance(doc, dict):
        for key, value in doc.items():
            yield doc, key
            yield from _json_slots(value)
    elif isinstance(doc, list):
        for k, value in enumerate(doc):
            yield doc, k
            yield from _json_slots(value)


@FUZZ
@given(slot=st.integers(0, 200), value=JSON_VALUES)
def test_json_with_any_value_loads_or_is_refused_by_name(tmp_path_factory, slot, value):
    folder = tmp_path_factory.mktemp("json")
    (folder / "p.bpt").write_text("\n".join(bpt_lines()) + "\n")
    doc = {"objects": [{"file": "p.bpt", "object_id": 3,
                        "transform": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}],
           "camera": {"eye": [0, -5, 1], "target": [0, 0, 0], "up": [0, 0, 1], "fov_y_deg": 40,
                      "width": 64, "height": 48, "near": 0.1, "far": 100}}
    slots = list(_json_slots(doc))
    container, key = slots[slot % len(slots)]
    container[key] = value
    path = folder / "s.json"
    path.write_text(json.dumps(doc))
    load_or_scene_error(path)


def test_full_width_digit_in_bpt_names_file_and_line(capsys, tmp_path):
    lines = bpt_lines()
    lines[5] = "\uff10.5 0.5 0"
    scene = tmp_path / "s.bpt"
    scene.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", out / "m.ply")
    assert_refused(code, err, [f"{scene}: line 6", "not a number", "\uff10.5"])
    assert_nothing_written(out)


def test_json_integer_too_large_for_a_float_is_refused_by_key(capsys, tmp_path):
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps({"objects": [{"file": str(TEAPOT)}],
                                 "camera": {"eye": [0, 0, 10**400], "target": [0, 0, 0]}}))
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", out / "m.ply")
    assert_refused(code, err, [f"{scene}: camera.eye", "finite"])
    assert_nothing_written(out)


@pytest.mark.parametrize("value", ["2147483648", "65536", str(limits.MAX_FACTOR + 1), "9" * 30])
def test_max_factor_beyond_the_kernels_integers_exits_2(capsys, tmp_path, value):
    scene = tmp_path / "s.bpt"
    scene.write_text("\n".join(bpt_lines()) + "\n")
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "--max-factor", value, "-o", out / "m.ply")
    assert_refused(code, err, ["--max-factor", f"1..{limits.MAX_FACTOR}", "32-bit"])
    assert_nothing_written(out)


@settings(max_examples=300, deadline=None)
@given(eps=st.text(max_size=12), max_factor=st.text(max_size=12), memory=st.text(max_size=12))
def test_any_option_text_parses_or_is_a_usage_error(eps, max_factor, memory):
    arguments = ["tessellate", "s.bpt", "-o", "m.ply", "--eps", eps, "--max-factor", max_factor,
                 "--max-memory", memory]
    assume(not any(a.startswith("-") and a not in ("--eps", "--max-factor", "--max-memory", "-o")
                   for a in (eps, max_factor, memory)))
    try:
        args = build_parser().parse_args(arguments)
    except UsageError:
        return
    assert math.isfinite(args.eps) and args.eps > 0
    assert 1 <= args.max_factor <= limits.MAX_FACTOR
    assert 0 < args.max_memory < 2**63


@pytest.mark.parametrize("value", [0, limits.MAX_FACTOR + 1, 2**31, 2.5, True])
def test_api_refuses_a_max_factor_the_kernels_cannot_hold(tessellator, value):
    scene = load_scene(TEAPOT)
    with pytest.raises(ValueError, match="max_factor must be"):
        tessellator.tessellate(scene, eps=0.01, max_factor=value)


# --------------------------------------------------------------------------- item 4: non-finite output


def tetrahedron_stl(path: Path, flip: tuple[int, int] | None = None) -> Path:
    """A binary STL tetrahedron; ``flip`` = (triangle, float) sets that float's exponent byte
    to 0x7e (about 1.7e38: finite in float32, but not once squared or summed)."""
    import trimesh

    mesh = trimesh.creation.box().subdivide()
    data = bytearray(trimesh.exchange.stl.export_stl(mesh))
    if flip is not None:
        triangle, value = flip
        at = 84 + 50 * triangle + 12 + 4 * value + 3  # skip the facet normal; the float's top byte
        data[at] = 0x7E
    path.write_bytes(bytes(data))
    return path


def json_scene(folder: Path, transform) -> Path:
    (folder / "p.bpt").write_text("\n".join(bpt_lines()) + "\n")
    path = folder / "s.json"
    path.write_text(json.dumps({"objects": [{"file": "p.bpt", "transform": transform}]}))
    return path


def bpt_with_line(folder: Path, line: int, text: str, weights: bool = False) -> Path:
    lines = bpt_lines(weights)
    lines[line - 1] = text
    path = folder / "s.bpt"
    path.write_text("\n".join(lines) + "\n")
    return path


FLOAT32_CASES = [
    ("coordinate-1e39", lambda d: bpt_with_line(d, 5, "1e39 0.5 0"), ["line 5", "patch 0", "too large"]),
    ("coordinate-1e19", lambda d: bpt_with_line(d, 7, "0.5 1e19 0"), ["line 7", "too large"]),
    ("weight-1e-40", lambda d: bpt_with_line(d, 4, "0.5 0.5 0 1e-40", weights=True), ["line 4", "weight 1e-40", "too small"]),
    ("weight-1e300", lambda d: bpt_with_line(d, 9, "0.5 0.5 0 1e300", weights=True), ["line 9", "too large"]),
    ("transform-1e300", lambda d: json_scene(d, [[1e300, 0, 0, 0], [0, 1e300, 0, 0], [0, 0, 1e300, 0], [0, 0, 0, 1]]),
     ["objects[0].transform", "patch 0", "after the transform", "too large"]),
    ("stl-byte-flip", lambda d: tetrahedron_stl(d / "m.stl", flip=(5, 1)), ["vertex 15", "too large"]),
]


@pytest.mark.parametrize("case_id, make, fragments", FLOAT32_CASES, ids=[c[0] for c in FLOAT32_CASES])
def test_input_beyond_float32_is_refused_naming_file_and_place(capsys, tmp_path, case_id, make, fragments):
    scene = make(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", out / "m.ply")
    assert_refused(code, err, [str(scene), *fragments])
    assert_nothing_written(out)


@pytest.mark.parametrize("eps", ["1e-300", "1e-39", "1e39"])
def test_eps_that_is_not_a_float32_exits_2(capsys, tmp_path, eps):
    scene = bpt_with_line(tmp_path, 1, "1")
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", eps, "-o", out / "m.ply")
    assert_refused(code, err, ["eps must be between"])
    assert_nothing_written(out)


BASE_PATCH = np.array([[[i / 3, j / 3, 0.2 * np.sin(i + 2 * j)] for i in range(4)] for j in range(4)])


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(scale=st.integers(-45, 45), shift=st.integers(-45, 45), weight=st.integers(-45, 45),
       spread=st.integers(0, 25), relative_eps=st.integers(-12, 3), mesh=st.booleans(),
       seed=st.integers(0, 2**16))
def test_every_successful_run_has_finite_output(tessellator, scale, shift, weight, spread, relative_eps, mesh, seed):
    """Any magnitudes of coordinates, translation, weights and tolerance: the run is refused
    (SceneError, ValueError) or its whole output is finite."""
    rng = np.random.default_rng(seed)
    points = (BASE_PATCH + rng.normal(size=BASE_PATCH.shape) * 0.1) * 10.0**scale + 10.0**shift
    weights = 10.0 ** (weight + rng.uniform(0, spread, size=(4, 4)))
    eps = 10.0 ** (scale + relative_eps)
    with np.errstate(over="ignore", invalid="ignore"):
        patch = np.concatenate([points * weights[..., None], weights[..., None]], -1)
    assume(np.isfinite(patch).all() and eps < 1e300)
    try:
        if mesh:
            from cltess.scene import TriangleMesh
            faces = np.array([[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [4, 5, 9], [4, 9, 8]])
            scene = Scene.from_meshes([TriangleMesh(points.reshape(-1, 3), faces)])
        else:
            scene = Scene(patch[None], np.zeros(1, np.int32))
        result = tessellator.tessellate(scene, eps=eps, max_factor=8)
    except (SceneError, ValueError):
        return
    for name in ("positions", "normals", "uv"):
        assert np.isfinite(getattr(result, name)).all(), name


# --------------------------------------------------------------------------- item 1: sizes


def quad_counts_closed_form(f) -> tuple[int, int]:
    """(vertices, indices) of the quad pattern (kernels/cltess.h quad_triangles), Python ints."""
    f0, f1, f2, f3 = map(int, f)
    if f0 == f2 and f1 == f3:
        return (f0 + 1) * (f1 + 1), 6 * f0 * f1
    a, b = max(min(f0, f2), 2), max(min(f1, f3), 2)
    triangles = 2 * (a - 2) * (b - 2) + sum(fe + along - 2 for fe, along in ((f0, a), (f1, b), (f2, a), (f3, b)))
    return f0 + f1 + f2 + f3 + (a - 1) * (b - 1), 3 * triangles


def tri_counts_closed_form(f) -> tuple[int, int]:
    """(vertices, indices) of the triangle pattern (kernels/cltess.h tri_triangles)."""
    f = [int(x) for x in f[:3]]
    n = max(f)
    t = [int(x < n) for x in f]
    core = n - sum(t)
    triangles = core * core + sum(f[e] + (n - 1 - t[(e + 1) % 3]) - t[(e + 2) % 3] for e in range(3) if t[e])
    return sum(f) + (n - 1) * (n - 2) // 2, 3 * triangles


@pytest.mark.parametrize("kind, closed_form", [("bezier", quad_counts_closed_form), ("pn", tri_counts_closed_form)])
def test_closed_form_counts_are_the_reference_patterns(kind, closed_form):
    edges = 4 if kind == "bezier" else 3
    factors = np.array([f + (0,) * (4 - edges) for f in itertools.product(range(1, 7), repeat=edges)])
    vertices, indices = reference.counts(factors, kind)
    assert [closed_form(f) for f in factors] == list(zip(vertices.tolist(), indices.tolist()))


@pytest.mark.parametrize("m", [1, 2, 3, 5, 8])
def test_the_worst_case_table_is_the_largest_pattern(m):
    """limits.kernel_integer_extremes' counts are the largest over all factors in 1..m."""
    quad = np.array(list(itertools.product(range(1, m + 1), repeat=4)))
    tri = np.array([f + (0,) for f in itertools.product(range(1, m + 1), repeat=3)])
    quad_vertices, quad_indices = reference.counts(quad, "bezier")
    tri_vertices, tri_indices = reference.counts(tri, "pn")
    worst = limits.kernel_integer_extremes(m)
    assert quad_vertices.max() == worst["quad vertex count (int)"][0]
    assert tri_vertices.max() <= worst["triangle vertex count (int)"][0]
    assert (m - 1) * (m - 2) <= worst["triangle vertex count (int)"][0]  # the product before / 2
    assert quad_indices.max() - 1 == worst["index slot of the last triangle (uint)"][0]
    assert tri_indices.max() - 1 <= worst["index slot of the last triangle (uint)"][0]


def test_max_factor_is_the_largest_that_fits():
    assert limits.MAX_FACTOR == 26754
    assert all(value <= top for value, top in limits.kernel_integer_extremes(limits.MAX_FACTOR).values())
    assert any(value > top for value, top in limits.kernel_integer_extremes(limits.MAX_FACTOR + 1).values())


M = limits.MAX_FACTOR
EXTREME_FACTORS = {
    "bezier": [(M, M, M, M), (M, 1, M, 1), (M, M - 1, 2, M - 3), (1, M, 1, M), (M, M, 1, 1), (3, M, M, 2)],
    "pn": [(M, M, M, 0), (M, M - 1, 3, 0), (1, M, 2, 0), (M, 1, 1, 0), (2, 2, M, 0)],
}


@pytest.mark.parametrize("kind", ["bezier", "pn"])
def test_device_counts_at_the_largest_factor_are_exact(tessellator, kind):
    """Stage 3 at max_factor = MAX_FACTOR counts in its 32-bit integers without wrapping."""
    import pyopencl.array as cl_array

    factors = np.array(EXTREME_FACTORS[kind], np.int32)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(cl_array.to_device(tessellator.queue, factors), kind)
    closed_form = quad_counts_closed_form if kind == "bezier" else tri_counts_closed_form
    expected = [closed_form(f) for f in factors]
    assert np.diff(vertex_offsets.get()).tolist() == [v for v, _ in expected]
    assert np.diff(index_offsets.get()).tolist() == [i for _, i in expected]


def curved_patches_bpt(path: Path, count: int) -> Path:
    """``count`` strongly curved, separate patches: at eps 1e-20 every one saturates.  The weight
    100 on one inner point keeps them saturating at the tolerance floor of 2 float32 steps
    (criteria.tolerance.FLOAT32_TOLERANCE_STEPS): 1/du ~ 87,000 there, 4,000 with equal weights."""
    lines = [str(count)]
    for p in range(count):
        lines.append("3 3")
        lines += [f"{i + 10 * p} {j} {(i - 1.5) ** 2 * (j - 1.5) ** 2} {100.0 if (i, j) == (1, 1) else 1.0}"
                  for j in range(4) for i in range(4)]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_output_beyond_32_bit_vertex_numbers_exits_2(capsys, tmp_path):
    scene = curved_patches_bpt(tmp_path / "s.bpt", 7)  # 7 (M + 1)^2 > 2^32 vertices
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "1e-20", "--max-factor", M, "-o", out / "m.ply")
    assert_refused(code, err, [str(scene), "5010810175 vertices", "2**32"])
    assert_nothing_written(out)


@pytest.mark.parametrize("cap", ["1K", "16M"])
def test_a_patch_larger_than_the_memory_cap_exits_2(capsys, tmp_path, cap):
    scene = curved_patches_bpt(tmp_path / "s.bpt", 2)
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "1e-20", "--max-factor", "2048",
                        "--max-memory", cap, "-o", out / "m.ply")
    assert_refused(code, err, [str(scene), "patch 0 alone needs", "raise the cap"])
    assert_nothing_written(out)


# --------------------------------------------------------------------------- item 7: smaller things


def run_subprocess(*argv, timeout=120):
    """The real command in a child process (a hang is a failure, not a stuck test run)."""
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "cltess", *map(str, argv)], capture_output=True, text=True,
                          timeout=timeout)


@pytest.mark.parametrize("name", ["s.bpt", "s.bez", "s.json", "s.stl", "s.obj"])
def test_symlink_to_dev_zero_is_refused_unread(tmp_path, name):
    scene = tmp_path / name
    scene.symlink_to("/dev/zero")
    out = tmp_path / "out"
    out.mkdir()
    done = run_subprocess("tessellate", scene, "--eps", "0.01", "-o", out / "m.ply", timeout=60)
    assert_refused(done.returncode, done.stderr, [f"{scene}: is a device, not a regular file"])
    assert_nothing_written(out)


@pytest.mark.parametrize("name", ["s.bpt", "s.ply"])
def test_fifo_input_is_refused_without_blocking(tmp_path, name):
    import os

    scene = tmp_path / name
    os.mkfifo(scene)
    out = tmp_path / "out"
    out.mkdir()
    done = run_subprocess("tessellate", scene, "--eps", "0.01", "-o", out / "m.ply", timeout=60)
    assert_refused(done.returncode, done.stderr, [f"{scene}: is a FIFO"])
    assert_nothing_written(out)


def test_json_object_behind_a_symlink_loop_names_the_json_file(capsys, tmp_path):
    (tmp_path / "a.bpt").symlink_to(tmp_path / "b.bpt")
    (tmp_path / "b.bpt").symlink_to(tmp_path / "a.bpt")
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps({"objects": [{"file": "a.bpt"}]}))
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", out / "m.ply")
    assert_refused(code, err, [f"{scene}: objects[0].file", "a.bpt", "cannot read"])
    assert_nothing_written(out)


@pytest.mark.parametrize("centre", [0.0, 123.4, 1e5])
def test_a_patch_collapsed_to_a_point_gets_factors_1_and_no_warning(capsys, tmp_path, centre):
    """Far from the origin, its unequal weights round to unequal float32 points: that is not
    curvature (it saturated at 64 with a false warning, 8192 zero-area triangles).  Its four
    edges are collapsed, so it has no triangles at all (item 2: none of zero area)."""
    rng = np.random.default_rng(7)
    lines = ["2", "3 3", *(f"{i / 3} {j / 3} {0.1 * (i - 1.5) ** 2}" for j in range(4) for i in range(4)), "3 3"]
    lines += [f"{centre!r} {0.7 * centre!r} {-1.3 * centre!r} {w!r}" for w in rng.uniform(0.3, 3, 16).tolist()]
    scene = tmp_path / "s.bpt"
    scene.write_text("\n".join(lines) + "\n")
    out = tmp_path / "m.npz"
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.001", "--max-factor", "64", "-o", out)
    assert code == 0 and "does not meet" not in err, err  # (at 1e5, eps is flagged as below float32's steps)
    from cltess.io.npz import load_npz

    tess = load_npz(out)
    assert tess.factors[1].tolist() == [1, 1, 1, 1]
    assert (tess.patch_ids[tess.triangles[:, 0]] == 1).sum() == 0
    assert (tess.patch_ids == 1).sum() == 4  # its corners
    point = np.float32([centre, 0.7 * centre, -1.3 * centre])
    assert (tess.positions[tess.patch_ids == 1] == point).all()


def test_an_output_without_triangles_warns(capsys, tmp_path):
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps({"objects": [{"file": str(TEAPOT)}],
                                 "camera": {"eye": [0, -20, 5], "target": [0, -40, 5]}}))  # looking away
    out = tmp_path / "m.ply"
    code, err = run_cli(capsys, "tessellate", scene, "--pixels", "1", "-o", out)
    assert code == 0, err
    assert f"cltess: warning: {out}: the mesh has no triangles (of 32 patches: 32 outside the camera's view)" in err
    assert out.exists()


def test_a_full_disk_names_the_output_file(capsys, tmp_path, monkeypatch):
    import errno
    import os

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    scene = tmp_path / "s.bpt"
    scene.write_text("\n".join(bpt_lines()) + "\n")
    out = tmp_path / "out"
    out.mkdir()
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", out / "m.obj")
    assert_refused(code, err, [f"{out / 'm.obj'}: cannot write: No space left on device"])
    assert_nothing_written(out)


@pytest.mark.parametrize("folder", ["/sys", "/proc/self"])
def test_an_unwritable_folder_names_the_output_file(capsys, tmp_path, folder):
    """Read-only or special file systems (root ignores permission bits, so not a chmod)."""
    scene = tmp_path / "s.bpt"
    scene.write_text("\n".join(bpt_lines()) + "\n")
    target = Path(folder) / "cltess-test.ply"
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", target)
    assert_refused(code, err, [f"{target}: cannot write: "])
    assert not target.exists()


# --------------------------------------------------------------------------- item 6: signals


@pytest.mark.parametrize("signame, code", [("SIGTERM", 143), ("SIGHUP", 129), ("SIGINT", 130)])
def test_a_signal_mid_write_leaves_nothing_and_exits_128_plus_signal(tmp_path, signame, code):
    """A real run, stopped while it streams a large OBJ into its temporary file."""
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "out"
    out.mkdir()
    child = subprocess.Popen([sys.executable, "-m", "cltess", "tessellate", str(TEAPOT), "--eps", "0.0001",
                              "--max-factor", "256", "--max-memory", "16M", "--no-weld", "-o", str(out / "t.obj")],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not list(out.glob(".t.obj.*.tmp")):  # the writer has started
            assert child.poll() is None, child.communicate()
            assert time.monotonic() < deadline, "no temporary file appeared"
            time.sleep(0.01)
        time.sleep(0.2)
        child.send_signal(getattr(signal, signame))
        _, err = child.communicate(timeout=120)
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == code, err
    assert "Traceback" not in err, err
    assert_nothing_written(out)


# --------------------------------------------------------------------------- item 3 (host): eps vs float32


def translated(name: str, offset: float) -> tuple[Scene, float]:
    """A bundled scene moved by (offset, offset, offset), and its bounding-box diagonal."""
    base = load_scene(REPO / "scenes" / name)
    points = base.patches[..., :3] / base.patches[..., 3:]
    patches = base.patches.copy()
    patches[..., :3] = (points + offset) * patches[..., 3:]
    return Scene(patches, base.object_ids, name=f"{name} + {offset:g}"), \
        float(np.linalg.norm(np.ptp(points.reshape(-1, 3), axis=0)))


@pytest.mark.parametrize("name, offset, relative_eps", [
    ("teapot.bez", 0, 1e-3), ("teapot.bez", 1e3, 1e-3), ("teapot.bez", 1e4, 1e-3), ("teapot.bez", 1e5, 1e-3),
    ("teapot.bez", 1e5, 1e-2), ("sphere.bpt", 1e3, 1e-3), ("sphere.bpt", 1e4, 1e-3), ("sphere.bpt", 3e4, 1e-3),
    ("sphere.bpt", 1e5, 1e-2), ("teapot.bez", 1e4, 1e-2), ("sphere.bpt", 1e5, 1e-1)])
def test_far_from_the_origin_the_bound_holds_or_eps_is_flagged(tessellator, name, offset, relative_eps):
    """Measured against the float64 surface: where the run is not warned about, the bound holds
    (the unwarned cases must include translated ones, or the test would prove nothing)."""
    from support import bound_ratio

    scene, diagonal = translated(name, offset)
    eps = relative_eps * diagonal
    tess = tessellator.tessellate(scene, eps=eps, max_factor=256)
    assert tess.stats["saturated"] == 0
    ratio = bound_ratio(scene.patches, tess, eps)
    print(f"{scene.name} eps {eps:.3g}: ratio {ratio:.3f}, warned: {bool(limits.eps_below_float32(scene, eps))}")
    if limits.eps_below_float32(scene, eps) is None:
        assert ratio <= 1.0


def test_the_flag_is_raised_where_the_bound_breaks():
    scene, diagonal = translated("teapot.bez", 1e5)
    assert limits.eps_below_float32(scene, 1e-3 * diagonal)  # measured ratio 1.43 there
    scene, diagonal = translated("sphere.bpt", 3e4)
    assert limits.eps_below_float32(scene, 1e-3 * diagonal)  # 1.83
    scene, diagonal = translated("teapot.bez", 1e3)
    assert limits.eps_below_float32(scene, 1e-3 * diagonal) is None


def test_the_cli_warns_before_running_naming_the_scene(capsys, tmp_path):
    def scene_at(offset):
        path = tmp_path / f"at{offset:g}.json"
        path.write_text(json.dumps({"objects": [{"file": str(TEAPOT), "transform": [
            [1, 0, 0, offset], [0, 1, 0, offset], [0, 0, 1, offset], [0, 0, 0, 1]]}]}))
        return path

    far = scene_at(1e5)
    code, err = run_cli(capsys, "tessellate", far, "--eps", "0.008", "-q", "-o", tmp_path / "far.ply")
    assert code == 0
    assert f"cltess: warning: {far}: eps 0.008 is below 16 float32 steps (0.125)" in err
    code, err = run_cli(capsys, "tessellate", scene_at(1e3), "--eps", "0.008", "-q", "-o", tmp_path / "near.ply")
    assert code == 0 and err == ""


OBJ_TEXT = """v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0.5
vn 0 0 1
vn 0 0 1
vn 0 0 1
vn 0 0 1
f 1//1 2//2 3//3
f 2//2 4//4 3//3
"""


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(line=st.integers(0, 9), column=st.integers(0, 3), token=st.one_of(ODD_TOKENS, st.text(max_size=10)))
def test_obj_with_any_token_loads_or_is_refused_by_name(tmp_path_factory, line, column, token):
    """Mesh files go through trimesh, which raises anything on bad input: still a SceneError."""
    assume(not any(0xD800 <= ord(c) <= 0xDFFF for c in token))
    lines = OBJ_TEXT.splitlines()
    fields = lines[line].split(" ")
    fields[min(column, len(fields) - 1)] = token
    lines[line] = " ".join(fields)
    path = tmp_path_factory.mktemp("obj") / "m.obj"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    load_or_scene_error(path)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(at=st.integers(0, 84 + 50 * 24 - 1), value=st.integers(0, 255))
def test_binary_stl_with_any_byte_changed_loads_or_is_refused_by_name(tmp_path_factory, at, value):
    import trimesh

    data = bytearray(trimesh.exchange.stl.export_stl(trimesh.creation.box().subdivide()))
    data[at] = value
    path = tmp_path_factory.mktemp("stl") / "m.stl"
    path.write_bytes(bytes(data))
    scene = load_or_scene_error(path)
    if scene is not None:  # what loads is usable by the device
        assert limits.float32_problem(scene.meshes[0].vertices) is None

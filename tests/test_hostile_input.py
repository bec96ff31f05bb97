"""Hostile input through the command line (issue 5): every bad scene, option or environment
exits non-zero with ``cltess: error: <file>: <line, patch or key>: ...`` and no traceback, writes
no output file, leaves an existing output file byte-identical and no temporary file behind.

The readers' messages in detail are tested in test_formats.py, the CLI's argument checks in
test_cli.py; this file runs one representative of every kind of bad input end to end, and
checks what those do not: existing outputs untouched, bounded memory for huge header counts,
the no-platform and failed-build paths, and Ctrl-C in the middle of a streamed write.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tracemalloc
from pathlib import Path

import pytest

from cltess.cli import main
from cltess.device import DEVICE_ENV_VAR

REPO = Path(__file__).resolve().parents[1]
TEAPOT = REPO / "scenes" / "teapot.bez"
EXISTING = b"ply\nformat binary_little_endian 1.0\ncomment an earlier result, not to be touched\nend_header\n"


@pytest.fixture(autouse=True)
def no_device_env(monkeypatch):
    monkeypatch.delenv(DEVICE_ENV_VAR, raising=False)


# --------------------------------------------------------------------------- scene texts


def bpt(points: list[str] | None = None, count: str = "1", degree: str = "3 3") -> str:
    """A one-patch .bpt; ``points`` replaces the 16 point lines."""
    points = points or [f"{i / 3} {j / 3} {0.1 * (i - 1.5) ** 2}" for j in range(4) for i in range(4)]
    return "\n".join([count, degree, *points]) + "\n"


def bpt_with(line: int, text: str, **kwargs) -> str:
    """The one-patch .bpt with 1-based ``line`` replaced."""
    lines = bpt(**kwargs).splitlines()
    lines[line - 1] = text
    return "\n".join(lines) + "\n"


def bez(indices: str = ",".join(map(str, range(1, 17))), count: str = "1", vertex_count: str = "16",
        vertices: list[str] | None = None) -> str:
    vertices = vertices or [f"{i},{j},{(i * j) % 3 * 0.1}" for j in range(4) for i in range(4)]
    return "\n".join([count, indices, vertex_count, *vertices]) + "\n"


def scene_json(objects=None, camera=None, **extra) -> str:
    doc = {"objects": objects if objects is not None else [{"file": str(TEAPOT)}], **extra}
    if camera is not None:
        doc["camera"] = camera
    return json.dumps(doc)


def transform(rows) -> str:
    return scene_json([{"file": str(TEAPOT), "transform": rows}])


IDENTITY = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]

# (id, scene file name, content, extra arguments, expected fragments of the message).
# The scene's path is expected in the message too, except where the option is at fault.
BAD_SCENES = [
    # non-finite numbers
    ("bpt-nan", "s.bpt", bpt_with(5, "0.5 nan 0"), [], ["line 5", "non-finite"]),
    ("bpt-inf", "s.bpt", bpt_with(7, "0.5 -inf 0"), [], ["line 7", "non-finite"]),
    ("bpt-overflow", "s.bpt", bpt_with(4, "1e400 0 0"), [], ["line 4", "overflows"]),
    ("bez-nan", "s.bez", bez(vertices=["0,0,0"] * 5 + ["0,NaN,0"] + ["0,0,0"] * 10), [], ["line 9", "non-finite"]),
    ("json-nan", "s.json", '{"objects": [{"file": "x.bez",\n "transform": [[NaN]]}]}', [], ["line 2", "NaN"]),
    # non-positive weights
    ("bpt-zero-weight", "s.bpt", bpt([f"{i} {j} 0 {1 if (i, j) != (2, 1) else 0}" for j in range(4) for i in range(4)]),
     [], ["line 9", "patch 0", "weight 0.0 <= 0"]),
    ("bez-negative-weight", "s.bez", bez(vertices=[f"{i},{j},0,{-1 if i == 3 else 1}" for j in range(4) for i in range(4)]),
     [], ["line 7", "vertex 4", "weight -1.0 <= 0"]),
    ("json-weights-flipped", "s.json", transform([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, -1]]), [],
     ["objects[0].transform", "patch 0", "<= 0 after the transform"]),
    # wrong counts
    ("bpt-count-too-big", "s.bpt", bpt(count="2"), [], ["line 1", "patch count 2", "truncated"]),
    ("bpt-count-zero", "s.bpt", bpt(count="0"), [], ["line 1", "patch count is 0"]),
    ("bpt-count-negative", "s.bpt", bpt(count="-1"), [], ["line 1", "-1"]),
    ("bpt-count-not-int", "s.bpt", bpt(count="1.5"), [], ["line 1", "patch count"]),
    ("bpt-15-points", "s.bpt", bpt([f"{i} {j} 0" for j in range(4) for i in range(4)][:15]), [], ["line 1", "truncated"]),
    ("bpt-trailing", "s.bpt", bpt() + "1 2 3\n", [], ["line 19", "unexpected content"]),
    ("bpt-degree", "s.bpt", bpt(degree="2 3"), [], ["line 2", "patch 0", "wrong degree"]),
    ("bpt-arity", "s.bpt", bpt_with(6, "1 2"), [], ["line 6", "patch 0", "arity"]),
    ("bez-15-indices", "s.bez", bez(indices=",".join(map(str, range(1, 16)))), [], ["line 2", "patch 0", "got 15"]),
    ("bez-vertex-count", "s.bez", bez(vertex_count="17"), [], ["line 3", "vertex count 17", "truncated"]),
    ("bez-vertex-arity", "s.bez", bez(vertices=["0,0,0"] * 15 + ["0,0"]), [], ["line 19", "vertex 16"]),
    # bad indices
    ("bez-index-zero", "s.bez", bez(indices="0," + ",".join(map(str, range(2, 17)))), [], ["line 2", "patch 0", "out of range 1..16"]),
    ("bez-index-high", "s.bez", bez(indices=",".join(map(str, range(1, 16))) + ",17"), [], ["line 2", "patch 0", "17 out of range"]),
    ("bez-index-float", "s.bez", bez(indices="1.5," + ",".join(map(str, range(2, 17)))), [], ["line 2", "non-integer"]),
    ("bez-index-huge", "s.bez", bez(indices="9" * 40 + "," + ",".join(map(str, range(2, 17)))), [], ["line 2", "out of range"]),
    # huge counts in a header (memory: test_huge_header_counts_allocate_nothing)
    ("bpt-huge-count", "s.bpt", bpt(count="1000000000000"), [], ["line 1", "truncated"]),
    ("bez-huge-patch-count", "s.bez", bez(count="99999999999999999999"), [], ["line 1", "truncated"]),
    ("bez-huge-vertex-count", "s.bez", bez(vertex_count="4000000000"), [], ["line 3", "vertex count 4000000000"]),
    # wrong JSON schema
    ("json-syntax", "s.json", '{"objects": [\n', [], ["line 2", "not valid JSON"]),
    ("json-top-level", "s.json", "[1, 2]", [], ["top level", "JSON object"]),
    ("json-missing-objects", "s.json", "{}", [], ["missing required key 'objects'"]),
    ("json-unknown-key", "s.json", scene_json(lights=[]), [], ["lights", "unknown key"]),
    ("json-file-type", "s.json", scene_json([{"file": 3}]), [], ["objects[0].file", "string"]),
    ("json-file-missing", "s.json", scene_json([{"file": "nothere.bez"}]), [], ["objects[0].file", "nothere.bez: file not found"]),
    ("json-bad-object-file", "s.json", None, [], ["objects[0].file", "bad.bpt: line 5"]),  # content made below
    ("json-object-id", "s.json", scene_json([{"file": str(TEAPOT), "object_id": -3}]), [], ["objects[0].object_id"]),
    ("json-camera", "s.json", scene_json(camera={"eye": [0, 0], "target": [0, 0, 0]}), [], ["camera.eye", "3 numbers"]),
    ("json-duplicate-key", "s.json", '{"objects": [], "objects": []}', [], ["duplicate key 'objects'"]),
    ("json-nested-deep", "s.json", '{"objects": ' + "[" * 100000, [], ["nested too deeply"]),
    ("json-int-too-long", "s.json", '{"objects": [{"file": "t.bez", "object_id": ' + "7" * 5000 + "}]}", [], ["not usable JSON"]),
    # transforms that are not finite or are singular
    ("json-transform-overflow", "s.json", transform([[1e308, 0, 0, 0], [0, 1e308, 0, 0], [0, 0, 1e308, 0], [0, 0, 0, 1e308]]), [],
     ["objects[0].transform", "not finite after the transform"]),
    ("json-transform-inf", "s.json", '{"objects": [{"file": %s, "transform": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1e999]]}]}'
     % json.dumps(str(TEAPOT)),
     [], ["objects[0].transform[3]", "finite"]),
    ("json-transform-singular", "s.json", transform([[1, 0, 0, 0], [0, 1, 0, 0], [1, 1, 0, 0], [0, 0, 0, 1]]), [],
     ["objects[0].transform", "singular"]),
    ("json-transform-shape", "s.json", transform(IDENTITY[:3]), [], ["objects[0].transform", "4x4"]),
    # empty, binary garbage, unknown extension, not a file
    ("empty-bpt", "s.bpt", "", [], ["empty file"]),
    ("blank-bez", "s.bez", "\n \t\n\n", [], ["empty file"]),
    ("empty-json", "s.json", "", [], ["empty file"]),
    ("garbage-bpt", "s.bpt", bytes(range(256)) * 8, [], ["line 2", "not UTF-8 text (byte 128)"]),
    ("garbage-bez", "s.bez", b"1\n2\n" + os.urandom(64) + b"\xff\xfe", [], ["not UTF-8"]),
    ("nul-bytes", "s.bpt", b"1\x00\n3 3\n", [], ["line 1", "patch count"]),
    ("unknown-extension", "s.xyz", "0 0 0\n", [], ["'.xyz'", ".bpt, .bez, .json"]),
    ("no-extension", "scene", bpt(), [], ["(none)"]),
    # pixels without a camera
    ("pixels-no-camera", "s.bpt", bpt(), ["--pixels", "0.5"], ["--pixels needs a camera"]),
]

BAD_OPTIONS = [
    # (id, arguments replacing "--eps 0.01", fragments); the scene file itself is fine
    ("eps-zero", ["--eps", "0"], ["--eps", "> 0"]),
    ("eps-negative", ["--eps", "-1e-3"], ["--eps"]),
    ("eps-nan", ["--eps", "nan"], ["--eps"]),
    ("eps-inf", ["--eps", "inf"], ["--eps"]),
    ("pixels-zero", ["--pixels", "0"], ["--pixels"]),
    ("max-factor-zero", ["--eps", "0.01", "--max-factor", "0"], ["--max-factor"]),
    ("both-tolerances", ["--eps", "0.01", "--pixels", "1"], ["not allowed"]),
]


def write_scene(folder: Path, name: str, content) -> Path:
    path = folder / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return path


def run_cli(capsys, *argv) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.err


def assert_refused(code: int, err: str, fragments, expected_code: int = 2) -> None:
    assert code == expected_code, err
    assert err.count("cltess: error: ") == 1, err
    assert "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in err, f"{fragment!r} not in {err!r}"


def snapshot(folder: Path) -> dict:
    """Every file of ``folder``: name -> (bytes, mtime_ns)."""
    return {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in folder.iterdir()}


@pytest.fixture(params=["absent", "existing"])
def output(request, tmp_path) -> Path:
    """The -o path: not there yet, or holding an earlier result that must survive."""
    folder = tmp_path / "out"
    folder.mkdir()
    path = folder / "mesh.ply"
    if request.param == "existing":
        path.write_bytes(EXISTING)
    return path


def assert_output_untouched(output: Path, before: dict) -> None:
    assert snapshot(output.parent) == before  # same files, same bytes, same times: no temp file left


# A clear error and nothing else: no NumPy warning on the way (a huge .bez index once cast to int64 first).
@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("case_id, name, content, extra, fragments", BAD_SCENES, ids=[c[0] for c in BAD_SCENES])
def test_bad_scene(capsys, tmp_path, output, case_id, name, content, extra, fragments):
    if case_id == "json-bad-object-file":
        write_scene(tmp_path, "bad.bpt", bpt_with(5, "0.5 zero 0"))
        content = scene_json([{"file": "bad.bpt"}])
    scene = write_scene(tmp_path, name, content)
    before = snapshot(output.parent)
    code, err = run_cli(capsys, "tessellate", scene, *(extra or ["--eps", "0.01"]), "-o", output)
    assert_refused(code, err, [str(scene), *fragments])
    assert_output_untouched(output, before)


@pytest.mark.parametrize("case_id, arguments, fragments", BAD_OPTIONS, ids=[c[0] for c in BAD_OPTIONS])
def test_bad_option(capsys, tmp_path, output, case_id, arguments, fragments):
    scene = write_scene(tmp_path, "s.bpt", bpt())
    before = snapshot(output.parent)
    code, err = run_cli(capsys, "tessellate", scene, *arguments, "-o", output)
    assert_refused(code, err, fragments)
    assert_output_untouched(output, before)


@pytest.mark.parametrize("target", ["missing-scene", "scene-is-folder", "unreadable-scene"])
def test_scene_that_cannot_be_read(capsys, tmp_path, output, target):
    scene = tmp_path / "s.bez"
    if target == "scene-is-folder":
        scene.mkdir()
    elif target == "unreadable-scene":
        if os.geteuid() == 0:
            pytest.skip("root reads any file")
        scene.write_text(bez())
        scene.chmod(0)
    before = snapshot(output.parent)
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", output)
    assert_refused(code, err, [str(scene)])
    assert_output_untouched(output, before)


@pytest.mark.parametrize("name", ["mesh.3ds", "mesh", "mesh.PLY.gz"])
def test_unknown_output_extension_touches_nothing(capsys, tmp_path, name):
    scene = write_scene(tmp_path, "s.bpt", bpt())
    before = snapshot(tmp_path)
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", tmp_path / name)
    assert_refused(code, err, [name, ".ply"])
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("name, content", [
    ("huge.bpt", bpt(count="1000000000000")),
    ("huge.bpt", "2000000000\n" + "3 3\n" * 10),
    ("huge.bez", bez(count="1000000000000")),
    ("huge.bez", bez(vertex_count="4000000000")),
    ("huge.bez", "1\n" + ",".join(["3999999999"] * 16) + "\n4000000000\n1,2,3\n"),
])
def test_huge_header_counts_allocate_nothing(capsys, tmp_path, name, content):
    """A header count that would need gigabytes is refused from the line count alone: the
    whole run allocates less than 2 MB (tracemalloc counts numpy's buffers too)."""
    scene = write_scene(tmp_path, name, content)
    main(["devices"])  # import everything first: only the reading is measured
    capsys.readouterr()
    tracemalloc.start()
    try:
        code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", tmp_path / "out.ply")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert_refused(code, err, [str(scene), "line"])
    assert peak < 2 * 2**20, f"peak {peak / 2**20:.1f} MB"
    assert not (tmp_path / "out.ply").exists()


MESH_HEADERS = [
    ("huge.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 2000000000\nproperty float x\n"
                 b"property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                 b"end_header\n" + bytes(100)),
    ("huge_ascii.ply", b"ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\nproperty float y\n"
                       b"property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                       b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
    ("huge.off", b"OFF\n2000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
    ("huge.stl", bytes(80) + (2_000_000_000).to_bytes(4, "little") + bytes(50)),
    ("bad_index.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
    ("nan.obj", b"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n"),
    ("garbage.glb", b"glTF" + bytes(range(256))),
]


@pytest.mark.parametrize("name, content", MESH_HEADERS, ids=[m[0] for m in MESH_HEADERS])
def test_bad_mesh_files_allocate_nothing(capsys, tmp_path, name, content):
    """Triangle-mesh files (read through trimesh) whose headers claim billions of elements,
    or that index past their vertices: refused naming the file, within 16 MB."""
    import trimesh  # noqa: F401 - imported before measuring

    scene = write_scene(tmp_path, name, content)
    main(["devices"])
    capsys.readouterr()
    output = tmp_path / "out.ply"
    output.write_bytes(EXISTING)
    tracemalloc.start()
    try:
        code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", output)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert_refused(code, err, [str(scene)])
    assert peak < 16 * 2**20, f"peak {peak / 2**20:.1f} MB"
    assert output.read_bytes() == EXISTING


# --------------------------------------------------------------------------- clear failures


def test_no_opencl_platform_end_to_end(tmp_path):
    """No ICD at all: exit 1 with the install hint, output untouched.

    pyopencl's wheel bundles ocl-icd, patched to load the ICDs in ``$PYOPENCL_HOME/.libs``
    (pocl.icd, oclgrind.icd) as well as those in ``$OCL_ICD_VENDORS`` (else
    /etc/OpenCL/vendors); pyopencl sets PYOPENCL_HOME to its own folder when imported.  So the
    child points OCL_ICD_VENDORS at an empty folder and PYOPENCL_HOME elsewhere after the
    import, before the loader first looks: clGetPlatformIDs then fails with
    PLATFORM_NOT_FOUND_KHR (pyopencl raises LogicError), as with a pyopencl installed
    without any runtime.
    """
    vendors = tmp_path / "vendors"
    vendors.mkdir()
    scene = write_scene(tmp_path, "s.bpt", bpt())
    output = tmp_path / "mesh.ply"
    output.write_bytes(EXISTING)
    env = {k: v for k, v in os.environ.items() if k not in (DEVICE_ENV_VAR, "PYOPENCL_CTX")}
    env["OCL_ICD_VENDORS"] = str(vendors)
    env["CLTESS_REGISTER_RUNTIMES"] = "0"  # nor Intel's pip-installed runtime
    child = ("import os, sys, pyopencl\n"
             "os.environ['PYOPENCL_HOME'] = os.environ['OCL_ICD_VENDORS']\n"
             "from cltess.cli import main\n"
             "sys.exit(main(sys.argv[1:]))\n")
    probe = subprocess.run([sys.executable, "-c", child.replace("from cltess.cli import main", "print(pyopencl.get_platforms())")],
                           env=env, capture_output=True, text=True, timeout=120)
    assert "PLATFORM_NOT_FOUND_KHR" in probe.stderr, probe.stdout + probe.stderr
    for argv in (["devices"], ["tessellate", str(scene), "--eps", "0.01", "-o", str(output)]):
        result = subprocess.run([sys.executable, "-c", child, *argv], env=env, capture_output=True,
                                text=True, timeout=120, cwd=tmp_path)
        assert_refused(result.returncode, result.stderr, ["no OpenCL platform", 'pip install "pyopencl[pocl]"'],
                       expected_code=1)
    assert output.read_bytes() == EXISTING
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mesh.ply", "s.bpt", "vendors"]


def test_kernel_build_failure_shows_the_build_log(capsys, tmp_path, monkeypatch):
    """A kernel that does not compile: the CLI exits 1 with the compiler's log (the error's
    line and message), through the real Programs build path."""
    from cltess.backends.opencl import programs

    broken = tmp_path / "kernels"
    shutil.copytree(programs.kernel_dir(), broken, ignore=shutil.ignore_patterns("__pycache__", "*.py"))
    stage = broken / "stages" / "crack_free.cl"
    stage.write_text(stage.read_text().replace(
        "uint edge = get_global_id(0);", "uint edge = get_global_id(0) + undeclared_thing_42;"))
    monkeypatch.setattr(programs, "kernel_dir", lambda: broken)
    monkeypatch.setattr(programs.Programs, "_by_context", {})
    scene = write_scene(tmp_path, "s.bpt", bpt())
    output = tmp_path / "mesh.ply"
    output.write_bytes(EXISTING)
    code, err = run_cli(capsys, "tessellate", scene, "--eps", "0.01", "-o", output, "--device", "pocl")
    assert_refused(code, err, ["crack_free.cl", "failed to build", "undeclared_thing_42"], expected_code=1)
    assert "error" in err.split("undeclared_thing_42")[0].lower()
    assert output.read_bytes() == EXISTING


@pytest.mark.parametrize("extension", [".ply", ".obj"])
def test_ctrl_c_mid_write_leaves_no_partial_file(capsys, tmp_path, monkeypatch, extension):
    """KeyboardInterrupt after some batches were already written (a small --max-memory cap
    makes many batches): exit 130, the earlier file intact, no temporary file left."""
    from cltess.io.obj import ObjWriter
    from cltess.io.ply import PlyWriter

    writer = PlyWriter if extension == ".ply" else ObjWriter
    calls = []
    original = writer.write_vertices

    def interrupted(self, block):
        calls.append(len(block.positions))
        if len(calls) == 3:
            raise KeyboardInterrupt
        return original(self, block)

    monkeypatch.setattr(writer, "write_vertices", interrupted)
    output = tmp_path / f"mesh{extension}"
    output.write_bytes(EXISTING)
    before = snapshot(tmp_path)
    code, err = run_cli(capsys, "tessellate", TEAPOT, "--eps", "0.01", "--max-memory", "256K", "--no-weld",
                        "-o", output)  # per-patch output streams in batches
    assert code == 130 and "interrupted" in err, err
    assert len(calls) == 3  # two batches had been written to the temporary file
    assert snapshot(tmp_path) == before


def test_json_instancing_beyond_memory_is_refused_before_copying(tmp_path, monkeypatch, capsys):
    """Listing one object a huge number of times must not make the reader allocate it all."""
    import json

    from cltess.io import json_scene

    monkeypatch.setattr(json_scene, "_MAX_SCENE_BYTES", 200_000)  # as if the machine had 400 kB
    (tmp_path / "teapot.bez").write_bytes((Path(__file__).resolve().parent.parent / "scenes" / "teapot.bez").read_bytes())
    scene = tmp_path / "herd.json"
    scene.write_text(json.dumps({"objects": [{"file": "teapot.bez"}] * 1000}))
    code = main(["tessellate", str(scene), "--eps", "0.1", "-o", str(tmp_path / "out.ply")])
    err = capsys.readouterr().err
    assert code == 2 and "herd.json" in err and "objects[" in err and "memory" in err
    assert not (tmp_path / "out.ply").exists()


def test_a_binary_stl_whose_count_does_not_fit_its_size_says_so(capsys, tmp_path):
    """Not trimesh's ASCII fallback error (an unrelated missing module): the count and the size."""
    stl = tmp_path / "cut.stl"
    stl.write_bytes(bytes(80) + (3).to_bytes(4, "little") + bytes(100))  # 3 triangles need 234 bytes
    code = main(["tessellate", str(stl), "--eps", "0.1", "-o", str(tmp_path / "out.ply")])
    err = capsys.readouterr().err
    assert code == 2 and "cut.stl" in err and "3 triangles" in err and "184 bytes" in err
    assert not (tmp_path / "out.ply").exists()

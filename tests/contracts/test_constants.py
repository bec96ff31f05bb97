"""Constants shared by Python and OpenCL C are equal (an assertion, not a comment: Skia's
static_assert): the #defines of kernels/common.h against the Python constants they name, and
the vertex record of the kernels against VERTEX_RECORD."""
import re

import numpy as np

from cltess.backends.opencl.programs import kernel_dir
from cltess.kinds import base as kinds_base
from cltess.patterns import fractional
from cltess.surfaces import bezier, pn
from cltess.tessellation import BYTES_PER_VERTEX, VERTEX_RECORD, Tessellation


def defines(header: str) -> dict[str, float]:
    text = (kernel_dir() / header).read_text()
    return {name: float(value.rstrip("f")) for name, value in
            re.findall(r"^#define\s+(\w+)\s+([-+0-9.eE]+f?)\b", text, re.MULTILINE)}


def test_defines_equal_the_python_constants():
    found = defines("common.h")
    expected = {"NORMAL_SHIFT": bezier.NORMAL_SHIFT, "NORMAL_DEGENERATE": bezier.NORMAL_DEGENERATE,
                "PN_NORMAL_VANISHES": pn.PN_NORMAL_VANISHES, "FACTOR_SLOTS": kinds_base.FACTOR_SLOTS,
                "FLAG_SATURATED": kinds_base.FLAG_SATURATED, "FLAG_CULLED": kinds_base.FLAG_CULLED,
                "FLAG_FOLDED": kinds_base.FLAG_FOLDED, "FIXED_ONE": fractional.FIXED_ONE}
    for name, value in expected.items():
        assert name in found, f"kernels/common.h has no #define {name}"
        # The kernels hold float32: the define must be the Python constant rounded to float32.
        assert np.float32(found[name]) == np.float32(value), (name, found[name], value)


C_TYPES = {"float": np.float32, "int": np.int32}


def test_the_kernels_vertex_record_is_vertex_record():
    common = (kernel_dir() / "common.h").read_text()
    struct = re.search(r"typedef struct \{(.*?)\} vertex_out;", common, re.DOTALL).group(1)
    fields = re.findall(r"__global (\w+) \*(\w+);", struct)
    assert [(name, C_TYPES[ctype]) for ctype, name in fields] == [(name, dtype) for name, dtype, _ in VERTEX_RECORD]
    stage = (kernel_dir() / "stages" / "vertices.cl").read_text()
    arguments = re.findall(r"__global (\w+) \*(\w+)", stage.split("__kernel void vertices(")[1].split(")")[0])
    assert arguments[-len(VERTEX_RECORD):] == fields  # the kernel's outputs, in the record's order
    assert [name for name, _, _ in VERTEX_RECORD] == list(Tessellation.__dataclass_fields__)[:len(VERTEX_RECORD)]
    assert BYTES_PER_VERTEX == 3 * 4 + 3 * 4 + 2 * 4 + 4 + 4


def test_the_engine_never_imports_the_reference():
    """cltess.reference only gathers the NumPy mirrors for tests and scripts: no module of the
    package imports it (the mirrors live by what varies: surfaces, patterns, criteria, crack)."""
    import ast
    from pathlib import Path

    import cltess

    package = Path(cltess.__file__).parent
    for path in package.rglob("*.py"):
        if path.name == "reference.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, (ast.Import, ast.ImportFrom)) else []
            module = node.module or "" if isinstance(node, ast.ImportFrom) else ""
            assert "reference" not in module.split(".") and not any("reference" in n.split(".") for n in names), path


def test_the_strip_restart_marker_is_shared():
    from cltess.strips import STRIP_RESTART

    common = (kernel_dir() / "common.h").read_text()
    value = re.search(r"^#define\s+STRIP_RESTART\s+(0x[0-9A-Fa-f]+)u\b", common, re.MULTILINE).group(1)
    assert int(value, 16) == int(STRIP_RESTART) == 2**32 - 1


def test_the_float32_tolerance_floor_equals_the_mirrors():
    from cltess.criteria import tolerance

    found = defines("criteria/tolerance.h")
    assert np.float32(found["FLOAT32_TOLERANCE_STEPS"]) == np.float32(tolerance.FLOAT32_TOLERANCE_STEPS)
    assert np.float32(found["FLOAT32_ROUNDING_STEPS"]) == np.float32(tolerance.FLOAT32_ROUNDING_STEPS)


def test_the_sd2_zone_constants_equal_the_mirrors():
    from cltess.patterns import sd2

    found = defines("patterns/sd2.h")
    assert found["SD2_HINT_SHIFT"] == sd2.HINT_SHIFT
    assert np.float32(found["SD2_SWITCH_REACH"]) == np.float32(sd2.SWITCH_REACH)


def test_the_error_hull_constants_equal_the_mirror():
    from cltess.criteria import error_hull

    found = defines("criteria/error_hull.h")
    for name in ("DEPTH", "UNIT", "NET_STEPS", "WEIGHT_STEPS", "POINT_STEPS", "MEET_WIDENING", "CONDITION"):
        assert np.float32(found[f"ERROR_HULL_{name}"]) == np.float32(getattr(error_hull, name)), name

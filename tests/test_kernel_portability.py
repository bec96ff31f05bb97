"""Every composed program compiles as OpenCL C 3.0 on every usable CPU device, and as 1.2 on one.

In OpenCL C 2.0 and later an unqualified pointer parameter may be a *generic* pointer, and a
generic pointer cannot be passed where a private one is expected: NVIDIA's compiler and PoCL 5
refused the kind headers for exactly that (a `kind_patch *` whose members went on to helpers
taking `float4 c[4]`), while PoCL 3 and Intel's runtime, building OpenCL C 1.2 by default,
accepted them. Intel's compiler with -cl-std=CL3.0 reproduces the refusal, so the kernels are
compiled under both standards here: as 3.0 on every usable CPU runtime, and as 1.2 on the first
of them in ``CPU_RUNTIME_ORDER`` (Intel's where usable).  The PoCL we install (3.0) builds as 1.2
by default, as every PoCL test of the suite builds its programs; 3.0 is what PoCL 5 builds by
default, and tested nowhere else.  Compiling every composition on PoCL as 1.2 as well cost about
75 CPU-s more on a cold kernel cache (2026-11-28).

Compiled (``clCompileProgram``: the front end, where such errors are found), not built: a full
build of every composition under two standards on two runtimes was most of the suite's time
with a cold kernel cache (a fresh CI machine), 7-20x a compile (ESC's stage 4 on Intel's
runtime: 7.1 s against 0.5 s).  The programs the pipeline runs are built in full by the rest
of the suite on each runtime.
"""
from __future__ import annotations

import pyopencl as cl
import pytest

from cltess.backends.opencl.programs import STAGES, composition, program_text
from cltess.criteria.tolerance import ObjectSpace, ScreenSpace
from cltess.device import CPU_RUNTIME_ORDER, list_devices, probe_device
from cltess.kinds import KINDS
from cltess.patterns import PATTERNS, SD2, pattern_named

CPU_DEVICES = sorted((info for info in list_devices() if info.type == "CPU" and probe_device(info).usable),
                     key=lambda info: (info.platform not in CPU_RUNTIME_ORDER,
                                       CPU_RUNTIME_ORDER.index(info.platform) if info.platform in CPU_RUNTIME_ORDER else 0))


def compositions():
    for kind in KINDS:
        for pattern in PATTERNS.values():
            if pattern.domain != kind.domain:
                continue
            for tolerance in (ObjectSpace(1.0), ScreenSpace(1.0, None)):
                for stage in STAGES:
                    yield stage, composition(stage, kind=kind, pattern=pattern, tolerance=tolerance)
            yield "vertex_rows", composition("vertex_rows", kind=kind, pattern=pattern)  # issue 15
            yield "vertex_points", composition("vertex_points", kind=kind, pattern=pattern)
            yield "prepared_points", composition("prepared_points", kind=kind, pattern=pattern)
            yield "offsets", composition("offsets", pattern=pattern)  # stage 3 in one launch
            yield "triangles", composition("triangles", pattern=pattern)
        semi_uniform = pattern_named("semi_uniform", kind.domain)
        yield "level_vertices", composition("level_vertices", kind=kind, pattern=semi_uniform)  # by level
        yield "level_indices", composition("level_indices", pattern=semi_uniform)
        for stage in ("silhouette_alpha", "silhouette_levels", "silhouette_vertices"):  # per frame
            yield stage, composition(stage, kind=kind, pattern=semi_uniform)
    for stage in ("strip_counts", "strip_indices", "vertex_levels", "vertex_bounds", "level_factors"):  # SD-2
        yield stage, composition(stage, pattern=SD2)


STANDARDS = [(info, standard) for index, info in enumerate(CPU_DEVICES)
             for standard in (["CL1.2", "CL3.0"] if index == 0 else ["CL3.0"])]


@pytest.mark.parametrize("info, standard", STANDARDS, ids=[f"{info.platform}-{standard}" for info, standard in STANDARDS])
def test_every_program_compiles_under_both_standards(info, standard):
    context = cl.Context([info.device])
    compiled = set()
    for stage, (headers, defines) in compositions():
        if (stage, headers, tuple(defines.items())) in compiled:
            continue
        source, options = program_text(stage, headers, defines)
        try:
            cl.Program(context, source).compile(options=options + [f"-cl-std={standard}"])
        except cl.RuntimeError as error:
            pytest.fail(f"{stage} with {headers} {defines} fails as {standard} on {info.name}:\n{error}")
        compiled.add((stage, headers, tuple(defines.items())))


#: The bug this module guards against, in small: a private array passed on through a pointer
#: parameter, which is generic from OpenCL C 2.0 on.
GENERIC_POINTER = """
inline float first(float4 c[4]) { return c[0].x; }
typedef struct { float4 b[4]; } patch_t;
inline float get(patch_t *p) { return first(p->b); }
__kernel void k(__global float *out)
{ patch_t p; for (int i = 0; i < 4; ++i) p.b[i] = (float4)(i); out[0] = get(&p); }
"""


def test_a_compile_finds_the_generic_pointer_error():
    """Compiling (not building) is enough to see the refusal: Intel's runtime compiles the
    snippet as OpenCL C 1.2 and refuses it as 3.0."""
    intel = [info for info in CPU_DEVICES if "Intel" in info.platform]
    if not intel:
        pytest.skip("Intel's CPU runtime is not usable here")
    context = cl.Context([intel[0].device])
    cl.Program(context, GENERIC_POINTER).compile(options=["-cl-std=CL1.2"])
    with pytest.raises(cl.RuntimeError):
        cl.Program(context, GENERIC_POINTER).compile(options=["-cl-std=CL3.0"])

"""The OpenCL programs, composed from shared sources with ``#include`` and ``-D`` when they are
built (as OpenSubdiv's ``Osd::CLEvaluator::Compile`` does), and cached per context.

Each stage is one short generic kernel in ``kernels/stages/<stage>.cl``.  What it is built
against depends on the stage (``STAGE_AXES``): stage 1 on the kind (its header includes the
kind's criterion) and the tolerance (``-D TOLERANCE_SCREEN``), stage 2 on the crack policy,
stages 3 and 5 on the pattern, stage 4 on the kind and the pattern.  The device contract that the
headers fulfil is in docs/extending.md.
"""
from __future__ import annotations

import math
import os
import shlex
from dataclasses import dataclass
from functools import cached_property
from importlib import resources
from pathlib import Path

import numpy as np
import pyopencl as cl
import pyopencl._cl as _cl
from pyopencl.tools import get_or_register_dtype, match_dtype_to_c_struct

from ...device import BuildError, first_error_line
from .scan_kernel import GenericScanKernel

STAGES = ("factors", "crack_free", "counts", "vertices", "indices")
#: What each stage's program is composed of: the headers it includes, in this order.
STAGE_AXES = {
    "factors": ("kind",),
    "crack_free": ("crack",),
    "counts": ("pattern",),
    "vertices": ("kind", "pattern"),
    "indices": ("pattern",),
    # stages 4-5 by level (levels.py), for a pattern with a template: built when asked for
    "level_vertices": ("kind", "pattern"),
    "level_indices": ("pattern",),  # two kernels: level_interior, level_band
    "vertex_rows": ("kind", "pattern"),  # stage 4 a work-item per row (Tessellator(work="rows"))
    "vertex_points": ("kind", "pattern"),  # stage 4 a work-item per vertex (Tessellator(work="point"))
    "triangles": ("pattern",),  # stage 5 a work-item per triangle (Tessellator(work="point"))
    "offsets": ("pattern",),  # stage 3 in one launch (Tessellator.fused_offsets)
    "crack_offsets": ("crack", "pattern"),  # stages 2 and 3 in one launch (Tessellator.fused_crack_free)
    "prepared_points": ("kind", "pattern"),  # stage 4 per vertex from prepared patches (work="*-prep")
    "verify": ("kind",),  # on request only (Tessellator.verify), so not in STAGES
    "integral_bound": ("integral",),  # on request only (Request(bound="integral"): integral.py)
    "error_hull_bound": ("error_hull",),  # on request only (Request(bound="error-hull"): error_hull.py)
    # silhouette refinement per frame (silhouette.py; they include criteria/silhouette.h)
    "silhouette_alpha": (),
    "silhouette_levels": (),
    "silhouette_vertices": ("kind", "pattern"),
    # strip output, for a pattern with pattern_strips (SD-2; cltess/backends/opencl/strips.py)
    "strip_counts": ("pattern",),
    "strip_indices": ("pattern",),
    # the SD-2 level functions (criteria/level.h; cltess/backends/opencl/level_functions.py)
    "vertex_levels": ("level",),
    "vertex_bounds": ("level",),
    "level_factors": ("level",),
}

OFFSET_PAIR_FUNCTIONS = """
offset_pair offset_pair_of(ulong v, ulong i) { offset_pair p; p.v = v; p.i = i; return p; }
offset_pair offset_pair_add(offset_pair a, offset_pair b) { return offset_pair_of(a.v + b.v, a.i + b.i); }
"""

#: The summary scan (``Programs.summary_scan``): (vertex, index, flags) triples, the flags of a
#: patch counted as 1 in the low 32 bits if culled and 1 in the high 32 bits if saturated (a scene
#: has fewer than 2**32 patches, so the halves never carry into each other).
OFFSET_TRIPLE_FUNCTIONS = """
#define FLAG_SATURATED {saturated}
#define FLAG_CULLED {culled}
offset_triple offset_triple_of(ulong v, ulong i, ulong f) {{ offset_triple t; t.v = v; t.i = i; t.f = f; return t; }}
offset_triple offset_triple_add(offset_triple a, offset_triple b) {{ return offset_triple_of(a.v + b.v, a.i + b.i, a.f + b.f); }}
ulong flag_counts(int flag) {{ return (ulong)((flag & FLAG_CULLED) != 0) | ((ulong)((flag & FLAG_SATURATED) != 0) << 32); }}
"""

#: The stage 4-5 programs of a work distribution other than a patch per work-item
#: (tessellator.py WORK_DISTRIBUTIONS).
WORK_STAGES = {"rows": ("vertex_rows",), "vertex": ("vertex_points",), "point": ("vertex_points", "triangles"),
               "vertex-prep": ("prepared_points",), "point-prep": ("prepared_points", "triangles"),
               "rows-prep": ("prepared_points", "triangles"),
               "auto": ("vertex_points", "prepared_points", "triangles")}


def changed_arguments(args: tuple, kept: tuple | None) -> tuple | None:
    """The positions at which a launch's arguments differ from those kept from the last one
    (None where they cannot be compared: nothing kept, or another count).  Equal: each the same
    object, or an equal value of the same type; a NumPy struct (stage 1's float16 view matrix)
    compared by its bytes, since NumPy's own comparison of two structs cost ~100 µs on this VM's
    CPUs (bench/RESULTS.md, "Issue 15: a recorded frame")."""
    if kept is None or len(args) != len(kept):
        return None
    changed = ()
    for index, (arg, other) in enumerate(zip(args, kept)):
        if arg is other:
            continue
        if type(arg) is not type(other) or (
                arg.tobytes() != other.tobytes() if isinstance(arg, np.void) else arg != other):
            changed += (index,)
    return changed


#: Work-items per work-group where a launch names the size: the kernels that stage through
#: local memory, and every launch on PoCL (``named_local_size``).  Global sizes are whole
#: multiples of it (tessellator._global_size).
WORK_GROUP = 64


def names_local_size(device: cl.Device) -> bool:
    """Whether launches on ``device`` name their work-group size where the caller leaves it to the
    runtime.  PoCL compiles a kernel once per work-group size and, left to choose, picks the size
    from the global size, so each scene of a new size cost about 2.6 CPU-s of compiling on a cold
    kernel cache (bench/RESULTS.md "Session 9, lead: one work-group size on PoCL").  Intel's CPU
    runtime did not compile again for a new size (the same section); it and the others are left
    to choose."""
    return device.platform.name.strip() == "Portable Computing Language"


def named_local_size(global_size: tuple) -> tuple:
    """WORK_GROUP, or the largest size that divides the global one (OpenCL 1.2 wants whole groups)."""
    return (math.gcd(global_size[0], WORK_GROUP), *(1 for _ in global_size[1:]))


def same_arguments(args: tuple, kept: tuple | None) -> bool:
    """Whether a launch's arguments are those kept from the last one (``changed_arguments``)."""
    return changed_arguments(args, kept) == ()


@dataclass(frozen=True)
class Launch:
    """One launch of a ``Kernel`` as made (``Programs.recording``): the kernel, its global and
    local sizes, its arguments and options, and the event it returned."""

    kernel: "Kernel"
    global_size: tuple
    local_size: tuple | None
    args: tuple
    options: dict
    event: cl.Event

    def again(self, queue, args: tuple | None = None) -> cl.Event:
        """The same launch enqueued again, or with these arguments instead (each set only if
        another launch changed it: ``Kernel``)."""
        return self.kernel.launch(queue, self.global_size, self.local_size, self.args if args is None else args,
                                  self.options)


class Kernel:
    """A built kernel whose scalar arguments' C types are fixed at its first launch, from the
    NumPy scalars it was given (``pyopencl.Kernel.set_arg_types``): later launches pack each
    scalar with ``struct`` (0.3 us) instead of pyopencl's generic ``set_arg`` of a NumPy
    scalar (9 us each on Intel's CPU runtime and PoCL, bench/RESULTS.md "Issue 15: a frame's
    host cost"; a frame sets about 20).  Buffers, ``LocalMemory`` and anything but a NumPy
    scalar keep the generic path.  Every call site passes a kernel parameter the same NumPy
    type each time (the kernel's C type); a later value of another type is packed as the first
    call's type, or refused by ``struct`` (out of range, wrong kind), never reinterpreted.
    A launch made while ``Programs.keep_arguments`` is on (a ``Session`` frame) keeps its
    arguments; the next launch with equal arguments (the same buffers, equal scalars: stages 2-5
    of frame after frame) enqueues the kernel alone, without setting them again (issue 15: a
    frame's host cost), and one that changes a few of them during a frame (stage 1's camera)
    sets those alone (``_set_changed``).  Any other launch forgets them, so that no buffer
    outlives its caller for the sake of this.
    While ``Programs.recording`` is a list, each launch is also appended to it as a ``Launch``
    (a Session records a frame's launches to replay them: cltess/backends/opencl/recorded.py).
    Anything else (``get_work_group_info``, ``function_name``) is the pyopencl kernel's."""

    __slots__ = ("kernel", "arg_types", "programs", "kept")

    def __init__(self, kernel: cl.Kernel, programs: "Programs | None" = None):
        self.kernel = kernel
        self.arg_types = None
        self.programs = programs
        self.kept = None  # the last launch's arguments, still set on the kernel (Programs.keep_arguments)

    def __call__(self, queue, global_size, local_size, *args, **options) -> cl.Event:
        return self.launch(queue, global_size, local_size, args, options)

    def launch(self, queue, global_size, local_size, args: tuple, options: dict | None = None) -> cl.Event:
        """``__call__`` with the arguments as a tuple: the kept tuple itself (a recorded launch
        enqueued again, ``Launch.again``) is known to be set without comparing them.  A local size
        left as None is named here where the runtime compiles per size (``names_local_size``)."""
        if local_size is None and self.programs is not None and self.programs.names_local_size:
            local_size = named_local_size(global_size)
        kept = self.kept
        changed = None if options or kept is None else () if args is kept else changed_arguments(args, kept)
        keep = self.programs is not None and self.programs.keep_arguments and not options
        if changed == () or (changed and keep and self._set_changed(args, changed)):
            # set by the last launch (and the changed ones now): enqueue alone
            event = _cl.enqueue_nd_range_kernel(queue, self.kernel, global_size, local_size, None, None, False, False)
            if keep:  # (this tuple from now on: a recorded launch's own, found again by identity)
                self.kept = args
        else:
            if self.arg_types is None:
                self.arg_types = tuple(a.dtype if isinstance(a, np.generic) else None for a in args)
                self.kernel.set_arg_types(self.arg_types)
            event = self.kernel(queue, global_size, local_size, *args, **(options or {}))
            self.kept = args if keep else None
        if self.programs is not None and self.programs.recording is not None:
            self.programs.recording.append(Launch(self, global_size, local_size, args, options or {}, event))
        return event

    def _set_changed(self, args: tuple, changed: tuple) -> bool:
        """Set the arguments at ``changed`` alone, as pyopencl's typed launch sets them: memory
        objects by ``_set_arg_multi``, a NumPy scalar or struct of the kernel's type by its own
        bytes (``_set_arg_buf_multi``: what ``struct.pack`` of the type makes).  pyopencl's
        public ``Kernel.set_arg`` took 30-45 µs an argument here (its generic path tries each
        kind of argument in turn), against 0.6 µs (bench/RESULTS.md, "Issue 15: a frame's host
        cost, session 8").  False (nothing set) where an argument is neither."""
        objects, scalars = (), ()
        for index in changed:
            arg, arg_type = args[index], self.arg_types[index]
            if arg_type is None and isinstance(arg, cl.MemoryObjectHolder):
                objects += (index, arg)
            elif arg_type is not None and isinstance(arg, np.generic) and arg.dtype == arg_type:
                scalars += (index, arg)
            else:
                return False
        if objects:
            self.kernel._set_arg_multi(objects)
        if scalars:
            self.kernel._set_arg_buf_multi(scalars)
        return True

    def __getattr__(self, name):
        return getattr(self.kernel, name)


def kernel_dir() -> Path:
    """Folder of the kernel sources (top-level kernels/, installed as cltess.kernels)."""
    return Path(str(resources.files("cltess.kernels")))


def composition(stage: str, kind=None, pattern=None, tolerance=None, crack: str = "crack/max.h"):
    """(headers, defines) of a stage's program: the kind's and pattern's headers (objects with a
    ``header``), the crack policy's header, and the tolerance's and the pattern's ``defines``
    (stage 1 only: ``-D PATTERN_DYADIC`` rounds the factors for a dyadic pattern)."""
    parts = {"kind": kind and kind.header, "pattern": pattern and pattern.header, "crack": crack,
             "level": "criteria/level.h", "integral": "criteria/integral_bound.h",
             "error_hull": "criteria/error_hull.h"}
    headers = tuple(parts[axis] for axis in STAGE_AXES[stage])  # stage 1 also reads the tolerance
    if None in headers:
        raise ValueError(f"stage {stage} needs {', '.join(STAGE_AXES[stage])}")
    defines = {}
    if stage == "factors":  # the tolerance field, and the rounding a dyadic pattern asks for
        defines.update(tolerance.defines if tolerance is not None else {})
        defines.update(pattern.defines if pattern is not None else {})
    return headers, defines


def program_text(stage: str, headers: tuple, defines: dict) -> tuple[str, list[str]]:
    """(source, build options) of a composed stage program: ``#include`` lines for common.h and
    the headers, then the stage's kernel; the kernel folder on the include path, the defines."""
    folder = kernel_dir()
    source = "".join(f'#include "{header}"\n' for header in ("common.h", *headers))
    source += (folder / "stages" / f"{stage}.cl").read_text()
    options = ["-I", str(folder)] + [f"-D{name}={value}" for name, value in sorted(defines.items())]
    return source, options


def correctly_rounded_division(device: cl.Device) -> list[str]:
    """``-cl-fp32-correctly-rounded-divide-sqrt`` where the device offers it: a corner's position
    ``h / w`` must be the float32 point that the host made it project to exactly
    (``cltess.scene.exact_corners``: a sphere's pole is one position, issue 9 item 2).  OpenCL
    otherwise allows 2.5 ulp for a division."""
    config = getattr(device, "single_fp_config", 0)
    return ["-cl-fp32-correctly-rounded-divide-sqrt"] if config & cl.device_fp_config.CORRECTLY_ROUNDED_DIVIDE_SQRT else []


def extra_build_options() -> list[str]:
    """Compiler options added to every stage program from ``CLTESS_BUILD_OPTIONS`` (shell
    words), for tuning a device's compiler, e.g. ``-cl-nv-maxrregcount=128`` on NVIDIA.  They
    are part of pyopencl's cache key, so a change rebuilds."""
    return shlex.split(os.environ.get("CLTESS_BUILD_OPTIONS", ""))


class Programs:
    """The built programs of one context, each built once per composition (pyopencl also
    caches the binaries on disk)."""

    _by_context: dict = {}

    def __init__(self, context: cl.Context):
        self.context = context
        #: Whether launches name their work-group size (``names_local_size``).
        self.names_local_size = names_local_size(context.devices[0])
        self._programs: dict = {}
        self._kernels: dict = {}
        self._seen: dict = {}  # Programs.kernel's look-up by the identity of its arguments
        #: Whether launches keep their arguments for the next (``Kernel``): on while a Session
        #: enqueues a frame, whose buffers live with the session.
        self.keep_arguments = False
        #: A list to which every launch is appended (``Launch``) while a Session records a frame.
        self.recording = None
        self._summary_scan = None

    @cached_property
    def offsets_scan(self) -> GenericScanKernel:
        """Exclusive offsets of uint64 counts (built on first use: pyopencl builds its programs)."""
        return GenericScanKernel(
            self.context, np.uint64, arguments="__global const ulong *counts, __global ulong *offsets",
            input_expr="counts[i]", scan_expr="a+b", neutral="0",
            output_statement="offsets[i + 1] = item;")

    @cached_property
    def offsets_pair_scan(self) -> GenericScanKernel:
        """Stage 3's vertex and index offsets in one scan of (vertex, index) pairs: a struct of
        two ulongs (8-byte aligned; a ulong2 was stored misaligned in the scan's local memory)."""
        pair, declaration = match_dtype_to_c_struct(self.context.devices[0], "offset_pair",
                                                    np.dtype([("v", np.uint64), ("i", np.uint64)]))
        pair = get_or_register_dtype("offset_pair", pair)
        return GenericScanKernel(
            self.context, pair, preamble=declaration + OFFSET_PAIR_FUNCTIONS,
            arguments="__global const ulong *vertex_counts, __global const ulong *index_counts, "
                      "__global ulong *vertex_offsets, __global ulong *index_offsets",
            input_expr="offset_pair_of(vertex_counts[i], index_counts[i])", scan_expr="offset_pair_add(a, b)",
            neutral="offset_pair_of(0, 0)",
            output_statement="vertex_offsets[i + 1] = item.v; index_offsets[i + 1] = item.i;")

    def summary_scan(self) -> GenericScanKernel:
        """Stage 3's one scan that also writes a frame's summary (built on first use): the
        vertex and index offsets as ``offsets_pair_scan``, and at the last patch ``summary``
        = (vertex total, index total, patches culled, patches saturated) from stage 1's
        ``flags``, so that the host reads one 32-byte buffer per frame (issue 15; the fused
        stage 3's twin is ``offsets_summary`` in stages/offsets.cl)."""
        if self._summary_scan is None:
            from ...kinds import FLAG_CULLED, FLAG_SATURATED

            triple, declaration = match_dtype_to_c_struct(
                self.context.devices[0], "offset_triple",
                np.dtype([("v", np.uint64), ("i", np.uint64), ("f", np.uint64)]))
            triple = get_or_register_dtype("offset_triple", triple)
            self._summary_scan = GenericScanKernel(
                self.context, triple,
                preamble=declaration + OFFSET_TRIPLE_FUNCTIONS.format(saturated=FLAG_SATURATED, culled=FLAG_CULLED),
                arguments="__global const ulong *vertex_counts, __global const ulong *index_counts, "
                          "__global const int *flags, __global ulong *vertex_offsets, "
                          "__global ulong *index_offsets, __global ulong *summary",
                input_expr="offset_triple_of(vertex_counts[i], index_counts[i], flag_counts(flags[i]))",
                scan_expr="offset_triple_add(a, b)", neutral="offset_triple_of(0, 0, 0)",
                output_statement="vertex_offsets[i + 1] = item.v; index_offsets[i + 1] = item.i; "
                                 "if (i + 1 == N) { summary[0] = item.v; summary[1] = item.i; "
                                 "summary[2] = item.f & 0xffffffffUL; summary[3] = item.f >> 32; }")
        return self._summary_scan

    def kernel(self, stage: str, entry: str | None = None, kind=None, pattern=None, tolerance=None,
               crack: str = "crack/max.h") -> Kernel:
        """The stage's kernel composed for kind=, pattern=, tolerance=, crack=: the one named as
        the stage, or ``entry`` where its file holds several.  Found again by the identity of
        the kind and pattern (registry objects, kept alive by the entry) and the tolerance's
        class (its defines are the class's): a frame looks up each of its kernels this way."""
        seen = (stage, entry, id(kind), id(pattern), type(tolerance), crack)
        found = self._seen.get(seen)
        if found is not None:
            return found[0]
        found = self._kernel(stage, entry, kind=kind, pattern=pattern, tolerance=tolerance, crack=crack)
        self._seen[seen] = (found, kind, pattern)
        return found

    def _kernel(self, stage: str, entry: str | None, **axes) -> Kernel:
        headers, defines = composition(stage, **axes)
        key = (stage, headers, tuple(sorted(defines.items())))
        if key not in self._programs:
            self._programs[key] = self.build(stage, headers, defines)
        if (key, entry) not in self._kernels:  # one Kernel object each: pyopencl caches its call set-up
            self._kernels[key, entry] = Kernel(getattr(self._programs[key], entry or stage), self)
        return self._kernels[key, entry]

    def compose(self, kind, pattern, tolerance, work: str = "patch") -> None:
        """Build (or find) every stage's program for one (kind, pattern, tolerance) now, and the
        stage 4-5 kernels of a work distribution (``WORK_STAGES``)."""
        for stage in STAGES + WORK_STAGES.get(work, ()):
            self.kernel(stage, kind=kind, pattern=pattern, tolerance=tolerance, crack=pattern.crack)

    def build(self, stage: str, headers: tuple, defines: dict) -> cl.Program:
        source, options = program_text(stage, headers, defines)
        options += correctly_rounded_division(self.context.devices[0]) + extra_build_options()
        try:
            return cl.Program(self.context, source).build(options=options)
        except cl.RuntimeError as error:  # the build log is in the message
            raise BuildError(f"kernels/stages/{stage}.cl with {', '.join(headers)} failed to build on "
                             f"{self.context.devices[0].name.strip()!r}: {first_error_line(error)}. "
                             "The full log: --verbose", log=str(error)) from error

    @classmethod
    def of(cls, context: cl.Context) -> "Programs":
        if context not in cls._by_context:
            cls._by_context[context] = cls(context)
        return cls._by_context[context]

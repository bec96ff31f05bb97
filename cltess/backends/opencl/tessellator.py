"""The OpenCL backend: the five stages on one OpenCL device (docs/design.md section 1).

    1. factors     stages/factors.cl     kind_factors of the kind (and its criterion), per tolerance
    2. crack-free  stages/crack_free.cl  the crack policy (crack/max.h), every kind at once
    3. counts      stages/counts.cl      the pattern's vertex layout and primitives (count mode),
                                         then pyopencl.scan into offsets
    4. vertices    stages/vertices.cl    the kind evaluated at the pattern's points
    5. indices     stages/indices.cl     the pattern's primitives (emit mode)

Programs are composed per (kind, pattern, tolerance) (programs.py).  The scene's patches are
numbered kind after kind (``cltess.kinds.KINDS``), and one (P, 4) factor array, one crack-free
pass, one scan, one Plan and its batches cover them all.  A kind's kernels take
``patch_base``, the scene number of the kind's first patch; factors, offsets, object ids and
patch ids are indexed by scene number.

Everything between stage 1 and stage 5 stays on the device; the host reads back the two totals
to size the output buffers, then the outputs, or leaves them there (``emit(..., on_device=True)``
and every ``cltess.Session`` frame: ``OutputBuffers``, ``DeviceOutput``).
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass

import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array
import pyopencl.tools as cl_tools

from ...criteria.tolerance import ObjectSpace, ScreenSpace
from ...crack.adjacency import merge_edge_groups
from ...device import pick_device
from ...kinds import BEZIER, FACTOR_SLOTS, KINDS, PN, PatchKind
from ...kinds import kind as kind_named
from ...patterns import PATTERNS, Pattern
from ...patterns.semi_uniform import DEFAULT_MAX_LEVEL, level_histogram
from ...request import Request
from ...scene import Scene
from ...tessellation import VERTEX_RECORD, DeviceOutput, Tessellation
from .events import span_ms, wait_ms
from .level_functions import build_level_function_programs, level_factors
from .output import OutputBuffers
from .plan import HostPlan, Plan, PlanPart, SceneData
from .programs import WORK_GROUP, Programs
from .strips import build_strip_programs, emit_strips, strip_offsets, strip_parts

#: stages/vertex_rows.cl: work-items per patch (the ring and 64 rows; a patch with more rows has
#: its last work-item do the rest, so this is a speed setting, never a limit).
MAX_ROWS_PER_PATCH = 65
#: stages/vertex_points.cl and stages/triangles.cl: records per work-item (a work-group of
#: WORK_GROUP work-items owns WORK_GROUP * this consecutive records, written side by side in
#: steps; a patch is found and loaded once per work-item and patch, not per record).
RECORDS_PER_ITEM = 4
#: The same for "vertex-prep" and "point-prep" (stage 4 from prepared patches, and stage 5 with
#: it): a distribution for scenes of large patches, where on the H100 16 records per work-item
#: made stages 4 + 5 of uniform level 16 7% faster than 4 (1.29 against 1.39 ms; stage 5 0.217
#: against 0.250: fewer patch searches per triangle; bench/RESULTS.md, "Issue 15: GPU stages
#: 4-5, session 5"), and 1 slower (1.76).  "point" keeps RECORDS_PER_ITEM (the paper's scenes).
RECORDS_PER_ITEM_PREPARED = 16
PREPARED_WORK = ("vertex-prep", "point-prep", "rows-prep")
#: "rows-prep" (stages/prepared_points.cl prepared_rows): work-items per work-group, each walking
#: one line (an interior row or a ring edge) of the group's patches; the kernel's LINE_GROUP
#: (kernel line_constants, checked equal by tests/test_work_points.py).  One warp: on the H100,
#: uniform level 16, stage 4 took 0.508-0.511 ms with groups of 32 and 32 patches against
#: 0.539-0.542 with groups of 64 and 64 patches (the same number of warps; a warp waits for no
#: other at the group's barriers), 0.540 at 32 and 16, 0.771 at 32 and 64 (half the warps:
#: the SMs not filled) (bench/RESULTS.md, "Issue 15: stage 4 a work-item per row or ring edge").
LINE_GROUP = 32
#: Patches per work-group of "rows-prep" (a speed setting; at most the kernel's LINE_MAX_PATCHES).
#: A scene of few patches gets few work-groups: "rows-prep" is for scenes of large patches.
LINE_PATCHES = 32
LINE_MAX_PATCHES = 64
#: "rows-prep" on a batch of fewer patches than LINE_PATCHES per warp for LINE_WARPS_PER_UNIT warps
#: of every compute unit: fewer patches per work-group (``line_patches_for``), so that the
#: batch still spreads over the whole device.  A warp walks its group's lines in turn (latency-
#: bound: 255 registers on the H100 leave 8 warps per SM), so a scene of few patches in groups of
#: 32 left most of the device idle (the tea table's 332 patches: 11 warps).
LINE_WARPS_PER_UNIT = 8
#: work="auto" (the GPU default): "rows-prep" for a batch whose patches average at least this many
#: output vertices (counting its culled patches) ..., "point" otherwise (``Tessellator.auto_work``).
#: rows-prep walks a row's points in order, so it gains with long rows and many patches; point
#: spreads any patch over consecutive work-items, so it wins on the paper's scenes (3-22 vertices
#: per patch, or the tea table's 70 on 332 patches); bench/RESULTS.md, "Issue 15: stage 4 variants and work="auto"
#: (session 7, branch gpu15e)".  On the H100 at 81 vertices per patch (uniform level 8) rows-prep
#: took 0.203 ms against 0.219 on 3,200 patches and 0.424 against 1.342 on 32,000.
AUTO_ROWS_MIN_VERTICES_PER_PATCH = 64
#: ... and at least this many patches (a smaller batch gives rows-prep too few warps: on the H100
#: 320 teapot patches at levels 12 and 16 took 0.15-0.18 ms against point's 0.09-0.10; 3,200
#: took 0.20-0.35 against 0.22-0.42; measured at 320 and 3,200 only, the cut between them).
AUTO_ROWS_MIN_PATCHES = 2048
#: How stages 4-5 spread their work (docs/design.md, "Work distribution"): "patch" a work-item
#: per patch (stages/vertices.cl, stages/indices.cl); "rows" stage 4 a work-item per (patch,
#: row) (stages/vertex_rows.cl), stage 5 per patch; "vertex" stage 4 a work-item per output
#: vertex (stages/vertex_points.cl), stage 5 per patch; "point" a work-item per output vertex and
#: per output triangle (stages/vertex_points.cl, stages/triangles.cl: consecutive work-items
#: write consecutive records).  All write the same bits.
#: "vertex-prep" and "point-prep": the same, with each visible patch's kind_patch made once per
#: frame (stages/prepared_points.cl prepare_patches, into a scratch buffer) and stage 4's
#: work-items copying it instead of re-running kind_load at every patch change (issue 15, GPUs).
#: "rows-prep": stage 4 a work-item per interior row or ring edge of prepared patches, its points
#: walked in order (one forward-differencing step each) and staged in local memory to be written
#: side by side (stages/prepared_points.cl prepared_rows); stage 5 a work-item per triangle.
#: "auto": "rows-prep" or "point" for each frame, by its vertices per patch (AUTO_ROWS_MIN_VERTICES_PER_PATCH).
WORK_DISTRIBUTIONS = ("patch", "rows", "vertex", "point", "vertex-prep", "point-prep", "rows-prep", "auto")
#: What work="auto" chooses between.
AUTO_WORK = ("point", "rows-prep")
#: The default per device type, chosen by bench/frame_loop.py --work gpu (bench/RESULTS.md, "Issue
#: 15: the work distributions on the H100"): CPUs keep a patch per work-item (the point kernels
#: replay forward differencing per vertex: more arithmetic, which a CPU pays); GPUs a work-item
#: per vertex and triangle ("point": fastest or within 20% of the fastest on the paper's scenes
#: on the H100; "point-prep" wins only where patches have hundreds of vertices, uniform level 16).
#: Since session 7: GPUs "auto" ("point" on the paper's scenes, "rows-prep" where patches have
#: hundreds of vertices).
DEFAULT_WORK = {"gpu": "auto", "other": "patch"}


#: Stage 3 in one launch per range of patches (stages/offsets.cl: counts and the scan by one
#: work-group) up to this many patches; more go through the counts kernel and pyopencl.scan.  On
#: the H100 one launch took 0.03 ms against the scans' 0.14-0.25 ms up to 1,536 patches, 0.17
#: against 0.14 at 11,532 and 0.71 against 0.19 at 32,000 (bench/RESULTS.md, issue 15 on the H100);
#: at 11,532 (killeroo) it still wins a frame: the device's 0.06 ms more against 0.15 ms less
#: of the host's (the scans' allocations and three launches), 0.320 against 0.458 ms per
#: overlapped frame (bench/RESULTS.md, "Session 4 on the H100").
FUSED_OFFSETS_MAX_PATCHES = 1 << 14
#: The same on a CPU device (one work-group runs on one core): measured on Intel's runtime and PoCL
#: (2 vCPUs), a frame took 0.1 ms less fused than with the counts kernel and pyopencl.scan at 332
#: and 1,536 patches (mostly the scan's host cost: two temporary arrays and three launches per call),
#: the same within noise at 11,532 (bench/RESULTS.md, "Issue 15: a frame's host cost").
FUSED_OFFSETS_MAX_PATCHES_CPU = 1 << 11
#: The fused launch's work-group size at most (a power of two; less where the device says so).
FUSED_OFFSETS_GROUP = 1024
#: Stage 3 in two launches (stages/offsets.cl offsets_tiles, offsets_carries) above the one-launch
#: cap and up to this many patches, where a frame asks for its summary: the counts kernel and
#: pyopencl.scan cost four launches and ~100 µs of host Python per frame (two temporary arrays;
#: bench/RESULTS.md, "Issue 15: a frame's host cost, session 5").  The carries kernel reads every
#: earlier tile's record per tile (quadratic in the tiles), so more patches keep the scan.
TILED_OFFSETS_MAX_PATCHES = 1 << 18
#: Patches per tile of the two-launch stage 3 (a power of two; less where the device says so).
TILED_OFFSETS_GROUP = 256
#: Stages 2 and 3 in one launch (stages/crack_offsets.cl: every edge's crack-free factor, then the
#: first range's counts and offsets, by one work-group) for a Session frame whose stage 3 is one
#: launch, up to this many patches: a launch fewer per frame (13.7 µs of the host's time a launch on
#: NVIDIA's runtime, bench/RESULTS.md "Session 4 on the H100"), for stage 2's 4 edges a patch on one
#: compute unit instead of the whole device (8 edges a work-item at 1,024 work-items).
FUSED_CRACK_FREE_MAX_PATCHES = 1 << 11
#: A frame's summary, written by stage 3 and read back in one copy (``Tessellator.stage_counts``):
#: vertex total, index total, patches culled, patches saturated (uint64 each).
SUMMARY_FIELDS = 4


#: One context per device for the process: the tessellators of a device share it, and with it
#: its built programs and the scene data kept per context.  A context per tessellator was never
#: freed (the programs cache holds it) and NVIDIA's driver refuses new contexts after a few
#: dozen (OUT_OF_HOST_MEMORY).
_CONTEXTS: dict = {}


def shared_context(device: cl.Device) -> cl.Context:
    if device not in _CONTEXTS:
        _CONTEXTS[device] = cl.Context([device])
    return _CONTEXTS[device]


def switch_setting(name: str) -> bool | None:
    """An on/off environment setting: "1" on, "0" off, unset or empty None (the default's)."""
    chosen = os.environ.get(name)
    if chosen not in (None, "", "0", "1"):
        raise ValueError(f"{name}={chosen!r}: expected 0 or 1")
    return chosen == "1" if chosen else None


def default_fused_offsets(device: cl.Device) -> bool:
    """Stage 3 by stages/offsets.cl: ``CLTESS_FUSED_OFFSETS`` (0 or 1) if set, else on GPUs and
    on CPUs (one work-group: a GPU saves launches; on a CPU, where it runs on one core, only up to
    ``FUSED_OFFSETS_MAX_PATCHES_CPU`` patches, ``Tessellator.stage_counts``).  Not on a device
    that says it is both (Oclgrind: "all")."""
    chosen = switch_setting("CLTESS_FUSED_OFFSETS")
    if chosen is not None:
        return chosen
    return bool(device.type & cl.device_type.GPU) != bool(device.type & cl.device_type.CPU)


def default_tiled_offsets(device: cl.Device) -> bool:
    """Stage 3 in two launches where a plan asks for its summary and one launch would be too slow
    (``TILED_OFFSETS_MAX_PATCHES``): ``CLTESS_TILED_OFFSETS`` (0 or 1) if set, else on GPUs only.
    On CPUs (Intel's runtime, 2 vCPUs) its tiles' scans in local memory took twice the device
    time of the counts kernel and pyopencl.scan (killeroo 1.3-1.6 against 0.7-0.9 ms, spheres 3.7
    against 2.0, model zoo 8.5 against 4.0; bench/RESULTS.md, "Issue 15: a frame's host cost,
    session 5").  Not on a device that says it is both (Oclgrind: "all")."""
    chosen = switch_setting("CLTESS_TILED_OFFSETS")
    if chosen is not None:
        return chosen
    return bool(device.type & cl.device_type.GPU) and not device.type & cl.device_type.CPU


def default_fused_crack_free(device: cl.Device) -> bool:
    """Stage 2 in stage 3's one launch for a Session frame (``Tessellator.fuses_crack_free``):
    ``CLTESS_FUSED_CRACK_FREE`` (0 or 1) if set, else where stage 3 is one launch by default
    (``default_fused_offsets``)."""
    chosen = switch_setting("CLTESS_FUSED_CRACK_FREE")
    if chosen is not None:
        return chosen
    return default_fused_offsets(device)


def pure_cpu(device: cl.Device) -> bool:
    """A CPU device and nothing else (Oclgrind says "all")."""
    return bool(device.type & cl.device_type.CPU and not device.type & cl.device_type.GPU)


def default_work(device: cl.Device) -> str:
    """The work distribution for a device: ``CLTESS_WORK`` if set, else ``DEFAULT_WORK``."""
    gpu = device.type & cl.device_type.GPU and not device.type & cl.device_type.CPU  # Oclgrind says "all"
    chosen = os.environ.get("CLTESS_WORK") or DEFAULT_WORK["gpu" if gpu else "other"]
    if chosen not in WORK_DISTRIBUTIONS:
        raise ValueError(f"CLTESS_WORK={chosen!r}: expected one of {', '.join(WORK_DISTRIBUTIONS)}")
    return chosen


VERIFY_ORDER = 6  # Tessellator.verify: 28 points per triangle, corners and edges included
VERIFY_MAX_TRIANGLES = 4_000_000  # above this, every k-th triangle is verified


def _pattern(kind_or_pattern) -> Pattern:
    return kind_or_pattern if isinstance(kind_or_pattern, Pattern) else kind_named(kind_or_pattern).pattern


def crack_policy(patterns) -> str:
    """Stage 2's crack policy header for a scene's patterns: the first other than crack/max.h
    (ESC's crack/or_masks.h, which takes the largest factor for the other patterns' edges)."""
    return next((pattern.crack for pattern in patterns if pattern.crack != "crack/max.h"), "crack/max.h")


def _tolerance(eps, pixels, camera):
    return ObjectSpace(eps) if pixels is None else ScreenSpace(pixels, camera)


def _global_size(n: int) -> tuple[int]:
    return (max(WORK_GROUP, -(-n // WORK_GROUP) * WORK_GROUP),)


def _record_groups(records: int, per_item: int) -> tuple[int]:
    """Global size of the record kernels: WORK_GROUP work-items per per_item * WORK_GROUP
    records."""
    per_group = per_item * WORK_GROUP
    return (max(1, -(-records // per_group)) * WORK_GROUP,)


#: Where stage 1's tolerance arguments (``kernel_args()`` of ObjectSpace, ScreenSpace) sit among
#: its kernel's (stage_factors_of, stages/factors.cl): the only arguments of a Session frame's
#: launches that change with the camera (recorded.py).
TOLERANCE_ARGUMENTS = slice(4, 9)




class Tessellator:
    """Tessellates scenes on one OpenCL device.

    >>> tess = Tessellator().tessellate(load_scene("scenes/teapot.bez"), eps=1e-3)
    """

    name = "opencl"

    def __init__(self, device: cl.Device | str | None = None, rows_in_parallel: bool = False,
                 work: str | None = None):
        """work: how stages 4-5 spread over work-items (``WORK_DISTRIBUTIONS``: "patch", "rows",
        "vertex", "point", "vertex-prep", "point-prep" or "rows-prep", bitwise the same output); default per
        device type (``default_work``).
        rows_in_parallel=True is work="rows" (stages/vertex_rows.cl)."""
        self.device = device if isinstance(device, cl.Device) else pick_device(device)
        self.one_scan = os.environ.get("CLTESS_ONE_SCAN", "1") != "0"  # stage 3: one scan, else two
        self.records_per_item = None  # stages/vertex_points.cl, triangles.cl: None is RECORDS_PER_ITEM
        self.patches_per_group = None  # work="rows-prep": None is line_patches_for the batch
        self._batch_seen = None  # work="auto": the latest settled plan's (vertices, patches) (note_plan)
        self.work = "rows" if rows_in_parallel else work or default_work(self.device)
        if self.work not in WORK_DISTRIBUTIONS:
            raise ValueError(f"work={self.work!r}: expected one of {', '.join(WORK_DISTRIBUTIONS)}")
        self.context = shared_context(self.device)
        self.queue = cl.CommandQueue(self.context, properties=cl.command_queue_properties.PROFILING_ENABLE)
        self.programs = Programs.of(self.context)
        # The scans' temporary arrays (two per call) from a pool, not a new buffer each frame.
        self._scan_memory = cl_tools.MemoryPool(cl_tools.ImmediateAllocator(self.queue))
        self._prepared = None  # work="*-prep": the prepared patches' scratch buffer (_prepared_points)
        self.fused_offsets = default_fused_offsets(self.device)  # stage 3 by stages/offsets.cl
        self._cpu = pure_cpu(self.device)  # stage 3 fused up to FUSED_OFFSETS_MAX_PATCHES_CPU only
        self._kind_patch_sizes: dict = {}
        self._fused_groups: dict = {}  # (a stage 3 kernel, group cap) -> (work-group size, local arrays): _group_of
        self.tiled_offsets = default_tiled_offsets(self.device)  # stage 3 in two launches above the fused cap
        self.fused_crack_free = default_fused_crack_free(self.device)  # a Session frame's stage 2 in stage 3's launch

    @property
    def per_item(self) -> int:
        """Records per work-item of the record kernels under this Tessellator's ``work``
        (``records_for``)."""
        return self.records_for(self.work)

    def records_for(self, work: str) -> int:
        """Records per work-item of the record kernels under work distribution ``work``:
        ``records_per_item`` if set, else ``RECORDS_PER_ITEM_PREPARED`` for the prepared
        distributions and ``RECORDS_PER_ITEM`` otherwise (read at each launch)."""
        if self.records_per_item:
            return self.records_per_item
        return RECORDS_PER_ITEM_PREPARED if work in PREPARED_WORK else RECORDS_PER_ITEM

    def note_plan(self, plan: "Plan", first: int = 0, last: int | None = None) -> None:
        """Keep a settled plan's (vertices, patches) of patches first .. last-1 (culled ones
        counted) for work="auto" (``auto_work``); an unsettled plan is ignored."""
        last = plan.num_patches if last is None else last
        if plan.settled and last > first:
            start, stop = plan.vertex_range(first, last)
            self._batch_seen = (stop - start, last - first)

    def auto_work(self, vertices: int | None = None, patches: int | None = None) -> str:
        """The work distribution that work="auto" runs for a batch of ``vertices`` on
        ``patches`` (both, or neither: then the latest plan given to ``note_plan``, "point"
        before any): "rows-prep" where the batch has at least ``AUTO_ROWS_MIN_PATCHES`` patches
        averaging at least ``AUTO_ROWS_MIN_VERTICES_PER_PATCH`` vertices, else "point".  Any
        other ``work`` is returned as it is."""
        if self.work != "auto":
            return self.work
        if vertices is None or patches is None:
            if self._batch_seen is None:
                return "point"
            vertices, patches = self._batch_seen
        if patches >= AUTO_ROWS_MIN_PATCHES and vertices >= AUTO_ROWS_MIN_VERTICES_PER_PATCH * patches:
            return "rows-prep"
        return "point"

    def line_patches_for(self, patches: int) -> int:
        """Patches per work-group of "rows-prep" for a batch of ``patches``: ``patches_per_group``
        if set; else LINE_PATCHES where that gives at least half of LINE_WARPS_PER_UNIT
        work-groups (one warp each) per compute unit, and fewer, to give about
        LINE_WARPS_PER_UNIT, on a smaller batch.  (On the H100, uniform level 16 on 32,000
        patches: 31 per group, 1,033 warps, took 0.548 ms against 32's 0.508, 1,000 warps.)"""
        if self.patches_per_group:
            return self.patches_per_group
        groups = LINE_WARPS_PER_UNIT * self.device.max_compute_units
        if 2 * -(-patches // LINE_PATCHES) >= groups:
            return LINE_PATCHES
        return max(1, min(LINE_PATCHES, -(-patches // groups)))

    @property
    def rows_in_parallel(self) -> bool:
        """Stage 4 a work-item per (patch, row): work == "rows"."""
        return self.work == "rows"

    @rows_in_parallel.setter
    def rows_in_parallel(self, on: bool) -> None:
        self.work = "rows" if on else ("patch" if self.work == "rows" else self.work)

    def tessellate(self, scene: Scene, request: Request | None = None, **options) -> Tessellation:
        """Run the five stages on a scene; returns the mesh and per-stage device times.

        Give a ``Request``, or its parts as keyword arguments (``Request.of``): exactly one of
        ``eps`` (object-space tolerance) and ``pixels`` (screen-space, needs ``scene.camera``),
        ``max_factor``, ``forward_differencing``, ``sharp_edges`` (meshes only: "straight",
        "average" or "keep", ``cltess.kinds.pn.pn_edge_normals``; only "keep" may leave cracks),
        ``pattern`` ("semi_uniform", "transition" or a pattern's name) and ``max_level`` (the
        semi-uniform patterns' largest level, default 6); for pattern "sd2" ``level_function``,
        ``level_factors``, ``depth_map``, ``depth_range``, ``camera`` (``Request``, docs/sd2.md).
        """
        plan = self.plan(scene, request, **options)
        return self.emit(plan, 0, plan.num_patches)

    def tessellate_in_batches(self, scene: Scene, max_output_bytes: int, request: Request | None = None,
                              **options):
        """(plan, iterator of Tessellation batches) whose outputs each fit ``max_output_bytes``.

        Stages 1-3 run once for the whole scene (so factors are crack-free across batches);
        stages 4-5 run per batch of consecutive patches.  Batch triangles number the vertices
        globally, so concatenating the batches gives exactly the single-pass result.
        """
        plan = self.plan(scene, request, **options)
        ranges = plan.batch_ranges(max_output_bytes)
        return plan, (self.emit(plan, first, last) for first, last in ranges)

    def plan(self, scene: Scene, request: Request | None = None, **options) -> "Plan":
        """Stages 1-3 for the whole scene: final factors and offsets, left on the device."""
        request = request if request is not None else Request.of(**options)
        request.check(scene)
        started = time.perf_counter()
        self.compose(scene, request)
        if request.bound == "integral":  # tighter factors, certified triangle by triangle
            from .integral import plan_integral
            return plan_integral(self, scene, request, started)
        if request.bound == "error-hull":  # tighter factors, certified triangle by triangle
            from .error_hull import plan_error_hull
            return plan_error_hull(self, scene, request, started)
        return self.plan_on(self.scene_data(scene, request.sharp_edges), request, started)

    def compose(self, scene: Scene, request: Request) -> None:
        """Build every program a request needs for a scene.  Every program is built before the
        plan's first buffer exists: builds in between made Oclgrind's uninitialised-value plugin
        report the scans' output (tests/test_oclgrind.py)."""
        tolerance = request.tolerance_for(scene)
        for kind in KINDS:
            if kind.count(scene):
                pattern = request.pattern_for(kind)
                self.programs.compose(kind, pattern, tolerance, self.work)
                if self.fused_offsets:
                    self.programs.kernel("offsets", pattern=pattern)
                    self.programs.kernel("offsets", "offsets_summary", pattern=pattern)
                if self.fused_offsets and self.fused_crack_free and scene.num_patches <= FUSED_CRACK_FREE_MAX_PATCHES:
                    crack = crack_policy(request.pattern_for(k) for k in KINDS if k.count(scene))
                    self.programs.kernel("crack_offsets", pattern=pattern, crack=crack)
                    self.programs.kernel("crack_offsets", "crack_offsets_summary", pattern=pattern, crack=crack)
                if self.tiled_offsets:
                    self.programs.kernel("offsets", "offsets_tiles", pattern=pattern)
                    self.programs.kernel("offsets", "offsets_carries", pattern=pattern)
                may_prepare = self.work == "auto" and scene.num_patches >= AUTO_ROWS_MIN_PATCHES  # auto_work
                if self.work.endswith("-prep") or may_prepare:  # before the plan's buffers (prepared_scratch)
                    self.prepared_scratch(kind, pattern, kind.count(scene))
                if pattern.fixed_point:  # SD-2's level functions
                    build_level_function_programs(self)
                if pattern.primitive == "strips":
                    build_strip_programs(self, pattern)
        if self.one_scan:  # stage 3's scan that writes a frame's summary (stage_counts)
            self.programs.summary_scan()
        if request.bound == "integral":
            self.programs.kernel("integral_bound")
        if request.bound == "error-hull":
            self.programs.kernel("error_hull_bound")

    def scene_data(self, scene: Scene, sharp_edges: str = "straight", keep_prepared: bool = False) -> "SceneData":
        """What stays on the device for a scene whatever the tolerance or camera: every kind's
        upload (``upload``), the object ids and the edge groups of stage 2.  The host side
        (adjacency, welding) is cached on the scene (``Scene.prepared``).  keep_prepared (a
        Session's): a kind whose stage-4 input is its upload, which no frame rewrites (Bézier
        patches), gets a "prepared" dict in its device arrays, where "*-prep" stage 4 keeps the
        patches it prepares once for every later call (``_prepared_points``)."""
        kinds = [kind for kind in KINDS if kind.count(scene)]
        parts, inputs, base = [], [], 0
        for kind in kinds:
            count = kind.count(scene)
            host = scene.prepared((kind.name, sharp_edges), lambda: kind.prepare(scene, sharp_edges))
            uploaded = self.upload(kind, host.source, scene)
            if keep_prepared and kind.controls_shape(count) is None:
                uploaded["prepared"] = {}
            parts.append((kind, base, count, uploaded))
            inputs.append(host)
            base += count
        objects = cl_array.to_device(self.queue, np.concatenate([host.objects for host in inputs]).astype(np.int32))
        groups = scene.prepared(("edge groups", sharp_edges), lambda: merge_edge_groups(
            [(host.groups, kind.edges, b) for host, (kind, b, _, _) in zip(inputs, parts)], base, FACTOR_SLOTS))
        stats = {
            "shared_edges": sum(host.groups.shared for host in inputs),
            "boundary_edges": sum(host.groups.boundary for host in inputs),
            "nonmanifold_edges": sum(host.groups.nonmanifold for host in inputs),
        }
        for host in inputs:
            stats.update(host.stats)
        return SceneData(scene, sharp_edges, base, parts, objects, self.upload_groups(groups, base), stats)

    def plan_on(self, data: "SceneData", request: Request, started: float | None = None,
                scratch: dict | None = None, stage1_hook=None, defer_totals: bool = False) -> "Plan":
        """Stages 1-3 on a scene's device data (``scene_data``) for a request (its programs
        built: ``compose``).  scratch: a dict in which the per-patch arrays (factors, flags,
        counts, offsets) are kept and reused from call to call (a ``Session``'s), so that a
        new plan overwrites the last one's; else fresh arrays.  stage1_hook(factors, flags):
        called after stage 1, before stage 2, may rewrite the factors (integral.py's trials).
        defer_totals: return without waiting for the totals' read-back (``Plan.settle`` waits;
        a Session frame's stages 4-5 are enqueued meanwhile, docs/design.md section 11), where
        nothing else of the plan is read back (no strips, no semi-uniform levels)."""
        started = time.perf_counter() if started is None else started
        scene, count = data.scene, data.num_patches
        tolerance = request.tolerance_for(scene)
        scratch = {} if scratch is None else scratch
        parts = [PlanPart(kind, request.pattern_for(kind), base, n, uploaded) for kind, base, n, uploaded in data.parts]
        if "factors" not in scratch:
            scratch["factors"] = cl_array.empty(self.queue, (count, FACTOR_SLOTS), np.int32)
            scratch["flags"] = cl_array.empty(self.queue, count, np.int32)
        factors, flags = scratch["factors"], scratch["flags"]
        events = {"factors": []}
        for part in parts:
            events["factors"] += self.stage_factors_of(part.kind, part.data, tolerance, request.max_factor,
                                                       factors, flags, part.base, part.pattern, request.max_level)
        level_stats = {}
        for part in parts:  # a fixed-point pattern's factors come from a level function (SD-2)
            if part.pattern.fixed_point:
                level_events, level_stats = level_factors(self, scene, request, part, factors)
                events["factors"] += level_events
        if stage1_hook is not None:
            stage1_hook(factors, flags)
        crack = crack_policy(part.pattern for part in parts)
        ranges = [(part.pattern, part.base, part.count) for part in parts]
        crack_free = None
        if defer_totals and self.fuses_crack_free(count, ranges):  # stage 2 in stage 3's first launch
            if "final" not in scratch:
                scratch["final"] = cl_array.empty(self.queue, factors.shape, np.int32)
            final, events["crack_free"], crack_free = scratch["final"], [], (factors, data.groups, crack)
        else:
            final, events["crack_free"] = self.stage_crack_free(factors, data.groups, crack, out=scratch.get("final"))
            scratch["final"] = final
        summary = None
        if self.writes_summary(count, ranges):  # stage 3 writes totals and flag counts: one read
            if "summary" not in scratch:
                scratch["summary"] = cl_array.empty(self.queue, SUMMARY_FIELDS, np.uint64)
            summary = scratch["summary"]
        vertex_offsets, index_offsets, events["counts"] = self.stage_counts(
            final, ranges, scratch=scratch, flags=flags, summary=summary, crack_free=crack_free)
        strips = strip_offsets(self, final, parts) if strip_parts(parts) else (None, [])
        events["counts"] += strips[1]
        totals, flag_values = self._read_back_arrays(scratch if defer_totals else None, count, summary is None)
        if summary is not None:
            copies = [cl.enqueue_copy(self.queue, totals, summary.data, is_blocking=False)]
        else:
            copies = [
                cl.enqueue_copy(self.queue, totals[:1], vertex_offsets.data, src_offset=8 * count, is_blocking=False),
                cl.enqueue_copy(self.queue, totals[1:2], index_offsets.data, src_offset=8 * count, is_blocking=False),
                cl.enqueue_copy(self.queue, flag_values, flags.data, is_blocking=False)]
        stats = {"patches": count, "culled": None, "saturated": None, "vertices": None, "triangles": None,
                 **data.stats, **level_stats}  # the counts: Plan.settle
        plan = Plan(scene.name, count, parts, data.objects, final, vertex_offsets, index_offsets, None, None,
                    stats, events, started, request, strip_offsets=strips[0],
                    _pending=(totals, flag_values, copies))
        if defer_totals and strips[0] is None and not any(part.pattern.dyadic for part in parts):
            return plan
        plan.settle()
        if strips[0] is not None:
            plan.num_strip_indices = int(strips[0][count].get())  # a third read-back
        if any(part.pattern.dyadic for part in parts):  # the semi-uniform patches' levels
            plan._host["factors"] = final.get()
            stats["patch_levels"] = level_histogram(np.concatenate(
                [plan._host["factors"][p.base:p.base + p.count] for p in parts if p.pattern.dyadic]))
        return plan

    #: Page-locked host arrays for the summaries (or totals and flags) of a Session's frames:
    #: three, used in turn (at most two frames are unsettled at once: Session.tessellate).
    READ_BACK_SLOTS = 3

    def _read_back_arrays(self, scratch: dict | None, count: int, flags: bool = True):
        """(totals (SUMMARY_FIELDS,) uint64, flags (count,) int32 or None) host arrays that
        stage 3's summary (totals, culled, saturated), or its two totals and stage 1's flags
        (``flags``), are copied into: fresh NumPy arrays, or, for a Session's deferred frames
        (``scratch``), page-locked ones kept with the scratch and used in turn: on the H100 a
        non-blocking read of 8 bytes cost the host 10 µs into page-locked memory and 17.5 µs
        into pageable memory (bench/RESULTS.md, "Session 4 on the H100")."""
        if scratch is None:
            return np.zeros(SUMMARY_FIELDS, np.uint64), np.empty(count, np.int32) if flags else None
        head = 8 * SUMMARY_FIELDS
        if "read_back" not in scratch:
            slots = []
            for _ in range(self.READ_BACK_SLOTS):  # each: one buffer, mapped once and kept mapped
                size = head + 4 * max(count, 1)
                buffer = cl.Buffer(self.context, cl.mem_flags.READ_WRITE | cl.mem_flags.ALLOC_HOST_PTR, size)
                memory, _ = cl.enqueue_map_buffer(self.queue, buffer, cl.map_flags.READ | cl.map_flags.WRITE, 0,
                                                  (size,), np.uint8, is_blocking=True)
                slots.append((buffer, memory[:head].view(np.uint64), memory[head:head + 4 * count].view(np.int32)))
            scratch["read_back"], scratch["read_back_turn"] = slots, 0
        turn = scratch["read_back_turn"]
        scratch["read_back_turn"] = (turn + 1) % self.READ_BACK_SLOTS
        _, totals, flag_values = scratch["read_back"][turn]
        return totals, flag_values if flags else None

    def upload_groups(self, groups, num_patches: int) -> dict:
        """Stage 2's edge groups (cltess.crack.adjacency.EdgeGroups over the P * 4 edge slots)
        as device arrays: group_of, group_start, members, collapsed (int32)."""
        collapsed = np.zeros(num_patches * FACTOR_SLOTS, bool) if groups.collapsed_edges is None \
            else groups.collapsed_edges
        return {name: cl_array.to_device(self.queue, np.ascontiguousarray(a, np.int32)) for name, a in
                (("group_of", groups.group_of), ("group_start", groups.group_start), ("members", groups.members),
                 ("collapsed", collapsed))}

    def upload(self, kind: PatchKind, source: np.ndarray, scene: Scene | None = None) -> dict:
        """Device arrays of a kind: "source" (one row per patch) for stage 1, "controls" what
        stage 4 reads (written by stage 1, or the source itself).  A kind with
        ``per_patch_constants`` has the source as controls and its constants as stage 1's
        source (``patch_constants``, kept on ``scene``)."""
        data = {"source": cl_array.to_device(self.queue, np.ascontiguousarray(source, np.float32))}
        shape = kind.controls_shape(len(source))
        data["controls"] = data["source"] if shape is None else cl_array.empty(self.queue, shape, np.float32)
        if kind.per_patch_constants:
            data["source"] = self.patch_constants(kind, len(source), scene)
        return data

    def patch_constants(self, kind: PatchKind, count: int, scene: Scene | None = None) -> cl_array.Array:
        """(count, 4) float32 on the device where stage 1 keeps the patches' bound constants
        (PatchKind.per_patch_constants): made as "not yet" (-1), filled by stage 1 for each patch
        it sees (not culled), kept with ``scene`` for this context (``Scene.prepared``: again
        from scratch when the scene's arrays change), so every later call reads them."""
        def make():
            return self.context, cl_array.to_device(self.queue, np.full((count, 4), -1.0, np.float32))

        if scene is None:
            return make()[1]
        # Cached with the context object itself, so that its id is not reused while cached.
        return scene.prepared((kind.name, "constants", id(self.context)), make)[1]

    def emit(self, plan: "Plan", first: int, last: int, forward_differencing: bool | None = None,
             on_device: bool = False, out: "OutputBuffers | None" = None) -> Tessellation:
        """Stages 4-5 for patches ``first .. last-1`` of a plan (forward_differencing: the plan's
        request's unless given).

        on_device: leave the output on the device (``Tessellation.device``, pyopencl arrays),
        read back to host arrays only when one is asked for; else it is read back now (on a CPU
        device by mapping the buffers: no copy).  out: output buffers to write into (grown as
        needed; a ``Session`` reuses its own), else fresh ones.  A request with emit="by_level"
        runs them by level (levels.emit_by_level, without forward differencing, read back now)."""
        job = self.emit_async(plan, first, last, forward_differencing, out)
        if not on_device:  # read back now: enqueued behind the stages
            job.start_read_back()
        return job.result(on_device)

    def emit_async(self, plan: "Plan", first: int, last: int, forward_differencing: bool | None = None,
                   out: "OutputBuffers | None" = None) -> "PendingEmit":
        """Enqueue stages 4-5 as ``emit`` does and return at once: ``.result()`` waits for
        them.  The host may meanwhile do other work, such as writing the previous batch
        (cltess.stream).  A strip pattern's strips are read back here (strips.emit_strips); a
        request with emit="by_level" runs at once (levels.emit_by_level, read back)."""
        if plan.request.emit == "by_level":  # the semi-uniform parts from per-level templates
            from .levels import emit_by_level
            return _Ready(emit_by_level(self, plan, first, last))
        if forward_differencing is None:
            forward_differencing = plan.request.forward_differencing
        buffers = out if out is not None else OutputBuffers(self)
        capacity = buffers.capacity
        if not plan.settled and ((first, last) != (0, plan.num_patches) or not min(capacity)):
            plan.settle()  # a part of the plan, or no buffers yet: their sizes from the totals
        if plan.settled:
            vertex_range = plan.vertex_range(first, last)
            index_range = plan.index_range(first, last)
        else:  # on the buffers' capacity; PendingEmit.result runs them again if it was too small
            vertex_range, index_range = (0, capacity[0]), (0, 3 * capacity[1])
        work = self.work
        if work == "auto":  # by this plan's vertices per patch where known, else by the latest settled plan's
            self.note_plan(plan, first, last)
            work = self.auto_work()
        events = dict(plan.events) if first == 0 else {}
        arrays = buffers.take(vertex_range[1] - vertex_range[0], (index_range[1] - index_range[0]) // 3)
        vertices = {name: arrays.raw(name) for name, _, _ in VERTEX_RECORD}
        events["vertices"], events["indices"] = [], []
        for part in plan.parts:
            lo, hi = max(first, part.base), min(last, part.base + part.count)
            if lo >= hi:
                continue
            events["vertices"] += self.stage_vertices(
                part.data["controls"], plan.factors, plan.vertex_offsets, plan.objects, vertex_range,
                (lo, hi), forward_differencing, kind=part.kind, patch_base=part.base, out=vertices,
                pattern=part.pattern, work=work, kept_prepared=part.data.get("prepared"))[1]
            events["indices"] += self.stage_indices(
                plan.factors, plan.vertex_offsets, plan.index_offsets, index_range, (lo, hi),
                kind=part.pattern, out=arrays.raw("triangles"), work=work)[1]
        strips = None
        if plan.strip_offsets is not None:
            strips, events["strips"] = emit_strips(self, plan, first, last)
        self.queue.flush()
        return PendingEmit(self, plan, first, last, vertex_range[0], arrays, events, buffers, strips,
                           forward_differencing)

    # --- stage 6 on request: the error, measured (issue 9 item 9) ---------------------------------

    def verify(self, scene: Scene, plan: "Plan", tess: Tessellation, order: int = VERIFY_ORDER,
               max_triangles: int = VERIFY_MAX_TRIANGLES) -> dict:
        """Measure on the device the worst |S(u,v) - mesh(u,v)| / tolerance of ``tess`` (the
        output of ``emit(plan, ...)`` for ``scene``, one batch or all), at the barycentric points
        of order ``order`` of every triangle (``stages/verify.cl``; float64 host mirror:
        ``cltess.bound.worst_bound_ratio``).  Above ``max_triangles`` triangles, every k-th is
        measured (k = "verify_stride" > 1: triangles k, 2k, ... of the whole mesh, so batches
        sample as the single pass does).  Returns the stats: "verify_ratio" (the worst ratio),
        "verify_patch" and "verify_triangle" (where: scene patch number, triangle number in the
        whole mesh), "verify_triangles" (how many were measured), "verify_stride",
        "verify_order", "verify_ms" (device time).  ``combine_verified`` merges batches'."""
        from ...bound import scene_tolerances

        request = plan.request
        pixels = request.tolerance.pixels if isinstance(request.tolerance, ScreenSpace) else None
        eps = request.tolerance.eps if isinstance(request.tolerance, ObjectSpace) else None
        first, last = tess.stats.get("first_patch", 0), tess.stats.get("last_patch", plan.num_patches)
        vertex_base, index_base = plan.vertex_range(first, last)[0], plan.index_range(first, last)[0]
        stride = max(1, -(-(plan.num_indices // 3) // max_triangles)) if max_triangles else 1
        triangle_base = index_base // 3  # tess's triangle 0 in the whole mesh
        tolerances = cl_array.to_device(self.queue, scene_tolerances(scene, eps, pixels, request.sharp_edges)
                                        .astype(np.float32))
        positions, uv, patch_ids = (cl_array.to_device(self.queue, np.ascontiguousarray(a))
                                    for a in (tess.positions, tess.uv, tess.patch_ids))
        triangles = cl_array.to_device(self.queue, (tess.triangles - np.uint32(vertex_base)).astype(np.uint32))
        worst = {"verify_ratio": 0.0, "verify_patch": -1, "verify_triangle": -1}
        measured, events = 0, []
        for part in plan.parts:
            lo, hi = max(first, part.base), min(last, part.base + part.count)
            if lo >= hi:
                continue
            start, stop = (i // 3 for i in plan.index_range(lo, hi))
            start = -(-start // stride) * stride - triangle_base  # the whole mesh's triangles k * stride
            stop -= triangle_base
            samples = max(0, -(-(stop - start) // stride))
            if not samples:
                continue
            ratios = cl_array.empty(self.queue, samples, np.float32)
            events.append(self.programs.kernel("verify", kind=part.kind)(
                self.queue, _global_size(samples), None, part.data["controls"].data, positions.data,
                uv.data, patch_ids.data, triangles.data, np.uint64(start), np.uint32(stride),
                np.uint32(samples), np.uint32(part.base), np.int32(order), tolerances.data, ratios.data))
            host = ratios.get()
            at = int(host.argmax())
            if host[at] > worst["verify_ratio"] or worst["verify_triangle"] < 0:
                triangle = start + at * stride
                worst = {"verify_ratio": float(host[at]), "verify_triangle": triangle_base + triangle,
                         "verify_patch": int(tess.patch_ids[tess.triangles[triangle, 0] - vertex_base])}
            measured += samples
        return dict(worst, verify_triangles=measured, verify_stride=stride, verify_order=order,
                    verify_ms=span_ms(events) if events else 0.0)

    # --- stages 4-5 from a plan made elsewhere (issue 17, cltess/batch.py) -----------------------

    def upload_plan(self, host: "HostPlan", first: int = 0, last: int | None = None) -> "Plan":
        """A Plan on this device from a plan read back on another (``Plan.to_host``), so that
        ``emit(plan, a, b)`` runs stages 4-5 for any ``first <= a < b <= last`` without running
        stages 1-3 again.  Only the controls of patches ``first .. last-1`` are uploaded (the
        stage-4 kernels read patch p's at ``p - patch_base``, so a part may start mid-kind);
        factors, offsets and object ids are uploaded whole (36 bytes per patch)."""
        last = host.num_patches if last is None else last
        parts = []
        for (name, pattern, base, count), controls in zip(host.kinds, host.controls):
            lo, hi = max(first, base), min(last, base + count)
            if lo < hi:
                kind = kind_named(name)
                data = {"controls": cl_array.to_device(self.queue, controls[lo - base:hi - base])}
                parts.append(PlanPart(kind, PATTERNS[pattern], lo, hi - lo, data))
        arrays = {name: cl_array.to_device(self.queue, getattr(host, name))
                  for name in ("objects", "factors", "vertex_offsets", "index_offsets")}
        if host.strip_offsets is not None:  # a strip pattern's strips (emit_strips) come along
            arrays["strip_offsets"] = cl_array.to_device(self.queue, host.strip_offsets)
        return Plan(host.name, host.num_patches, parts, num_vertices=host.num_vertices,
                    num_strip_indices=host.num_strip_indices,
                    num_indices=host.num_indices, stats=dict(host.stats), events={},
                    started=time.perf_counter(), request=host.request,
                    _host={name: getattr(host, name) for name in ("factors", "vertex_offsets", "index_offsets")},
                    **arrays)

    # --- the stages: device arrays in, device arrays and their events out ----------------------

    def stage_factors(self, patches, eps, pixels, camera, max_factor):
        """Stage 1 for Bézier patches.  patches: (P, 16, 4) float32 -> factors (P, 4) int32,
        flags (P,) int32 (bit 0 saturated, bit 1 culled)."""
        count = len(patches)
        factors = cl_array.empty(self.queue, (count, FACTOR_SLOTS), np.int32)
        flags = cl_array.empty(self.queue, count, np.int32)
        data = {"source": self.patch_constants(BEZIER, len(patches)), "controls": patches}
        events = self.stage_factors_of(BEZIER, data, _tolerance(eps, pixels, camera), max_factor, factors, flags)
        return factors, flags, events

    def stage_pn_factors(self, triangles, eps, pixels, camera, max_factor):
        """Stage 1 for PN triangles.  triangles: (T, 12, 4) float32 (PNKind's source) ->
        controls (T, 16, 4) float32, factors (T, 4) int32 (fourth 0), flags (T,) int32."""
        count = len(triangles)
        controls = cl_array.empty(self.queue, (count, 16, 4), np.float32)
        factors = cl_array.empty(self.queue, (count, FACTOR_SLOTS), np.int32)
        flags = cl_array.empty(self.queue, count, np.int32)
        events = self.stage_factors_of(PN, {"source": triangles, "controls": controls},
                                       _tolerance(eps, pixels, camera), max_factor, factors, flags)
        return controls, factors, flags, events

    def stage_factors_of(self, kind, data, tolerance, max_factor, factors, flags, patch_base=0, pattern=None,
                         max_level=DEFAULT_MAX_LEVEL):
        """Stage 1 for a kind: data its device arrays (``upload``), tolerance an ObjectSpace or
        ScreenSpace; writes factors and flags of its patches at patch_base.., and returns the events.
        pattern: the kind's own unless given; a dyadic one rounds the factors to 2^p_e,
        p_e <= max_level."""
        count = len(data["source"])
        arguments = (data["source"].data, data["controls"].data, np.uint32(count), np.uint32(patch_base),
                     *tolerance.kernel_args(), np.int32(max_factor), np.int32(max_level), factors.data, flags.data)
        event = self.programs.kernel("factors", kind=kind, tolerance=tolerance, pattern=pattern or kind.pattern)(
            self.queue, _global_size(count), None, *arguments)
        return [event]

    def stage_crack_free(self, factors, groups, crack="crack/max.h", out=None):
        """Stage 2.  factors (P, 4) int32 and edge groups over its P * 4 entries
        (cltess.adjacency, or merge_edge_groups for several kinds; or ``upload_groups`` of them)
        -> (P, 4) int32 (``out`` when given); the groups' collapsed_edges are stored negated
        (kernels/common.h, patch_factors)."""
        edges = factors.size
        if not isinstance(groups, dict):
            groups = self.upload_groups(groups, len(factors))
        final = cl_array.empty(self.queue, factors.shape, np.int32) if out is None else out
        event = self.programs.kernel("crack_free", crack=crack)(
            self.queue, _global_size(edges), None, factors.data, groups["group_of"].data,
            groups["group_start"].data, groups["members"].data, groups["collapsed"].data, np.uint32(edges),
            final.data)
        return final, [event]

    def stage_counts(self, factors, kind=BEZIER, scratch: dict | None = None, flags=None, summary=None,
                     crack_free: tuple | None = None):
        """Stage 3.  factors (P, 4) -> vertex and index offsets (P+1,) uint64, [P] = total.

        kind: the kind (a PatchKind or its name) or the pattern of every patch, or a list of
        (kind or pattern, base, count) ranges covering 0..P-1.  scratch: a dict keeping the
        count and offset arrays for the next call (``plan_on``).  summary: a (4,) uint64 device
        array that stage 3 fills with (vertex total, index total, patches culled, patches
        saturated) from stage 1's ``flags`` (P,) int32, so that the host reads one buffer
        (``writes_summary`` says where it can: not with two scans).  crack_free: (stage 1's
        factors, the uploaded edge groups, the crack policy's header) to run stage 2 into
        ``factors`` in the first range's launch (stages/crack_offsets.cl; the one-launch path
        only: ``fuses_crack_free``)."""
        count = len(factors)
        ranges = [(kind, 0, count)] if not isinstance(kind, (list, tuple)) else kind
        scratch = {} if scratch is None else scratch
        if "vertex_counts" not in scratch:  # the scan writes offsets[1:]; offsets[0] stays 0
            for name in ("vertex_counts", "index_counts"):
                scratch[name] = cl_array.empty(self.queue, count, np.uint64)
            for name in ("vertex_offsets", "index_offsets"):
                scratch[name] = cl_array.zeros(self.queue, count + 1, np.uint64)
        vertex_counts, index_counts = scratch["vertex_counts"], scratch["index_counts"]
        vertex_offsets, index_offsets = scratch["vertex_offsets"], scratch["index_offsets"]
        if summary is not None and not self.writes_summary(count, ranges):
            raise ValueError("stage 3 writes a summary in one launch or with one scan (CLTESS_ONE_SCAN=1)")
        path = self._stage3_path(count, ranges)
        if crack_free is not None and path != "fused":
            raise ValueError("stage 2 runs in stage 3's launch only where stage 3 is one launch per range")
        if summary is not None and path == "tiled":  # two launches: tiles, then their carries
            return vertex_offsets, index_offsets, self._tiled_offsets(ranges, factors, flags, summary, scratch)
        if path == "fused":  # one launch per range, in order; the last one writes the summary
            ranges = [r for r in sorted(ranges, key=lambda r: r[1]) if r[2]]
            events = [self._fused_offsets(_pattern(k), factors, base, n, vertex_counts, index_counts,
                                          vertex_offsets, index_offsets,
                                          (flags, count, summary) if summary is not None and at == len(ranges) - 1
                                          else None, crack_free if at == 0 else None)
                      for at, (k, base, n) in enumerate(ranges)]
            return vertex_offsets, index_offsets, events
        events = [self.programs.kernel("counts", pattern=_pattern(k))(
            self.queue, _global_size(n), None, factors.data, np.uint32(n), np.uint32(base),
            vertex_counts.data, index_counts.data) for k, base, n in ranges if n]
        if summary is not None:  # the pair scan with the flags' counts, and the summary at the end
            events.append(self.programs.summary_scan()(vertex_counts, index_counts, flags, vertex_offsets,
                                                       index_offsets, summary, allocator=self._scan_memory))
        elif self.one_scan:  # both offsets in one scan of (vertex, index) pairs (programs.py)
            events.append(self.programs.offsets_pair_scan(vertex_counts, index_counts, vertex_offsets,
                                                          index_offsets, allocator=self._scan_memory))
        else:
            events += [self.programs.offsets_scan(vertex_counts, vertex_offsets, allocator=self._scan_memory),
                       self.programs.offsets_scan(index_counts, index_offsets, allocator=self._scan_memory)]
        return vertex_offsets, index_offsets, events

    def _stage3_path(self, count: int, ranges) -> str:
        """How stage 3 of ``count`` patches in these ranges runs: "fused", one launch per range
        (stages/offsets.cl; ``fused_offsets``, up to the device type's cap); "tiled", two
        launches (``_tiled_offsets``; ``tiled_offsets``, up to ``TILED_OFFSETS_MAX_PATCHES``,
        only where a summary is asked for); else "scan" (counts kernel and pyopencl.scan).  Never
        one of the first two for a pattern whose counts walk the patch (that wants the whole device)."""
        if any(_pattern(k).counts_walk for k, _, n in ranges if n):
            return "scan"
        cap = min(FUSED_OFFSETS_MAX_PATCHES, FUSED_OFFSETS_MAX_PATCHES_CPU) if self._cpu else FUSED_OFFSETS_MAX_PATCHES
        if self.fused_offsets and count <= cap:
            return "fused"
        if self.tiled_offsets and count <= TILED_OFFSETS_MAX_PATCHES:
            return "tiled"
        return "scan"

    def _tiled_offsets(self, ranges, factors, flags, summary, scratch: dict) -> list:
        """Stage 3 in two launches (stages/offsets.cl offsets_tiles per range, then
        offsets_carries once), the summary written by the last tile."""
        ranges = [r for r in sorted(ranges, key=lambda r: r[1]) if r[2]]
        tiles_kernel = [self.programs.kernel("offsets", "offsets_tiles", pattern=_pattern(k)) for k, _, _ in ranges]
        group, local_v, local_i = self._group_of(tiles_kernel[0], TILED_OFFSETS_GROUP)
        for kernel in tiles_kernel[1:]:
            group = min(group, self._group_of(kernel, TILED_OFFSETS_GROUP)[0])
        carries = self.programs.kernel("offsets", "offsets_carries", pattern=_pattern(ranges[-1][0]))
        group = min(group, self._group_of(carries, TILED_OFFSETS_GROUP)[0])
        local = self._group_of(carries, group)[1:]  # (local arrays of that size)
        tile_counts = [-(-n // group) for _, _, n in ranges]
        num_tiles = sum(tile_counts)
        if scratch.get("tiles") is None or scratch["tiles"].size < 4 * num_tiles:
            scratch["tiles"] = cl_array.empty(self.queue, 4 * num_tiles, np.uint64)
        tiles = scratch["tiles"]
        events, tile_base = [], 0
        for kernel, (_, base, n), count in zip(tiles_kernel, ranges, tile_counts):
            events.append(kernel(self.queue, (count * group,), (group,), factors.data, np.uint32(n), np.uint32(base),
                                 np.uint32(tile_base), flags.data, scratch["vertex_counts"].data,
                                 scratch["index_counts"].data, scratch["vertex_offsets"].data,
                                 scratch["index_offsets"].data, tiles.data, *local))
            tile_base += count
        events.append(carries(self.queue, (num_tiles * group,), (group,), np.uint32(num_tiles), tiles.data,
                              scratch["vertex_offsets"].data, scratch["index_offsets"].data, summary.data, *local))
        return events

    def _group_of(self, kernel, cap: int) -> tuple:
        """(work-group size, two local ulong arrays of that size) of a stage 3 kernel that scans
        in one work-group: a power of two, at most ``cap`` and what the device allows for it
        (asked once per kernel: a frame's launch needs no device query)."""
        found = self._fused_groups.get((kernel, cap))
        if found is None:
            limit = min(cap, self.device.max_work_group_size,
                        kernel.get_work_group_info(cl.kernel_work_group_info.WORK_GROUP_SIZE, self.device))
            group = 1 << (int(limit).bit_length() - 1)  # a power of two: the scan's steps
            found = self._fused_groups[kernel, cap] = (group, cl.LocalMemory(8 * group), cl.LocalMemory(8 * group))
        return found

    def writes_summary(self, count: int, ranges) -> bool:
        """Whether stage 3 (``stage_counts``) can write a frame's summary: in one launch per
        range, in two (tiles, carries), or with one scan; not with two scans
        (``CLTESS_ONE_SCAN=0``) nor without patches."""
        return count > 0 and (self.one_scan or self._stage3_path(count, ranges) != "scan")

    def _fused_offsets(self, pattern, factors, base, n, vertex_counts, index_counts, vertex_offsets,
                       index_offsets, summary=None, crack_free=None) -> cl.Event:
        """Stage 3 for patches base .. base+n-1 of one pattern in one work-group
        (stages/offsets.cl), from offsets[base] on; summary: (flags, their number, summary
        array) for ``offsets_summary``; crack_free: (stage 1's factors, edge groups, crack
        policy) to write ``factors`` first, every edge's (stages/crack_offsets.cl)."""
        if crack_free is None:
            kernel = self.programs.kernel("offsets", None if summary is None else "offsets_summary", pattern=pattern)
            stage2 = (factors.data,)
        else:
            raw, groups, crack = crack_free
            kernel = self.programs.kernel("crack_offsets", None if summary is None else "crack_offsets_summary",
                                          pattern=pattern, crack=crack)
            stage2 = (raw.data, groups["group_of"].data, groups["group_start"].data, groups["members"].data,
                      groups["collapsed"].data, np.uint32(raw.size), factors.data)
        group, local_v, local_i = self._group_of(kernel, FUSED_OFFSETS_GROUP)
        extra = () if summary is None else (summary[0].data, np.uint32(summary[1]), summary[2].data)
        return kernel(self.queue, (group,), (group,), *stage2, np.uint32(n), np.uint32(base),
                      vertex_counts.data, index_counts.data, vertex_offsets.data, index_offsets.data, *extra,
                      local_v, local_i)

    def fuses_crack_free(self, count: int, ranges) -> bool:
        """Whether a Session frame (``plan_on(defer_totals=True)``) of ``count`` patches in these
        ranges runs stage 2 in stage 3's first launch (stages/crack_offsets.cl): where stage 3 is
        one launch per range, ``fused_crack_free`` is on and the patches are at most
        ``FUSED_CRACK_FREE_MAX_PATCHES``.  One-shot plans keep stage 2's own launch, so that
        their ``stage_ms`` time it apart (the suite's "crack_free" column)."""
        return (self.fused_crack_free and 0 < count <= FUSED_CRACK_FREE_MAX_PATCHES
                and self._stage3_path(count, ranges) == "fused")

    def _vertex_arrays(self, n: int) -> dict:
        """The vertex record's arrays (VERTEX_RECORD, in the kernel's argument order)."""
        return {name: cl_array.empty(self.queue, (n, *shape), dtype) for name, dtype, shape in VERTEX_RECORD}

    def stage_vertices(self, controls, factors, vertex_offsets, patch_objects, vertex_range,
                       patch_range, forward_differencing=True, kind=BEZIER, patch_base=0, out=None,
                       pattern=None, rows_per_patch: int | None = None, work: str | None = None,
                       kept_prepared: dict | None = None):
        """Stage 4 for patches patch_range = (first, last) (scene numbers, all of one kind whose
        first patch is patch_base; controls: that kind's stage-4 input, Bézier patches or PN
        control points), whose vertices are vertex_range = (start, stop) -> dict of positions
        (V, 3), normals (V, 3), uv (V, 2), patch_ids (V,), object_ids (V,) device arrays,
        V = stop - start (written into ``out`` when given), and the events.  The patches'
        vertices may be fewer than V (a Session frame launched on the buffers' capacity before
        stage 3's totals were read); if they are more, the kernels write none (batch_fits in
        kernels/common.h).  rows_per_patch:
        work-items per patch of stages/vertex_rows.cl (0: one per patch, stages/vertices.cl;
        None: as ``work``).  work: "patch", "rows" (with ``MAX_ROWS_PER_PATCH``), "vertex" or
        "point" (stages/vertex_points.cl, a work-item per vertex), "vertex-prep" or "point-prep"
        (stages/prepared_points.cl: the patches prepared first), "rows-prep" (the same, a
        work-item per row or ring edge); None: the Tessellator's ``work``.  kept_prepared: where a
        "*-prep" distribution keeps the patches it prepares, across calls (``_prepared_points``)."""
        out = self._vertex_arrays(vertex_range[1] - vertex_range[0]) if out is None else out
        first, last = patch_range
        if vertex_range[1] == vertex_range[0] or last <= first:
            return out, []
        kind = kind_named(kind)
        pattern = pattern or kind.pattern
        arguments = (controls.data, factors.data, vertex_offsets.data, patch_objects.data, np.uint32(first),
                     np.uint32(last - first), np.uint32(patch_base), np.uint64(vertex_range[0]),
                     np.int32(forward_differencing), np.uint64(vertex_range[1] - vertex_range[0]))
        work = work or self.work
        if work == "auto":  # called directly (levels.py): by this batch's vertices per patch
            work = self.auto_work(vertex_range[1] - vertex_range[0], last - first)
        if rows_per_patch is None and work == "rows":
            rows_per_patch = MAX_ROWS_PER_PATCH
        if rows_per_patch is None and work in PREPARED_WORK:
            event = self._prepared_points(controls, factors, vertex_offsets, patch_objects, vertex_range, first, last,
                                          forward_differencing, kind, patch_base, pattern, out, work, kept_prepared)
        elif rows_per_patch is None and work in ("vertex", "point"):  # work-items past the part's vertices return
            event = self.programs.kernel("vertex_points", kind=kind, pattern=pattern)(
                self.queue, _record_groups(vertex_range[1] - vertex_range[0], self.records_for(work)), (WORK_GROUP,),
                *arguments, np.uint32(self.records_for(work)), *(a.data for a in out.values()))
        elif rows_per_patch:
            event = self.programs.kernel("vertex_rows", kind=kind, pattern=pattern)(
                self.queue, _global_size((last - first) * rows_per_patch), None, *arguments,
                np.uint32(rows_per_patch), *(a.data for a in out.values()))
        else:
            event = self.programs.kernel("vertices", kind=kind, pattern=pattern)(
                self.queue, _global_size(last - first), None, *arguments, *(a.data for a in out.values()))
        return out, list(event) if isinstance(event, tuple) else [event]

    def prepared_scratch(self, kind, pattern, patches: int) -> cl.Buffer:
        """The scratch buffer of work="*-prep" with room for ``patches`` of ``kind``'s
        kind_patch (its size as the device compiler lays it out: kernel kind_patch_size), grown
        when needed.  Tessellator.compose makes it for the scene before the plan's buffers:
        Oclgrind's uninitialised-value plugin took a buffer made after them for never written
        (every prepared_points read reported; made first, the same run is clean).  So too a
        buffer made where one just freed had been: the size's answer array lives until the
        buffer is made (with it freed first, as a helper returning the size did, every
        prepared_rows read of mixed_culled_by_prepared_rows was reported)."""
        size = self._kind_patch_sizes.get((kind.name, pattern.header))
        if size is None:
            answer = cl_array.empty(self.queue, 1, np.uint32)
            self.programs.kernel("prepared_points", "kind_patch_size", kind=kind, pattern=pattern)(
                self.queue, (1,), None, answer.data)
            size = self._kind_patch_sizes[kind.name, pattern.header] = int(answer.get()[0])
        needed = max(1, patches) * size
        if self._prepared is None or self._prepared.size < needed:
            self._prepared = cl.Buffer(self.context, cl.mem_flags.READ_WRITE, needed + needed // 4)
        return self._prepared

    def kind_patch_size(self, kind, pattern) -> int:
        """Bytes of ``kind``'s kind_patch as the device compiler lays it out (``prepared_scratch``
        finds it, and compose calls that for every "*-prep" scene)."""
        if (kind.name, pattern.header) not in self._kind_patch_sizes:
            self.prepared_scratch(kind, pattern, 1)
        return self._kind_patch_sizes[kind.name, pattern.header]

    def _prepared_points(self, controls, factors, vertex_offsets, patch_objects, vertex_range, first, last,
                         forward_differencing, kind, patch_base, pattern, out, work="point-prep",
                         kept: dict | None = None) -> tuple:
        """Stage 4 from prepared patches (stages/prepared_points.cl): prepare_patches writes
        patches first .. last-1's kind_patch to a scratch buffer (kept, grown as needed; the
        queue is in order, so a later batch's prepare waits for this batch's reads), then
        prepared_points (a work-item per vertex) or, for work="rows-prep", prepared_rows (a
        work-group per ``patches_per_group`` patches, a work-item per line) writes the vertices.
        Returns the events: prepare_patches' and the vertices' kernel's (the profiling span of
        stage 4 runs from the first to the last).

        kept: a dict the caller keeps with the scene's device data (a Session's, for a kind whose
        stage-4 input is its upload, which no frame rewrites): the patches are prepared there
        once, every one of them (a patch culled in this frame may be seen in the next), and
        later calls read them without preparing again.  That preparation is the scene's set-up,
        as its upload is: not recorded for a replayed frame, and not among the returned events
        (stage 4 is then the vertices' kernel alone)."""
        program = dict(kind=kind, pattern=pattern)

        def prepare(into, every: int):
            return self.programs.kernel("prepared_points", "prepare_patches", **program)(
                self.queue, _global_size(last - first), None, controls.data, vertex_offsets.data, np.uint32(first),
                np.uint32(last - first), np.uint32(patch_base), into, np.int32(every))

        if kept is None:  # this call's patches that have vertices, into the scratch buffer
            prepared = self.prepared_scratch(kind, pattern, last - first)
            events = (prepare(prepared, every=0),)
        else:
            key, events = (pattern.header, first, last, patch_base), ()
            prepared = kept.get(key)
            if prepared is None:  # the first call: every patch, into a buffer of the caller's
                size = max(1, last - first) * self.kind_patch_size(kind, pattern)
                prepared = kept[key] = cl.Buffer(self.context, cl.mem_flags.READ_WRITE, size)
                recording, self.programs.recording = self.programs.recording, None  # (set-up: not replayed)
                try:
                    prepare(prepared, every=1)
                finally:
                    self.programs.recording = recording
        if work == "rows-prep":
            per_group = self.line_patches_for(last - first)
            if not 0 < per_group <= LINE_MAX_PATCHES:
                raise ValueError(f"patches_per_group={per_group}: expected 1 .. {LINE_MAX_PATCHES}")
            rows = self.programs.kernel("prepared_points", "prepared_rows", **program)(
                self.queue, (-(-(last - first) // per_group) * LINE_GROUP,), (LINE_GROUP,),
                prepared, factors.data, vertex_offsets.data, patch_objects.data, np.uint32(first),
                np.uint32(last - first), np.uint64(vertex_range[0]), np.int32(forward_differencing),
                np.uint64(vertex_range[1] - vertex_range[0]), np.uint32(per_group), *(a.data for a in out.values()))
            return (*events, rows)
        per_item = self.records_for("point-prep")
        points = self.programs.kernel("prepared_points", **program)(
            self.queue, _record_groups(vertex_range[1] - vertex_range[0], per_item), (WORK_GROUP,),
            prepared, factors.data, vertex_offsets.data, patch_objects.data, np.uint32(first),
            np.uint32(last - first), np.uint64(vertex_range[0]), np.int32(forward_differencing),
            np.uint64(vertex_range[1] - vertex_range[0]), np.uint32(per_item), *(a.data for a in out.values()))
        return (*events, points)

    def stage_indices(self, factors, vertex_offsets, index_offsets, index_range, patch_range,
                      kind=BEZIER, out=None, work: str | None = None):
        """Stage 5 for patches patch_range = (first, last) (scene numbers, all of one kind or
        pattern), whose indices are index_range = (start, stop) -> triangles ((stop - start) / 3,
        3) uint32 device array (``out`` when given), and the events; as stage_vertices, the
        patches' indices may be fewer, and none is written if they are more.  work: "point" a work-item
        per triangle (stages/triangles.cl), else per patch (stages/indices.cl); None: the
        Tessellator's ``work``."""
        n = index_range[1] - index_range[0]
        triangles = cl_array.empty(self.queue, (n // 3, 3), np.uint32) if out is None else out
        first, last = patch_range
        if not n or last <= first:
            return triangles, []
        arguments = (factors.data, vertex_offsets.data, index_offsets.data, np.uint32(first),
                     np.uint32(last - first), np.uint64(index_range[0]), np.uint64(n))
        work = work or self.work
        if work == "auto":  # called directly (levels.py, silhouette.py): "point" or "rows-prep", both per triangle
            work = self.auto_work()
        if work in ("point", "point-prep", "rows-prep"):  # work-items past the part's triangles stop
            per_item = self.records_for(work)
            event = self.programs.kernel("triangles", pattern=_pattern(kind))(
                self.queue, _record_groups(n // 3, per_item), (WORK_GROUP,), *arguments,
                np.uint32(per_item), triangles.data)
        else:
            event = self.programs.kernel("indices", pattern=_pattern(kind))(
                self.queue, _global_size(last - first), None, *arguments, triangles.data)
        return triangles, [event]


def combine_verified(parts: list[dict]) -> dict:
    """The verify stats of several batches of one mesh (Tessellator.verify) as one."""
    parts = [p for p in parts if p]
    if not parts:
        return {}
    worst = max(parts, key=lambda p: p["verify_ratio"])
    return dict(worst, verify_triangles=sum(p["verify_triangles"] for p in parts),
                verify_ms=sum(p["verify_ms"] for p in parts))


@dataclass
class _Ready:
    """An emit that ran synchronously, with PendingEmit's ``start_read_back`` and ``result``."""

    tessellation: Tessellation

    def start_read_back(self, sizes: tuple | None = None) -> bool:  # (read back already)
        return True

    def result(self, on_device: bool = False, wait: bool = True) -> Tessellation:
        return self.tessellation


@dataclass
class PendingEmit:
    """Stages 4-5 enqueued (``Tessellator.emit_async``); ``result()`` waits and gives the
    Tessellation."""

    tessellator: "Tessellator"
    plan: "Plan"
    first: int
    last: int
    vertex_base: int
    arrays: dict
    events: dict
    buffers: "OutputBuffers"
    strips: np.ndarray | None = None  # host strips of a strip pattern (cltess.strips)
    forward_differencing: bool | None = None  # as asked of emit_async (a run again asks the same)

    def start_read_back(self, sizes: tuple | None = None) -> bool:
        """Enqueue the host read-back (and the factors' copy) now, right behind these stages,
        so that ``result()`` only waits for it: what the host enqueues meanwhile (the next
        batch's stages: cltess.stream) then runs while the host reads this output, and the
        read-back costs no round trip of its own.  A CPU device's map needs no sizes, so it is
        started also for a Session frame whose totals are still on their way; a GPU's copies
        need them: there only for a settled plan, or with ``sizes`` (vertices, triangles) of
        the output as settled (a Session frame once its totals are read: its DeviceOutput's
        arrays).  Returns whether it was started."""
        if self.buffers.mapped:
            sizes = ()
        elif sizes is None:
            if not self.plan.settled:
                return False
            sizes = (self.arrays.num_vertices, self.arrays.num_triangles)
        self.plan.enqueue_host_factors()
        self.buffers.start_read_back(*sizes)
        return True

    def result(self, on_device: bool = False, wait: bool = True) -> Tessellation:
        """The Tessellation.  wait=False (with on_device): return at once, the stages still
        running; the first look at its ``stage_ms``, ``wall_ms``, ``stats``, sizes or arrays,
        or ``finish()``, waits for them (commands on the same in-order queue need no wait).

        A plan not yet settled (a Session frame: stages 4-5 launched on the buffers' capacity)
        settles first: if its output did not fit, the kernels wrote nothing, and stages 4-5 run
        again on buffers grown to its totals, unless a later frame has taken the buffers (this
        output is stale then, and its plan's arrays are that frame's)."""
        if not wait and not on_device:
            raise ValueError("wait=False leaves the output on the device: give on_device=True too")
        plan, first, last, buffers = self.plan, self.first, self.last, self.buffers
        events, times = self.events, {}
        current = {"arrays": self.arrays, "generation": buffers.generation}
        launched_on_capacity = not plan.settled

        def settle() -> None:  # the totals known; stages 4-5 again where the output did not fit
            if plan.settled and "stats" in times:
                return
            plan.settle()
            times["stats"] = dict(plan.stats, first_patch=first, last_patch=last)
            if not launched_on_capacity:  # launched on the settled plan's sizes (of this range)
                return
            arrays = current["arrays"]
            fits = plan.num_vertices <= arrays.num_vertices and plan.num_indices // 3 <= arrays.num_triangles
            times["stats"]["output_fit"] = fits  # False: the first launch of stages 4-5 wrote nothing (too small)
            if fits or buffers.generation != current["generation"]:  # (stale: its sizes, never its arrays)
                arrays.num_vertices, arrays.num_triangles = plan.num_vertices, plan.num_indices // 3
            else:
                again = self.tessellator.emit_async(plan, first, last, self.forward_differencing, out=buffers)
                events.update(vertices=again.events["vertices"], indices=again.events["indices"])
                current.update(arrays=again.arrays, generation=buffers.generation)
                device.arrays = again.arrays

        def finish(tess: Tessellation) -> None:  # wait for the stages; their times
            settle()
            tess.stats = times["stats"]
            all_events = [event for evs in events.values() for event in evs]
            waited = wait_ms(all_events) if all_events else 0.0
            tess.stage_ms = {stage: span_ms(evs) for stage, evs in events.items() if evs}
            tess.wall_ms = times["wall_ms"] = {"stages": (time.perf_counter() - plan.started) * 1e3,
                                               "waits": (plan.wait_ms if first == 0 else 0.0) + waited}
            tess.stage_ms["total_wall"] = tess.wall_ms["stages"]  # until the host arrays: Tessellation.fetch

        def read_back() -> dict:  # (Tessellation.fetch has waited for the stages: finish)
            plan.enqueue_host_factors()  # with the output's copies or maps: one wait for all
            host = buffers.read_back(current["arrays"].num_vertices, current["arrays"].num_triangles)
            if "wall_ms" in times:
                times["wall_ms"]["waits"] += buffers.read_back_wait_ms
            host["factors"], host["real_factors"] = plan.output_factors(first, last)
            return host

        def share():  # the output handed to another API (OutputBuffers.shares)
            return buffers.share(current["arrays"].num_vertices, current["arrays"].num_triangles)

        device = DeviceOutput(self.arrays, self.tessellator.queue, self.vertex_base, read_back,
                              valid=lambda: buffers.generation == current["generation"], settle=settle,
                              share=share if buffers.shares else None, shares=buffers.shares)
        tess = Tessellation.on_device(device, None, None, None, self.strips, finish=finish)
        if wait:
            tess.finish()
        if not on_device:
            tess.fetch()
            tess.device = None  # the device buffers go when the caller drops nothing but the host arrays
        return tess

"""Host orchestration of the five-stage pipeline (DESIGN.md section 1).

    1. factors     kernels/factors.cl     zs_factors     pn_factors
    2. crack-free  kernels/crack_free.cl  crack_free_factors (every kind)
    3. counts      kernels/counts.cl      quad_counts    pn_counts, then pyopencl.scan into offsets
    4. vertices    kernels/vertices.cl    quad_vertices  pn_vertices
    5. indices     kernels/indices.cl     quad_indices   pn_indices

Each patch type is a plug-in, a :class:`PatchKind`: how its scene part goes to the device, its
kernels for stages 1, 3, 4 and 5, its edges per patch and its adjacency.  Everything else is
shared: the scene's patches are numbered kind after kind (Bézier patches, then mesh triangles:
``cltess.scene``), and one (P, 4) factor array, one crack-free pass, one scan, one Plan and its
batches cover them all.  A kind's kernels take ``patch_base``, the scene number of the kind's
first patch; factors, offsets, object ids and patch ids are indexed by scene number.

Everything between stage 1 and stage 5 stays on the device; the host reads back the two totals
to size the output buffers, then the outputs.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array
from pyopencl.scan import GenericScanKernel

from . import reference
from .adjacency import (SHARP_EDGE_MODES, EdgeGroups, edge_groups, merge_edge_groups, mesh_edge_groups,
                        pn_edge_normals)
from .device import BuildError, first_error_line, pick_device
from .limits import OutputTooLarge, check_max_factor, check_patch_count, check_tolerance_value, check_totals
from .reference import DEFAULT_MAX_FACTOR
from .scene import Scene, device_patches
from .tessellation import Tessellation

STAGES = ("factors", "crack_free", "counts", "vertices", "indices")
WORK_GROUP = 64  # global sizes are rounded up to this; kernels guard their index
FACTOR_SLOTS = 4  # factors per patch in the shared (P, 4) array; a kind uses its first `edges`


def kernel_dir() -> Path:
    """Folder of the .cl sources (top-level kernels/, installed as cltess.kernels)."""
    return Path(str(resources.files("cltess.kernels")))


# --- patch kinds ------------------------------------------------------------------------------

@dataclass
class KindInput:
    """A kind's part of a scene, prepared on the host: what is uploaded and what stage 2 needs.

    source:  the float32 array its stage-1 kernel reads, one row per patch.
    objects: (n,) int32 object id per patch.
    groups:  its patch-edges (``edges`` per patch) grouped into shared edges.
    stats:   extra counts for the summary (e.g. sharp edges).
    """

    source: np.ndarray
    objects: np.ndarray
    groups: EdgeGroups
    stats: dict = field(default_factory=dict)


class PatchKind:
    """One patch type of the pipeline (a plug-in).

    name:    its name ("bezier", "pn").
    edges:   boundary curves per patch (at most FACTOR_SLOTS); its factors fill the first
             ``edges`` slots of the patch's row of the (P, 4) factor array, the rest are 0.
    kernels: its kernel for stages 1, 3, 4, 5, by stage name.  The stage-3, -4 and -5 kernels
             of all kinds take the same arguments (kernels/counts.cl, vertices.cl, indices.cl);
             stage 1 takes ``factor_buffers(data)`` then the common ones (kernels/factors.cl).
    """

    name = ""
    edges = 0
    kernels: dict = {}

    def count(self, scene: Scene) -> int:
        """How many patches of this kind the scene has."""
        raise NotImplementedError

    def prepare(self, scene: Scene, sharp_edges: str = "straight") -> KindInput:
        """The kind's part of the scene on the host (sharp_edges: for meshes, see
        ``adjacency.pn_edge_normals``)."""
        raise NotImplementedError

    def upload(self, queue: cl.CommandQueue, source: np.ndarray) -> dict:
        """Device arrays: ``"source"`` (one row per patch) for stage 1, ``"controls"`` what stage
        4 reads (after stage 1 has run)."""
        raise NotImplementedError

    def factor_buffers(self, data: dict) -> list:
        """The stage-1 kernel's leading arguments."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<PatchKind {self.name}>"


class BezierKind(PatchKind):
    """Rational bicubic Bézier patches (DESIGN.md section 2): source = controls = (P, 16, 4)."""

    name = "bezier"
    edges = 4
    kernels = {"factors": "zs_factors", "counts": "quad_counts", "vertices": "quad_vertices",
               "indices": "quad_indices"}

    def count(self, scene):
        return scene.num_bezier

    def prepare(self, scene, sharp_edges="straight"):
        return KindInput(device_patches(scene.patches), scene.object_ids,
                         edge_groups(scene.patches))

    def upload(self, queue, source):
        patches = cl_array.to_device(queue, np.ascontiguousarray(source, np.float32))
        return {"source": patches, "controls": patches}

    def factor_buffers(self, data):
        return [data["source"].data]


class PNKind(PatchKind):
    """PN triangles of the scene's meshes (DESIGN.md section 3).

    source (T, 12, 4) float32: positions P1 P2 P3 (w = 1), vertex normals N1 N2 N3, and the
    normals each edge's boundary curve uses at its two ends (``adjacency.pn_edge_normals``:
    the vertex normals, except at sharp edges).  Stage 1 (pn_factors) writes the control points
    (T, 16, 4) that stage 4 reads.
    """

    name = "pn"
    edges = 3
    kernels = {"factors": "pn_factors", "counts": "pn_counts", "vertices": "pn_vertices",
               "indices": "pn_indices"}

    def count(self, scene):
        return scene.num_triangles

    def prepare(self, scene, sharp_edges="straight"):
        meshes = scene.meshes
        corners = np.concatenate([m.vertices[m.faces] for m in meshes]).astype(np.float32)
        normals = np.concatenate([m.normals[m.faces] for m in meshes]).astype(np.float32)
        groups, sharp = mesh_edge_groups(corners, normals)
        source = np.zeros((len(corners), 12, 4), np.float32)
        source[:, 0:3, :3] = corners
        source[:, 0:3, 3] = 1.0
        source[:, 3:6, :3] = normals
        source[:, 6:12, :3] = pn_edge_normals(normals, groups, sharp, sharp_edges).reshape(-1, 6, 3)
        objects = np.concatenate([np.full(m.num_faces, m.object_id, np.int32) for m in meshes])
        stats = {
            "pn_triangles": len(corners),
            "sharp_edges": int(len(np.unique(groups.group_of[sharp]))),
            "degenerate_triangles": sum(m.degenerate_triangles for m in meshes),
            "folded_triangles": int(reference.pn_folded(corners).sum()),
            "repaired_normals": sum(m.repaired_normals for m in meshes),
        }
        return KindInput(source, objects, groups, stats)

    def upload(self, queue, source):
        triangles = cl_array.to_device(queue, np.ascontiguousarray(source, np.float32))
        return {"source": triangles, "controls": cl_array.empty(queue, (len(source), 16, 4), np.float32)}

    def factor_buffers(self, data):
        return [data["source"].data, data["controls"].data]


BEZIER = BezierKind()
PN = PNKind()
#: The kinds in scene patch order.
KINDS = (BEZIER, PN)


@dataclass
class PlanPart:
    """One kind's patches in a plan: scene numbers ``base .. base + count - 1``."""

    kind: PatchKind
    base: int
    count: int
    data: dict


class Programs:
    """The built stage programs of one context, built once (pyopencl caches the binaries)."""

    _by_context: dict = {}

    def __init__(self, context: cl.Context):
        options = ["-I", str(kernel_dir())]
        self.built = {}
        for stage in STAGES:
            source = (kernel_dir() / f"{stage}.cl").read_text()
            try:
                self.built[stage] = cl.Program(context, source).build(options=options)
            except cl.RuntimeError as error:  # the build log is in the message
                raise BuildError(f"kernels/{stage}.cl failed to build on {context.devices[0].name.strip()!r}: "
                                 f"{first_error_line(error)}. The full log: --verbose", log=str(error)) from error
        self.crack_free_factors = self.built["crack_free"].crack_free_factors
        self._kernels = {}
        self.offsets_scan = GenericScanKernel(
            context, np.uint64, arguments="__global const ulong *counts, __global ulong *offsets",
            input_expr="counts[i]", scan_expr="a+b", neutral="0",
            output_statement="offsets[i + 1] = item;")

    def kernel(self, kind: PatchKind, stage: str) -> cl.Kernel:
        """The kind's kernel for a stage (one Kernel object each, reused)."""
        key = (kind.name, stage)
        if key not in self._kernels:
            self._kernels[key] = getattr(self.built[stage], kind.kernels[stage])
        return self._kernels[key]

    @classmethod
    def of(cls, context: cl.Context) -> "Programs":
        if context not in cls._by_context:
            cls._by_context[context] = cls(context)
        return cls._by_context[context]


def _global_size(n: int) -> tuple[int]:
    return (max(WORK_GROUP, -(-n // WORK_GROUP) * WORK_GROUP),)


def _span_ms(events) -> float:
    """Device milliseconds from the first event's start to the last one's end."""
    return (events[-1].profile.end - events[0].profile.start) * 1e-6


def _kind(kind) -> PatchKind:
    if isinstance(kind, PatchKind):
        return kind
    for k in KINDS:
        if k.name == kind:
            return k
    raise ValueError(f"unknown patch kind {kind!r}; expected one of {', '.join(k.name for k in KINDS)}")


class Tessellator:
    """Tessellates scenes on one OpenCL device.

    >>> tess = Tessellator().tessellate(load_scene("scenes/teapot.bez"), eps=1e-3)
    """

    def __init__(self, device: cl.Device | str | None = None):
        self.device = device if isinstance(device, cl.Device) else pick_device(device)
        self.context = cl.Context([self.device])
        self.queue = cl.CommandQueue(self.context, properties=cl.command_queue_properties.PROFILING_ENABLE)
        self.programs = Programs.of(self.context)

    def tessellate(self, scene: Scene, eps: float | None = None, pixels: float | None = None,
                   max_factor: int = DEFAULT_MAX_FACTOR, forward_differencing: bool = True,
                   sharp_edges: str = "straight") -> Tessellation:
        """Run the five stages on a scene; returns the mesh and per-stage device times.

        Exactly one of ``eps`` (object-space tolerance) and ``pixels`` (screen-space tolerance,
        needs ``scene.camera``) must be given.  ``sharp_edges`` (meshes only): what a mesh edge
        whose two sides have different normals becomes, "straight" (default), "average" or
        "keep" (``cltess.adjacency.pn_edge_normals``; only "keep" may leave cracks).
        """
        plan = self.plan(scene, eps=eps, pixels=pixels, max_factor=max_factor, sharp_edges=sharp_edges)
        return self.emit(plan, 0, plan.num_patches, forward_differencing)

    def tessellate_in_batches(self, scene: Scene, max_output_bytes: int, eps: float | None = None,
                              pixels: float | None = None, max_factor: int = DEFAULT_MAX_FACTOR,
                              forward_differencing: bool = True, sharp_edges: str = "straight"):
        """(plan, iterator of Tessellation batches) whose outputs each fit ``max_output_bytes``.

        Stages 1-3 run once for the whole scene (so factors are crack-free across batches);
        stages 4-5 run per batch of consecutive patches.  Batch triangles number the vertices
        globally, so concatenating the batches gives exactly the single-pass result.
        """
        plan = self.plan(scene, eps=eps, pixels=pixels, max_factor=max_factor, sharp_edges=sharp_edges)
        ranges = plan.batch_ranges(max_output_bytes)
        return plan, (self.emit(plan, first, last, forward_differencing) for first, last in ranges)

    def plan(self, scene: Scene, eps: float | None = None, pixels: float | None = None,
             max_factor: int = DEFAULT_MAX_FACTOR, sharp_edges: str = "straight") -> "Plan":
        """Stages 1-3 for the whole scene: final factors and offsets, left on the device."""
        _check_tolerance(scene, eps, pixels, max_factor)
        if sharp_edges not in SHARP_EDGE_MODES:
            raise ValueError(f"sharp_edges must be one of {', '.join(SHARP_EDGE_MODES)}, got {sharp_edges!r}")
        started = time.perf_counter()
        parts, inputs, base = [], [], 0
        for kind in KINDS:
            count = kind.count(scene)
            if count:
                host = scene.prepared((kind.name, sharp_edges), lambda: kind.prepare(scene, sharp_edges))
                parts.append(PlanPart(kind, base, count, kind.upload(self.queue, host.source)))
                inputs.append(host)
                base += count
        count = base
        objects = cl_array.to_device(self.queue, np.concatenate([host.objects for host in inputs]).astype(np.int32))
        factors = cl_array.empty(self.queue, (count, FACTOR_SLOTS), np.int32)
        flags = cl_array.empty(self.queue, count, np.int32)
        camera = scene.camera if pixels is not None else None
        events = {"factors": []}
        for part in parts:
            events["factors"] += self._factors(part.kind, part.data, eps, pixels, camera, max_factor,
                                               factors, flags, part.base)
        groups = scene.prepared(("edge groups", sharp_edges), lambda: merge_edge_groups(
            [(host.groups, part.kind.edges, part.base) for host, part in zip(inputs, parts)], count, FACTOR_SLOTS))
        final, events["crack_free"] = self.stage_crack_free(factors, groups)
        vertex_offsets, index_offsets, events["counts"] = self.stage_counts(
            final, [(part.kind, part.base, part.count) for part in parts])
        num_vertices = int(vertex_offsets[count].get())  # the two read-backs
        num_indices = int(index_offsets[count].get())
        check_totals(scene.name, num_vertices)
        flag_values = flags.get()
        stats = {
            "patches": count,
            "culled": int(np.count_nonzero(flag_values & 2)),
            "saturated": int(np.count_nonzero(flag_values & 1)),
            "vertices": num_vertices,
            "triangles": num_indices // 3,
            "shared_edges": sum(host.groups.shared for host in inputs),
            "boundary_edges": sum(host.groups.boundary for host in inputs),
            "nonmanifold_edges": sum(host.groups.nonmanifold for host in inputs),
        }
        for host in inputs:
            stats.update(host.stats)
        return Plan(scene.name, count, parts, objects, final, vertex_offsets, index_offsets,
                    num_vertices, num_indices, stats, events, started)

    def emit(self, plan: "Plan", first: int, last: int, forward_differencing: bool = True) -> Tessellation:
        """Stages 4-5 for patches ``first .. last-1`` of a plan, read back to the host."""
        vertex_range = plan.vertex_range(first, last)
        index_range = plan.index_range(first, last)
        events = dict(plan.events) if first == 0 else {}
        vertices = self._vertex_arrays(vertex_range[1] - vertex_range[0])
        triangles = cl_array.empty(self.queue, ((index_range[1] - index_range[0]) // 3, 3), np.uint32)
        events["vertices"], events["indices"] = [], []
        for part in plan.parts:
            lo, hi = max(first, part.base), min(last, part.base + part.count)
            if lo >= hi:
                continue
            events["vertices"] += self.stage_vertices(
                part.data["controls"], plan.factors, plan.vertex_offsets, plan.objects, vertex_range,
                (lo, hi), forward_differencing, kind=part.kind, patch_base=part.base, out=vertices)[1]
            events["indices"] += self.stage_indices(
                plan.factors, plan.vertex_offsets, plan.index_offsets, index_range, (lo, hi),
                kind=part.kind, out=triangles)[1]
        self.queue.finish()
        stage_ms = {stage: _span_ms(evs) for stage, evs in events.items() if evs}
        stage_ms["total_wall"] = (time.perf_counter() - plan.started) * 1e3
        stats = dict(plan.stats, first_patch=first, last_patch=last)
        return Tessellation(triangles=triangles.get(), factors=plan.host_factors()[first:last],
                            stage_ms=stage_ms, stats=stats, **{k: a.get() for k, a in vertices.items()})

    # --- stages 4-5 from factors made elsewhere (issue 17, cltess/batch.py) ---------------------

    def upload_plan(self, host: "HostPlan", first: int = 0, last: int | None = None) -> "Plan":
        """A Plan on this device from a plan read back on another (``Plan.to_host``), so that
        ``emit(plan, a, b)`` runs stages 4-5 for any ``first <= a < b <= last`` without running
        stages 1-3 again.  Only the controls of patches ``first .. last-1`` are uploaded (the
        stage-4 kernels read patch p's at ``p - patch_base``, so a part may start mid-kind);
        factors, offsets and object ids are uploaded whole (36 bytes per patch)."""
        last = host.num_patches if last is None else last
        parts = []
        for (name, base, count), controls in zip(host.kinds, host.controls):
            lo, hi = max(first, base), min(last, base + count)
            if lo < hi:
                data = {"controls": cl_array.to_device(self.queue, controls[lo - base:hi - base])}
                parts.append(PlanPart(_kind(name), lo, hi - lo, data))
        arrays = {name: cl_array.to_device(self.queue, getattr(host, name))
                  for name in ("objects", "factors", "vertex_offsets", "index_offsets")}
        return Plan(host.name, host.num_patches, parts, num_vertices=host.num_vertices,
                    num_indices=host.num_indices, stats=dict(host.stats), events={},
                    started=time.perf_counter(), _host={name: getattr(host, name) for name in
                                                        ("factors", "vertex_offsets", "index_offsets")},
                    **arrays)

    # --- the stages: device arrays in, device arrays and their events out ----------------------

    def stage_factors(self, patches, eps, pixels, camera, max_factor):
        """Stage 1 for Bézier patches.  patches: (P, 16, 4) float32 -> factors (P, 4) int32,
        flags (P,) int32 (bit 0 saturated, bit 1 culled)."""
        count = len(patches)
        factors = cl_array.empty(self.queue, (count, FACTOR_SLOTS), np.int32)
        flags = cl_array.empty(self.queue, count, np.int32)
        events = self._factors(BEZIER, {"source": patches}, eps, pixels, camera, max_factor, factors, flags, 0)
        return factors, flags, events

    def stage_pn_factors(self, triangles, eps, pixels, camera, max_factor):
        """Stage 1 for PN triangles.  triangles: (T, 12, 4) float32 (PNKind's source) ->
        controls (T, 16, 4) float32, factors (T, 4) int32 (fourth 0), flags (T,) int32."""
        count = len(triangles)
        controls = cl_array.empty(self.queue, (count, 16, 4), np.float32)
        factors = cl_array.empty(self.queue, (count, FACTOR_SLOTS), np.int32)
        flags = cl_array.empty(self.queue, count, np.int32)
        events = self._factors(PN, {"source": triangles, "controls": controls}, eps, pixels, camera,
                               max_factor, factors, flags, 0)
        return controls, factors, flags, events

    def _factors(self, kind, data, eps, pixels, camera, max_factor, factors, flags, patch_base):
        count = len(data["source"])
        view, frustum, pixel_size = _camera_arguments(camera)
        event = self.programs.kernel(kind, "factors")(
            self.queue, _global_size(count), None, *kind.factor_buffers(data), np.uint32(count),
            np.uint32(patch_base), np.float32(eps or 0.0), np.int32(camera is not None), view, frustum,
            np.float32(pixels or 0.0), np.float32(pixel_size), np.int32(max_factor),
            factors.data, flags.data)
        return [event]

    def stage_crack_free(self, factors, groups):
        """Stage 2.  factors (P, 4) int32 and edge groups over its P * 4 entries
        (cltess.adjacency, or merge_edge_groups for several kinds) -> (P, 4) int32."""
        edges = factors.size
        group_of, group_start, members = (cl_array.to_device(self.queue, a.astype(np.int32))
                                          for a in (groups.group_of, groups.group_start, groups.members))
        final = cl_array.empty(self.queue, factors.shape, np.int32)
        event = self.programs.crack_free_factors(
            self.queue, _global_size(edges), None, factors.data, group_of.data, group_start.data,
            members.data, np.uint32(edges), final.data)
        return final, [event]

    def stage_counts(self, factors, kind=BEZIER):
        """Stage 3.  factors (P, 4) -> vertex and index offsets (P+1,) uint64, [P] = total.

        kind: the kind of every patch (a PatchKind or its name), or a list of (kind, base, count)
        ranges covering 0..P-1."""
        count = len(factors)
        ranges = [(kind, 0, count)] if not isinstance(kind, (list, tuple)) else kind
        vertex_counts = cl_array.empty(self.queue, count, np.uint64)
        index_counts = cl_array.empty(self.queue, count, np.uint64)
        vertex_offsets = cl_array.zeros(self.queue, count + 1, np.uint64)
        index_offsets = cl_array.zeros(self.queue, count + 1, np.uint64)
        events = [self.programs.kernel(_kind(k), "counts")(
            self.queue, _global_size(n), None, factors.data, np.uint32(n), np.uint32(base),
            vertex_counts.data, index_counts.data) for k, base, n in ranges if n]
        events += [self.programs.offsets_scan(vertex_counts, vertex_offsets),
                   self.programs.offsets_scan(index_counts, index_offsets)]
        return vertex_offsets, index_offsets, events

    def _vertex_arrays(self, n: int) -> dict:
        q = self.queue
        return {"positions": cl_array.empty(q, (n, 3), np.float32),
                "normals": cl_array.empty(q, (n, 3), np.float32),
                "uv": cl_array.empty(q, (n, 2), np.float32),
                "patch_ids": cl_array.empty(q, n, np.int32),
                "object_ids": cl_array.empty(q, n, np.int32)}

    def stage_vertices(self, controls, factors, vertex_offsets, patch_objects, vertex_range,
                       patch_range, forward_differencing=True, kind=BEZIER, patch_base=0, out=None):
        """Stage 4 for patches patch_range = (first, last) (scene numbers, all of one kind whose
        first patch is patch_base; controls: that kind's stage-4 input, Bézier patches or PN
        control points), whose vertices are vertex_range = (start, stop) -> dict of positions
        (V, 3), normals (V, 3), uv (V, 2), patch_ids (V,), object_ids (V,) device arrays,
        V = stop - start (written into ``out`` when given), and the events."""
        out = self._vertex_arrays(vertex_range[1] - vertex_range[0]) if out is None else out
        first, last = patch_range
        if vertex_range[1] == vertex_range[0] or last <= first:
            return out, []
        event = self.programs.kernel(_kind(kind), "vertices")(
            self.queue, _global_size(last - first), None, controls.data, factors.data, vertex_offsets.data,
            patch_objects.data, np.uint32(first), np.uint32(last - first), np.uint32(patch_base),
            np.uint64(vertex_range[0]), np.int32(forward_differencing), *(a.data for a in out.values()))
        return out, [event]

    def stage_indices(self, factors, vertex_offsets, index_offsets, index_range, patch_range,
                      kind=BEZIER, out=None):
        """Stage 5 for patches patch_range = (first, last) (scene numbers, all of one kind),
        whose indices are index_range = (start, stop) -> triangles ((stop - start) / 3, 3) uint32
        device array (``out`` when given), and the events."""
        n = index_range[1] - index_range[0]
        triangles = cl_array.empty(self.queue, (n // 3, 3), np.uint32) if out is None else out
        first, last = patch_range
        if not n or last <= first:
            return triangles, []
        event = self.programs.kernel(_kind(kind), "indices")(
            self.queue, _global_size(last - first), None, factors.data, vertex_offsets.data,
            index_offsets.data, np.uint32(first), np.uint32(last - first), np.uint64(index_range[0]),
            triangles.data)
        return triangles, [event]


BYTES_PER_VERTEX = 3 * 4 + 3 * 4 + 2 * 4 + 4 + 4  # position, normal, uv, patch id, object id
BYTES_PER_INDEX = 4


@dataclass
class Plan:
    """Stages 1-3 done for a whole scene: what stages 4-5 need, on the device.

    parts: the kinds' patch ranges and device data (PlanPart); objects: (P,) object ids;
    factors: (P, 4) final factors; vertex_offsets, index_offsets: (P+1,) exclusive scans with
    the totals last; stats: the scene's counts (see Tessellation.stats).
    """

    name: str
    num_patches: int
    parts: list
    objects: cl_array.Array
    factors: cl_array.Array
    vertex_offsets: cl_array.Array
    index_offsets: cl_array.Array
    num_vertices: int
    num_indices: int
    stats: dict
    events: dict
    started: float
    _host: dict = field(default_factory=dict)

    def host_factors(self) -> np.ndarray:
        if "factors" not in self._host:
            self._host["factors"] = self.factors.get()
        return self._host["factors"]

    def _offsets(self, which: str) -> np.ndarray:
        if which not in self._host:  # read back only when a range is asked of a partial batch
            self._host[which] = getattr(self, which).get()
        return self._host[which]

    def vertex_range(self, first: int, last: int) -> tuple[int, int]:
        if (first, last) == (0, self.num_patches):
            return 0, self.num_vertices
        offsets = self._offsets("vertex_offsets")
        return int(offsets[first]), int(offsets[last])

    def index_range(self, first: int, last: int) -> tuple[int, int]:
        if (first, last) == (0, self.num_patches):
            return 0, self.num_indices
        offsets = self._offsets("index_offsets")
        return int(offsets[first]), int(offsets[last])

    @property
    def output_bytes(self) -> int:
        return self.num_vertices * BYTES_PER_VERTEX + self.num_indices * BYTES_PER_INDEX

    def batch_ranges(self, max_output_bytes: int) -> list[tuple[int, int]]:
        """Consecutive patch ranges whose vertex + index output fits max_output_bytes each."""
        if self.output_bytes <= max_output_bytes:
            return [(0, self.num_patches)]
        size = (self._offsets("vertex_offsets").astype(np.int64) * BYTES_PER_VERTEX
                + self._offsets("index_offsets").astype(np.int64) * BYTES_PER_INDEX)  # < 2**40: check_totals
        per_patch = np.diff(size)
        if per_patch.max() > max_output_bytes:
            worst = int(per_patch.argmax())
            raise OutputTooLarge(f"{self.name}: patch {worst} alone needs {per_patch[worst]} bytes of output, "
                                 f"more than the cap of {max_output_bytes}; lower max_factor or raise the cap")
        ranges, first = [], 0
        while first < self.num_patches:
            last = int(np.searchsorted(size, size[first] + max_output_bytes, side="right")) - 1
            last = max(min(last, self.num_patches), first + 1)
            ranges.append((first, last))
            first = last
        return ranges

    def to_host(self) -> "HostPlan":
        """Read the plan back to the host (picklable), for ``Tessellator.upload_plan`` on
        another device or process (issue 17)."""
        return HostPlan(self.name, self.num_patches, [(p.kind.name, p.base, p.count) for p in self.parts],
                        [p.data["controls"].get() for p in self.parts], self.objects.get(),
                        self.host_factors(), self._offsets("vertex_offsets"), self._offsets("index_offsets"),
                        self.num_vertices, self.num_indices, dict(self.stats))


@dataclass
class HostPlan:
    """A Plan on the host: stages 1-3 done, what stages 4-5 need for any patch range.

    kinds: (kind name, base, count) per part; controls: each part's stage-4 input,
    (count, 16, 4) float32 (the Bézier patches, or the PN control points stage 1 made);
    objects (P,) int32; factors (P, 4) int32, final (crack-free); vertex_offsets and
    index_offsets (P+1,) uint64 with the totals last; stats as Plan.stats.
    """

    name: str
    num_patches: int
    kinds: list
    controls: list
    objects: np.ndarray
    factors: np.ndarray
    vertex_offsets: np.ndarray
    index_offsets: np.ndarray
    num_vertices: int
    num_indices: int
    stats: dict


def _check_tolerance(scene: Scene, eps, pixels, max_factor) -> None:
    if (eps is None) == (pixels is None):
        raise ValueError("give exactly one of eps (object space) and pixels (screen space)")
    value = eps if eps is not None else pixels
    name = "eps" if eps is not None else "pixels"
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    check_tolerance_value(name, value)
    if pixels is not None and scene.camera is None:
        raise ValueError(f"{scene.name}: a pixel tolerance needs a camera in the scene")
    check_max_factor(max_factor)
    if scene.num_patches == 0:
        raise ValueError(f"{scene.name}: the scene has no patches")
    check_patch_count(scene.name, scene.num_patches)


def _camera_arguments(camera):
    """(view float16 row-major, frustum (tan_x, tan_y, near, far), pixel size at depth 1)."""
    if camera is None:
        return np.zeros(16, np.float32).view(cl.cltypes.float16)[0], \
            np.zeros(4, np.float32).view(cl.cltypes.float4)[0], 0.0
    tan_y = math.tan(math.radians(camera.fov_y_deg) / 2)
    frustum = np.array([tan_y * camera.width / camera.height, tan_y, camera.near, camera.far], np.float32)
    return (camera.view_matrix().astype(np.float32).reshape(16).view(cl.cltypes.float16)[0],
            frustum.view(cl.cltypes.float4)[0], camera.pixel_size_at_unit_depth())

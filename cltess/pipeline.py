"""Host orchestration of the five-stage pipeline (DESIGN.md section 1).

    1. factors     kernels/factors.cl     zs_factors
    2. crack-free  kernels/crack_free.cl  crack_free_factors
    3. counts      kernels/counts.cl      quad_counts, then pyopencl.scan into offsets
    4. vertices    kernels/vertices.cl    quad_vertices
    5. indices     kernels/indices.cl     quad_indices

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

from .adjacency import edge_groups
from .device import pick_device
from .reference import DEFAULT_MAX_FACTOR
from .scene import Scene
from .tessellation import Tessellation

STAGES = ("factors", "crack_free", "counts", "vertices", "indices")
WORK_GROUP = 64  # global sizes are rounded up to this; kernels guard their index


def kernel_dir() -> Path:
    """Folder of the .cl sources (top-level kernels/, installed as cltess.kernels)."""
    return Path(str(resources.files("cltess.kernels")))


class Programs:
    """The built stage programs of one context, built once (pyopencl caches the binaries)."""

    _by_context: dict = {}

    def __init__(self, context: cl.Context):
        options = ["-I", str(kernel_dir())]
        built = {}
        for stage in STAGES:
            source = (kernel_dir() / f"{stage}.cl").read_text()
            try:
                built[stage] = cl.Program(context, source).build(options=options)
            except cl.RuntimeError as error:  # the build log is in the message
                raise RuntimeError(f"kernels/{stage}.cl failed to build:\n{error}") from error
        self.zs_factors = built["factors"].zs_factors
        self.crack_free_factors = built["crack_free"].crack_free_factors
        self.quad_counts = built["counts"].quad_counts
        self.quad_vertices = built["vertices"].quad_vertices
        self.quad_indices = built["indices"].quad_indices
        self.offsets_scan = GenericScanKernel(
            context, np.uint64, arguments="__global const ulong *counts, __global ulong *offsets",
            input_expr="counts[i]", scan_expr="a+b", neutral="0",
            output_statement="offsets[i + 1] = item;")

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
                   max_factor: int = DEFAULT_MAX_FACTOR, forward_differencing: bool = True) -> Tessellation:
        """Run the five stages on a scene; returns the mesh and per-stage device times.

        Exactly one of ``eps`` (object-space tolerance) and ``pixels`` (screen-space tolerance,
        needs ``scene.camera``) must be given.
        """
        plan = self.plan(scene, eps=eps, pixels=pixels, max_factor=max_factor)
        return self.emit(plan, 0, plan.num_patches, forward_differencing)

    def tessellate_in_batches(self, scene: Scene, max_output_bytes: int, eps: float | None = None,
                              pixels: float | None = None, max_factor: int = DEFAULT_MAX_FACTOR,
                              forward_differencing: bool = True):
        """(plan, iterator of Tessellation batches) whose outputs each fit ``max_output_bytes``.

        Stages 1-3 run once for the whole scene (so factors are crack-free across batches);
        stages 4-5 run per batch of consecutive patches.  Batch triangles number the vertices
        globally, so concatenating the batches gives exactly the single-pass result.
        """
        plan = self.plan(scene, eps=eps, pixels=pixels, max_factor=max_factor)
        ranges = plan.batch_ranges(max_output_bytes)
        return plan, (self.emit(plan, first, last, forward_differencing) for first, last in ranges)

    def plan(self, scene: Scene, eps: float | None = None, pixels: float | None = None,
             max_factor: int = DEFAULT_MAX_FACTOR) -> "Plan":
        """Stages 1-3 for the whole scene: final factors and offsets, left on the device."""
        _check_tolerance(scene, eps, pixels, max_factor)
        started = time.perf_counter()
        count = scene.num_patches
        patches = cl_array.to_device(self.queue, scene.patches.reshape(count, 16, 4).astype(np.float32))
        objects = cl_array.to_device(self.queue, scene.object_ids)
        events = {}
        camera = scene.camera if pixels is not None else None
        factors, flags, events["factors"] = self.stage_factors(patches, eps, pixels, camera, max_factor)
        groups = edge_groups(scene.patches)
        final, events["crack_free"] = self.stage_crack_free(factors, groups)
        vertex_offsets, index_offsets, events["counts"] = self.stage_counts(final)
        num_vertices = int(vertex_offsets[count].get())  # the two read-backs
        num_indices = int(index_offsets[count].get())
        if num_vertices >= 2**32:
            raise MemoryError(f"{scene.name}: {num_vertices} vertices do not fit 32-bit indices; "
                              "raise the tolerance or lower --max-factor")
        flag_values = flags.get()
        stats = {
            "patches": count,
            "culled": int(np.count_nonzero(flag_values & 2)),
            "saturated": int(np.count_nonzero(flag_values & 1)),
            "vertices": num_vertices,
            "triangles": num_indices // 3,
            "shared_edges": groups.shared,
            "boundary_edges": groups.boundary,
            "nonmanifold_edges": groups.nonmanifold,
        }
        return Plan(scene.name, count, patches, objects, final, vertex_offsets, index_offsets,
                    num_vertices, num_indices, stats, events, started)

    def emit(self, plan: "Plan", first: int, last: int, forward_differencing: bool = True) -> Tessellation:
        """Stages 4-5 for patches ``first .. last-1`` of a plan, read back to the host."""
        vertex_range = plan.vertex_range(first, last)
        index_range = plan.index_range(first, last)
        events = dict(plan.events) if first == 0 else {}
        vertices, events["vertices"] = self.stage_vertices(
            plan.patches, plan.factors, plan.vertex_offsets, plan.objects, vertex_range,
            (first, last), forward_differencing)
        triangles, events["indices"] = self.stage_indices(
            plan.factors, plan.vertex_offsets, plan.index_offsets, index_range, (first, last))
        self.queue.finish()
        stage_ms = {stage: _span_ms(evs) for stage, evs in events.items() if evs}
        stage_ms["total_wall"] = (time.perf_counter() - plan.started) * 1e3
        stats = dict(plan.stats, first_patch=first, last_patch=last)
        return Tessellation(triangles=triangles.get(), factors=plan.host_factors()[first:last],
                            stage_ms=stage_ms, stats=stats, **{k: a.get() for k, a in vertices.items()})

    # --- the stages: device arrays in, device arrays and their events out ----------------------

    def stage_factors(self, patches, eps, pixels, camera, max_factor):
        """Stage 1.  patches: (P, 16, 4) float32 -> factors (P, 4) int32, flags (P,) int32."""
        count = len(patches)
        factors = cl_array.empty(self.queue, (count, 4), np.int32)
        flags = cl_array.empty(self.queue, count, np.int32)
        view, frustum, pixel_size = _camera_arguments(camera)
        event = self.programs.zs_factors(
            self.queue, _global_size(count), None, patches.data, np.uint32(count),
            np.float32(eps or 0.0), np.int32(camera is not None), view, frustum,
            np.float32(pixels or 0.0), np.float32(pixel_size), np.int32(max_factor),
            factors.data, flags.data)
        return factors, flags, [event]

    def stage_crack_free(self, factors, groups):
        """Stage 2.  factors (P, 4) int32 and edge groups (cltess.adjacency) -> (P, 4) int32."""
        edges = factors.size
        group_of, group_start, members = (cl_array.to_device(self.queue, a.astype(np.int32))
                                          for a in (groups.group_of, groups.group_start, groups.members))
        final = cl_array.empty(self.queue, factors.shape, np.int32)
        event = self.programs.crack_free_factors(
            self.queue, _global_size(edges), None, factors.data, group_of.data, group_start.data,
            members.data, np.uint32(edges), final.data)
        return final, [event]

    def stage_counts(self, factors):
        """Stage 3.  factors (P, 4) -> vertex and index offsets (P+1,) uint64, [P] = total."""
        count = len(factors)
        vertex_counts = cl_array.empty(self.queue, count, np.uint64)
        index_counts = cl_array.empty(self.queue, count, np.uint64)
        vertex_offsets = cl_array.zeros(self.queue, count + 1, np.uint64)
        index_offsets = cl_array.zeros(self.queue, count + 1, np.uint64)
        events = [
            self.programs.quad_counts(self.queue, _global_size(count), None, factors.data,
                                      np.uint32(count), vertex_counts.data, index_counts.data),
            self.programs.offsets_scan(vertex_counts, vertex_offsets),
            self.programs.offsets_scan(index_counts, index_offsets)]
        return vertex_offsets, index_offsets, events

    def stage_vertices(self, patches, factors, vertex_offsets, patch_objects, vertex_range,
                       patch_range, forward_differencing=True):
        """Stage 4 for patches patch_range = (first, last), whose vertices are vertex_range =
        (start, stop) -> dict of positions (V, 3), normals (V, 3), uv (V, 2), patch_ids (V,),
        object_ids (V,) device arrays, V = stop - start."""
        q, n = self.queue, vertex_range[1] - vertex_range[0]
        out = {"positions": cl_array.empty(q, (n, 3), np.float32),
               "normals": cl_array.empty(q, (n, 3), np.float32),
               "uv": cl_array.empty(q, (n, 2), np.float32),
               "patch_ids": cl_array.empty(q, n, np.int32),
               "object_ids": cl_array.empty(q, n, np.int32)}
        if not n:
            return out, []
        first, last = patch_range
        event = self.programs.quad_vertices(
            q, _global_size(last - first), None, patches.data, factors.data, vertex_offsets.data,
            patch_objects.data, np.uint32(first), np.uint32(last - first), np.uint64(vertex_range[0]),
            np.int32(forward_differencing), *(a.data for a in out.values()))
        return out, [event]

    def stage_indices(self, factors, vertex_offsets, index_offsets, index_range, patch_range):
        """Stage 5 for patches patch_range = (first, last), whose indices are index_range =
        (start, stop) -> triangles ((stop - start) / 3, 3) uint32 device array."""
        n = index_range[1] - index_range[0]
        triangles = cl_array.empty(self.queue, (n // 3, 3), np.uint32)
        if not n:
            return triangles, []
        first, last = patch_range
        event = self.programs.quad_indices(
            self.queue, _global_size(last - first), None, factors.data, vertex_offsets.data,
            index_offsets.data, np.uint32(first), np.uint32(last - first), np.uint64(index_range[0]),
            triangles.data)
        return triangles, [event]


BYTES_PER_VERTEX = 3 * 4 + 3 * 4 + 2 * 4 + 4 + 4  # position, normal, uv, patch id, object id
BYTES_PER_INDEX = 4


@dataclass
class Plan:
    """Stages 1-3 done for a whole scene: what stages 4-5 need, on the device.

    factors: (P, 4) final factors; vertex_offsets, index_offsets: (P+1,) exclusive scans with
    the totals last; stats: the scene's counts (see Tessellation.stats).
    """

    name: str
    num_patches: int
    patches: cl_array.Array
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
        size = (self._offsets("vertex_offsets") * BYTES_PER_VERTEX
                + self._offsets("index_offsets") * BYTES_PER_INDEX).astype(np.int64)
        per_patch = np.diff(size)
        if per_patch.max() > max_output_bytes:
            worst = int(per_patch.argmax())
            raise MemoryError(f"{self.name}: patch {worst} alone needs {per_patch[worst]} bytes of output, "
                              f"more than the cap of {max_output_bytes}; lower max_factor or raise the cap")
        ranges, first = [], 0
        while first < self.num_patches:
            last = int(np.searchsorted(size, size[first] + max_output_bytes, side="right")) - 1
            last = max(min(last, self.num_patches), first + 1)
            ranges.append((first, last))
            first = last
        return ranges


def _check_tolerance(scene: Scene, eps, pixels, max_factor) -> None:
    if (eps is None) == (pixels is None):
        raise ValueError("give exactly one of eps (object space) and pixels (screen space)")
    value = eps if eps is not None else pixels
    name = "eps" if eps is not None else "pixels"
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if pixels is not None and scene.camera is None:
        raise ValueError(f"{scene.name}: a pixel tolerance needs a camera in the scene")
    if int(max_factor) < 1:
        raise ValueError(f"max_factor must be >= 1, got {max_factor}")
    if scene.num_patches == 0:
        raise ValueError(f"{scene.name}: the scene has no patches")


def _camera_arguments(camera):
    """(view float16 row-major, frustum (tan_x, tan_y, near, far), pixel size at depth 1)."""
    if camera is None:
        return np.zeros(16, np.float32).view(cl.cltypes.float16)[0], \
            np.zeros(4, np.float32).view(cl.cltypes.float4)[0], 0.0
    tan_y = math.tan(math.radians(camera.fov_y_deg) / 2)
    frustum = np.array([tan_y * camera.width / camera.height, tan_y, camera.near, camera.far], np.float32)
    return (camera.view_matrix().astype(np.float32).reshape(16).view(cl.cltypes.float16)[0],
            frustum.view(cl.cltypes.float4)[0], camera.pixel_size_at_unit_depth())

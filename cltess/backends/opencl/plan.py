"""A plan: stages 1-3 done for a scene, what stages 4-5 need (Plan on the device, HostPlan on
the host), and the scene's device data it is made from (SceneData)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array

from ...kinds import FLAG_CULLED, FLAG_SATURATED, PatchKind
from ...limits import OutputTooLarge, check_totals
from ...patterns import Pattern
from ...request import Request
from ...scene import Scene
from ...tessellation import BYTES_PER_INDEX, BYTES_PER_VERTEX
from .events import wait_ms


@dataclass
class PlanPart:
    """One kind's patches in a plan: scene numbers ``base .. base + count - 1``, tessellated
    with ``pattern``; data: its device arrays ("source", "controls"; for a Session's scene,
    "prepared": the patches prepared for stage 4, kept across frames: Tessellator._prepared_points)."""

    kind: PatchKind
    pattern: Pattern
    base: int
    count: int
    data: dict


@dataclass
class SceneData:
    """A scene's device data, whatever the tolerance or camera (``Tessellator.scene_data``):
    parts: (kind, base, count, its device arrays ``upload``) per kind in scene order; objects:
    (P,) int32 object ids; groups: stage 2's edge groups (``upload_groups``); stats: the
    scene's edge and mesh counts."""

    scene: Scene
    sharp_edges: str
    num_patches: int
    parts: list
    objects: cl_array.Array
    groups: dict
    stats: dict


@dataclass
class Plan:
    """Stages 1-3 done for a whole scene: what stages 4-5 need, on the device.

    parts: the kinds' patch ranges and device data (PlanPart); objects: (P,) object ids;
    factors: (P, 4) final factors (collapsed edges negated: kernels/common.h patch_factors;
    ``Tessellation.factors`` are their absolute values); vertex_offsets, index_offsets: (P+1,) exclusive scans with
    the totals last; stats: the scene's counts (see Tessellation.stats); request: what it was
    planned for.
    """

    name: str
    num_patches: int
    parts: list
    objects: cl_array.Array
    factors: cl_array.Array
    vertex_offsets: cl_array.Array
    index_offsets: cl_array.Array
    num_vertices: int | None  # None until settle (plan_on(defer_totals=True))
    num_indices: int | None
    stats: dict
    events: dict
    started: float
    request: Request
    _host: dict = field(default_factory=dict)
    strip_offsets: cl_array.Array | None = None  # strip patterns' (P+1,) strip index offsets
    num_strip_indices: int = 0
    wait_ms: float = 0.0  # host ms blocked waiting for stages 1-3's totals (wall_ms["waits"])
    _pending: tuple | None = None  # (summary or totals, flags or None, their copies' events) until settle

    @property
    def settled(self) -> bool:
        """Whether the totals are known (``settle`` has run)."""
        return self._pending is None

    def totals_ready(self) -> bool:
        """Whether the totals' copies have completed (settle would not wait)."""
        return self._pending is None or all(
            event.command_execution_status == cl.command_execution_status.COMPLETE for event in self._pending[2])

    def settle(self, ready: bool = False) -> "Plan":
        """Wait for stage 3's totals and the flags (copied without waiting by plan_on) and
        fill in num_vertices, num_indices and the counts of ``stats``.  ready: their copies
        are known to be complete (``totals_ready``), so there is nothing to wait for (a
        Session frame skips the runtime's wait call then)."""
        if self._pending is None:
            return self
        totals, flags, copies = self._pending
        if not ready:
            self.wait_ms += wait_ms(copies)
        self._pending = None
        totals = totals.tolist()  # (Python ints, in one call)
        self.num_vertices, self.num_indices = totals[0], totals[1]
        check_totals(self.name, self.num_vertices)
        if flags is None:  # stage 3's summary (Tessellator.stage_counts)
            culled, saturated = totals[2], totals[3]
        else:
            culled = int(np.count_nonzero(flags & FLAG_CULLED))
            saturated = int(np.count_nonzero(flags & FLAG_SATURATED))
        self.stats.update(culled=culled, saturated=saturated, vertices=self.num_vertices,
                          triangles=self.num_indices // 3)
        return self

    def output_factors(self, first: int, last: int) -> tuple[np.ndarray, np.ndarray | None]:
        """(factors (n, 4) int32: each edge's segments, real_factors (n, 4) float32 or None when
        no pattern is fractional) of patches first .. last-1."""
        factors = np.abs(self.host_factors()[first:last])
        fixed = [p for p in self.parts if p.pattern.fixed_point]
        if not fixed:
            return factors, None
        from ...patterns.fractional import FIXED_ONE
        real, whole = factors.astype(np.float32), factors.copy()
        for part in fixed:
            lo, hi = max(first, part.base) - first, min(last, part.base + part.count) - first
            if lo < hi:
                rows = factors[lo:hi].copy()
                rows[:, 3] = 0  # slot 3 of a triangle: the SD-2 pattern's hint, not an edge
                real[lo:hi] = rows / np.float32(FIXED_ONE)
                whole[lo:hi] = np.where(rows > 0, 2 * ((rows + 2 * FIXED_ONE - 1 + FIXED_ONE) >> 17) - 1, 0)
        return whole, real

    def host_factors(self) -> np.ndarray:
        self.enqueue_host_factors()
        pending = self._host.pop("factors pending", None)
        if pending is not None:
            pending.wait()
        return self._host["factors"]

    def enqueue_host_factors(self) -> None:
        """Start the factors' copy to the host without waiting (``host_factors`` waits)."""
        if "factors" not in self._host:
            self._host["factors"] = np.empty(self.factors.shape, self.factors.dtype)
            self._host["factors pending"] = cl.enqueue_copy(self.factors.queue, self._host["factors"],
                                                            self.factors.data, is_blocking=False)

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
        return HostPlan(self.name, self.num_patches,
                        [(p.kind.name, p.pattern.name, p.base, p.count) for p in self.parts],
                        [p.data["controls"].get() for p in self.parts], self.objects.get(),
                        self.host_factors(), self._offsets("vertex_offsets"), self._offsets("index_offsets"),
                        self.num_vertices, self.num_indices, dict(self.stats), self.request,
                        self.strip_offsets.get() if self.strip_offsets is not None else None,
                        self.num_strip_indices)


@dataclass
class HostPlan:
    """A Plan on the host: stages 1-3 done, what stages 4-5 need for any patch range.

    kinds: (kind name, pattern name, base, count) per part; controls: each part's stage-4
    input, (count, 16, 4) float32 (the Bézier patches, or the PN control points stage 1 made);
    objects (P,) int32; factors (P, 4) int32, final (crack-free, collapsed edges negated); vertex_offsets and
    index_offsets (P+1,) uint64 with the totals last; stats as Plan.stats; request: what it
    was planned for; strip_offsets and num_strip_indices as Plan's (None, 0 without strips).
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
    request: Request
    strip_offsets: np.ndarray | None = None  # a strip pattern's (P+1,) strip index offsets (Plan's)
    num_strip_indices: int = 0

"""A frame loop: one scene tessellated again and again as the camera or the tolerance changes.

    session = cltess.Session(scene, pixels=0.5)            # or eps=..., or request=Request(...)
    for camera in path:
        frame = session.tessellate(camera=camera)          # the five stages, nothing else
        draw(frame.device.positions, frame.device.triangles)  # pyopencl arrays, no read-back

What a ``Session`` keeps between calls, so that a frame costs only the five stages:

* the scene's device data (``Tessellator.scene_data``): every kind's upload, the object ids,
  stage 2's edge groups (the host adjacency behind them is cached on the scene);
* the per-patch arrays of stages 1-3 (factors, flags, counts, offsets: sized by the scene);
* for the "*-prep" work distributions (GPUs), the patches prepared for stage 4 (each kind_patch,
  made once from a kind's upload where no frame rewrites it: Bézier patches);
* the output buffers (``OutputBuffers``), grown only when a frame needs more, and on a GPU the
  page-locked host buffers its read-back goes through.

A frame for a new camera alone enqueues the launches of the last frame recorded for the
session's request again, with stage 1's camera arguments replaced (``RecordedFrame``,
cltess/backends/opencl/recorded.py): no kernel look-up, path choice or argument set-up.

A frame does not wait for stage 3's totals before it enqueues stages 4-5: they run on the
buffers' capacity, and write nothing if the frame's output does not fit (``batch_fits`` in
kernels/common.h).  The host reads the totals when the frame's sizes, arrays or times are
first asked for (or ``finish()``); an output that did not fit then runs stages 4-5 again on
grown buffers.  So with ``wait=False`` the host's next frame is enqueued while the device still
works on this one, with no round trip between (docs/design.md section 11).

A frame's output stays on the device (``Tessellation.device``); its host arrays are read back
when first asked for (``frame.positions``, ``frame.fetch()``): on a CPU device by mapping the
buffers (no copy), on a GPU by a copy into the pinned buffers.  Either way they are *views of
the session's buffers*: valid until the next ``tessellate`` call, which reuses them (a stale
frame's ``device`` and ``fetch`` raise ``StaleOutput``; host arrays already taken are simply
overwritten, as a renderer's frame buffers are).  ``.copy()`` what must outlive the frame.

``Session(..., buffers=2)`` keeps two sets of those buffers (and of the per-patch arrays of
stages 1-3), which frames take in turn, as a renderer double-buffers: a frame's output then stays
valid until the second ``tessellate`` call after it, so the host can use frame k's arrays while
the device computes frame k+1 (``tessellate(camera, host=True, wait=False)``, then the previous
frame's ``fetch()``).  Twice the output memory; each set grows when its own turn comes.
"""
from __future__ import annotations

import dataclasses
import importlib
import time
from dataclasses import dataclass, field

from .backends.opencl.recorded import RecordedFrame
from .backends.opencl.output import OutputBuffers
from .backends.opencl.tessellator import Tessellator
from .criteria.tolerance import ObjectSpace, ScreenSpace
from .request import Request
from .scene import Camera, Scene
from .tessellation import Tessellation


#: Session(share=...): the output buffers' class, by the API the output is handed to, as
#: (module of backends/opencl, class), imported when a Session asks for it.
SHARED_OUTPUTS = {None: ("output", "OutputBuffers"), "cuda": ("share_cuda", "CudaOutputBuffers"),
                  "gl": ("share_gl", "GlOutputBuffers"), "vulkan": ("share_vulkan", "VulkanOutputBuffers")}


@dataclass
class FrameBuffers:
    """What a frame writes, one set of it (``Session(buffers=N)`` keeps N, taken in turn): the
    output buffers, the per-patch arrays of stages 1-3 (a frame whose output did not fit runs
    stages 4-5 again from them), and the last frame made on them for the session's request,
    to replay (``RecordedFrame``: its launches name these buffers)."""

    output: OutputBuffers
    scratch: dict = field(default_factory=dict)  # sharp_edges -> the per-patch arrays of stages 1-3
    recorded: RecordedFrame | None = None


class Session:
    """Tessellate one scene per frame on one OpenCL device, keeping its device data.

    scene: the scene; device: an OpenCL device or its name (``cltess.device.pick_device``), or
    give ``tessellator`` (to share its context and programs); request: a ``Request``, or its
    parts as keywords (``Request.of``: eps= or pixels=, max_factor=, pattern=, ...).  buffers:
    sets of output buffers that frames take in turn (the module's notes): 1, or 2 so that a
    frame's output stays valid while the next frame computes.  share: "cuda" to hand each
    frame's output to CUDA without a copy (``frame.cuda()``; an NVIDIA device:
    backends/opencl/share_cuda.py), "gl" to OpenGL (``frame.gl()``; made, used and closed with
    the GL context current: backends/opencl/share_gl.py), "vulkan" to the Vulkan device and
    queue named by ``vulkan`` (a ``VulkanQueue``; ``frame.vulkan()``:
    backends/opencl/share_vulkan.py), else None.  ``close()`` (or a ``with`` block) lets the
    buffers go at once.
    """

    def __init__(self, scene: Scene, device=None, request: Request | None = None,
                 tessellator: Tessellator | None = None, buffers: int = 1, share: str | None = None,
                 vulkan=None, **options):
        if isinstance(buffers, bool) or not isinstance(buffers, int) or buffers < 1:
            raise ValueError(f"buffers must be a whole number >= 1, got {buffers!r}")
        if share not in SHARED_OUTPUTS:
            raise ValueError(f"share={share!r}: expected one of {', '.join(map(repr, SHARED_OUTPUTS))}")
        if (vulkan is not None) != (share == "vulkan"):
            raise ValueError("vulkan=VulkanQueue(...) goes with share=\"vulkan\", and only with it")
        self.tessellator = tessellator if tessellator is not None else Tessellator(device)
        self.scene = scene
        self.request = request if request is not None else Request.of(**options)
        self.request.check(scene)
        module, name = SHARED_OUTPUTS[share]
        outputs = getattr(importlib.import_module(f".backends.opencl.{module}", __package__), name)
        where = {"vulkan": vulkan} if share == "vulkan" else {}
        self._sets = [FrameBuffers(outputs(self.tessellator, pinned=True, **where)) for _ in range(buffers)]
        self._current = self._sets[0]  # the set of the latest frame (the next frame's before the first)
        self._scene_data: dict = {}  # sharp_edges -> SceneData
        self.frames = 0
        self._plans: list = []  # the last two frames' plans: their totals grow the buffers for the next
        self._composed = None  # the (work, stage 3 choices) of the last frame composed for the session's request
        self._unread = None  # (pending, frame): the last host frame whose copies wait for its totals (_start_unread)

    @property
    def output(self) -> OutputBuffers:
        """The output buffers of the latest frame (before any frame: the first frame's)."""
        return self._current.output

    @property
    def _recorded(self) -> RecordedFrame | None:
        """The recorded frame of the latest frame's buffer set."""
        return self._current.recorded

    @property
    def device(self):
        return self.tessellator.device

    def request_for(self, camera: Camera | None = None, **overrides) -> Request:
        """The session's request with a frame's changes: ``camera`` (for a pixel tolerance),
        ``eps`` or ``pixels`` (a new tolerance), and any other ``Request`` field."""
        request = self.request
        tolerance = request.tolerance
        if "eps" in overrides and "pixels" in overrides:
            raise ValueError("give at most one of eps and pixels")
        if "eps" in overrides:
            tolerance = ObjectSpace(overrides.pop("eps"))
        elif "pixels" in overrides:
            tolerance = ScreenSpace(overrides.pop("pixels"), getattr(tolerance, "camera", None))
        if camera is not None:
            if not isinstance(tolerance, ScreenSpace):
                raise ValueError("camera= is for a pixel tolerance; this session's is eps "
                                 f"{tolerance.eps!r} (give pixels= to the session or to this call)")
            tolerance = ScreenSpace(tolerance.pixels, camera)
        if camera is not None and not overrides and tolerance.pixels == getattr(request.tolerance, "pixels", None):
            # A new camera alone: the request as it was, with this tolerance (its fields were
            # checked when it was made; check() asks for a camera, which there now is).
            framed = object.__new__(type(request))
            framed.__dict__.update(request.__dict__, tolerance=tolerance)
            return framed
        if tolerance is not request.tolerance or overrides:
            request = dataclasses.replace(request, tolerance=tolerance, **overrides)
            request.check(self.scene)
        return request

    def tessellate(self, camera: Camera | None = None, wait: bool = True, host: bool = False,
                   **request_overrides) -> Tessellation:
        """One frame: stages 1-5 for the whole scene with this camera (pixel tolerance) and
        these changes to the session's request (``request_for``).  The output stays on the
        device (``.device``); host arrays on first use, valid until the next call (with
        ``buffers=2``, the call after next).

        host=True: the frame is for host arrays (``frame.positions`` and the rest, as
        ``fetch()``): their read-back is enqueued right behind the stages (on a CPU device the
        buffers' map, and the factors' copy), so that it is done when the stages are, instead
        of a round trip of its own after them (tea table, Intel's CPU runtime: a frame with host
        arrays 1.28x its device time instead of 1.34x; bench/RESULTS.md, "Session 11, lead").
        With wait=True the arrays are fetched before the call returns.

        wait=False: return once stages 1-5 are enqueued, without waiting for any of them, so that
        the host's work until the next frame (drawing, the next camera, the next frame's
        enqueueing) overlaps them on the device.  ``frame.finish()`` waits for them (as does the
        first look at ``frame.stage_ms``, ``wall_ms``, ``stats``, its sizes or its arrays), and
        is needed before commands on the session's queue use ``frame.device``: until the host
        has read the frame's totals, an output larger than the buffers is not written (see
        the module's notes)."""
        started = time.perf_counter()
        request = self.request_for(camera, **request_overrides)
        if request.bound != "hull":  # its loop re-plans and emits on the host (Tessellator.plan)
            raise ValueError(f"a Session tessellates per frame with the hull bound; bound={request.bound!r} "
                             "is for Tessellator.plan / tessellate")
        tessellator = self.tessellator
        # A new camera alone needs the programs of the last frame (they depend on the tolerance's
        # kind, not its camera); anything else is looked up (compose: found in the cache).
        composed = None if request_overrides else (tessellator.work, tessellator.fused_offsets,
                                                   tessellator.tiled_offsets, tessellator.one_scan)
        if composed is None or composed != self._composed:
            tessellator.compose(self.scene, request)
            self._composed = composed
        key = request.sharp_edges
        if key not in self._scene_data:
            self._scene_data[key] = tessellator.scene_data(self.scene, key, keep_prepared=True)
        self._current = buffers = self._sets[self.frames % len(self._sets)]
        # The frame before last is settled (its totals are read: a wait only if the device is two
        # frames behind, so no more than two frames are ever in flight), the last one if its
        # totals are there; the buffers then hold at least what those needed.
        for age, plan in enumerate(reversed(self._plans)):
            if age == 1:
                plan.settle()
            elif plan.totals_ready():  # (its copy is complete: no wait call)
                plan.settle(ready=True)
            if plan.settled:  # (this frame's set only: the other sets' frames may still be in use)
                buffers.output.reserve(plan.num_vertices, plan.num_indices // 3)
        if self._unread is not None:
            self._start_unread()
        settled = [plan for plan in self._plans if plan.settled]
        if settled:  # work="auto" chooses by the latest settled frame (Tessellator.auto_work)
            tessellator.note_plan(settled[-1])
        # The launches keep their arguments (the session's buffers): the next frame's launches
        # with the same ones only enqueue (programs.Kernel).  A new camera alone replays the last
        # frame recorded for these settings and buffers (recorded.py); any other frame is made
        # the normal way, and recorded if it was made for the session's request.
        programs, data = tessellator.programs, self._scene_data[key]
        scratch, recorded = buffers.scratch.setdefault(key, {}), buffers.recorded
        programs.keep_arguments = True
        try:
            if not request_overrides and recorded is not None and recorded.key == self._frame_key():
                pending = recorded.replay(tessellator, data, request, started, scratch, buffers.output)
            else:
                programs.recording = [] if not request_overrides else None
                plan = tessellator.plan_on(data, request, started, scratch, defer_totals=True)
                pending = tessellator.emit_async(plan, 0, plan.num_patches, out=buffers.output)
                if not request_overrides:
                    buffers.recorded = RecordedFrame.of(self._frame_key(), data, pending, programs.recording,
                                                      scratch.get("summary"))
        finally:
            programs.keep_arguments = False
            programs.recording = None
        self._plans = [*self._plans[-1:], pending.plan]
        self.frames += 1
        reading = pending.start_read_back() if host else True  # (a GPU's copies need the totals)
        frame = pending.result(on_device=True, wait=wait)
        if not reading and not wait and len(self._sets) > 1:  # the next call enqueues them (_start_unread)
            self._unread = (pending, frame)
        return frame.fetch() if host and wait else frame

    def _start_unread(self) -> None:
        """The read-back of the last frame, asked for host arrays with ``wait=False`` on a device
        whose copies need the frame's totals (a GPU): enqueued now, before this frame's stages,
        once those totals are read (they are, unless its stage 3 is still running: then a short
        wait), so that its ``fetch()`` waits for its own copies alone and not for this frame's
        stages behind them on the in-order queue.  Only with two buffer sets, where that frame
        stays valid through this one; not for a frame already fetched or stale."""
        pending, frame = self._unread
        self._unread = None
        device = frame.device
        if frame.on_host or device is None or not device.valid():
            return
        device.settle()  # its totals; its stages 4-5 again where its output did not fit
        arrays = device.arrays  # (as settled: the sizes its fetch reads back, 0 included)
        pending.start_read_back((arrays.num_vertices, arrays.num_triangles))

    def close(self) -> None:
        """Let the output buffers go now; the session's frames are stale, and a later frame
        makes new ones.  With share="gl": the GL objects are deleted (the session's GL context
        current), with share="vulkan" the objects made in the caller's device (before that device
        is destroyed), and the session makes no more frames."""
        for buffers in self._sets:
            buffers.output.close()
            buffers.recorded = None  # (its launches name the buffers let go)

    def __enter__(self) -> "Session":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _frame_key(self) -> tuple:
        """What a frame's launches depend on besides its camera: the tessellator's settings
        that choose them (work distribution and, for work="auto", what it chooses now, records
        per work-item, patches per work-group,
        stage 3's path) and the output buffers' capacity (they are only replaced when they grow)."""
        tessellator = self.tessellator
        return (tessellator.work, tessellator.records_per_item, tessellator.patches_per_group,
                tessellator.fused_offsets, tessellator.tiled_offsets, tessellator.one_scan, tessellator._cpu,
                tessellator.fused_crack_free,
                tessellator.auto_work(), self.output.capacity)

    def __repr__(self) -> str:
        return (f"Session({self.scene.name!r}, {self.device.name.strip()!r}, {self.frames} frames, "
                f"output buffers {sum(s.output.nbytes for s in self._sets)} bytes)")


__all__ = ["Session"]

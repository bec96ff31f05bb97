"""A Session frame recorded once and enqueued again for each new camera (issue 15: a frame's
host cost; docs/design.md section 11).

From one frame of a ``cltess.Session`` to the next with a new camera alone, only stage 1's
tolerance arguments change (``TOLERANCE_ARGUMENTS``: the view matrix, frustum and pixel size).
Every launch is otherwise the same kernel with the same arguments (the scene's device data,
the session's per-patch arrays, the output buffers at their capacity: a frame's stages 4-5 are
launched on the capacity before its totals are known) and the same global and local sizes, and
stage 3's summary is read the same way.  So a frame made the normal way
(``Tessellator.plan_on(defer_totals=True)`` and ``emit_async``: stage 3's path chosen, kernels
looked up, sizes and arguments worked out) is recorded as its launches (``programs.Launch``),
and the next frames enqueue them again with stage 1's tolerance arguments replaced
(``RecordedFrame.replay``), with none of that work.  The launches are the normal path's, with
the same arguments: the frames are bitwise the same.

A record is for one ``key`` (``Session._frame_key``: the tessellator's settings that choose the
launches, the output buffers' capacity); a frame with another key, or with request overrides,
is made the normal way (and recorded again if it was made for the session's request).
"""
from __future__ import annotations

from dataclasses import dataclass

import pyopencl._cl as _cl

from .programs import same_arguments
from .plan import Plan, SceneData
from .tessellator import TOLERANCE_ARGUMENTS, PendingEmit

#: A frame's stages in the order of their launches, stage 3's summary read after "counts".
PLANNED_STAGES = ("factors", "crack_free", "counts")
EMITTED_STAGES = ("vertices", "indices")


def with_tolerance(args: tuple, tolerance_args: tuple) -> tuple:
    """Stage 1's arguments with other tolerance arguments (``TOLERANCE_ARGUMENTS``)."""
    return args[:TOLERANCE_ARGUMENTS.start] + tolerance_args + args[TOLERANCE_ARGUMENTS.stop:]


@dataclass
class RecordedFrame:
    """A frame's launches (``of``), to enqueue again for a new camera (``replay``).

    key: what the launches were made for (the Session compares it); plan: the recorded frame's
    plan (its parts, per-patch arrays and name); stats: its statistics before its totals were
    read (the template of each replay's); launches: stage -> its ``Launch``es in order;
    summary: stage 3's summary array (read back after stage 3)."""

    key: tuple
    plan: Plan
    stats: dict
    launches: dict
    summary: object
    forward_differencing: bool

    @classmethod
    def of(cls, key: tuple, data: SceneData, pending: PendingEmit, launches: list, summary) -> "RecordedFrame | None":
        """The record of a frame just enqueued by ``plan_on(defer_totals=True)`` on ``data`` and
        ``emit_async`` (``pending``), from the launches they made (``Programs.recording``); None
        where enqueueing them again would not make the same frame: a plan settled before stages
        4-5 (sized by its totals, not by the buffers' capacity), a command that is not a
        ``Kernel`` launch (pyopencl's scans, strips), stage 1 other than one launch per kind with
        its tolerance arguments in their place (SD-2's level functions), or no summary to read."""
        plan = pending.plan
        stage_of = {id(event): stage for stage, events in pending.events.items() for event in events}
        # (stage 2 has no launch of its own where it runs in stage 3's: Tessellator.fuses_crack_free)
        if (plan.settled or summary is None or plan._pending[1] is not None or pending.strips is not None
                or len(launches) != len(stage_of) or any(id(launch.event) not in stage_of for launch in launches)
                or set(stage_of.values()) | {"crack_free"} != {*PLANNED_STAGES, *EMITTED_STAGES}):
            return None
        by_stage = {stage: [] for stage in PLANNED_STAGES + EMITTED_STAGES}
        for launch in launches:
            by_stage[stage_of[id(launch.event)]].append(launch)
        tolerance_args = plan.request.tolerance_for(data.scene).kernel_args()
        if len(by_stage["factors"]) != len(plan.parts) or not all(
                same_arguments(launch.args[TOLERANCE_ARGUMENTS], tolerance_args) for launch in by_stage["factors"]):
            return None
        return cls(key, plan, dict(plan.stats), by_stage, summary, pending.forward_differencing)

    def replay(self, tessellator, data: SceneData, request, started: float, scratch: dict, output) -> PendingEmit:
        """This frame for ``request`` (the recorded one's with a new camera): stages 1-3 with
        stage 1's tolerance arguments for its camera, the summary's read, stages 4-5 on the
        output buffers (a new generation), as ``plan_on`` and ``emit_async`` enqueue them."""
        recorded, queue = self.plan, tessellator.queue
        tolerance_args = request.tolerance_for(data.scene).kernel_args()
        events = {"factors": [launch.again(queue, with_tolerance(launch.args, tolerance_args))
                              for launch in self.launches["factors"]]}
        for stage in PLANNED_STAGES[1:]:
            events[stage] = [launch.again(queue) for launch in self.launches[stage]]
        totals, _ = tessellator._read_back_arrays(scratch, recorded.num_patches, flags=False)
        # pyopencl's C entry point, as enqueue_copy calls it, without its dispatch on the argument
        # kinds (10 against 16 µs a call here: bench/RESULTS.md, "Issue 15 ... session 8")
        copy = _cl._enqueue_read_buffer(queue, self.summary.data, totals, 0, None, False)
        plan = Plan(recorded.name, recorded.num_patches, recorded.parts, recorded.objects, recorded.factors,
                    recorded.vertex_offsets, recorded.index_offsets, None, None, dict(self.stats), events, started,
                    request, _pending=(totals, None, [copy]))
        arrays = output.take(*output.capacity)
        emitted = dict(events)
        for stage in EMITTED_STAGES:
            emitted[stage] = [launch.again(queue) for launch in self.launches[stage]]
        queue.flush()
        return PendingEmit(tessellator, plan, 0, recorded.num_patches, 0, arrays, emitted, output, None,
                           self.forward_differencing)


__all__ = ["RecordedFrame"]

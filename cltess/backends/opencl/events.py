"""OpenCL events as the stages use them: the host's time blocked on them, and their device span."""
from __future__ import annotations

import time

import pyopencl as cl

_START, _END = cl.profiling_info.START, cl.profiling_info.END
_COMPLETE = cl.command_execution_status.COMPLETE


def wait_ms(events) -> float:
    """Wait for events; the host milliseconds spent blocked (a frame's wall_ms["waits"]).

    Events already complete are not waited for: Intel's CPU runtime lends the waiting thread
    to whatever work is queued, so a wait on finished events still ran the next batch's
    kernels on the host's thread before it returned (cltess.stream: the host waited about as
    long as a batch's stages, every batch; bench/RESULTS.md, "Session 11, lead")."""
    started = time.perf_counter()
    if not all(event.command_execution_status == _COMPLETE for event in events):
        cl.wait_for_events(events)
    return (time.perf_counter() - started) * 1e3


def span_ms(events) -> float:
    """Device milliseconds from the first event's start to the last one's end."""
    return (events[-1].get_profiling_info(_END) - events[0].get_profiling_info(_START)) * 1e-6

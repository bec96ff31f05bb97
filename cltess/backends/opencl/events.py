"""OpenCL events as the stages use them: the host's time blocked on them, and their device span."""
from __future__ import annotations

import time

import pyopencl as cl

_START, _END = cl.profiling_info.START, cl.profiling_info.END


def wait_ms(events) -> float:
    """Wait for events; the host milliseconds spent blocked (a frame's wall_ms["waits"])."""
    started = time.perf_counter()
    cl.wait_for_events(events)
    return (time.perf_counter() - started) * 1e3


def span_ms(events) -> float:
    """Device milliseconds from the first event's start to the last one's end."""
    return (events[-1].get_profiling_info(_END) - events[0].get_profiling_info(_START)) * 1e-6

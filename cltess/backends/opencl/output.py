"""Stages 4-5's output on the device: buffers kept and grown across frames (OutputBuffers), and
the views a device-resident result hands out (OutputArrays); how they reach host arrays."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array

from ...tessellation import VERTEX_RECORD
from .events import wait_ms

if TYPE_CHECKING:
    from .tessellator import Tessellator


class _Raw:
    """A buffer where the stage functions expect an array (they read ``.data`` only)."""

    __slots__ = ("data",)

    def __init__(self, data):
        self.data = data


class OutputArrays(dict):
    """The pyopencl arrays of one output (name -> ``pyopencl.array.Array``, made on first
    access: a frame whose output nobody looks at on the device does not pay for them)."""

    def __init__(self, queue, fields: dict, buffers: dict, num_vertices: int, num_triangles: int):
        """fields: name -> (dtype, per-row shape) (``OutputBuffers.FIELDS``); buffers: name ->
        device buffer."""
        super().__init__()
        self.queue, self.layout, self.buffers = queue, fields, buffers
        self.num_vertices, self.num_triangles = num_vertices, num_triangles

    def raw(self, name: str) -> _Raw:
        return _Raw(self.buffers[name])

    def __contains__(self, name) -> bool:
        return name in self.layout

    def __missing__(self, name):
        if name not in self.layout:
            raise KeyError(name)
        dtype, shape = self.layout[name]
        rows = self.num_triangles if name == "triangles" else self.num_vertices
        self[name] = cl_array.Array(self.queue, (rows, *shape), dtype, data=self.buffers[name])
        return self[name]

    def keys(self):
        return self.layout.keys()

    def values(self):
        return [self[name] for name in self.layout]

    def items(self):
        return [(name, self[name]) for name in self.layout]

    def __iter__(self):
        return iter(self.layout)

    def __len__(self) -> int:
        return len(self.layout)


class OutputBuffers:
    """The output buffers of stages 4-5 on one device: one per field of the vertex record
    (``VERTEX_RECORD``) and one of triangles, kept and grown only when an output needs more
    (by a quarter more than asked, so a slowly growing output does not reallocate every frame).

    How the output reaches host arrays (``read_back``) depends on the device:

    * a CPU device: the buffers are sub-buffers of one allocation with ``CL_MEM_ALLOC_HOST_PTR``,
      *mapped* at once: the host arrays are the buffers' own memory, no copy (``_take_mapped``);
    * another device with ``pinned=True`` (a ``Session``): copied into page-locked host buffers
      (``ALLOC_HOST_PTR``, mapped once and kept), which DMA engines fill at the bus's rate;
    * otherwise copied into fresh (pageable) NumPy arrays.

    Every ``take`` starts a new generation: a result of an earlier one is stale (its arrays
    will be overwritten), which ``DeviceOutput.valid`` reports.  Host arrays from a mapping or
    a pinned buffer are views of memory the next ``take`` reuses too.
    """

    GROWTH = 1.25
    #: The API a subclass hands the buffers to without a copy (``share``), or None.
    shares: str | None = None

    def __init__(self, tessellator: "Tessellator", pinned: bool = False):
        self.queue = tessellator.queue
        self.context = tessellator.context
        self.mapped = bool(tessellator.device.type & cl.device_type.CPU)
        self.pinned = pinned and not self.mapped
        self.generation = 0
        self._buffers: dict = {}  # name -> (device buffer, capacity in rows)
        self._staging: dict = {}  # name -> (pinned buffer, its mapped host array)
        self._maps: list = []
        self.read_back_wait_ms = 0.0  # host ms blocked in the last read_back
        self._parent = None  # a mapped device's one allocation (_take_mapped), its fields' offsets
        self._offsets: dict = {}
        self._started = None  # (generation, vertices, triangles, what was enqueued): start_read_back
        self._capacity = (0, 0)  # (vertices, triangles) of the buffers (_grow)
        self._field_buffers: dict = {}  # name -> device buffer (_grow)

    #: (name, dtype, per-row shape) of every output buffer: the vertex record, then triangles.
    LAYOUT = tuple((name, np.dtype(dtype), shape) for name, dtype, shape in VERTEX_RECORD) + \
        (("triangles", np.dtype(np.uint32), (3,)),)
    #: name -> (dtype, per-row shape), as OutputArrays reads them.
    FIELDS = {name: (dtype, shape) for name, dtype, shape in LAYOUT}

    @classmethod
    def _layout(cls):
        return cls.LAYOUT

    def take(self, num_vertices: int, num_triangles: int) -> dict:
        """pyopencl arrays of (num_vertices, ...) per vertex field and (num_triangles, 3)
        triangles, on buffers at least that large; a new generation.  Within the buffers'
        capacity (frame after frame of a Session) nothing but the generation changes."""
        self.generation += 1
        self.unmap()
        vertices, triangles = self._capacity
        if num_vertices > vertices or num_triangles > triangles or not self._buffers:
            self._grow(num_vertices, num_triangles)
        return OutputArrays(self.queue, self.FIELDS, self._field_buffers, num_vertices, num_triangles)

    def _grow(self, num_vertices: int, num_triangles: int) -> None:
        """Buffers for at least this many vertices and triangles (the first allocation as asked;
        growing, a quarter more)."""
        layout = self._layout()
        if self.mapped:
            self._take_mapped(layout, num_vertices, num_triangles)
        else:
            for name, dtype, shape in layout:
                rows = num_triangles if name == "triangles" else num_vertices
                row_bytes = dtype.itemsize * math.prod(shape)
                buffer, capacity = self._buffers.get(name, (None, -1))
                if rows > capacity:
                    capacity = rows if buffer is None else int(rows * self.GROWTH)
                    self._buffers.pop(name, None)
                    self._staging.pop(name, None)
                    buffer = self._new_buffer(name, max(capacity, 1) * row_bytes)
                    self._buffers[name] = (buffer, capacity)
        self._field_buffers = {name: self._buffers[name][0] for name, _, _ in layout}
        self._capacity = (min(capacity for name, (_, capacity) in self._buffers.items() if name != "triangles"),
                          self._buffers["triangles"][1])

    def _new_buffer(self, name: str, nbytes: int) -> cl.Buffer:
        """A device buffer of ``nbytes`` for field ``name`` (a buffer sharing its memory with
        another API in a subclass: share_cuda.CudaOutputBuffers)."""
        return cl.Buffer(self.context, cl.mem_flags.READ_WRITE, nbytes)

    def _take_mapped(self, layout, num_vertices: int, num_triangles: int) -> None:
        """A CPU device's buffers: every field a sub-buffer of one ``ALLOC_HOST_PTR`` allocation
        (each at a multiple of the device's base address alignment), so that ``read_back`` maps
        once: one map and one release a frame instead of six (measured: 9 against 44 µs on
        Intel's runtime, 38 against 113 on PoCL).  Grown as a whole when a field needs more."""
        rows_of = {name: num_triangles if name == "triangles" else num_vertices for name, _, _ in layout}
        if self._parent is not None and all(rows_of[name] <= self._buffers[name][1] for name in rows_of):
            return
        capacities = {}
        for name, rows in rows_of.items():  # the first allocation as asked; growing, a quarter more
            kept = -1 if self._parent is None else self._buffers[name][1]
            capacities[name] = kept if rows <= kept else rows if self._parent is None else int(rows * self.GROWTH)
        align = max(1, self.queue.device.mem_base_addr_align // 8)
        offsets, end = {}, 0
        for name, dtype, shape in layout:
            offsets[name] = end
            end += -(-max(capacities[name], 1) * dtype.itemsize * math.prod(shape) // align) * align
        self._buffers.clear()
        self._parent = cl.Buffer(self.context, cl.mem_flags.READ_WRITE | cl.mem_flags.ALLOC_HOST_PTR, end)
        for name, dtype, shape in layout:
            size = max(capacities[name], 1) * dtype.itemsize * math.prod(shape)
            self._buffers[name] = (self._parent.get_sub_region(offsets[name], size), capacities[name])
        self._offsets = offsets

    def start_read_back(self, num_vertices: int | None = None, num_triangles: int | None = None) -> None:
        """Enqueue the current generation's read-back now, without waiting; ``read_back`` then
        only waits for it.  The queue is in order: a read-back enqueued when the host asks for
        it waits behind whatever was enqueued since (the next batch's stages: cltess.stream),
        and costs the host a round trip of its own after the stages' (a Session frame).  A CPU
        device's map covers the whole allocation, so the sizes may be left out (a frame whose
        totals are still on their way); copies need them (else nothing is started)."""
        if self.mapped:
            self._started = (self.generation, None, None, self._enqueue_map())
        elif num_vertices is not None:
            self._started = (self.generation, num_vertices, num_triangles,
                             self._enqueue_copies(num_vertices, num_triangles))

    def read_back(self, num_vertices: int, num_triangles: int) -> dict:
        """The current generation's output as host arrays (see the class)."""
        started, self._started = self._started, None
        if started is not None and started[0] == self.generation and started[1] in (None, num_vertices) \
                and started[2] in (None, num_triangles):
            enqueued = started[3]
        else:
            enqueued = self._enqueue_map() if self.mapped else self._enqueue_copies(num_vertices, num_triangles)
        if self.mapped:  # each field a view of the one mapping
            memory, event = enqueued
            host, events = self._views(memory, num_vertices, num_triangles), [event]
        else:
            host, events = enqueued
        self.read_back_wait_ms = wait_ms(events) if events else 0.0
        return host

    def _enqueue_map(self):
        """(memory, event): one map of the whole allocation (a CPU device), not waited for."""
        memory, event = cl.enqueue_map_buffer(self.queue, self._parent, cl.map_flags.READ | cl.map_flags.WRITE,
                                              0, (self._parent.size,), np.uint8, is_blocking=False)
        self._maps.append(memory.base)  # the pyopencl MemoryMap
        return memory, event

    def _views(self, memory, num_vertices: int, num_triangles: int) -> dict:
        """Each field's host array: a view of the mapped allocation."""
        host = {}
        for name, dtype, shape in self._layout():
            rows = num_triangles if name == "triangles" else num_vertices
            start = self._offsets[name]
            host[name] = memory[start:start + rows * dtype.itemsize * math.prod(shape)].view(dtype) \
                .reshape(rows, *shape)
        return host

    def _enqueue_copies(self, num_vertices: int, num_triangles: int) -> tuple[dict, list]:
        """(host arrays, the events to wait for before reading them): each field's copy enqueued
        (into its page-locked array, or a fresh one)."""
        host, events = {}, []
        for name, dtype, shape in self._layout():
            rows = num_triangles if name == "triangles" else num_vertices
            buffer, capacity = self._buffers[name]
            if not rows:
                host[name] = np.zeros((0, *shape), dtype)
            else:
                target = self._pinned(name, dtype, shape, capacity)[:rows] if self.pinned \
                    else np.empty((rows, *shape), dtype)
                events.append(cl.enqueue_copy(self.queue, target, buffer, is_blocking=False))
                host[name] = target
        return host, events

    def unmap(self) -> None:
        """Unmap the host views of the last generation (before the device writes the buffers
        again, as OpenCL asks).  On a CPU device the views still show the buffers' memory, which
        the next generation overwrites; the buffers live as long as a view of them does."""
        if self._maps:  # enqueued, not waited for: the queue is in order, so before the writes
            for memory_map in self._maps:
                memory_map.release(self.queue)
            self._maps.clear()

    def _pinned(self, name, dtype, shape, capacity) -> np.ndarray:
        """The page-locked host array of a field (allocated and mapped once per capacity)."""
        if name not in self._staging:
            buffer = cl.Buffer(self.context, cl.mem_flags.READ_WRITE | cl.mem_flags.ALLOC_HOST_PTR,
                               max(capacity, 1) * dtype.itemsize * math.prod(shape))
            array, _ = cl.enqueue_map_buffer(self.queue, buffer, cl.map_flags.READ | cl.map_flags.WRITE, 0,
                                             (max(capacity, 1), *shape), dtype, is_blocking=True)
            self._staging[name] = (buffer, array)
        return self._staging[name][1]

    def close(self) -> None:
        """Let the buffers go now (a later ``take`` makes new ones); earlier results are stale."""
        self.generation += 1
        self.unmap()
        self._buffers.clear()
        self._staging.clear()
        self._field_buffers = {}
        self._parent = None
        self._capacity = (0, 0)

    @property
    def capacity(self) -> tuple[int, int]:
        """(vertices, triangles) the buffers hold now; (0, 0) before the first ``take``."""
        return self._capacity

    def reserve(self, num_vertices: int, num_triangles: int) -> None:
        """Grow the buffers now (as ``take`` would) if they hold fewer than this."""
        vertices, triangles = self.capacity
        if (vertices, triangles) != (0, 0) and (num_vertices > vertices or num_triangles > triangles):
            self.take(max(num_vertices, vertices), max(num_triangles, triangles))  # (a new generation)

    @property
    def nbytes(self) -> int:
        if self._parent is not None:
            return self._parent.size
        return sum(buffer.size for buffer, _ in self._buffers.values())

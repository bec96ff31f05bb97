"""The result of a tessellation run: arrays in, arrays out (shapes in the field docs).

A result of the OpenCL backend may hold its output on the device only (``Tessellation.device``,
a :class:`DeviceOutput`): the host arrays are then read back the first time one is asked for
(``tess.positions``, ``tess.fetch()``), and ``wall_ms`` says what each wall-clock figure covers.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

#: The vertex record: (field, dtype, per-vertex shape), in the order of the kernels' output
#: (kernels/common.h vertex_out), the Tessellation fields and the writers' columns.
VERTEX_RECORD = (
    ("positions", np.float32, (3,)),
    ("normals", np.float32, (3,)),
    ("uv", np.float32, (2,)),
    ("patch_ids", np.int32, ()),
    ("object_ids", np.int32, ()),
)
#: Bytes of one vertex and of one index in the output.
BYTES_PER_VERTEX = sum(np.dtype(dtype).itemsize * int(np.prod(shape)) for _, dtype, shape in VERTEX_RECORD)
BYTES_PER_INDEX = 4


#: The Tessellation fields a device-resident result reads back on first use.
HOST_FIELDS = tuple(name for name, _, _ in VERTEX_RECORD) + ("triangles", "factors", "real_factors")


class StaleOutput(RuntimeError):
    """A session's output buffers were reused by a later frame (cltess.session)."""


@dataclass
class DeviceOutput:
    """A tessellation's output where the device wrote it, with no read-back.

    arrays: ``pyopencl.array.Array`` per field of the vertex record (``VERTEX_RECORD``: one
    C-contiguous array per field, structure of arrays, row i = vertex i: positions (V, 3) and
    normals (V, 3) float32 at a 12-byte stride, uv (V, 2) float32 at 8, patch_ids and
    object_ids (V,) int32 at 4) and "triangles" (T, 3) uint32 at 12, each starting at byte
    ``offset`` 0 of its array's ``.data`` buffer (``.base_data`` / ``.offset`` for a view of a
    larger reused buffer).  Triangle indices are global: vertex i of this batch is number
    ``vertex_base + i`` (0 for a whole scene).
    read_back: returns the host arrays (a dict with the same keys); valid: whether the buffers
    still hold this output (False once a session's next frame reused them); settle: called
    before the arrays or sizes are first given, for an output whose size the host learns late
    (a Session frame, launched before stage 3's totals were read back); share: hands the
    buffers to the API named by ``shares`` and returns its arrays (a Session made with
    ``share="cuda"``, ``"gl"`` or ``"vulkan"``), else None.
    """

    arrays: dict
    queue: object
    vertex_base: int = 0
    read_back: Callable[[], dict] | None = None
    valid: Callable[[], bool] = lambda: True
    settle: Callable[[], None] = lambda: None
    share: Callable[[], dict] | None = None
    shares: str | None = None

    def __getattr__(self, name):
        arrays = self.__dict__.get("arrays", {})
        if name in arrays:
            self.check()
            self.settle()
            return self.arrays[name]
        raise AttributeError(name)

    def check(self) -> None:
        if not self.valid():
            raise StaleOutput("this output's device buffers were reused by a later Session.tessellate "
                              "call; fetch() or copy what you need before the next frame")

    @property
    def num_vertices(self) -> int:
        self.settle()
        return int(getattr(self.arrays, "num_vertices", None) or self.arrays["positions"].shape[0])

    @property
    def num_triangles(self) -> int:
        self.settle()
        return int(getattr(self.arrays, "num_triangles", None) or self.arrays["triangles"].shape[0])

    @property
    def nbytes(self) -> int:
        self.settle()
        return sum(int(a.nbytes) for a in self.arrays.values())


class IndexedMesh:
    """What every mesh of cltess answers: its vertex and triangle counts (``positions`` (V, 3),
    ``triangles`` (T, 3))."""

    @property
    def num_vertices(self) -> int:
        return len(self.positions)

    @property
    def num_triangles(self) -> int:
        return len(self.triangles)


@dataclass
class Tessellation(IndexedMesh):
    """A triangle mesh sampled from a scene's patches, with its per-patch bookkeeping.

    positions:  (V, 3) float32
    normals:    (V, 3) float32, unit length
    uv:         (V, 2) float32, the patch parameters of each vertex (PN triangles: the
                barycentric weights of the face's first two corners)
    patch_ids:  (V,) int32, the patch each vertex belongs to: the scene's Bézier patches
                first, then its meshes' faces (``cltess.scene``; a mesh file: the face index)
    object_ids: (V,) int32, the object of that patch
    triangles:  (T, 3) uint32, counter-clockwise seen from the normal side
    factors:    (P, 4) int32, the final (crack-free) edge factors; 0 = culled (PN triangles:
                (f0, f1, f2, 0))
    stage_ms:   device milliseconds per stage, from OpenCL profiling events, and "total_wall"
                (= wall_ms["total"])
    stats:      counts for the summary: patches, culled, saturated, shared/boundary edges...
    wall_ms:    host wall-clock milliseconds: "stages" from the start of the call until the
                device stages finished (upload, stages 1-5, the two totals read back),
                "read_back" copying (or, on a CPU device, mapping) the output to host arrays,
                "total" both: until the caller holds the host arrays.  A device-resident result
                (``device``) has no "read_back" until its arrays are fetched, and "total" then
                is "stages" + "read_back" (the time the caller spent between is not counted).
                "waits" (the OpenCL backend's five stages): of those, the ms the host was
                blocked waiting for the device (stages 1-3's totals, stages 4-5, the read-back's
                maps or copies); the rest is host work: Python, launches, copies' set-up.
    device:     the output on the device (:class:`DeviceOutput`), or None (host arrays only).
    strips:     (S,) uint32 triangle strips of the strip patterns' patches (SD-2, ESC), restart-
                separated (cltess.strips), or None; they expand to those patches' triangles
                (ESC's with their zero-area steps dropped: expand_strips(..., drop_degenerate=True))
    real_factors: (P, 4) float32 real edge factors where a pattern is fractional (SD-2; there
                ``factors`` are each edge's segments, the odd ceiling), else None
    """

    positions: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    patch_ids: np.ndarray
    object_ids: np.ndarray
    triangles: np.ndarray
    factors: np.ndarray
    stage_ms: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)
    wall_ms: dict = field(default_factory=dict)
    device: DeviceOutput | None = field(default=None, repr=False, compare=False)
    strips: np.ndarray | None = None
    real_factors: np.ndarray | None = None

    @classmethod
    def on_device(cls, device: DeviceOutput, stage_ms: dict | None, stats: dict | None, wall_ms: dict | None,
                  strips: np.ndarray | None = None, finish=None) -> "Tessellation":
        """A result whose host arrays (and factors) are read back from ``device`` when first
        asked for (strips, when a pattern makes them, are host arrays already).  finish: for a
        result whose stages may still run (``Session.tessellate(wait=False)``), a function that
        waits for them and sets ``stage_ms``, ``wall_ms`` and ``stats`` (given as None); called
        by ``finish()`` or the first look at one of them."""
        tess = object.__new__(cls)
        tess.device, tess.strips = device, strips
        if stats is not None:  # else finish sets it
            tess.stats = stats
        if stage_ms is not None:
            tess.stage_ms, tess.wall_ms = stage_ms, wall_ms
        if finish is not None:
            tess._finish = finish
        return tess

    def finish(self) -> "Tessellation":
        """Wait until the device stages of this result are done (a no-op when they were
        waited for already: every result but ``Session.tessellate(wait=False)``'s)."""
        finish = self.__dict__.pop("_finish", None)
        if finish is not None:
            finish(self)
        return self

    def __getattr__(self, name):
        # Called only for attributes not set: the host arrays of a device-resident result, and
        # the times of one whose stages were not waited for.
        if name in ("stage_ms", "wall_ms", "stats") and "_finish" in self.__dict__:
            self.finish()
            return self.__dict__[name]
        if name in HOST_FIELDS and self.__dict__.get("device") is not None:
            self.fetch()
            return self.__dict__[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def on_host(self) -> bool:
        """Whether the host arrays are there (read back already, or made on the host)."""
        return all(name in self.__dict__ for name in HOST_FIELDS)

    def fetch(self) -> "Tessellation":
        """Read the output back to host arrays now (a no-op if they are there); records
        wall_ms["read_back"] and the total."""
        if self.on_host:
            return self
        self.device.check()
        self.finish()
        started = time.perf_counter()
        self.__dict__.update(self.device.read_back())
        self.wall_ms["read_back"] = (time.perf_counter() - started) * 1e3
        self.wall_ms["total"] = self.wall_ms.get("stages", 0.0) + self.wall_ms["read_back"]
        self.stage_ms["total_wall"] = self.wall_ms["total"]
        return self

    def cuda(self):
        """The output as CUDA device arrays, no copy (``share_cuda.CudaArrays``: positions,
        normals, uv, patch_ids, object_ids, triangles, each with ``__cuda_array_interface__``)
        for a frame of ``Session(..., share="cuda")``.  Waits for the frame's stages; the arrays
        are views of the session's buffers, valid until its next ``tessellate`` call."""
        return self._shared("cuda")

    def gl(self):
        """The output as buffer objects of the Session's OpenGL context, no copy
        (``share_gl.GlBuffers``: each field's GL buffer name, rows and components) for a frame
        of ``Session(..., share="gl")``; GL commands issued after the call see the frame (GL
        waits on the device; the host does not).  Valid until the session's next ``tessellate``
        call: issue the commands that use them before it."""
        return self._shared("gl")

    def vulkan(self):
        """The output as ``VkBuffer``s of the Session's Vulkan device, no copy
        (``share_vulkan.VulkanBuffers``: each field's buffer and memory handles, rows and
        components) for a frame of ``Session(..., share="vulkan", vulkan=VulkanQueue(...))``;
        commands submitted to that queue after the call see the frame (the queue waits on the
        device; the host does not).  Valid until the session's next ``tessellate`` call: submit
        the commands that use them before it."""
        return self._shared("vulkan")

    def _shared(self, api: str):
        device = self.__dict__.get("device")
        if device is None or device.shares != api:
            raise ValueError(f"{api}() is for the frames of a Session made with share=\"{api}\"")
        device.check()
        self.finish()
        device.settle()
        return device.share()

    @property
    def num_vertices(self) -> int:
        return self.device.num_vertices if not self.on_host and self.device is not None else len(self.positions)

    @property
    def num_triangles(self) -> int:
        return self.device.num_triangles if not self.on_host and self.device is not None else len(self.triangles)

    def welded(self, uv: str = "drop", check_t_junctions: bool = True):
        """One indexed mesh per object, shared boundary vertices merged exactly
        (:func:`cltess.weld.weld`; ``uv="seam"`` keeps the per-patch (u, v) per triangle corner)."""
        from .weld import weld

        return weld(self, uv=uv, check_t_junctions=check_t_junctions)

    def to_trimesh(self, weld: bool = True):
        """A ``trimesh.Trimesh``: welded (watertight where the surface is closed) by default, else
        the per-patch vertices as they are."""
        from .io.trimesh_formats import to_trimesh

        return to_trimesh(self.welded(check_t_junctions=False) if weld else self)

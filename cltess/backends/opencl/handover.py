"""The output handed to an API that waits on the device for it (OpenGL: share_gl.py; Vulkan:
share_vulkan.py), by two binary semaphores that OpenCL and that API share.

The memory is share_cuda.py's (CUDA allocates and exports it, OpenCL imports it; the other API
imports it once more).  The semaphores come from a small Vulkan device of the process's own on
the same GPU (neither OpenCL, CUDA nor GL exports one on NVIDIA's driver 580; Vulkan does), and
each is imported by OpenCL (``cl_khr_external_semaphore_opaque_fd``) and by the other API:

* ``ready``: ``share()`` enqueues OpenCL's release of the buffers and a signal of ``ready``, and
  has the other API wait for it (``_wait_ready``): its commands after the call see the frame; the
  host waits for nothing.
* ``done``: the next time OpenCL needs the buffers (the next frame's stages, a read-back,
  growing, ``close``), the other API signals ``done`` after the commands it has been given
  (``_signal_done``), and OpenCL waits for it before it acquires them again.

A binary semaphore's signal must be followed by one wait before the next signal, so each is
signalled only when its wait follows: ``ready`` only by ``share()``, ``done`` only after the
other API had the buffers.  OpenCL's imports are kept per context and lent to one set of
buffers at a time (``OpenCLSemaphores``).
"""
from __future__ import annotations

import ctypes

import pyopencl as cl

from .share_cuda import CudaOutputBuffers, SharingUnavailable
from .vulkan import ExportableSemaphores, VulkanDevice

# cl_khr_semaphore, cl_khr_external_semaphore (cl_ext.h)
CL_SEMAPHORE_TYPE_KHR = 0x203D
CL_SEMAPHORE_TYPE_BINARY_KHR = 1
CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR = 0x2055

#: What share="gl" and share="vulkan" need of the OpenCL device beyond share="cuda": the semaphores.
NEEDED_CL_EXTENSIONS = ("cl_khr_semaphore", "cl_khr_external_semaphore", "cl_khr_external_semaphore_opaque_fd")

_u32, _ptr, _u64 = ctypes.c_uint32, ctypes.c_void_p, ctypes.c_uint64


class _VulkanSemaphores(ExportableSemaphores):
    """A Vulkan device on the GPU with this UUID (vulkan.py), only to make binary semaphores
    exportable as opaque fds; it runs no work.  One per GPU for the process (``for_uuid``),
    never destroyed: on the H200 (driver 580) ``vkDestroyInstance`` left the thread with no
    current GL context (bench/RESULTS.md, "Session 17, lead")."""

    _made: dict = {}  # uuid -> the one of that GPU

    @classmethod
    def for_uuid(cls, uuid: bytes, api: str) -> "_VulkanSemaphores":
        if uuid not in cls._made:
            device = VulkanDevice(uuid, ("VK_KHR_external_semaphore_fd",), api=api)
            cls._made[uuid] = cls(device.vk, device.device)
        return cls._made[uuid]


class OpenCLSemaphores:
    """cl_khr_external_semaphore on the session's device: binary semaphores made by the process's
    Vulkan device on that GPU (``vulkan``) and imported into the session's context, to wait on and
    signal (for the share= ``api``).  A set of buffers borrows its pairs (``lend``) and gives them
    back when it closes, unsignalled, for the next set of that context: they are imported once per
    context and kept for the process.  NVIDIA's OpenCL (driver 580) keeps a ``/dev/nvidiactl``
    descriptor open for every semaphore imported and released in a context that also holds
    imported memory: one more per closed session before this (bench/RESULTS.md, "Session 18,
    lead", fd_parts5.txt)."""

    _spare: dict = {}  # the context's int_ptr -> (the context, its free (Vulkan, OpenCL) semaphore pairs)

    def __init__(self, opencl, device: cl.Device, api: str):
        missing = [name for name in NEEDED_CL_EXTENSIONS if name not in device.extensions.split()]
        if missing:
            raise SharingUnavailable(f"{device.name.strip()}: share=\"{api}\" needs the OpenCL extensions "
                                     f"{', '.join(missing)}, which this device does not offer")
        function = opencl.extension_function
        self.context, self.device = opencl.context, device
        self._create = function("clCreateSemaphoreWithPropertiesKHR", _ptr, _ptr, ctypes.POINTER(_u64),
                                ctypes.POINTER(ctypes.c_int))
        enqueue = (ctypes.c_int, _ptr, _u32, ctypes.POINTER(_ptr), _ptr, _u32, _ptr, _ptr)
        self._wait = function("clEnqueueWaitSemaphoresKHR", *enqueue)
        self._signal = function("clEnqueueSignalSemaphoresKHR", *enqueue)
        self.vulkan = _VulkanSemaphores.for_uuid(opencl.uuid, api)

    def lend(self) -> tuple[int, int]:
        """An unsignalled (Vulkan semaphore, OpenCL semaphore) pair on one payload, for one set of
        buffers until it gives it back; ``vulkan.fd`` of the first hands it to another API."""
        _, spare = self._spare.setdefault(self.context.int_ptr, (self.context, []))
        if spare:
            return spare.pop()
        semaphore = self.vulkan.make()
        return semaphore, self.import_fd(self.vulkan.fd(semaphore))

    def give_back(self, pair: tuple[int, int]) -> None:
        """A lent pair back, unsignalled and with nothing pending on it."""
        self._spare[self.context.int_ptr][1].append(pair)

    def import_fd(self, fd: int) -> int:
        """An OpenCL binary semaphore on the payload behind ``fd`` (which OpenCL takes over).
        The context has one device, so no device list is named (NVIDIA's driver 580 refused
        the list, -64 CL_INVALID_PROPERTY)."""
        properties = (_u64 * 5)(CL_SEMAPHORE_TYPE_KHR, CL_SEMAPHORE_TYPE_BINARY_KHR, CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR,
                                fd, 0)
        error = ctypes.c_int()
        semaphore = self._create(self.context.int_ptr, properties, ctypes.byref(error))
        if error.value or not semaphore:
            raise RuntimeError(f"clCreateSemaphoreWithPropertiesKHR (an opaque fd) failed: {error.value}")
        return semaphore

    def enqueue(self, command: str, queue: cl.CommandQueue, semaphore: int) -> None:
        semaphores = (_ptr * 1)(semaphore)
        function = self._wait if command == "wait" else self._signal
        result = function(queue.int_ptr, 1, semaphores, None, 0, None, None)
        if result:
            raise RuntimeError(f"clEnqueue{command.title()}SemaphoresKHR failed: {result}")


class HandedOverBuffers(CudaOutputBuffers):
    """CudaOutputBuffers handed over to an API that waits on the device (the module's notes).  A
    subclass sets ``shares`` and gives that API's side:

    * ``_import_semaphores()``: its own semaphores on the lent pairs' payloads (``self._lent``,
      role -> (Vulkan, OpenCL) semaphore; ``self.cl_semaphores.vulkan.fd`` of the first);
    * ``_wait_ready()``: it waits for ``ready`` and takes the buffers;
    * ``_signal_done()``: it gives them back and signals ``done`` after its commands;
    * ``_close_api()``: its objects go, those it has made so far (the semaphores it imported
      among them);
    * ``share()``: ``_hand_over()``, then its view of each field (``_shared_fields``);
    * its ``__init__`` ends with ``_borrow_semaphores()``.
    """

    def __init__(self, tessellator, pinned: bool = False):
        super().__init__(tessellator, pinned)
        self.cl_semaphores = OpenCLSemaphores(self.opencl, tessellator.device, self.shares)
        self._lent = {}
        self._with_api = False  # whether the other API has the buffers (share() since OpenCL last took them)

    def _borrow_semaphores(self) -> None:
        """The two pairs lent, and the other API's imports of them."""
        try:
            for role in ("ready", "done"):
                self._lent[role] = self.cl_semaphores.lend()
            self._import_semaphores()
        except Exception:  # (nothing signalled yet)
            self._close_api()
            self._give_back()
            raise

    def _give_back(self) -> None:
        for pair in self._lent.values():
            self.cl_semaphores.give_back(pair)
        self._lent = None

    def _reclaim(self) -> None:
        if self._with_api and self._buffers:
            self._signal_done()
            self.cl_semaphores.enqueue("wait", self.queue, self._lent["done"][1])
            self._with_api = False

    def _hand_over(self) -> None:
        """The current output handed to the other API: released by OpenCL, ``ready`` signalled
        behind it and waited for there (no host wait)."""
        if self._held:
            self._let_go()
            self.cl_semaphores.enqueue("signal", self.queue, self._lent["ready"][1])
            self.queue.flush()
            self._wait_ready()
            self._with_api = True

    def take(self, num_vertices: int, num_triangles: int):
        if self._lent is None:
            raise RuntimeError(f"this share=\"{self.shares}\" Session was closed: make a new one")
        return super().take(num_vertices, num_triangles)

    def close(self) -> None:
        """The other API's objects go, after it gave the buffers back and OpenCL finished; the
        semaphores go back to the context's pool (unsignalled: OpenCL waited for ``done``, which
        the other API signalled after its wait for ``ready``).  No frame can be made after it."""
        if self._lent is None:  # (closed already)
            return
        self._reclaim()
        self.queue.finish()
        self._close_api()
        self._give_back()
        super().close()


__all__ = ["HandedOverBuffers", "NEEDED_CL_EXTENSIONS", "OpenCLSemaphores"]

"""A Session's output handed to OpenGL without a copy: ``Session(scene, device="nvidia",
share="gl")`` made while an OpenGL context is current (EGL or GLX), then ``frame.gl()``: the
frame's fields as GL buffer objects of that context, to draw from.

NVIDIA's OpenCL offers no ``cl_khr_gl_sharing`` (docs/design.md section 9, "Handing the output
to other APIs"), so the buffers go the way share_cuda.py's do: memory that CUDA allocates and
exports, imported by OpenCL (``cl_khr_external_memory``) and by GL (``GL_EXT_memory_object_fd``:
``glImportMemoryFdEXT``, ``glNamedBufferStorageMemEXT``).  GL sees another API's writes only
after a ``glWaitSemaphoreEXT`` naming the buffers, on a semaphore that the writer signals, and
neither OpenCL nor CUDA nor GL exports one there; Vulkan does.  So a small Vulkan device on the
same GPU (matched by UUID) makes two binary semaphores and exports each twice as an opaque fd,
once for OpenCL (``cl_khr_external_semaphore_opaque_fd``; OpenCL's imports are kept per context
and lent to one session at a time: ``OpenCLSemaphores``) and once for GL (``GL_EXT_semaphore_fd``):

* ``ready``: ``frame.gl()`` enqueues OpenCL's release of the buffers and a signal of ``ready``,
  and has GL wait for it (``glWaitSemaphoreEXT`` with the buffers): GL's commands after the call
  see the frame; the host waits for nothing.
* ``done``: the next time OpenCL needs the buffers (the next frame's stages, a read-back), GL
  signals ``done`` after the commands it has been given (``glSignalSemaphoreEXT``, flushed), and
  OpenCL waits for it before it acquires them again.

A binary semaphore's signal must be followed by one wait before the next signal, so each is
signalled only when its wait follows: ``ready`` only by ``frame.gl()``, ``done`` only after GL had
the buffers.  GL calls need the session's GL context current on the calling thread (checked).
``Session.close()`` deletes the GL objects (with that context current).
"""
from __future__ import annotations

import ctypes
import os

import numpy as np
import pyopencl as cl

from .share_cuda import CudaOutputBuffers, SharedFields, SharingUnavailable
from .vulkan import ExportableSemaphores, VulkanDevice

# cl_khr_semaphore, cl_khr_external_semaphore (cl_ext.h)
CL_SEMAPHORE_TYPE_KHR = 0x203D
CL_SEMAPHORE_TYPE_BINARY_KHR = 1
CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR = 0x2055
# GL_EXT_memory_object_fd, GL_EXT_semaphore_fd
GL_HANDLE_TYPE_OPAQUE_FD_EXT = 0x9586
GL_NUM_EXTENSIONS = 0x821D
GL_EXTENSIONS = 0x1F03

#: What share="gl" needs beyond share="cuda": the OpenCL and GL extensions.
NEEDED_CL_EXTENSIONS = ("cl_khr_semaphore", "cl_khr_external_semaphore", "cl_khr_external_semaphore_opaque_fd")
NEEDED_GL_EXTENSIONS = ("GL_EXT_memory_object", "GL_EXT_memory_object_fd", "GL_EXT_semaphore", "GL_EXT_semaphore_fd")

_u32, _ptr, _u64 = ctypes.c_uint32, ctypes.c_void_p, ctypes.c_uint64


class _CurrentGL:
    """The OpenGL context current on this thread (EGL, else GLX), and the functions used here."""

    FUNCTIONS = {  # name -> (restype, argtypes)
        "glGetIntegerv": (None, [_u32, ctypes.POINTER(ctypes.c_int)]),
        "glGetStringi": (ctypes.c_char_p, [_u32, _u32]),
        "glGetError": (_u32, []),
        "glFlush": (None, []),
        "glCreateMemoryObjectsEXT": (None, [ctypes.c_int, ctypes.POINTER(_u32)]),
        "glImportMemoryFdEXT": (None, [_u32, _u64, _u32, ctypes.c_int]),
        "glDeleteMemoryObjectsEXT": (None, [ctypes.c_int, ctypes.POINTER(_u32)]),
        "glCreateBuffers": (None, [ctypes.c_int, ctypes.POINTER(_u32)]),
        "glNamedBufferStorageMemEXT": (None, [_u32, ctypes.c_ssize_t, _u32, _u64]),
        "glDeleteBuffers": (None, [ctypes.c_int, ctypes.POINTER(_u32)]),
        "glGenSemaphoresEXT": (None, [ctypes.c_int, ctypes.POINTER(_u32)]),
        "glImportSemaphoreFdEXT": (None, [_u32, _u32, ctypes.c_int]),
        "glDeleteSemaphoresEXT": (None, [ctypes.c_int, ctypes.POINTER(_u32)]),
        "glWaitSemaphoreEXT": (None, [_u32, _u32, ctypes.POINTER(_u32), _u32, _ptr, _ptr]),
        "glSignalSemaphoreEXT": (None, [_u32, _u32, ctypes.POINTER(_u32), _u32, _ptr, _ptr]),
    }

    def __init__(self):
        self.current, address = self._window_system()
        for name, (restype, argtypes) in self.FUNCTIONS.items():
            pointer = address(name.encode())
            if not pointer:
                raise SharingUnavailable(f"share=\"gl\": the GL context has no {name}")
            setattr(self, name, ctypes.CFUNCTYPE(restype, *argtypes)(pointer))
        self.context = self.current()
        count = ctypes.c_int()
        self.glGetIntegerv(GL_NUM_EXTENSIONS, ctypes.byref(count))
        extensions = {self.glGetStringi(GL_EXTENSIONS, k).decode() for k in range(count.value)}
        missing = [name for name in NEEDED_GL_EXTENSIONS if name not in extensions]
        if missing:
            raise SharingUnavailable(f"share=\"gl\" needs the OpenGL extensions {', '.join(missing)}, which the "
                                     "current context does not offer")

    @staticmethod
    def _window_system():
        """(the current context's getter, the function-address getter) of EGL or GLX, whichever
        has a context current on this thread."""
        for library, current, address in (("libEGL.so.1", "eglGetCurrentContext", "eglGetProcAddress"),
                                           ("libGLX.so.0", "glXGetCurrentContext", "glXGetProcAddressARB"),
                                           ("libGL.so.1", "glXGetCurrentContext", "glXGetProcAddressARB")):
            try:
                lib = ctypes.CDLL(library)
            except OSError:
                continue
            getter, finder = getattr(lib, current), getattr(lib, address)
            getter.restype, finder.restype, finder.argtypes = _ptr, _ptr, [ctypes.c_char_p]
            if getter():
                return getter, finder
        raise SharingUnavailable("share=\"gl\" needs an OpenGL context current on this thread (EGL or GLX)")

    def check(self, doing: str) -> None:
        if self.current() != self.context:
            raise RuntimeError(f"{doing} needs the OpenGL context the Session was made with, current on this thread")
        error = self.glGetError()
        if error:
            raise RuntimeError(f"OpenGL error {error:#x} before {doing}")

    def raise_error(self, doing: str) -> None:
        error = self.glGetError()
        if error:
            raise RuntimeError(f"OpenGL error {error:#x} in {doing}")


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
    signal (share="gl" and share="vulkan": ``api``).  An output set borrows its pair (``lend``)
    and gives it back when it closes, unsignalled, for the next set of that context: they are
    imported once per context and kept for the process.  NVIDIA's OpenCL (driver 580) keeps a
    ``/dev/nvidiactl`` descriptor open for every semaphore imported and released in a context that
    also holds imported memory: one more per closed session before this (bench/RESULTS.md,
    "Session 18, lead", fd_parts5.txt)."""

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
        """An unsignalled (Vulkan semaphore, OpenCL semaphore) pair on one payload, for one output
        set until it gives it back; ``vulkan.fd`` of the first hands it to another API."""
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


class GlBuffer:
    """One output field as a GL buffer object (``name``, of the Session's GL context): ``rows``
    rows of ``components`` values of ``dtype``, tightly packed from byte 0 (positions: 3 float32,
    a 12-byte stride; triangles: 3 uint32 a row, ``GL_UNSIGNED_INT`` indices)."""

    def __init__(self, name: int, rows: int, shape: tuple, dtype):
        self.name, self.rows, self.dtype = name, rows, np.dtype(dtype)
        self.components = int(np.prod(shape)) if shape else 1

    @property
    def nbytes(self) -> int:
        return self.rows * self.components * self.dtype.itemsize

    def __repr__(self) -> str:
        return f"GlBuffer(name={self.name}, rows={self.rows}, components={self.components}, dtype={self.dtype})"


class GlBuffers(SharedFields):
    """A frame's output as ``GlBuffer``s."""


class GlOutputBuffers(CudaOutputBuffers):
    """CudaOutputBuffers whose allocations GL imports too, handed to GL by semaphores (the
    module's notes)."""

    shares = "gl"

    def __init__(self, tessellator, pinned: bool = False):
        self.gl = _CurrentGL()  # first: without a current GL context nothing else is made
        super().__init__(tessellator, pinned)
        self.cl_semaphores = OpenCLSemaphores(self.opencl, tessellator.device, "gl")
        self._gl_objects: dict = {}  # name -> (GL memory object, GL buffer)
        self._with_gl = False  # whether GL has the buffers (frame.gl() since OpenCL last took them)
        self._lent, self._cl_semaphore, self._gl_semaphore = {}, {}, {}  # "ready" / "done" -> pair, handles
        for role in ("ready", "done"):
            self._lent[role] = self.cl_semaphores.lend()
            self._cl_semaphore[role] = self._lent[role][1]
            made = _u32()
            self.gl.glGenSemaphoresEXT(1, ctypes.byref(made))
            self.gl.glImportSemaphoreFdEXT(made, GL_HANDLE_TYPE_OPAQUE_FD_EXT,
                                           self.cl_semaphores.vulkan.fd(self._lent[role][0]))
            self._gl_semaphore[role] = made.value
        self.gl.raise_error("importing the semaphores")

    def _new_buffer(self, name: str, nbytes: int) -> cl.Buffer:
        self.gl.check("growing the shared buffers")
        self._delete_gl(name)
        buffer = super()._new_buffer(name, nbytes)
        allocation = self._allocations[name]
        memory, gl_buffer, fd = _u32(), _u32(), allocation.export_fd()
        self.gl.glCreateMemoryObjectsEXT(1, ctypes.byref(memory))
        self.gl.glImportMemoryFdEXT(memory, allocation.nbytes, GL_HANDLE_TYPE_OPAQUE_FD_EXT, fd)
        error = self.gl.glGetError()
        if error:  # (GL takes the fd over only when the import succeeds)
            os.close(fd)
            self.gl.glDeleteMemoryObjectsEXT(1, ctypes.byref(memory))
            raise RuntimeError(f"OpenGL error {error:#x} importing {name}'s memory (glImportMemoryFdEXT)")
        self.gl.glCreateBuffers(1, ctypes.byref(gl_buffer))
        self.gl.glNamedBufferStorageMemEXT(gl_buffer, allocation.nbytes, memory, 0)
        self._gl_objects[name] = (memory.value, gl_buffer.value)
        self.gl.raise_error(f"importing {name} into OpenGL")
        return buffer

    def _delete_gl(self, name: str) -> None:
        if name in self._gl_objects:
            memory, gl_buffer = self._gl_objects.pop(name)
            self.gl.glDeleteBuffers(1, ctypes.byref(_u32(gl_buffer)))
            self.gl.glDeleteMemoryObjectsEXT(1, ctypes.byref(_u32(memory)))

    def _gl_buffer_list(self) -> ctypes.Array:
        return (_u32 * len(self._gl_objects))(*(gl_buffer for _, gl_buffer in self._gl_objects.values()))

    def _reclaim(self) -> None:
        if self._with_gl and self._buffers:  # GL gives the buffers back after the commands it has: done
            self.gl.check("taking the buffers back from OpenGL")
            buffers = self._gl_buffer_list()
            self.gl.glSignalSemaphoreEXT(self._gl_semaphore["done"], len(buffers), buffers, 0, None, None)
            self.gl.glFlush()
            self.cl_semaphores.enqueue("wait", self.queue, self._cl_semaphore["done"])
            self._with_gl = False

    def share(self, num_vertices: int, num_triangles: int) -> GlBuffers:
        """The current output handed to GL: released by OpenCL, ``ready`` signalled behind it
        and waited for by GL (no host wait)."""
        if self._held:
            self.gl.check("handing the buffers to OpenGL")
            self._let_go()
            self.cl_semaphores.enqueue("signal", self.queue, self._cl_semaphore["ready"])
            self.queue.flush()
            buffers = self._gl_buffer_list()
            self.gl.glWaitSemaphoreEXT(self._gl_semaphore["ready"], len(buffers), buffers, 0, None, None)
            self.gl.raise_error("waiting for the frame in OpenGL")
            self._with_gl = True
        return self._shared_fields(GlBuffers(), num_vertices, num_triangles,
                                   lambda name, *layout: GlBuffer(self._gl_objects[name][1], *layout))

    def take(self, num_vertices: int, num_triangles: int):
        self._check_open(self._gl_semaphore)
        return super().take(num_vertices, num_triangles)

    def close(self) -> None:
        """Delete the GL objects (the session's GL context current) and the semaphores; wait
        for OpenCL first.  No frame can be made after it."""
        if not self._gl_semaphore:  # (closed already)
            return
        self.gl.check("closing the shared buffers")
        self._reclaim()  # (GL's commands on them done before OpenCL's wait ends)
        self.queue.finish()
        for name in list(self._gl_objects):
            self._delete_gl(name)
        self.gl.glDeleteSemaphoresEXT(2, (_u32 * 2)(*self._gl_semaphore.values()))
        for pair in self._lent.values():  # (unsignalled: OpenCL waited for done, which GL signalled after ready)
            self.cl_semaphores.give_back(pair)
        self._lent, self._cl_semaphore, self._gl_semaphore = {}, {}, {}
        super().close()


__all__ = ["GlBuffer", "GlBuffers", "GlOutputBuffers"]

"""A Session's output handed to OpenGL without a copy: ``Session(scene, device="nvidia",
share="gl")`` made while an OpenGL context is current (EGL or GLX), then ``frame.gl()``: the
frame's fields as GL buffer objects of that context, to draw from.

NVIDIA's OpenCL offers no ``cl_khr_gl_sharing`` (docs/design.md section 9, "Handing the output
to other APIs"), so the buffers go the way share_cuda.py's do: memory that CUDA allocates and
exports, imported by OpenCL (``cl_khr_external_memory``) and by GL (``GL_EXT_memory_object_fd``:
``glImportMemoryFdEXT``, ``glNamedBufferStorageMemEXT``).  GL sees another API's writes only
after a ``glWaitSemaphoreEXT`` naming the buffers, on a semaphore that the writer signals: the
hand-over of handover.py, GL's side here (``GL_EXT_semaphore_fd``): GL waits for ``ready`` with
``glWaitSemaphoreEXT`` and signals ``done`` with ``glSignalSemaphoreEXT`` (flushed), each naming
the buffers.  GL calls need the session's GL context current on the calling thread (checked).
``Session.close()`` deletes the GL objects (with that context current).
"""
from __future__ import annotations

import ctypes
import os

import pyopencl as cl

from .handover import HandedOverBuffers
from .share_cuda import SharedBuffer, SharedFields, SharingUnavailable

# GL_EXT_memory_object_fd, GL_EXT_semaphore_fd
GL_HANDLE_TYPE_OPAQUE_FD_EXT = 0x9586
GL_NUM_EXTENSIONS = 0x821D
GL_EXTENSIONS = 0x1F03

#: What share="gl" needs of the GL context (of the OpenCL device: handover.NEEDED_CL_EXTENSIONS).
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


class GlBuffer(SharedBuffer):
    """One output field as a GL buffer object (``name``, of the Session's GL context), laid out as
    SharedBuffer says (triangles: ``GL_UNSIGNED_INT`` indices)."""

    def __init__(self, name: int, rows: int, shape: tuple, dtype):
        super().__init__(rows, shape, dtype)
        self.name = name

    def __repr__(self) -> str:
        return f"GlBuffer(name={self.name}, rows={self.rows}, components={self.components}, dtype={self.dtype})"


class GlBuffers(SharedFields):
    """A frame's output as ``GlBuffer``s."""


class GlOutputBuffers(HandedOverBuffers):
    """CudaOutputBuffers whose allocations GL imports too, handed to GL by semaphores
    (handover.py; the module's notes)."""

    shares = "gl"

    def __init__(self, tessellator, pinned: bool = False):
        self.gl = _CurrentGL()  # first: without a current GL context nothing else is made
        super().__init__(tessellator, pinned)
        self._gl_objects: dict = {}  # name -> (GL memory object, GL buffer)
        self._gl_semaphore = {}  # "ready" / "done" -> GL semaphore
        self._borrow_semaphores()

    def _import_semaphores(self) -> None:
        for role, (vulkan_semaphore, _) in self._lent.items():
            made = _u32()
            self.gl.glGenSemaphoresEXT(1, ctypes.byref(made))
            self._gl_semaphore[role] = made.value
            fd = self.cl_semaphores.vulkan.fd(vulkan_semaphore)
            self.gl.glImportSemaphoreFdEXT(made, GL_HANDLE_TYPE_OPAQUE_FD_EXT, fd)
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

    def _signal_done(self) -> None:
        self.gl.check("taking the buffers back from OpenGL")
        buffers = self._gl_buffer_list()
        self.gl.glSignalSemaphoreEXT(self._gl_semaphore["done"], len(buffers), buffers, 0, None, None)
        self.gl.glFlush()

    def _wait_ready(self) -> None:
        buffers = self._gl_buffer_list()
        self.gl.glWaitSemaphoreEXT(self._gl_semaphore["ready"], len(buffers), buffers, 0, None, None)
        self.gl.raise_error("waiting for the frame in OpenGL")

    def share(self, num_vertices: int, num_triangles: int) -> GlBuffers:
        """The current output handed to GL (HandedOverBuffers._hand_over: no host wait)."""
        if self._held:
            self.gl.check("handing the buffers to OpenGL")
        self._hand_over()
        return self._shared_fields(GlBuffers(), num_vertices, num_triangles,
                                   lambda name, *layout: GlBuffer(self._gl_objects[name][1], *layout))

    def close(self) -> None:
        """HandedOverBuffers.close, the session's GL context current."""
        if self._lent is not None:
            self.gl.check("closing the shared buffers")
        super().close()

    def _close_api(self) -> None:
        for name in list(self._gl_objects):
            self._delete_gl(name)
        if self._gl_semaphore:
            self.gl.glDeleteSemaphoresEXT(len(self._gl_semaphore), (_u32 * len(self._gl_semaphore))(
                *self._gl_semaphore.values()))
        self._gl_semaphore = {}


__all__ = ["GlBuffer", "GlBuffers", "GlOutputBuffers"]

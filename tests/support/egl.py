"""A headless OpenGL 4.5 context through EGL (the device platform: no display), made current
on this thread, and reading a GL buffer back, for share="gl" (cltess/backends/opencl/share_gl.py)
in tests/test_share_handover.py and bench/gpu_share.py.  On the lent GPU machine EGL and GL come
from the .deb packages its README names (libegl1, libopengl0, ...)."""
from __future__ import annotations

import ctypes

import numpy as np

_ptr, _u32, _int = ctypes.c_void_p, ctypes.c_uint32, ctypes.c_int
EGL_PLATFORM_DEVICE_EXT = 0x313F
EGL_OPENGL_API = 0x30A2
EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE = 0x3033, 0x1, 0x3040, 0x8, 0x3038
EGL_CONTEXT_MAJOR_VERSION, EGL_CONTEXT_MINOR_VERSION = 0x3098, 0x30FB
GL_COPY_READ_BUFFER, GL_STATIC_READ = 0x8F36, 0x88E5


class HeadlessGL:
    """An EGL display on the first EGL device that initialises, a GL 4.5 core context with no
    surface, current on this thread; ``read(name, nbytes)`` the bytes of GL buffer ``name`` as
    GL's GPU copy sees them (glCopyNamedBufferSubData into a buffer of its own, then read)."""

    def __init__(self):
        try:
            egl = self.egl = ctypes.CDLL("libEGL.so.1")
            gl = self.gl = ctypes.CDLL("libOpenGL.so.0")
        except OSError as error:
            raise RuntimeError(f"no EGL or OpenGL library: {error}") from None
        egl.eglGetProcAddress.restype, egl.eglGetProcAddress.argtypes = _ptr, [ctypes.c_char_p]
        egl.eglInitialize.argtypes = [_ptr, _ptr, _ptr]
        egl.eglChooseConfig.argtypes = [_ptr, _ptr, _ptr, _int, _ptr]
        egl.eglCreateContext.restype, egl.eglCreateContext.argtypes = _ptr, [_ptr, _ptr, _ptr, _ptr]
        egl.eglMakeCurrent.argtypes = [_ptr, _ptr, _ptr, _ptr]
        egl.eglDestroyContext.argtypes = [_ptr, _ptr]
        egl.eglTerminate.argtypes = [_ptr]
        egl.eglGetCurrentContext.restype = _ptr
        query = ctypes.CFUNCTYPE(_u32, _int, ctypes.POINTER(_ptr), ctypes.POINTER(_int))(
            egl.eglGetProcAddress(b"eglQueryDevicesEXT"))
        platform_display = ctypes.CFUNCTYPE(_ptr, _int, _ptr, _ptr)(egl.eglGetProcAddress(b"eglGetPlatformDisplayEXT"))
        devices, count = (_ptr * 8)(), _int()
        if not query or not query(8, devices, ctypes.byref(count)):
            raise RuntimeError("no EGL devices")
        self.display = next((d for d in (platform_display(EGL_PLATFORM_DEVICE_EXT, devices[k], None)
                                         for k in range(count.value)) if d and egl.eglInitialize(d, None, None)), None)
        if not self.display:
            raise RuntimeError("no EGL device initialises")
        egl.eglBindAPI(EGL_OPENGL_API)
        config, found = _ptr(), _int()
        attributes = (_int * 5)(EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE)
        egl.eglChooseConfig(self.display, attributes, ctypes.byref(config), 1, ctypes.byref(found))
        version = (_int * 5)(EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5, EGL_NONE)
        self.context = egl.eglCreateContext(self.display, config, None, version)
        if not self.context or not egl.eglMakeCurrent(self.display, None, None, self.context):
            raise RuntimeError("no GL 4.5 context without a surface")

        def function(name, *argtypes):
            return ctypes.CFUNCTYPE(None, *argtypes)(egl.eglGetProcAddress(name.encode()))

        self._create = function("glCreateBuffers", _int, ctypes.POINTER(_u32))
        self._data = function("glNamedBufferData", _u32, ctypes.c_ssize_t, _ptr, _u32)
        self._copy = function("glCopyNamedBufferSubData", _u32, _u32, ctypes.c_ssize_t, ctypes.c_ssize_t,
                              ctypes.c_ssize_t)
        self._get = function("glGetNamedBufferSubData", _u32, ctypes.c_ssize_t, ctypes.c_ssize_t, _ptr)
        self._delete = function("glDeleteBuffers", _int, ctypes.POINTER(_u32))
        gl.glGetError.restype = _u32

    def read(self, name: int, nbytes: int, dtype, shape) -> np.ndarray:
        """GL buffer ``name``'s first ``nbytes`` as GL's GPU sees them, as an array."""
        out = np.empty(shape, dtype)
        assert out.nbytes == nbytes
        if not nbytes:
            return out
        copy = _u32()
        self._create(1, ctypes.byref(copy))
        self._data(copy, nbytes, None, GL_STATIC_READ)
        self._copy(name, copy, 0, 0, nbytes)
        self._get(copy, 0, nbytes, out.ctypes.data_as(_ptr))
        self._delete(1, ctypes.byref(copy))
        error = self.gl.glGetError()
        if error:
            raise RuntimeError(f"OpenGL error {error:#x} reading buffer {name}")
        return out

    def current(self) -> bool:
        """Whether this context is still the thread's current one."""
        return self.egl.eglGetCurrentContext() == self.context

    def finish(self) -> None:
        self.gl.glFinish()

    def close(self) -> None:
        self.egl.eglMakeCurrent(self.display, None, None, None)
        self.egl.eglDestroyContext(self.display, self.context)
        self.egl.eglTerminate(self.display)

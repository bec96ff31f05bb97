"""Feasibility probe: OpenCL (NVIDIA) writing into OpenGL buffers of a headless EGL context."""
import ctypes, ctypes.util, glob, os, sys, time
import numpy as np
import pyopencl as cl

def lib(*names):
    for n in names:
        try:
            return ctypes.CDLL(n)
        except OSError:
            pass
    raise OSError(names)

egl = lib("libEGL.so.1", "libEGL.so")
gl = lib("libOpenGL.so.0", "libGL.so.1")
loaders = glob.glob(os.path.join(os.path.dirname(cl.__file__), ".libs", "libOpenCL*"))
print("pyopencl loader:", loaders)
ocl = ctypes.CDLL(loaders[0]) if loaders else lib("libOpenCL.so.1")

vp = ctypes.c_void_p
egl.eglGetProcAddress.restype = vp; egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
egl.eglGetDisplay.restype = vp
egl.eglGetCurrentDisplay.restype = vp; egl.eglGetCurrentContext.restype = vp
egl.eglCreateContext.restype = vp; egl.eglCreateContext.argtypes = [vp, vp, vp, ctypes.POINTER(ctypes.c_int)]
egl.eglInitialize.argtypes = [vp, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int)]
egl.eglChooseConfig.argtypes = [vp, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(vp), ctypes.c_int, ctypes.POINTER(ctypes.c_int)]
egl.eglMakeCurrent.argtypes = [vp, vp, vp, vp]
egl.eglCreatePbufferSurface.restype = vp; egl.eglCreatePbufferSurface.argtypes = [vp, vp, ctypes.POINTER(ctypes.c_int)]
egl.eglQueryString.restype = ctypes.c_char_p; egl.eglQueryString.argtypes = [vp, ctypes.c_int]

def ints(*v):
    return (ctypes.c_int * len(v))(*v)

def display():
    query = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_int, ctypes.POINTER(vp), ctypes.POINTER(ctypes.c_int))(
        egl.eglGetProcAddress(b"eglQueryDevicesEXT"))
    get_platform = ctypes.CFUNCTYPE(vp, ctypes.c_int, vp, ctypes.POINTER(ctypes.c_int))(
        egl.eglGetProcAddress(b"eglGetPlatformDisplayEXT"))
    devices = (vp * 8)(); n = ctypes.c_int()
    print("eglQueryDevicesEXT", query(8, devices, ctypes.byref(n)), n.value)
    for i in range(n.value):
        d = get_platform(0x313F, devices[i], None)
        major, minor = ctypes.c_int(), ctypes.c_int()
        if d and egl.eglInitialize(d, ctypes.byref(major), ctypes.byref(minor)):
            print("EGL display", i, major.value, minor.value, egl.eglQueryString(d, 0x3053))  # EGL_VENDOR
            return d
    raise SystemExit("no EGL display")

d = display()
print("EGL_EXTENSIONS", egl.eglQueryString(d, 0x3055))
print("bind", egl.eglBindAPI(0x30A2))
config = vp(); n = ctypes.c_int()
egl.eglChooseConfig(d, ints(0x3033, 0x0001, 0x3040, 0x0008, 0x3038), ctypes.byref(config), 1, ctypes.byref(n))
print("configs", n.value)
surface = egl.eglCreatePbufferSurface(d, config, ints(0x3057, 1, 0x3056, 1, 0x3038))
ctx = egl.eglCreateContext(d, config, None, ints(0x3098, 4, 0x30FB, 5, 0x3038))
print("context", ctx, "surface", surface)
print("make current", egl.eglMakeCurrent(d, surface, surface, ctx))
gl.glGetString.restype = ctypes.c_char_p
print("GL", gl.glGetString(0x1F01), gl.glGetString(0x1F02))

def glf(name, res, *args):
    return ctypes.CFUNCTYPE(res, *args)(egl.eglGetProcAddress(name.encode()))
glGenBuffers = glf("glGenBuffers", None, ctypes.c_int, ctypes.POINTER(ctypes.c_uint))
glBindBuffer = glf("glBindBuffer", None, ctypes.c_uint, ctypes.c_uint)
glBufferData = glf("glBufferData", None, ctypes.c_uint, ctypes.c_ssize_t, vp, ctypes.c_uint)
glGetBufferSubData = glf("glGetBufferSubData", None, ctypes.c_uint, ctypes.c_ssize_t, ctypes.c_ssize_t, vp)
glFinish = glf("glFinish", None)

N = 1 << 20
name = ctypes.c_uint()
glGenBuffers(1, ctypes.byref(name))
glBindBuffer(0x8892, name)
glBufferData(0x8892, N * 4, None, 0x88E8)  # GL_DYNAMIC_DRAW? 0x88E8 = GL_DYNAMIC_DRAW
glFinish()
print("GL buffer", name.value)

platform = [p for p in cl.get_platforms() if "NVIDIA" in p.name][0]
device = platform.get_devices()[0]
print("CL device", device.name, device.version)
print("CL extensions", device.extensions)
ocl.clCreateContext.restype = vp
ocl.clCreateContext.argtypes = [ctypes.POINTER(ctypes.c_ssize_t), ctypes.c_uint, ctypes.POINTER(vp), vp, vp,
                                ctypes.POINTER(ctypes.c_int)]
props = (ctypes.c_ssize_t * 7)(0x1084, platform.int_ptr, 0x2008, ctx, 0x2009, d, 0)
devs = (vp * 1)(device.int_ptr)
err = ctypes.c_int()
context_ptr = ocl.clCreateContext(props, 1, devs, None, None, ctypes.byref(err))
print("clCreateContext with EGL sharing:", err.value, context_ptr)
if err.value:
    sys.exit(0)
context = cl.Context.from_int_ptr(context_ptr, retain=False)
queue = cl.CommandQueue(context)
ocl.clCreateFromGLBuffer.restype = vp
ocl.clCreateFromGLBuffer.argtypes = [vp, ctypes.c_uint64, ctypes.c_uint, ctypes.POINTER(ctypes.c_int)]
mem = ocl.clCreateFromGLBuffer(context.int_ptr, 1 << 1, name.value, ctypes.byref(err))  # CL_MEM_WRITE_ONLY
print("clCreateFromGLBuffer:", err.value, mem)
buffer = cl.Buffer.from_int_ptr(mem, retain=False)
print("size", buffer.size)
ocl.clEnqueueAcquireGLObjects.argtypes = [vp, ctypes.c_uint, ctypes.POINTER(vp), ctypes.c_uint, vp, vp]
ocl.clEnqueueReleaseGLObjects.argtypes = ocl.clEnqueueAcquireGLObjects.argtypes
mems = (vp * 1)(buffer.int_ptr)
prg = cl.Program(context, "__kernel void w(__global float *a){ size_t i = get_global_id(0); a[i] = 0.5f * i; }").build()
for rep in range(3):
    t0 = time.perf_counter()
    e1 = ocl.clEnqueueAcquireGLObjects(queue.int_ptr, 1, mems, 0, None, None)
    prg.w(queue, (N,), None, buffer)
    e2 = ocl.clEnqueueReleaseGLObjects(queue.int_ptr, 1, mems, 0, None, None)
    queue.finish()
    print("acquire", e1, "release", e2, "ms", (time.perf_counter() - t0) * 1e3)
out = np.zeros(N, np.float32)
glGetBufferSubData(0x8892, 0, N * 4, out.ctypes.data)
print("GL sees", out[:4], out[-2:], "ok" if np.array_equal(out, 0.5 * np.arange(N, dtype=np.float32)) else "MISMATCH")

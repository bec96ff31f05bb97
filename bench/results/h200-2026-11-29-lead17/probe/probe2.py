"""Feasibility probe 2: memory allocated by CUDA (VMM, exportable as an opaque fd), imported into
OpenCL (cl_khr_external_memory_opaque_fd) and into OpenGL (GL_EXT_memory_object_fd)."""
import ctypes, glob, os, sys, time
import numpy as np
import pyopencl as cl

vp, c_int, c_uint, c_u64, c_size = ctypes.c_void_p, ctypes.c_int, ctypes.c_uint, ctypes.c_uint64, ctypes.c_size_t
ocl = ctypes.CDLL(glob.glob(os.path.join(os.path.dirname(cl.__file__), ".libs", "libOpenCL*"))[0])
cuda = ctypes.CDLL("libcuda.so.1")

def ck(name, r):
    if r != 0:
        raise SystemExit(f"{name} -> {r}")

def nfds():
    return len(os.listdir("/proc/self/fd"))

# ---- CUDA: an exportable allocation
ck("cuInit", cuda.cuInit(0))
dev = c_int(); ck("cuDeviceGet", cuda.cuDeviceGet(ctypes.byref(dev), 0))
ctx = vp(); ck("cuDevicePrimaryCtxRetain", cuda.cuDevicePrimaryCtxRetain(ctypes.byref(ctx), dev))
ck("cuCtxSetCurrent", cuda.cuCtxSetCurrent(ctx))

class Location(ctypes.Structure):
    _fields_ = [("type", c_int), ("id", c_int)]
class AllocFlags(ctypes.Structure):
    _fields_ = [("compressionType", ctypes.c_ubyte), ("gpuDirectRDMACapable", ctypes.c_ubyte),
                ("usage", ctypes.c_ushort), ("reserved", ctypes.c_ubyte * 4)]
class Prop(ctypes.Structure):
    _fields_ = [("type", c_int), ("requestedHandleTypes", c_int), ("location", Location),
                ("win32HandleMetaData", vp), ("allocFlags", AllocFlags)]
class AccessDesc(ctypes.Structure):
    _fields_ = [("location", Location), ("flags", c_int)]

prop = Prop(type=1, requestedHandleTypes=1, location=Location(1, 0))
gran = c_size(); ck("granularity", cuda.cuMemGetAllocationGranularity(ctypes.byref(gran), ctypes.byref(prop), 0))
N = 3 << 20  # floats
size = -(-N * 4 // gran.value) * gran.value
print("granularity", gran.value, "size", size)
handle = c_u64(); ck("cuMemCreate", cuda.cuMemCreate(ctypes.byref(handle), c_size(size), ctypes.byref(prop), c_u64(0)))
fd = c_int(); ck("export", cuda.cuMemExportToShareableHandle(ctypes.byref(fd), handle, 1, c_u64(0)))
print("exported fd", fd.value)
ptr = c_u64(); ck("reserve", cuda.cuMemAddressReserve(ctypes.byref(ptr), c_size(size), c_size(0), c_u64(0), c_u64(0)))
ck("map", cuda.cuMemMap(ptr, c_size(size), c_size(0), handle, c_u64(0)))
access = AccessDesc(Location(1, 0), 3)
ck("access", cuda.cuMemSetAccess(ptr, c_size(size), ctypes.byref(access), c_size(1)))
ck("memset", cuda.cuMemsetD32_v2(ptr, c_uint(0x7fc00000), c_size(size // 4)))
ck("sync", cuda.cuCtxSynchronize())

# ---- OpenCL: import
platform = [p for p in cl.get_platforms() if "NVIDIA" in p.name][0]
device = platform.get_devices()[0]
context = cl.Context([device]); queue = cl.CommandQueue(context)
types = (c_uint * 8)(); got = c_size()
ocl.clGetDeviceInfo.argtypes = [vp, c_uint, c_size, vp, ctypes.POINTER(c_size)]
print("device import types", ocl.clGetDeviceInfo(device.int_ptr, 0x204F, ctypes.sizeof(types), types, ctypes.byref(got)),
      [hex(types[i]) for i in range(got.value // 4)])
ocl.clGetExtensionFunctionAddressForPlatform.restype = vp
ocl.clGetExtensionFunctionAddressForPlatform.argtypes = [vp, ctypes.c_char_p]
EnqFn = ctypes.CFUNCTYPE(c_int, vp, c_uint, ctypes.POINTER(vp), c_uint, vp, vp)
acquire = EnqFn(ocl.clGetExtensionFunctionAddressForPlatform(platform.int_ptr, b"clEnqueueAcquireExternalMemObjectsKHR"))
release = EnqFn(ocl.clGetExtensionFunctionAddressForPlatform(platform.int_ptr, b"clEnqueueReleaseExternalMemObjectsKHR"))
ocl.clCreateBufferWithProperties.restype = vp
ocl.clCreateBufferWithProperties.argtypes = [vp, ctypes.POINTER(c_u64), c_u64, c_size, vp, ctypes.POINTER(c_int)]
before = nfds()
cl_fd = os.dup(fd.value)
for label, props in (("with device list", [0x2060, cl_fd, 0x2051, device.int_ptr, 0, 0]), ("plain", [0x2060, cl_fd, 0])):
    err = c_int()
    mem = ocl.clCreateBufferWithProperties(context.int_ptr, (c_u64 * len(props))(*props), c_u64(1), c_size(size), None,
                                           ctypes.byref(err))
    print("clCreateBufferWithProperties", label, err.value, mem)
    if not err.value:
        break
print("fds open: before dup", before, "after import", nfds(), "(dup'd fd consumed?)", os.path.exists(f"/proc/self/fd/{cl_fd}"))
buffer = cl.Buffer.from_int_ptr(mem, retain=False)
mems = (vp * 1)(buffer.int_ptr)
prg = cl.Program(context, "__kernel void w(__global float *a, float s){ size_t i = get_global_id(0); a[i] = s * i; }").build()
for rep, s in enumerate((0.5, 0.25, 0.125)):
    t0 = time.perf_counter()
    a = acquire(queue.int_ptr, 1, mems, 0, None, None)
    prg.w(queue, (N,), None, buffer, np.float32(s))
    r = release(queue.int_ptr, 1, mems, 0, None, None)
    queue.finish()
    print("acquire", a, "release", r, "ms", round((time.perf_counter() - t0) * 1e3, 3))
host = np.empty(N, np.float32)
ck("dtoh", cuda.cuMemcpyDtoH_v2(host.ctypes.data_as(vp), ptr, c_size(N * 4)))
want = np.float32(0.125) * np.arange(N, dtype=np.float32)
print("CUDA sees", host[:3], host[-1], "OK" if np.array_equal(host, want) else "MISMATCH")
# pyopencl's own read of the imported buffer, and a copy into a plain CL buffer
back = np.empty(N, np.float32); cl.enqueue_copy(queue, back, buffer); print("CL reads", "OK" if np.array_equal(back, want) else "MISMATCH")

# ---- OpenGL (EGL, headless): import the same memory
egl = ctypes.CDLL("libEGL.so.1"); gl = ctypes.CDLL("libOpenGL.so.0")
egl.eglGetProcAddress.restype = vp; egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
egl.eglInitialize.argtypes = [vp, vp, vp]; egl.eglChooseConfig.argtypes = [vp, vp, vp, c_int, vp]
egl.eglCreateContext.restype = vp; egl.eglCreateContext.argtypes = [vp, vp, vp, vp]
egl.eglMakeCurrent.argtypes = [vp, vp, vp, vp]
def ints(*v): return (c_int * len(v))(*v)
query = ctypes.CFUNCTYPE(c_uint, c_int, ctypes.POINTER(vp), ctypes.POINTER(c_int))(egl.eglGetProcAddress(b"eglQueryDevicesEXT"))
platform_display = ctypes.CFUNCTYPE(vp, c_int, vp, vp)(egl.eglGetProcAddress(b"eglGetPlatformDisplayEXT"))
devices = (vp * 8)(); n = c_int(); query(8, devices, ctypes.byref(n))
d = platform_display(0x313F, devices[0], None); print("eglInitialize", egl.eglInitialize(d, None, None))
egl.eglBindAPI(0x30A2)
config = vp(); egl.eglChooseConfig(d, ints(0x3033, 0x0001, 0x3040, 0x0008, 0x3038), ctypes.byref(config), 1, ctypes.byref(n))
gctx = egl.eglCreateContext(d, config, None, ints(0x3098, 4, 0x30FB, 5, 0x3038))
print("make current (surfaceless)", egl.eglMakeCurrent(d, None, None, gctx))
gl.glGetStringi.restype = ctypes.c_char_p; gl.glGetStringi.argtypes = [c_uint, c_uint]
count = c_int(); gl.glGetIntegerv(0x821D, ctypes.byref(count))
exts = [gl.glGetStringi(0x1F03, i).decode() for i in range(count.value)]
print("GL memory object extensions", [e for e in exts if "memory_object" in e or "semaphore" in e])
def glf(name, *args): return ctypes.CFUNCTYPE(None, *args)(egl.eglGetProcAddress(name.encode()))
glCreateMemoryObjectsEXT = glf("glCreateMemoryObjectsEXT", c_int, ctypes.POINTER(c_uint))
glImportMemoryFdEXT = glf("glImportMemoryFdEXT", c_uint, c_u64, c_uint, c_int)
glCreateBuffers = glf("glCreateBuffers", c_int, ctypes.POINTER(c_uint))
glNamedBufferStorageMemEXT = glf("glNamedBufferStorageMemEXT", c_uint, ctypes.c_ssize_t, c_uint, c_u64)
glGetNamedBufferSubData = glf("glGetNamedBufferSubData", c_uint, ctypes.c_ssize_t, ctypes.c_ssize_t, vp)
gl.glGetError.restype = c_uint
memory_object = c_uint(); glCreateMemoryObjectsEXT(1, ctypes.byref(memory_object))
gl_fd = os.dup(fd.value)
glImportMemoryFdEXT(memory_object, c_u64(size), 0x9586, gl_fd)
print("import error", hex(gl.glGetError()), "gl fd still open", os.path.exists(f"/proc/self/fd/{gl_fd}"))
name = c_uint(); glCreateBuffers(1, ctypes.byref(name))
glNamedBufferStorageMemEXT(name, size, memory_object, c_u64(0))
print("storage error", hex(gl.glGetError()))
seen = np.zeros(N, np.float32)
glGetNamedBufferSubData(name, 0, N * 4, seen.ctypes.data_as(vp)); gl.glFinish()
print("GL sees", seen[:3], seen[-1], "OK" if np.array_equal(seen, want) else "MISMATCH", hex(gl.glGetError()))
# CL writes again, GL reads after the CL queue is finished (host sync)
kernel = cl.Kernel(prg, "w")
kernel.set_args(buffer, np.float32(2.0))
a = acquire(queue.int_ptr, 1, mems, 0, None, None); cl.enqueue_nd_range_kernel(queue, kernel, (N,), None)
r = release(queue.int_ptr, 1, mems, 0, None, None); queue.finish()
second = np.float32(2.0) * np.arange(N, dtype=np.float32)
back = np.empty(N, np.float32); cl.enqueue_copy(queue, back, buffer)
print("second write: acquire", a, "release", r, "CL reads", "OK" if np.array_equal(back, second) else "MISMATCH")
glGetNamedBufferSubData(name, 0, N * 4, seen.ctypes.data_as(vp))
print("GL sees the second write (host sync only)", "OK" if np.array_equal(seen, second) else "MISMATCH", seen[:3])

# ---- GPU-side reads by GL (a copy into a plain GL buffer), after host sync of each CL write
glCopyNamedBufferSubData = glf("glCopyNamedBufferSubData", c_uint, c_uint, ctypes.c_ssize_t, ctypes.c_ssize_t, ctypes.c_ssize_t)
glNamedBufferData = glf("glNamedBufferData", c_uint, ctypes.c_ssize_t, vp, c_uint)
plain = c_uint(); glCreateBuffers(1, ctypes.byref(plain)); glNamedBufferData(plain, N * 4, None, 0x88EA)
ok = 0
for k in range(3, 8):
    s = np.float32(k)
    kernel.set_args(buffer, s)
    acquire(queue.int_ptr, 1, mems, 0, None, None); cl.enqueue_nd_range_kernel(queue, kernel, (N,), None)
    release(queue.int_ptr, 1, mems, 0, None, None); queue.finish()
    glCopyNamedBufferSubData(name, plain, 0, 0, N * 4); gl.glFinish()
    glGetNamedBufferSubData(plain, 0, N * 4, seen.ctypes.data_as(vp))
    good = np.array_equal(seen, s * np.arange(N, dtype=np.float32)); ok += good
    print("round", k, "GL's GPU copy sees", "OK" if good else "MISMATCH", seen[:3], hex(gl.glGetError()))
print("GPU-side GL reads OK:", ok, "of 5")

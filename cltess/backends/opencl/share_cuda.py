"""A Session's output handed to CUDA without a copy (issue 15: hand buffers to other APIs):
``Session(scene, device="nvidia", share="cuda")``, then ``frame.cuda()``.

Each output buffer is memory that CUDA allocates and exports as an opaque file descriptor
(the driver API's virtual memory management: ``cuMemCreate`` with a POSIX file descriptor
handle, ``cuMemExportToShareableHandle``), imported into OpenCL by ``cl_khr_external_memory``
(``clCreateBufferWithProperties`` with ``CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR``) and mapped
to a CUDA device address.  Stages 4-5 write the imported buffers like any others; the
frame's arrays are then CUDA device arrays as they are (``__cuda_array_interface__``: CuPy,
PyTorch, Numba).  The direction is fixed by what the drivers offer: NVIDIA's OpenCL imports
external memory but exports none, and exports no semaphore (docs/design.md section 9, "Handing
the output to other APIs", for what was measured on which device).

Who holds the buffers: OpenCL from a frame's stages on (``clEnqueueAcquireExternalMemObjectsKHR``
when the buffers are taken, and before a read-back), CUDA once ``frame.cuda()`` has released
them (``clEnqueueReleaseExternalMemObjectsKHR``) and waited for the release: the frame's stages
are then done and their writes visible to CUDA.  The arrays are views of the session's
buffers, valid until the next ``tessellate`` call (as host arrays are: cltess.session); finish
CUDA's work on them (synchronise its stream) before that call.

Only ctypes and the drivers' own libraries (``libcuda.so.1``, the OpenCL loader pyopencl uses)
are needed; a device or driver without them gives ``SharingUnavailable`` when the Session is
made.
"""
from __future__ import annotations

import ctypes
import glob
import math
import os
import weakref

import numpy as np
import pyopencl as cl

from .output import OutputBuffers

# cl_khr_external_memory (cl_ext.h)
CL_DEVICE_EXTERNAL_MEMORY_IMPORT_HANDLE_TYPES_KHR = 0x204F
CL_DEVICE_HANDLE_LIST_KHR = 0x2051
CL_DEVICE_HANDLE_LIST_END_KHR = 0
CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR = 0x2060
CL_DEVICE_UUID_KHR = 0x106A  # cl_khr_device_uuid
CL_MEM_READ_WRITE = 1 << 0
# CUDA driver API (cuda.h)
CU_MEM_ALLOCATION_TYPE_PINNED = 1
CU_MEM_HANDLE_TYPE_POSIX_FILE_DESCRIPTOR = 1
CU_MEM_LOCATION_TYPE_DEVICE = 1
CU_MEM_ACCESS_FLAGS_PROT_READWRITE = 3
CU_MEM_ALLOC_GRANULARITY_MINIMUM = 0

#: The OpenCL device extensions sharing with CUDA needs.
NEEDED_EXTENSIONS = ("cl_khr_external_memory", "cl_khr_external_memory_opaque_fd", "cl_khr_device_uuid")


def sharing_apis(device) -> list[str]:
    """The APIs that ``Session(share=...)`` can hand this OpenCL device's output to, by its
    extensions alone ("cuda": NEEDED_EXTENSIONS; "gl" and "vulkan": those and
    handover.NEEDED_CL_EXTENSIONS, the semaphores).  The rest (libcuda, the Vulkan loader, a
    current GL context, the caller's Vulkan device) is checked when the Session is made."""
    from .handover import NEEDED_CL_EXTENSIONS

    extensions = set(device.extensions.split())
    if not extensions.issuperset(NEEDED_EXTENSIONS):
        return []
    return ["cuda", "gl", "vulkan"] if extensions.issuperset(NEEDED_CL_EXTENSIONS) else ["cuda"]


class SharingUnavailable(RuntimeError):
    """This device or machine cannot hand its output to the asked API without a copy."""


class _Location(ctypes.Structure):
    _fields_ = [("type", ctypes.c_int), ("id", ctypes.c_int)]


class _AllocationFlags(ctypes.Structure):
    _fields_ = [("compressionType", ctypes.c_ubyte), ("gpuDirectRDMACapable", ctypes.c_ubyte),
                ("usage", ctypes.c_ushort), ("reserved", ctypes.c_ubyte * 4)]


class _AllocationProperties(ctypes.Structure):  # CUmemAllocationProp
    _fields_ = [("type", ctypes.c_int), ("requestedHandleTypes", ctypes.c_int), ("location", _Location),
                ("win32HandleMetaData", ctypes.c_void_p), ("allocFlags", _AllocationFlags)]


class _AccessDescription(ctypes.Structure):  # CUmemAccessDesc
    _fields_ = [("location", _Location), ("flags", ctypes.c_int)]


def _opencl_loader() -> ctypes.CDLL:
    """The OpenCL ICD loader pyopencl itself links (a wheel's own copy, else the system's)."""
    wheel = sorted(glob.glob(os.path.join(os.path.dirname(cl.__file__), ".libs", "libOpenCL*")))
    for name in wheel + ["libOpenCL.so.1", "libOpenCL.so"]:
        try:
            return ctypes.CDLL(name)
        except OSError:
            continue
    raise SharingUnavailable("no OpenCL loader library found to call cl_khr_external_memory through")


class _Cuda:
    """The few CUDA driver API calls used here, on the primary context of one device."""

    def __init__(self, uuid: bytes):
        try:
            self.lib = ctypes.CDLL("libcuda.so.1")
        except OSError as error:
            raise SharingUnavailable(f"sharing with CUDA needs NVIDIA's driver library libcuda.so.1: {error}") from None
        self.call("cuInit", ctypes.c_uint(0))
        count = ctypes.c_int()
        self.call("cuDeviceGetCount", ctypes.byref(count))
        self.device = None
        for ordinal in range(count.value):
            device, found = ctypes.c_int(), (ctypes.c_char * 16)()
            self.call("cuDeviceGet", ctypes.byref(device), ctypes.c_int(ordinal))
            self.call("cuDeviceGetUuid", found, device)
            if bytes(found) == uuid:
                self.device = device.value
        if self.device is None:
            raise SharingUnavailable(f"no CUDA device has the OpenCL device's UUID {uuid.hex()}")
        self.context = ctypes.c_void_p()
        self.call("cuDevicePrimaryCtxRetain", ctypes.byref(self.context), ctypes.c_int(self.device))

    def call(self, name: str, *args) -> None:
        result = getattr(self.lib, name)(*args)
        if result:
            text = ctypes.c_char_p()
            self.lib.cuGetErrorName(result, ctypes.byref(text))
            raise RuntimeError(f"CUDA {name} failed: {(text.value or b'?').decode()} ({result})")

    def current(self, name: str, *args) -> None:
        """``call`` with the device's primary context current (pushed, then popped)."""
        self.call("cuCtxPushCurrent_v2", self.context)
        try:
            self.call(name, *args)
        finally:
            self.lib.cuCtxPopCurrent_v2(ctypes.byref(ctypes.c_void_p()))

    def properties(self) -> _AllocationProperties:
        return _AllocationProperties(type=CU_MEM_ALLOCATION_TYPE_PINNED,
                                     requestedHandleTypes=CU_MEM_HANDLE_TYPE_POSIX_FILE_DESCRIPTOR,
                                     location=_Location(CU_MEM_LOCATION_TYPE_DEVICE, self.device))

    def granularity(self) -> int:
        size = ctypes.c_size_t()
        self.call("cuMemGetAllocationGranularity", ctypes.byref(size), ctypes.byref(self.properties()),
                  ctypes.c_int(CU_MEM_ALLOC_GRANULARITY_MINIMUM))
        return size.value

    def copy_to_host(self, target: np.ndarray, pointer: int) -> None:
        self.current("cuMemcpyDtoH_v2", target.ctypes.data_as(ctypes.c_void_p), ctypes.c_uint64(pointer),
                     ctypes.c_size_t(target.nbytes))


class OpenCLExternalMemory:
    """cl_khr_external_memory on one OpenCL device: importing a file descriptor, and the
    acquire and release commands (extension functions of the device's platform)."""

    def __init__(self, context: cl.Context, device: cl.Device):
        missing = [name for name in NEEDED_EXTENSIONS if name not in device.extensions.split()]
        if missing:
            raise SharingUnavailable(f"{device.name.strip()} ({device.platform.name.strip()}): sharing with CUDA needs "
                                     f"the OpenCL extensions {', '.join(missing)}, which this device does not offer")
        self.context, self.device = context, device
        self.lib = lib = _opencl_loader()
        lib.clGetDeviceInfo.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_size_t, ctypes.c_void_p,
                                        ctypes.POINTER(ctypes.c_size_t)]
        types, size = (ctypes.c_uint * 16)(), ctypes.c_size_t()
        lib.clGetDeviceInfo(device.int_ptr, CL_DEVICE_EXTERNAL_MEMORY_IMPORT_HANDLE_TYPES_KHR, ctypes.sizeof(types),
                            types, ctypes.byref(size))
        if CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR not in list(types)[:size.value // 4]:
            raise SharingUnavailable(f"{device.name.strip()}: imports no opaque file descriptors")
        uuid = (ctypes.c_ubyte * 16)()
        lib.clGetDeviceInfo(device.int_ptr, CL_DEVICE_UUID_KHR, 16, uuid, None)
        self.uuid = bytes(uuid)
        lib.clCreateBufferWithProperties.restype = ctypes.c_void_p
        lib.clCreateBufferWithProperties.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint64),
                                                     ctypes.c_uint64, ctypes.c_size_t, ctypes.c_void_p,
                                                     ctypes.POINTER(ctypes.c_int)]
        lib.clGetExtensionFunctionAddressForPlatform.restype = ctypes.c_void_p
        lib.clGetExtensionFunctionAddressForPlatform.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
        enqueue = (ctypes.c_int, ctypes.c_void_p, ctypes.c_uint, ctypes.POINTER(ctypes.c_void_p), ctypes.c_uint,
                   ctypes.c_void_p, ctypes.POINTER(ctypes.c_void_p))
        self._enqueue = {command: self.extension_function(f"clEnqueue{command}ExternalMemObjectsKHR", *enqueue)
                         for command in ("Acquire", "Release")}

    def extension_function(self, name: str, restype, *argtypes):
        """The device's platform's extension function ``name``, typed."""
        address = self.lib.clGetExtensionFunctionAddressForPlatform(self.device.platform.int_ptr, name.encode())
        if not address:
            raise SharingUnavailable(f"{self.device.platform.name.strip()}: no {name}")
        return ctypes.CFUNCTYPE(restype, *argtypes)(address)

    def import_fd(self, fd: int, nbytes: int) -> cl.Buffer:
        """An OpenCL buffer on the memory behind ``fd``, which OpenCL then owns: NVIDIA's
        closes it when the buffer is released (driver 580: closing it again after the release
        failed with EBADF).  If the import fails, the fd is still the caller's."""
        properties = (ctypes.c_uint64 * 6)(CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR, fd, CL_DEVICE_HANDLE_LIST_KHR,
                                           self.device.int_ptr, CL_DEVICE_HANDLE_LIST_END_KHR, 0)
        error = ctypes.c_int()
        memory = self.lib.clCreateBufferWithProperties(self.context.int_ptr, properties, CL_MEM_READ_WRITE, nbytes,
                                                       None, ctypes.byref(error))
        if error.value or not memory:
            raise RuntimeError(f"clCreateBufferWithProperties (an opaque fd of {nbytes} bytes) failed: {error.value}")
        return cl.Buffer.from_int_ptr(memory, retain=False)

    def enqueue(self, command: str, queue: cl.CommandQueue, buffers) -> cl.Event:
        """Enqueue ``command`` ("Acquire" or "Release") of these buffers; its event."""
        handles = (ctypes.c_void_p * len(buffers))(*(buffer.int_ptr for buffer in buffers))
        event = ctypes.c_void_p()
        result = self._enqueue[command](queue.int_ptr, len(buffers), handles, 0, None, ctypes.byref(event))
        if result:
            raise RuntimeError(f"clEnqueue{command}ExternalMemObjectsKHR failed: {result}")
        return cl.Event.from_int_ptr(event.value, retain=False)


def _free_cuda_memory(cuda: _Cuda, handle: int, pointer: int, nbytes: int) -> None:
    """Unmap, unreserve and release what SharedAllocation made (pointer 0: not reserved yet)."""
    if pointer:
        cuda.current("cuMemUnmap", ctypes.c_uint64(pointer), ctypes.c_size_t(nbytes))
        cuda.call("cuMemAddressFree", ctypes.c_uint64(pointer), ctypes.c_size_t(nbytes))
    cuda.call("cuMemRelease", ctypes.c_uint64(handle))


def _free_allocation(cuda: _Cuda, queue: cl.CommandQueue, buffer: cl.Buffer, handle: int, pointer: int,
                     nbytes: int) -> None:
    """A SharedAllocation's end: nothing queued may still use it; OpenCL's buffer goes first
    (and with it the exported fd: import_fd)."""
    try:
        queue.finish()
        buffer.release()
    except cl.Error:  # (the context is gone at interpreter exit: nothing is queued then)
        pass
    _free_cuda_memory(cuda, handle, pointer, nbytes)


class SharedAllocation:
    """Device memory that CUDA allocated and exported (an opaque fd, handed to OpenCL),
    imported into OpenCL (``buffer``) and mapped at CUDA device address ``pointer``; freed
    when the last reference goes (the output buffers drop it when they grow; a frame's CUDA
    arrays keep it)."""

    def __init__(self, cuda: _Cuda, opencl: OpenCLExternalMemory, queue: cl.CommandQueue, nbytes: int):
        granularity = cuda.granularity()
        self.nbytes = -(-max(nbytes, 1) // granularity) * granularity
        self.cuda = cuda
        properties, handle = cuda.properties(), ctypes.c_uint64()
        cuda.current("cuMemCreate", ctypes.byref(handle), ctypes.c_size_t(self.nbytes), ctypes.byref(properties),
                     ctypes.c_uint64(0))
        fd, pointer = ctypes.c_int(-1), ctypes.c_uint64()
        try:
            cuda.call("cuMemExportToShareableHandle", ctypes.byref(fd), handle,
                      ctypes.c_int(CU_MEM_HANDLE_TYPE_POSIX_FILE_DESCRIPTOR), ctypes.c_uint64(0))
            cuda.call("cuMemAddressReserve", ctypes.byref(pointer), ctypes.c_size_t(self.nbytes), ctypes.c_size_t(0),
                      ctypes.c_uint64(0), ctypes.c_uint64(0))
            cuda.current("cuMemMap", pointer, ctypes.c_size_t(self.nbytes), ctypes.c_size_t(0), handle,
                         ctypes.c_uint64(0))
            access = _AccessDescription(_Location(CU_MEM_LOCATION_TYPE_DEVICE, cuda.device),
                                        CU_MEM_ACCESS_FLAGS_PROT_READWRITE)
            cuda.current("cuMemSetAccess", pointer, ctypes.c_size_t(self.nbytes), ctypes.byref(access),
                         ctypes.c_size_t(1))
            self.buffer = opencl.import_fd(fd.value, self.nbytes)
        except Exception:
            try:
                _free_cuda_memory(cuda, handle.value, pointer.value, self.nbytes)
            except RuntimeError:  # (the first failure is the one to report)
                pass
            if fd.value >= 0:
                os.close(fd.value)
            raise
        self.pointer, self.handle = pointer.value, handle.value
        weakref.finalize(self, _free_allocation, cuda, queue, self.buffer, handle.value, self.pointer, self.nbytes)

    def export_fd(self) -> int:
        """A new file descriptor of this memory, for another importer (it takes it over)."""
        fd = ctypes.c_int(-1)
        self.cuda.call("cuMemExportToShareableHandle", ctypes.byref(fd), ctypes.c_uint64(self.handle),
                       ctypes.c_int(CU_MEM_HANDLE_TYPE_POSIX_FILE_DESCRIPTOR), ctypes.c_uint64(0))
        return fd.value


class CudaArray:
    """One output field as a CUDA device array, no copy: ``__cuda_array_interface__`` (version
    3), so that ``cupy.asarray(a)``, ``torch.as_tensor(a, device="cuda")`` or
    ``numba.cuda.as_cuda_array(a)`` view it.  ``get()`` copies it to a NumPy array."""

    def __init__(self, allocation: SharedAllocation, shape: tuple, dtype):
        self.allocation, self.shape, self.dtype = allocation, shape, np.dtype(dtype)

    @property
    def pointer(self) -> int:
        return self.allocation.pointer

    @property
    def nbytes(self) -> int:
        return math.prod(self.shape) * self.dtype.itemsize

    @property
    def __cuda_array_interface__(self) -> dict:
        # stream None: no synchronisation needed (frame.cuda() waited for the writes)
        return {"shape": self.shape, "typestr": self.dtype.str, "data": (self.pointer, False), "version": 3,
                "strides": None, "stream": None}

    def get(self) -> np.ndarray:
        host = np.empty(self.shape, self.dtype)
        if host.nbytes:
            self.allocation.cuda.copy_to_host(host, self.pointer)
        return host

    def __repr__(self) -> str:
        return f"CudaArray(shape={self.shape}, dtype={self.dtype}, pointer={self.pointer:#x})"


class SharedFields(dict):
    """A frame's output handed to another API: field name -> what that API holds it as, also
    as attributes (``.positions``)."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


class SharedBuffer:
    """One output field as a buffer of another API (a subclass adds that API's handles):
    ``rows`` rows of ``components`` values of ``dtype``, tightly packed from byte 0 (positions: 3
    float32, a 12-byte stride; triangles: 3 uint32 a row)."""

    def __init__(self, rows: int, shape: tuple, dtype):
        self.rows, self.dtype = rows, np.dtype(dtype)
        self.components = int(np.prod(shape)) if shape else 1

    @property
    def nbytes(self) -> int:
        return self.rows * self.components * self.dtype.itemsize


class CudaArrays(SharedFields):
    """A frame's output as ``CudaArray``s."""


class CudaOutputBuffers(OutputBuffers):
    """OutputBuffers whose buffers are ``SharedAllocation``s (the module's notes)."""

    shares = "cuda"

    def __init__(self, tessellator, pinned: bool = False):
        super().__init__(tessellator, pinned)
        self.opencl = OpenCLExternalMemory(self.context, tessellator.device)
        self.cuda = _Cuda(self.opencl.uuid)
        self.mapped = False  # (a CPU device shares nothing here: OpenCLExternalMemory refused it)
        self._allocations: dict = {}  # name -> SharedAllocation
        self._held = False  # whether OpenCL holds the buffers (acquired, not released)

    def _new_buffer(self, name: str, nbytes: int) -> cl.Buffer:
        self._allocations.pop(name, None)  # (take let go and finished before growing)
        allocation = self._allocations[name] = SharedAllocation(self.cuda, self.opencl, self.queue, nbytes)
        return allocation.buffer

    def _field_list(self) -> list:
        return [self._buffers[name][0] for name, _, _ in self._layout()]

    def _reclaim(self) -> None:
        """Take the buffers back from the API they were handed to: nothing here, frame.cuda()
        waited for the release (share_gl's GL has to signal first)."""

    def _hold(self) -> None:
        self._reclaim()
        if not self._held and self._buffers:
            self.opencl.enqueue("Acquire", self.queue, self._field_list())
            self._held = True

    def _let_go(self) -> cl.Event | None:
        if not self._held:
            return None
        self._held = False
        return self.opencl.enqueue("Release", self.queue, self._field_list())

    def take(self, num_vertices: int, num_triangles: int):
        vertices, triangles = self._capacity
        if self._buffers and (num_vertices > vertices or num_triangles > triangles):
            self._reclaim()
            self._let_go()
            self.queue.finish()  # nothing queued uses a buffer that growing replaces
        arrays = super().take(num_vertices, num_triangles)
        self._hold()
        return arrays

    def _enqueue_copies(self, num_vertices: int, num_triangles: int):
        self._hold()  # (after frame.cuda() handed them over)
        return super()._enqueue_copies(num_vertices, num_triangles)

    def close(self) -> None:
        self._let_go()
        self.queue.finish()
        self._allocations.clear()  # (freed once no frame's arrays hold them)
        super().close()

    def share(self, num_vertices: int, num_triangles: int) -> CudaArrays:
        """The current output (this many vertices and triangles) handed to CUDA: the buffers
        released by OpenCL, the release waited for (so every command before it, the frame's
        stages among them, is done)."""
        released = self._let_go()
        if released is not None:
            released.wait()
        return self._shared_fields(CudaArrays(), num_vertices, num_triangles,
                                   lambda name, rows, shape, dtype: CudaArray(self._allocations[name], (rows, *shape),
                                                                              dtype))

    def _shared_fields(self, fields: SharedFields, num_vertices: int, num_triangles: int, make) -> SharedFields:
        """``fields`` filled with ``make(name, rows, shape, dtype)`` of each output field, rows
        being the frame's vertices or triangles."""
        for name, dtype, shape in self._layout():
            fields[name] = make(name, num_triangles if name == "triangles" else num_vertices, shape, dtype)
        return fields


__all__ = ["CudaArray", "CudaArrays", "CudaOutputBuffers", "SharedBuffer", "SharedFields", "SharingUnavailable",
           "sharing_apis"]

"""The few Vulkan 1.1 calls that sharing needs, over ctypes and the Vulkan loader
(``libvulkan.so.1``): a device on a given GPU (``VulkanDevice``, matched by UUID), binary
semaphores exportable as opaque fds, and the structures of buffers on imported memory and of
queue submissions (handover.py makes a device for the semaphores; share_vulkan.py works in the
caller's device).  Every handle is typed: an untyped Python int passes as a 32-bit int, a
truncated pointer (a physical-device handle passed so crashed ``vkCreateDevice`` on the H200;
bench/RESULTS.md, "Session 17, lead")."""
from __future__ import annotations

import ctypes
import os

from .share_cuda import SharingUnavailable

_u32, _u64, _ptr = ctypes.c_uint32, ctypes.c_uint64, ctypes.c_void_p

# vulkan_core.h
VK_API_VERSION_1_1 = (1 << 22) | (1 << 12)
VK_STRUCTURE_TYPE_APPLICATION_INFO = 0
VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO = 1
VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO = 2
VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO = 3
VK_STRUCTURE_TYPE_SUBMIT_INFO = 4
VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO = 5
VK_STRUCTURE_TYPE_FENCE_CREATE_INFO = 8
VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO = 9
VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO = 12
VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO = 39
VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO = 40
VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO = 42
VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER = 44
VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2 = 1000059001
VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES = 1000071004
VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO = 1000072000
VK_STRUCTURE_TYPE_IMPORT_MEMORY_FD_INFO_KHR = 1000074000
VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO = 1000077000
VK_STRUCTURE_TYPE_IMPORT_SEMAPHORE_FD_INFO_KHR = 1000079000
VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR = 1000079001
VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT = 0x1
VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT = 0x1
VK_BUFFER_USAGE_TRANSFER_SRC_BIT, VK_BUFFER_USAGE_TRANSFER_DST_BIT = 0x1, 0x2
VK_BUFFER_USAGE_STORAGE_BUFFER_BIT = 0x20
VK_BUFFER_USAGE_INDEX_BUFFER_BIT, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT = 0x40, 0x80
VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT = 0x1, 0x2
VK_MEMORY_PROPERTY_HOST_COHERENT_BIT = 0x4
VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT = 0x1
VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT = 0x2000, 0x10000
VK_ACCESS_MEMORY_READ_BIT, VK_ACCESS_MEMORY_WRITE_BIT = 0x8000, 0x10000
VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT, VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT = 0x1, 0x4
VK_QUEUE_FAMILY_EXTERNAL = 0xFFFFFFFE  # (~1U)
VK_WHOLE_SIZE = 0xFFFFFFFFFFFFFFFF
VK_QUEUE_GRAPHICS_BIT, VK_QUEUE_COMPUTE_BIT, VK_QUEUE_TRANSFER_BIT = 0x1, 0x2, 0x4

#: The device extensions share="vulkan" needs in the caller's device, each with a function of its
#: own, found only where it was enabled (``check_extensions``).
NEEDED_VK_EXTENSIONS = ("VK_KHR_external_memory_fd", "VK_KHR_external_semaphore_fd")
EXTENSION_FUNCTIONS = {"VK_KHR_external_memory_fd": "vkGetMemoryFdKHR",
                       "VK_KHR_external_semaphore_fd": "vkImportSemaphoreFdKHR"}


class ApplicationInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("pApplicationName", ctypes.c_char_p), ("applicationVersion", _u32),
                ("pEngineName", ctypes.c_char_p), ("engineVersion", _u32), ("apiVersion", _u32)]


class InstanceCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("flags", _u32), ("pApplicationInfo", _ptr),
                ("enabledLayerCount", _u32), ("ppEnabledLayerNames", _ptr), ("enabledExtensionCount", _u32),
                ("ppEnabledExtensionNames", _ptr)]


class PhysicalDeviceIDProperties(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("deviceUUID", ctypes.c_ubyte * 16),
                ("driverUUID", ctypes.c_ubyte * 16), ("deviceLUID", ctypes.c_ubyte * 8), ("deviceNodeMask", _u32),
                ("deviceLUIDValid", _u32)]


class PhysicalDeviceProperties2(ctypes.Structure):  # the properties themselves as room enough (824 bytes in 1.1)
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("properties", ctypes.c_ubyte * 2048)]


class QueueFamilyProperties(ctypes.Structure):
    _fields_ = [("queueFlags", _u32), ("queueCount", _u32), ("timestampValidBits", _u32),
                ("minImageTransferGranularity", _u32 * 3)]


class DeviceQueueCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("flags", _u32), ("queueFamilyIndex", _u32), ("queueCount", _u32),
                ("pQueuePriorities", ctypes.POINTER(ctypes.c_float))]


class DeviceCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("flags", _u32), ("queueCreateInfoCount", _u32),
                ("pQueueCreateInfos", _ptr), ("enabledLayerCount", _u32), ("ppEnabledLayerNames", _ptr),
                ("enabledExtensionCount", _u32), ("ppEnabledExtensionNames", _ptr), ("pEnabledFeatures", _ptr)]


class ExportSemaphoreCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("handleTypes", _u32)]


class SemaphoreCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("flags", _u32)]


class SemaphoreGetFdInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("semaphore", _u64), ("handleType", _u32)]


class ImportSemaphoreFdInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("semaphore", _u64), ("flags", _u32), ("handleType", _u32),
                ("fd", ctypes.c_int)]


class ExternalMemoryBufferCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("handleTypes", _u32)]


class BufferCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("flags", _u32), ("size", _u64), ("usage", _u32),
                ("sharingMode", _u32), ("queueFamilyIndexCount", _u32), ("pQueueFamilyIndices", _ptr)]


class MemoryRequirements(ctypes.Structure):
    _fields_ = [("size", _u64), ("alignment", _u64), ("memoryTypeBits", _u32)]


class MemoryType(ctypes.Structure):
    _fields_ = [("propertyFlags", _u32), ("heapIndex", _u32)]


class MemoryHeap(ctypes.Structure):
    _fields_ = [("size", _u64), ("flags", _u32)]


class PhysicalDeviceMemoryProperties(ctypes.Structure):
    _fields_ = [("memoryTypeCount", _u32), ("memoryTypes", MemoryType * 32), ("memoryHeapCount", _u32),
                ("memoryHeaps", MemoryHeap * 16)]


class ImportMemoryFdInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("handleType", _u32), ("fd", ctypes.c_int)]


class MemoryAllocateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("allocationSize", _u64), ("memoryTypeIndex", _u32)]


class CommandPoolCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("flags", _u32), ("queueFamilyIndex", _u32)]


class CommandBufferAllocateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("commandPool", _u64), ("level", _u32),
                ("commandBufferCount", _u32)]


class CommandBufferBeginInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("flags", _u32), ("pInheritanceInfo", _ptr)]


class BufferMemoryBarrier(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("srcAccessMask", _u32), ("dstAccessMask", _u32),
                ("srcQueueFamilyIndex", _u32), ("dstQueueFamilyIndex", _u32), ("buffer", _u64), ("offset", _u64),
                ("size", _u64)]


class SubmitInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("waitSemaphoreCount", _u32), ("pWaitSemaphores", _ptr),
                ("pWaitDstStageMask", _ptr), ("commandBufferCount", _u32), ("pCommandBuffers", _ptr),
                ("signalSemaphoreCount", _u32), ("pSignalSemaphores", _ptr)]


class FenceCreateInfo(ctypes.Structure):
    _fields_ = [("sType", _u32), ("pNext", _ptr), ("flags", _u32)]


class BufferCopy(ctypes.Structure):
    _fields_ = [("srcOffset", _u64), ("dstOffset", _u64), ("size", _u64)]


def memory_type(vk: ctypes.CDLL, physical_device, allowed: int, preferred: int = 0, required: int = 0) -> int:
    """The first memory type of ``physical_device`` among the ``allowed`` bits (a buffer's
    memoryTypeBits) that has the ``required`` property flags, one with the ``preferred`` flags too
    if there is one."""
    properties = PhysicalDeviceMemoryProperties()
    vk.vkGetPhysicalDeviceMemoryProperties(physical_device, ctypes.byref(properties))
    fitting = [k for k in range(properties.memoryTypeCount) if allowed >> k & 1
               and properties.memoryTypes[k].propertyFlags & required == required]
    if not fitting:
        raise RuntimeError("no Vulkan memory type can hold the buffer")
    return next((k for k in fitting if properties.memoryTypes[k].propertyFlags & preferred == preferred), fitting[0])


def pointer_to(structure) -> _ptr:
    """A structure's address, for a pNext or an array field."""
    return ctypes.cast(ctypes.pointer(structure), _ptr)


#: The loader's functions used here: name -> (restype, argtypes).  Handles of dispatchable
#: objects (instance, physical device, device, queue, command buffer) are pointers, the others
#: 64-bit integers.
FUNCTIONS = {
    "vkCreateInstance": (ctypes.c_int, [_ptr, _ptr, ctypes.POINTER(_ptr)]),
    "vkDestroyInstance": (None, [_ptr, _ptr]),
    "vkEnumeratePhysicalDevices": (ctypes.c_int, [_ptr, ctypes.POINTER(_u32), _ptr]),
    "vkGetPhysicalDeviceProperties2": (None, [_ptr, _ptr]),
    "vkGetPhysicalDeviceQueueFamilyProperties": (None, [_ptr, ctypes.POINTER(_u32), _ptr]),
    "vkGetPhysicalDeviceMemoryProperties": (None, [_ptr, _ptr]),
    "vkCreateDevice": (ctypes.c_int, [_ptr, _ptr, _ptr, ctypes.POINTER(_ptr)]),
    "vkDestroyDevice": (None, [_ptr, _ptr]),
    "vkGetDeviceQueue": (None, [_ptr, _u32, _u32, ctypes.POINTER(_ptr)]),
    "vkGetDeviceProcAddr": (_ptr, [_ptr, ctypes.c_char_p]),
    "vkCreateSemaphore": (ctypes.c_int, [_ptr, _ptr, _ptr, ctypes.POINTER(_u64)]),
    "vkDestroySemaphore": (None, [_ptr, _u64, _ptr]),
    "vkCreateBuffer": (ctypes.c_int, [_ptr, _ptr, _ptr, ctypes.POINTER(_u64)]),
    "vkDestroyBuffer": (None, [_ptr, _u64, _ptr]),
    "vkGetBufferMemoryRequirements": (None, [_ptr, _u64, _ptr]),
    "vkAllocateMemory": (ctypes.c_int, [_ptr, _ptr, _ptr, ctypes.POINTER(_u64)]),
    "vkFreeMemory": (None, [_ptr, _u64, _ptr]),
    "vkBindBufferMemory": (ctypes.c_int, [_ptr, _u64, _u64, _u64]),
    "vkMapMemory": (ctypes.c_int, [_ptr, _u64, _u64, _u64, _u32, ctypes.POINTER(_ptr)]),
    "vkUnmapMemory": (None, [_ptr, _u64]),
    "vkCreateCommandPool": (ctypes.c_int, [_ptr, _ptr, _ptr, ctypes.POINTER(_u64)]),
    "vkDestroyCommandPool": (None, [_ptr, _u64, _ptr]),
    "vkAllocateCommandBuffers": (ctypes.c_int, [_ptr, _ptr, ctypes.POINTER(_ptr)]),
    "vkFreeCommandBuffers": (None, [_ptr, _u64, _u32, ctypes.POINTER(_ptr)]),
    "vkBeginCommandBuffer": (ctypes.c_int, [_ptr, _ptr]),
    "vkEndCommandBuffer": (ctypes.c_int, [_ptr]),
    "vkCmdPipelineBarrier": (None, [_ptr, _u32, _u32, _u32, _u32, _ptr, _u32, _ptr, _u32, _ptr]),
    "vkCmdCopyBuffer": (None, [_ptr, _u64, _u64, _u32, _ptr]),
    "vkQueueSubmit": (ctypes.c_int, [_ptr, _u32, _ptr, _u64]),
    "vkQueueWaitIdle": (ctypes.c_int, [_ptr]),
    "vkCreateFence": (ctypes.c_int, [_ptr, _ptr, _ptr, ctypes.POINTER(_u64)]),
    "vkDestroyFence": (None, [_ptr, _u64, _ptr]),
    "vkWaitForFences": (ctypes.c_int, [_ptr, _u32, ctypes.POINTER(_u64), _u32, _u64]),
    "vkResetFences": (ctypes.c_int, [_ptr, _u32, ctypes.POINTER(_u64)]),
}

_loaded: list = []


def loader(api: str) -> ctypes.CDLL:
    """The Vulkan loader with FUNCTIONS typed (loaded once); SharingUnavailable naming ``api``
    (the share= that needs it) where there is none."""
    if not _loaded:
        try:
            vk = ctypes.CDLL("libvulkan.so.1")
        except OSError as error:
            raise SharingUnavailable(f"share=\"{api}\" needs the Vulkan loader libvulkan.so.1: {error}") from None
        for name, (restype, argtypes) in FUNCTIONS.items():
            function = getattr(vk, name)
            function.restype, function.argtypes = restype, argtypes
        _loaded.append(vk)
    return _loaded[0]


def check(name: str, result: int) -> None:
    if result:
        raise RuntimeError(f"Vulkan {name} failed: {result}")


def device_uuid(vk: ctypes.CDLL, physical_device) -> bytes:
    """The deviceUUID of a physical device (VkPhysicalDeviceIDProperties)."""
    ids = PhysicalDeviceIDProperties(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES, None)
    wanted = PhysicalDeviceProperties2(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, pointer_to(ids))
    vk.vkGetPhysicalDeviceProperties2(physical_device, ctypes.byref(wanted))
    return bytes(ids.deviceUUID)


def check_extensions(vk: ctypes.CDLL, device, extensions=NEEDED_VK_EXTENSIONS) -> None:
    """SharingUnavailable naming the extensions that ``device`` was made without (a device-level
    function of an extension not enabled has no address)."""
    missing = [name for name in extensions if not vk.vkGetDeviceProcAddr(device, EXTENSION_FUNCTIONS[name].encode())]
    if missing:
        raise SharingUnavailable(f"the Vulkan device was made without {', '.join(missing)}, which sharing needs")


def device_function(vk: ctypes.CDLL, device, name: str, restype, *argtypes):
    """A device-level extension function of ``device``, typed."""
    address = vk.vkGetDeviceProcAddr(device, name.encode())
    if not address:
        raise SharingUnavailable(f"the Vulkan device has no {name} (made without "
                                 f"{', '.join(NEEDED_VK_EXTENSIONS)}?)")
    return ctypes.CFUNCTYPE(restype, *argtypes)(address)


class VulkanDevice:
    """A Vulkan 1.1 instance and device on the GPU with this UUID, with ``extensions`` and one
    queue of the first family that can transfer (``family``, ``queue``).  handover.py makes one
    for the semaphores; the tests make one to play a renderer's."""

    def __init__(self, uuid: bytes, extensions=NEEDED_VK_EXTENSIONS, api: str = "gl"):
        vk = self.vk = loader(api)
        application = ApplicationInfo(VK_STRUCTURE_TYPE_APPLICATION_INFO, None, b"cltess", 1, b"cltess", 1,
                                      VK_API_VERSION_1_1)
        create = InstanceCreateInfo(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, None, 0, pointer_to(application), 0, None,
                                    0, None)
        self.instance = _ptr()
        check("vkCreateInstance", vk.vkCreateInstance(ctypes.byref(create), None, ctypes.byref(self.instance)))
        count = _u32()
        vk.vkEnumeratePhysicalDevices(self.instance, ctypes.byref(count), None)
        physical = (_ptr * count.value)()
        vk.vkEnumeratePhysicalDevices(self.instance, ctypes.byref(count), physical)
        chosen = [device for device in physical if device_uuid(vk, device) == uuid]
        if not chosen:
            self.close()
            raise SharingUnavailable(f"no Vulkan device has the OpenCL device's UUID {uuid.hex()}")
        self.physical_device = _ptr(chosen[0])
        families = _u32()
        vk.vkGetPhysicalDeviceQueueFamilyProperties(self.physical_device, ctypes.byref(families), None)
        properties = (QueueFamilyProperties * families.value)()
        vk.vkGetPhysicalDeviceQueueFamilyProperties(self.physical_device, ctypes.byref(families), properties)
        working = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT | VK_QUEUE_TRANSFER_BIT  # (any of them can transfer)
        self.family = next(k for k, family in enumerate(properties) if family.queueFlags & working)
        priority = ctypes.c_float(1.0)
        queue = DeviceQueueCreateInfo(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, None, 0, self.family, 1,
                                      ctypes.pointer(priority))
        names = (ctypes.c_char_p * len(extensions))(*(name.encode() for name in extensions))
        device_info = DeviceCreateInfo(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, None, 0, 1, pointer_to(queue), 0, None,
                                       len(extensions), ctypes.cast(names, _ptr), None)
        self.device = _ptr()
        check("vkCreateDevice", vk.vkCreateDevice(self.physical_device, ctypes.byref(device_info), None,
                                                  ctypes.byref(self.device)))
        self.queue = _ptr()
        vk.vkGetDeviceQueue(self.device, self.family, 0, ctypes.byref(self.queue))

    def close(self) -> None:
        """Destroy the device and the instance (never for handover.py's: see there)."""
        if getattr(self, "device", None):
            self.vk.vkDestroyDevice(self.device, None)
            self.device = None
        if self.instance:
            self.vk.vkDestroyInstance(self.instance, None)
            self.instance = None


class ExportableSemaphores:
    """Binary semaphores of one device whose payload can be exported as opaque fds
    (VK_KHR_external_semaphore_fd)."""

    def __init__(self, vk: ctypes.CDLL, device):
        self.vk, self.device = vk, device
        self._get_fd = device_function(vk, device, "vkGetSemaphoreFdKHR", ctypes.c_int, _ptr, _ptr,
                                       ctypes.POINTER(ctypes.c_int))

    def make(self) -> int:
        export = ExportSemaphoreCreateInfo(VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO, None,
                                           VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT)
        create = SemaphoreCreateInfo(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, pointer_to(export), 0)
        semaphore = _u64()
        check("vkCreateSemaphore", self.vk.vkCreateSemaphore(self.device, ctypes.byref(create), None,
                                                             ctypes.byref(semaphore)))
        return semaphore.value

    def fd(self, semaphore: int) -> int:
        """A new opaque fd of ``semaphore`` (each importer takes one over)."""
        info = SemaphoreGetFdInfo(VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR, None, semaphore,
                                  VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT)
        fd = ctypes.c_int(-1)
        check("vkGetSemaphoreFdKHR", self._get_fd(self.device, ctypes.byref(info), ctypes.byref(fd)))
        return fd.value


def imported_semaphore(vk: ctypes.CDLL, device, fd: int) -> int:
    """A binary semaphore of ``device`` on the payload behind opaque fd ``fd`` (a permanent
    import, VK_KHR_external_semaphore_fd; the device takes the fd over when it succeeds)."""
    create = SemaphoreCreateInfo(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, None, 0)
    semaphore = _u64()
    check("vkCreateSemaphore", vk.vkCreateSemaphore(device, ctypes.byref(create), None, ctypes.byref(semaphore)))
    import_fd = device_function(vk, device, "vkImportSemaphoreFdKHR", ctypes.c_int, _ptr, _ptr)
    info = ImportSemaphoreFdInfo(VK_STRUCTURE_TYPE_IMPORT_SEMAPHORE_FD_INFO_KHR, None, semaphore.value, 0,
                                 VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT, fd)
    result = import_fd(device, ctypes.byref(info))
    if result:  # (the fd is still ours)
        os.close(fd)
        vk.vkDestroySemaphore(device, semaphore, None)
        raise RuntimeError(f"Vulkan vkImportSemaphoreFdKHR failed: {result}")
    return semaphore.value


def submit(vk: ctypes.CDLL, queue, wait: int | None = None, signal: int | None = None,
           command_buffer=None, fence: int = 0) -> None:
    """One batch on ``queue``: a wait (at every stage) on semaphore ``wait``, a command buffer,
    a signal of ``signal``; each optional."""
    waits, stages = (_u64 * 1)(wait or 0), (_u32 * 1)(VK_PIPELINE_STAGE_ALL_COMMANDS_BIT)
    signals, commands = (_u64 * 1)(signal or 0), (_ptr * 1)(command_buffer)
    info = SubmitInfo(VK_STRUCTURE_TYPE_SUBMIT_INFO, None, int(wait is not None), ctypes.cast(waits, _ptr),
                      ctypes.cast(stages, _ptr), int(command_buffer is not None), ctypes.cast(commands, _ptr),
                      int(signal is not None), ctypes.cast(signals, _ptr))
    check("vkQueueSubmit", vk.vkQueueSubmit(queue, 1, ctypes.byref(info), _u64(fence)))

"""Which Vulkan teardown call leaves no EGL context current? (session 17)"""
import ctypes, sys
sys.path.insert(0, "tests")
from support.egl import HeadlessGL
from cltess.backends.opencl.share_gl import _VulkanSemaphores
import pyopencl as cl
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory
gl = HeadlessGL()
current = lambda: gl.egl.eglGetCurrentContext()
gl.egl.eglGetCurrentContext.restype = ctypes.c_void_p
print("current after making", current() == gl.context)
device = [d for p in cl.get_platforms() for d in p.get_devices() if "NVIDIA" in p.name][0]
ocl = OpenCLExternalMemory(cl.Context([device]), device)
vk = _VulkanSemaphores(ocl.uuid)
print("after vkCreateInstance/Device", current() == gl.context)
s = vk.semaphore(); fd = vk.fd(s)
print("after a semaphore and its fd", current() == gl.context)
vk.destroy(s)
print("after vkDestroySemaphore", current() == gl.context)
vk.vk.vkDestroyDevice(vk.device, None); vk.device = None
print("after vkDestroyDevice", current() == gl.context)
vk.vk.vkDestroyInstance(vk.instance, None); vk.instance = None
print("after vkDestroyInstance", current() == gl.context)

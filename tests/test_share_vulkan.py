"""A Session's output handed to the caller's Vulkan device without a copy
(``Session(share="vulkan", vulkan=VulkanQueue(...))``, ``frame.vulkan()``;
cltess/backends/opencl/share_vulkan.py; issue 15): without a VulkanQueue, on an OpenCL device
that cannot share, or with a Vulkan device made without the extensions sharing needs (on an
NVIDIA device with Vulkan), the Session is refused with the reason.  The hand-over itself is
tested with GL's in test_share_handover.py."""

import pytest

import cltess
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory, SharingUnavailable, sharing_apis


def test_vulkan_sharing_needs_a_vulkan_queue_and_a_device_that_shares(tessellator, tea_table):
    with pytest.raises(ValueError, match="share=\"vulkan\""):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="vulkan")
    queue = cltess.VulkanQueue(device=1, physical_device=2, queue=3, family=0)
    with pytest.raises(ValueError, match="only with it"):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, vulkan=queue)
    if "vulkan" not in sharing_apis(tessellator.device):  # every CPU runtime: refused before any handle is used
        with pytest.raises(SharingUnavailable, match="OpenCL extensions"):
            cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="vulkan", vulkan=queue)


def test_a_vulkan_device_made_without_the_extensions_is_refused(tessellator, tea_table):
    if "vulkan" not in sharing_apis(tessellator.device):
        pytest.skip(f"{tessellator.device.name.strip()} cannot share with Vulkan")
    from cltess.backends.opencl.vulkan import VulkanDevice
    try:
        bare = VulkanDevice(OpenCLExternalMemory(tessellator.context, tessellator.device).uuid, (), api="vulkan")
    except (SharingUnavailable, RuntimeError) as error:
        pytest.skip(f"no Vulkan device on this GPU: {error}")
    try:
        queue = cltess.VulkanQueue(bare.device.value, bare.physical_device.value, bare.queue.value, bare.family)
        with pytest.raises(SharingUnavailable, match="made without VK_KHR_external_memory_fd, "
                                                     "VK_KHR_external_semaphore_fd"):
            cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="vulkan", vulkan=queue)
    finally:
        bare.close()

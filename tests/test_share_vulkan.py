"""A Session's output handed to the caller's Vulkan device without a copy
(``Session(share="vulkan", vulkan=VulkanQueue(...))``, ``frame.vulkan()``;
cltess/backends/opencl/share_vulkan.py; issue 15): without a VulkanQueue, or on a device that
cannot share, the Session is refused with the reason.  The hand-over itself is tested with GL's
in test_share_handover.py (on an NVIDIA device with Vulkan)."""

import pytest

import cltess
from cltess.backends.opencl.share_cuda import SharingUnavailable, sharing_apis


def test_vulkan_sharing_needs_a_vulkan_queue_and_a_device_that_shares(tessellator, tea_table):
    with pytest.raises(ValueError, match="share=\"vulkan\""):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="vulkan")
    queue = cltess.VulkanQueue(device=1, physical_device=2, queue=3, family=0)
    with pytest.raises(ValueError, match="only with it"):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, vulkan=queue)
    if "vulkan" not in sharing_apis(tessellator.device):  # every CPU runtime: refused before any handle is used
        with pytest.raises(SharingUnavailable, match="OpenCL extensions"):
            cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="vulkan", vulkan=queue)

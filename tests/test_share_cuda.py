"""A Session's output handed to CUDA without a copy (``Session(share="cuda")``, ``frame.cuda()``;
cltess/backends/opencl/share_cuda.py; issue 15).  A device that cannot share (every CPU
runtime) refuses such a Session with its reason; the sharing itself runs where the device
offers cl_khr_external_memory_opaque_fd and libcuda is there (NVIDIA: CLTESS_DEVICE=nvidia)."""

import numpy as np
import pytest

import cltess
from cltess.backends.opencl.output import OutputBuffers
from cltess.backends.opencl.share_cuda import NEEDED_EXTENSIONS, SharingUnavailable, sharing_apis
from cltess.tessellation import StaleOutput
from support import assert_same_output
from test_session import orbit

FIELDS = list(OutputBuffers.FIELDS)  # the output buffers: the vertex record and the triangles


def offers_sharing(tessellator) -> bool:
    return "cuda" in sharing_apis(tessellator.device)


@pytest.fixture
def sharing(tessellator):
    if not offers_sharing(tessellator):
        pytest.skip(f"{tessellator.device.name.strip()} does not offer {', '.join(NEEDED_EXTENSIONS)}")
    return tessellator


def assert_cuda_is(arrays, expected) -> None:
    """CUDA arrays (copied to the host by CUDA) bitwise equal to a tessellation's host arrays."""
    for name in FIELDS:
        host = getattr(expected, name)
        assert arrays[name].shape == host.shape and arrays[name].dtype == host.dtype, name
        assert np.array_equal(arrays[name].get(), host), name


def test_a_device_without_external_memory_refuses_to_share(tessellator, tea_table):
    if offers_sharing(tessellator):
        pytest.skip("this device offers the extensions")
    with pytest.raises(SharingUnavailable, match="cl_khr_external_memory"):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="cuda")


def test_a_session_refuses_an_api_it_cannot_hand_to(tessellator, tea_table):
    with pytest.raises(ValueError, match="share='metal': expected one of None, 'cuda', 'gl', 'vulkan'"):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="metal")
    frame = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5).tessellate(camera=tea_table.camera)
    with pytest.raises(ValueError, match='share="cuda"'):
        frame.cuda()
    with pytest.raises(ValueError, match='share="cuda"'):
        tessellator.tessellate(tea_table, pixels=0.5).cuda()  # host arrays only: nothing on the device


def test_frames_handed_to_cuda_are_bitwise_the_session_frames(sharing, tea_table):
    shared = cltess.Session(tea_table, tessellator=sharing, pixels=0.5, share="cuda")
    plain = cltess.Session(tea_table, tessellator=sharing, pixels=0.5)
    for k, camera in enumerate(orbit(tea_table, 4)):
        frame = shared.tessellate(camera=camera, host=k == 1)  # one frame's copies enqueued with its stages
        expected = plain.tessellate(camera=camera, host=True)
        arrays = frame.cuda()
        assert_cuda_is(arrays, expected)
        interface = arrays.positions.__cuda_array_interface__
        assert interface["shape"] == (expected.num_vertices, 3) and interface["typestr"] == "<f4"
        assert interface["data"] == (arrays.positions.pointer, False) and interface["version"] == 3
        assert arrays.triangles.__cuda_array_interface__["typestr"] == "<u4"
        assert_same_output(frame, expected)  # OpenCL reads them again after the hand-over
        again = frame.cuda()  # handed over again: the same memory
        assert again.positions.pointer == arrays.positions.pointer
        assert_cuda_is(again, expected)


def test_shared_buffers_grow_and_a_stale_frame_is_refused(sharing, tea_table):
    session = cltess.Session(tea_table, tessellator=sharing, eps=0.02, share="cuda")
    coarse = session.tessellate()
    small = coarse.cuda()
    fine = session.tessellate(eps=0.002)  # more output: new allocations
    grown = fine.cuda()
    assert_cuda_is(grown, sharing.tessellate(tea_table, eps=0.002))
    assert grown.positions.pointer != small.positions.pointer
    with pytest.raises(StaleOutput):
        coarse.cuda()
    # the coarse frame's arrays keep their allocation alive: still its output, not freed memory
    assert_cuda_is(small, sharing.tessellate(tea_table, eps=0.02))
    again = session.tessellate(eps=0.02)  # fewer: the same buffers
    assert again.cuda().positions.pointer == grown.positions.pointer
    assert_cuda_is(again.cuda(), sharing.tessellate(tea_table, eps=0.02))


def test_two_buffer_sets_hand_over_frames_that_overlapped(sharing, tea_table):
    session = cltess.Session(tea_table, tessellator=sharing, pixels=0.5, share="cuda", buffers=2)
    cameras = list(orbit(tea_table, 4))
    frames = []
    for camera in cameras:  # each enqueued while the one before may still run
        frames.append(session.tessellate(camera=camera, wait=False))
        if len(frames) >= 2:
            earlier = frames[-2]
            assert_cuda_is(earlier.cuda(), sharing.tessellate(tea_table, request=session.request_for(
                cameras[len(frames) - 2])))
    assert_cuda_is(frames[-1].cuda(), sharing.tessellate(tea_table, request=session.request_for(cameras[-1])))


@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
def test_shared_memory_and_its_descriptors_go_with_the_session(sharing, tea_table):
    import gc
    import os

    def open_descriptors() -> int:
        return len(os.listdir("/proc/self/fd"))

    gc.collect()
    before = open_descriptors()
    session = cltess.Session(tea_table, tessellator=sharing, eps=0.02, share="cuda")
    session.tessellate().cuda()
    arrays = session.tessellate(eps=0.002).cuda()  # grown: the first allocations freed
    assert open_descriptors() > before  # (one exported fd per field's allocation, held by OpenCL)
    session.close()  # the buffers go now (the arrays keep theirs); a later frame makes new ones
    assert session.output.capacity == (0, 0)
    assert_cuda_is(session.tessellate(eps=0.02).cuda(), sharing.tessellate(tea_table, eps=0.02))
    del session, arrays
    gc.collect()
    assert open_descriptors() == before


@pytest.mark.parametrize("cuda_part", range(len(NEEDED_EXTENSIONS) + 1))
@pytest.mark.parametrize("gl_part", range(4))
def test_the_apis_a_device_can_share_with_follow_its_extensions(cuda_part, gl_part):
    from types import SimpleNamespace

    from cltess.backends.opencl.handover import NEEDED_CL_EXTENSIONS

    extensions = ["cl_khr_fp64", *NEEDED_EXTENSIONS[:cuda_part], *NEEDED_CL_EXTENSIONS[:gl_part]]
    cuda = cuda_part == len(NEEDED_EXTENSIONS)
    expected = (["cuda", "gl", "vulkan"] if gl_part == len(NEEDED_CL_EXTENSIONS) else ["cuda"]) if cuda else []
    assert sharing_apis(SimpleNamespace(extensions=" ".join(extensions))) == expected

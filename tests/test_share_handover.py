"""A Session's output handed without a copy to an API that waits on the device: OpenGL
(``Session(share="gl")``, ``frame.gl()``: cltess/backends/opencl/share_gl.py) and Vulkan
(``Session(share="vulkan", vulkan=VulkanQueue(...))``, ``frame.vulkan()``: share_vulkan.py), the
same contract for each (issue 15).  The sharing runs on an NVIDIA device with EGL and Vulkan
(CLTESS_DEVICE=nvidia on the lent machine), where the receiving API reads the buffers by its own
GPU copy: a headless GL context (tests/support/egl.py), a Vulkan device of the test's own
(tests/support/vulkan_reader.py).  The refusals are in test_share_gl.py and test_share_vulkan.py."""

import gc
import os
from dataclasses import dataclass, field

import pytest

import cltess
from cltess.backends.opencl.output import OutputBuffers
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory, SharingUnavailable, sharing_apis
from cltess.tessellation import StaleOutput
from test_session import orbit

FIELDS = list(OutputBuffers.FIELDS)  # the output buffers: the vertex record and the triangles


@dataclass
class Receiver:
    """The API a test hands frames to: the Session keywords, and how that API names, reads and
    finishes with a buffer."""

    api: str
    reader: object
    options: dict = field(default_factory=dict)

    def hand(self, frame):
        return getattr(frame, self.api)()

    def handle(self, buffer) -> int:
        return buffer.name if self.api == "gl" else buffer.buffer

    def read(self, buffer, dtype, shape):
        return self.reader.read(self.handle(buffer), buffer.nbytes, dtype, shape)

    def settle(self) -> None:  # the API's commands so far done
        self.reader.finish() if self.api == "gl" else self.reader.wait_idle()

    def session(self, scene, tessellator, **request):
        return cltess.Session(scene, tessellator=tessellator, share=self.api, **self.options, **request)


@pytest.fixture(params=["gl", "vulkan"])
def receiver(request, tessellator):
    api = request.param
    if api not in sharing_apis(tessellator.device):
        pytest.skip(f"{tessellator.device.name.strip()} cannot share with {api}")
    if api == "gl":
        from support.egl import HeadlessGL
        try:
            reader = HeadlessGL()
        except RuntimeError as error:
            pytest.skip(f"no headless GL context: {error}")
        yield Receiver(api, reader)
    else:
        from support.vulkan_reader import VulkanReader
        try:
            reader = VulkanReader(OpenCLExternalMemory(tessellator.context, tessellator.device).uuid)
        except (SharingUnavailable, RuntimeError) as error:
            pytest.skip(f"no Vulkan device on this GPU: {error}")
        yield Receiver(api, reader, {"vulkan": reader.queue_for_session()})
    reader.close()


def assert_handed_is(receiver, buffers, expected) -> None:
    """Buffers as the receiving API's GPU copy reads them, bitwise equal to a tessellation's host
    arrays."""
    for name in FIELDS:
        host = getattr(expected, name)
        buffer = buffers[name]
        assert buffer.rows == len(host) and buffer.dtype == host.dtype and buffer.nbytes == host.nbytes, name
        assert (receiver.read(buffer, host.dtype, host.shape) == host).all(), name


def test_frames_handed_over_are_bitwise_the_session_frames(tessellator, receiver, tea_table):
    plain = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5)
    with receiver.session(tea_table, tessellator, pixels=0.5) as shared:
        for k, camera in enumerate(orbit(tea_table, 5)):
            frame = shared.tessellate(camera=camera)
            expected = plain.tessellate(camera=camera, host=True)
            if k == 2:
                continue  # a frame the API never gets: the next one must not wait for it
            buffers = receiver.hand(frame)
            assert_handed_is(receiver, buffers, expected)
            again = receiver.hand(frame)  # asked again: the same
            assert receiver.handle(again.positions) == receiver.handle(buffers.positions)
            if k == 3:  # OpenCL reads them back after the API had them
                assert all((getattr(frame, name) == getattr(expected, name)).all() for name in FIELDS)
                assert_handed_is(receiver, receiver.hand(frame), expected)


def test_handed_buffers_grow_and_a_stale_frame_is_refused(tessellator, receiver, tea_table):
    with receiver.session(tea_table, tessellator, eps=0.02) as session:
        coarse = session.tessellate()
        receiver.hand(coarse)
        capacity = session.output.capacity
        fine = session.tessellate(eps=0.002)  # more output: new allocations, new buffers (names may be reused)
        assert session.output.capacity > capacity
        assert_handed_is(receiver, receiver.hand(fine), tessellator.tessellate(tea_table, eps=0.002))
        with pytest.raises(StaleOutput):
            receiver.hand(coarse)
        assert_handed_is(receiver, receiver.hand(session.tessellate(eps=0.02)),
                         tessellator.tessellate(tea_table, eps=0.02))


def open_descriptors() -> dict:
    found = {}
    for fd in os.listdir("/proc/self/fd"):
        try:
            found[fd] = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:  # (the listing's own descriptor)
            pass
    return found


def test_closing_a_session_frees_its_objects_and_descriptors(tessellator, receiver, tea_table):
    with receiver.session(tea_table, tessellator, eps=0.02) as first:
        receiver.hand(first.tessellate())  # (what the drivers open once, the first time, is not the session's)
    del first
    gc.collect()
    receiver.settle()
    before = open_descriptors()
    session = receiver.session(tea_table, tessellator, eps=0.02)
    frame = session.tessellate()
    receiver.hand(frame)
    session.close()
    if receiver.api == "gl":
        assert receiver.reader.current(), "closing the session left no GL context current"
    with pytest.raises(StaleOutput):
        receiver.hand(frame)
    session.close()  # (again: nothing)
    with pytest.raises(RuntimeError, match="was closed"):
        session.tessellate()
    receiver.session(tea_table, tessellator, eps=0.02).close()  # no frame made
    del session, frame
    gc.collect()
    receiver.settle()  # (the API's deletions done)
    after = open_descriptors()
    # Every exported fd is closed, and nothing of the driver's stays: the semaphores are lent from
    # the context's pool (handover.OpenCLSemaphores), which the first session filled.  (Importing
    # and releasing them per session left one /dev/nvidiactl each: bench/RESULTS.md, "Session 18,
    # lead".)
    kept = sorted(set(after.items()) - set(before.items()))
    assert set(before.items()) <= set(after.items()) and not kept, kept


def test_two_buffer_sets_hand_overlapping_frames_over(tessellator, receiver, tea_table):
    cameras = list(orbit(tea_table, 4))
    with receiver.session(tea_table, tessellator, pixels=0.5, buffers=2) as session:
        frames = []
        for k, camera in enumerate(cameras):  # each enqueued while the one before may still run
            frames.append(session.tessellate(camera=camera, wait=False))
            if k >= 1:
                expected = tessellator.tessellate(tea_table, request=session.request_for(cameras[k - 1]))
                assert_handed_is(receiver, receiver.hand(frames[k - 1]), expected)
        assert_handed_is(receiver, receiver.hand(frames[-1]),
                         tessellator.tessellate(tea_table, request=session.request_for(cameras[-1])))

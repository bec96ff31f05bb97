"""A Session's output handed to OpenGL without a copy (``Session(share="gl")``, ``frame.gl()``;
cltess/backends/opencl/share_gl.py; issue 15).  Without a current GL context the Session is
refused with the reason; the sharing itself runs on an NVIDIA device with EGL and Vulkan
(CLTESS_DEVICE=nvidia on the lent machine), where a headless GL context reads the buffers by its
own GPU copy."""

import gc
import os

import pytest

import cltess
from cltess.backends.opencl.output import OutputBuffers
from cltess.backends.opencl.share_cuda import SharingUnavailable, sharing_apis
from cltess.tessellation import StaleOutput
from test_session import orbit

FIELDS = list(OutputBuffers.FIELDS)  # the output buffers: the vertex record and the triangles


@pytest.fixture
def headless_gl(tessellator):
    if "gl" not in sharing_apis(tessellator.device):
        pytest.skip(f"{tessellator.device.name.strip()} cannot share with GL")
    from support.egl import HeadlessGL
    try:
        gl = HeadlessGL()
    except RuntimeError as error:
        pytest.skip(f"no headless GL context: {error}")
    yield gl
    gl.close()


def assert_gl_is(gl, buffers, expected) -> None:
    """GL buffers, as GL's GPU copy reads them, bitwise equal to a tessellation's host arrays."""
    for name in FIELDS:
        host = getattr(expected, name)
        buffer = buffers[name]
        assert buffer.rows == len(host) and buffer.dtype == host.dtype and buffer.nbytes == host.nbytes, name
        assert (gl.read(buffer.name, buffer.nbytes, host.dtype, host.shape) == host).all(), name


def test_without_a_current_gl_context_a_session_refuses_to_share_with_gl(tessellator, tea_table):
    with pytest.raises(SharingUnavailable, match="OpenGL context current"):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="gl")


def test_frames_handed_to_gl_are_bitwise_the_session_frames(tessellator, headless_gl, tea_table):
    plain = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5)
    with cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="gl") as shared:
        for k, camera in enumerate(orbit(tea_table, 5)):
            frame = shared.tessellate(camera=camera)
            expected = plain.tessellate(camera=camera, host=True)
            if k == 2:
                continue  # a frame GL never gets: the next one must not wait for GL
            buffers = frame.gl()
            assert_gl_is(headless_gl, buffers, expected)
            assert frame.gl()["positions"].name == buffers.positions.name  # asked again: the same
            if k == 3:  # OpenCL reads them back after GL had them
                assert all((getattr(frame, name) == getattr(expected, name)).all() for name in FIELDS)
                assert_gl_is(headless_gl, frame.gl(), expected)


def test_gl_buffers_grow_and_a_stale_frame_is_refused(tessellator, headless_gl, tea_table):
    with cltess.Session(tea_table, tessellator=tessellator, eps=0.02, share="gl") as session:
        coarse = session.tessellate()
        coarse.gl()
        capacity = session.output.capacity
        fine = session.tessellate(eps=0.002)  # more output: new allocations, new GL buffers (GL may reuse names)
        assert session.output.capacity > capacity
        assert_gl_is(headless_gl, fine.gl(), tessellator.tessellate(tea_table, eps=0.002))
        with pytest.raises(StaleOutput):
            coarse.gl()
        assert_gl_is(headless_gl, session.tessellate(eps=0.02).gl(), tessellator.tessellate(tea_table, eps=0.02))


def test_closing_a_gl_session_frees_its_objects_and_descriptors(tessellator, headless_gl, tea_table):
    def open_descriptors() -> dict:
        found = {}
        for fd in os.listdir("/proc/self/fd"):
            try:
                found[fd] = os.readlink(f"/proc/self/fd/{fd}")
            except OSError:  # (the listing's own descriptor)
                pass
        return found

    with cltess.Session(tea_table, tessellator=tessellator, eps=0.02, share="gl") as first:
        first.tessellate().gl()  # (what the drivers open once, the first time, is not the session's)
    del first
    gc.collect()
    headless_gl.finish()
    before = open_descriptors()
    session = cltess.Session(tea_table, tessellator=tessellator, eps=0.02, share="gl")
    frame = session.tessellate()
    frame.gl()
    session.close()
    assert headless_gl.current(), "closing the session left no GL context current"
    with pytest.raises(StaleOutput):
        frame.gl()
    session.close()  # (again: nothing)
    with pytest.raises(RuntimeError, match="was closed"):
        session.tessellate()
    cltess.Session(tea_table, tessellator=tessellator, eps=0.02, share="gl").close()  # no frame made
    del session, frame
    gc.collect()
    headless_gl.finish()  # (GL's deletions done)
    after = open_descriptors()
    # Every exported fd is closed: what stays is one /dev/nvidiactl, which NVIDIA's drivers
    # (580) keep per closed session that GL imported memory in, whether or not its GL objects are
    # deleted; none without GL's import (share="cuda": test_share_cuda.py) (bench/RESULTS.md,
    # "Session 17, lead", fd_steps2.txt).
    kept = sorted(set(after.items()) - set(before.items()))
    assert set(before.items()) <= set(after.items()) and len(kept) <= 1, kept
    assert all(target == "/dev/nvidiactl" for _, target in kept), kept


def test_two_buffer_sets_hand_overlapping_frames_to_gl(tessellator, headless_gl, tea_table):
    cameras = list(orbit(tea_table, 4))
    with cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="gl", buffers=2) as session:
        frames = []
        for k, camera in enumerate(cameras):  # each enqueued while the one before may still run
            frames.append(session.tessellate(camera=camera, wait=False))
            if k >= 1:
                expected = tessellator.tessellate(tea_table, request=session.request_for(cameras[k - 1]))
                assert_gl_is(headless_gl, frames[k - 1].gl(), expected)
        assert_gl_is(headless_gl, frames[-1].gl(),
                     tessellator.tessellate(tea_table, request=session.request_for(cameras[-1])))

"""Output that stays on the device (Tessellation.device, lazy host arrays), the frame loop
(cltess.Session) and the wall-clock figures a result carries (issue 15)."""

import numpy as np
import pyopencl as cl
import pytest

import cltess
from cltess.scene import Camera
from cltess.tessellation import StaleOutput
from support import assert_same_output


def orbit(scene, count):
    """Cameras on a circle around the scene's camera target, each nearer than the last."""
    camera = scene.camera
    target = np.asarray(camera.target, float)
    offset = np.asarray(camera.eye, float) - target
    for k in range(count):
        angle, scale = 2 * np.pi * k / count, 1.0 - 0.15 * k
        c, s = np.cos(angle), np.sin(angle)
        turned = np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], offset[2]])
        yield Camera(eye=target + scale * turned, target=target, up=camera.up)


def test_wall_times_cover_the_read_back(tessellator, tea_table):
    tess = tessellator.tessellate(tea_table, pixels=0.5)
    wall = tess.wall_ms
    assert wall["total"] == pytest.approx(wall["stages"] + wall["read_back"])
    assert tess.stage_ms["total_wall"] == wall["total"]
    assert tess.device is None and tess.on_host


def test_output_on_the_device_is_read_back_only_when_asked(tessellator, tea_table):
    plan = tessellator.plan(tea_table, pixels=0.5)
    tess = tessellator.emit(plan, 0, plan.num_patches, on_device=True)
    assert not tess.on_host and "read_back" not in tess.wall_ms
    assert tess.num_vertices == plan.num_vertices and tess.num_triangles == plan.num_indices // 3
    device = tess.device
    assert device.positions.shape == (plan.num_vertices, 3) and device.triangles.dtype == np.uint32
    positions = device.positions.get()  # a pyopencl array: read it without the Tessellation
    assert not tess.on_host
    assert np.array_equal(tess.positions, positions)  # the first host field fetches them all
    assert tess.on_host and tess.wall_ms["total"] >= tess.wall_ms["stages"]
    assert_same_output(tess, tessellator.tessellate(tea_table, pixels=0.5))


def test_batches_on_the_device_number_vertices_globally(tessellator, tea_table):
    plan = tessellator.plan(tea_table, eps=0.01)
    whole = tessellator.emit(plan, 0, plan.num_patches)
    middle = plan.num_patches // 2
    second = tessellator.emit(plan, middle, plan.num_patches, on_device=True)
    assert second.device.vertex_base == plan.vertex_range(middle, plan.num_patches)[0]
    assert np.array_equal(second.triangles, whole.triangles[plan.index_range(0, middle)[1] // 3:])


def test_session_frames_are_bitwise_the_one_shot_results(tessellator, tea_table):
    session = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5)
    for camera in orbit(tea_table, 4):
        frame = session.tessellate(camera=camera)
        expected = tessellator.tessellate(tea_table, request=session.request_for(camera))
        assert_same_output(frame, expected)
    assert session.frames == 4


def test_host_frames_read_back_with_their_stages(tessellator, tea_table, monkeypatch):
    """tessellate(host=True): host arrays bitwise those of fetch(); on a CPU device the map is
    enqueued with the stages (read_back then waits for it, enqueueing none), also for a frame
    that outgrows the buffers (its stages run again: the early map is dropped) and with
    wait=False (fetched on first use)."""
    from cltess.backends.opencl import output

    maps = []
    real_map = output.OutputBuffers._enqueue_map
    session = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5)
    monkeypatch.setattr(output.OutputBuffers, "_enqueue_map",
                        lambda self: (self is session.output and maps.append(1)) or real_map(self))
    plain = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5)
    fits = []
    for k, camera in enumerate(orbit(tea_table, 4)):  # nearer each time: the output grows
        maps.clear()
        frame = session.tessellate(camera=camera, host=True, wait=k % 2 == 0)
        assert frame.device is not None
        if session.output.mapped and k % 2:  # enqueued with the stages, before anything waited
            assert len(maps) == 1 and "_finish" in frame.__dict__
        expected = plain.tessellate(camera=camera).fetch()
        assert_same_output(frame, expected)
        assert np.array_equal(frame.factors, expected.factors)
        fits.append(frame.stats.get("output_fit", True))
        if session.output.mapped:  # one map, or two where the stages ran again on grown buffers
            assert len(maps) == (1 if fits[-1] else 2)
    assert False in fits  # (the case of stages run again is covered)


def test_one_shot_results_start_their_read_back_with_their_stages(tessellator, tea_table, monkeypatch):
    """emit() of host arrays enqueues their read-back right behind the stages (one wait for
    both); emit(on_device=True) reads nothing back until asked."""
    from cltess.backends.opencl import output

    started = []
    real = output.OutputBuffers.start_read_back
    monkeypatch.setattr(output.OutputBuffers, "start_read_back",
                        lambda self, *sizes: started.append(sizes) or real(self, *sizes))
    tess = tessellator.tessellate(tea_table, pixels=0.5)
    # (a CPU device maps the whole allocation, with no sizes; a GPU copies what the plan says)
    cpu = tessellator.device.type & cl.device_type.CPU
    expected = [()] if cpu else [(tess.num_vertices, tess.num_triangles)]
    assert started == expected and tess.on_host
    plan = tessellator.plan(tea_table, pixels=0.5)
    resident = tessellator.emit(plan, 0, plan.num_patches, on_device=True)
    assert len(started) == len(expected) and not resident.on_host
    assert_same_output(resident.fetch(), tess)


def test_two_buffer_sets_keep_a_frame_while_the_next_one_computes(tessellator, tea_table, monkeypatch):
    """Session(buffers=2): frames take two sets of buffers in turn, so frame k's output stays
    valid while frame k+1 is enqueued and computed (the host reads k meanwhile), and goes stale
    at frame k+2.  Every frame is bitwise the one-shot result: where the output grows (a frame
    launched on too small buffers runs again on its own set, grown) and for replayed frames
    (each set records and replays its own launches)."""
    from cltess.backends.opencl import recorded

    replays = []
    real_replay = recorded.RecordedFrame.replay
    monkeypatch.setattr(recorded.RecordedFrame, "replay",
                        lambda self, *args: replays.append(self) or real_replay(self, *args))
    session = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, buffers=2)
    near = list(orbit(tea_table, 4))  # nearer each time: the output grows
    cameras = near[:1] * 2 + near[3:] * 2 + near  # a jump that outgrows a set's buffers; then replays
    frames, fits = [], []
    for k, camera in enumerate(cameras):
        frames.append(session.tessellate(camera=camera, host=True, wait=False))
        if k >= 1:  # the previous frame, read while this one is in flight on the other set
            previous = frames[k - 1]
            assert_same_output(previous, tessellator.tessellate(tea_table, request=session.request_for(cameras[k - 1])))
            fits.append(previous.stats.get("output_fit", True))
        if k >= 2:  # the one before that shared this frame's set: stale now
            with pytest.raises(StaleOutput):
                frames[k - 2].device.positions
    assert_same_output(frames[-1], tessellator.tessellate(tea_table, request=session.request_for(cameras[-1])))
    assert False in fits  # (a frame run again on grown buffers is covered)
    assert {id(s.recorded) for s in session._sets} == {id(r) for r in replays[-2:]}  # each set its own
    assert len(replays) >= 2 and session.frames == len(cameras)
    assert session._sets[0].output is not session._sets[1].output


def test_two_buffer_sets_copy_a_frame_before_the_next_frames_stages(tessellator, tea_table, monkeypatch):
    """Where a frame's read-back is a copy that needs its totals (a GPU: forced here on any
    device), a frame asked for host arrays with wait=False has its copies enqueued by the next
    call at the latest, before that frame's stages 4-5, so that its fetch finds them started
    (no copy of its own, and no wait behind the next frame's stages); bitwise the one-shot
    result, also where it did not fit its buffers and ran again."""
    from cltess.backends.opencl import output

    session = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, buffers=2)
    for buffers in session._sets:  # copies through page-locked buffers, as on a GPU
        buffers.output.mapped, buffers.output.pinned = False, True
    events = []  # ("take", set): a frame's stages 4-5 are enqueued right after; ("copy", set)
    real_copies, real_take = output.OutputBuffers._enqueue_copies, output.OutputBuffers.take
    monkeypatch.setattr(output.OutputBuffers, "_enqueue_copies",
                        lambda self, *sizes: events.append(("copy", self)) or real_copies(self, *sizes))
    monkeypatch.setattr(output.OutputBuffers, "take",
                        lambda self, *sizes: events.append(("take", self)) or real_take(self, *sizes))
    near = list(orbit(tea_table, 4))
    cameras = near[:1] * 2 + near[3:] * 2 + near  # a jump that outgrows a set's buffers; then replays
    frames, starts, fits = [], [], []
    for k, camera in enumerate(cameras):
        starts.append(len(events))
        frames.append(session.tessellate(camera=camera, host=True, wait=False))
        if k >= 1:
            mine, theirs = session._sets[(k - 1) % 2].output, session._sets[k % 2].output
            last_take = max(i for i, event in enumerate(events) if event == ("take", theirs))
            assert ("copy", mine) in events[starts[k - 1]:last_take]  # frame k-1's, before frame k's stages
            before = len(events)
            assert_same_output(frames[k - 1], tessellator.tessellate(tea_table,
                                                                     request=session.request_for(cameras[k - 1])))
            assert ("copy", mine) not in events[before:]  # its fetch found them started
            fits.append(frames[k - 1].stats.get("output_fit", True))
    assert False in fits  # (a frame run again on grown buffers is covered)


def test_two_buffer_sets_with_overrides_grow_only_the_set_a_frame_takes(tessellator, tea_table):
    """Frames made the normal way (request overrides) take the sets in turn too: a finer frame
    grows its own set and leaves the previous frame's valid; the frame after takes that one."""
    session = cltess.Session(tea_table, tessellator=tessellator, eps=0.02, buffers=2)
    coarse = session.tessellate()
    coarse_size = session._sets[0].output.nbytes
    fine = session.tessellate(eps=0.002)  # set 1, more output
    assert session._sets[0].output.nbytes == coarse_size < session._sets[1].output.nbytes
    assert_same_output(coarse, tessellator.tessellate(tea_table, eps=0.02))  # still valid
    assert_same_output(fine, tessellator.tessellate(tea_table, eps=0.002))
    again = session.tessellate(eps=0.002)  # set 0 again: grows, and the coarse frame is stale
    assert session._sets[0].output.nbytes > coarse_size
    with pytest.raises(StaleOutput):  # (its host arrays, fetched above, are views the new frame overwrote)
        coarse.device.positions
    assert_same_output(again, tessellator.tessellate(tea_table, eps=0.002))


@pytest.mark.parametrize("work", ["rows-prep", "point-prep"])
def test_a_session_prepares_its_patches_once(tessellator, tea_table, monkeypatch, work):
    """A Session's "*-prep" frames prepare the scene's Bézier patches once, every patch (the
    first frame's set-up, not replayed), and later frames read them: bitwise the per-patch
    kernels' frames, also where a patch culled in one frame is seen in the next."""
    from cltess.backends.opencl import programs, tessellator as opencl

    launched = []
    real_launch = programs.Kernel.launch
    monkeypatch.setattr(programs.Kernel, "launch", lambda self, *args, **kwargs:
                        launched.append(self.kernel.function_name) or real_launch(self, *args, **kwargs))
    prepared = opencl.Tessellator(tessellator.device, work=work)
    session = cltess.Session(tea_table, tessellator=prepared, pixels=0.5)
    culled = []
    for camera in list(orbit(tea_table, 4))[::-1] * 2:  # nearest first: the most culled; then replays
        frame = session.tessellate(camera=camera)
        assert_same_output(frame, tessellator.tessellate(tea_table, request=session.request_for(camera)))
        culled.append(frame.stats["culled"])
    assert culled[0] > min(culled)  # (patches culled in the first frame are seen in later ones)
    assert launched.count("prepare_patches") == 1


@pytest.mark.parametrize("buffers", [0, -1, 1.5, True, "2"])
def test_session_refuses_a_count_of_buffer_sets_that_is_not_a_whole_number(tessellator, tea_table, buffers):
    with pytest.raises(ValueError, match="buffers must be"):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, buffers=buffers)


def test_session_overrides_and_growing_buffers(tessellator, tea_table):
    session = cltess.Session(tea_table, tessellator=tessellator, eps=0.02)
    coarse = session.tessellate()
    size = session.output.nbytes
    fine = session.tessellate(eps=0.002)  # more output: the buffers grow
    grown = session.output.nbytes
    assert grown > size
    assert_same_output(fine, tessellator.tessellate(tea_table, eps=0.002))
    with pytest.raises(StaleOutput):
        coarse.fetch()
    with pytest.raises(StaleOutput):
        coarse.device.positions
    again = session.tessellate(eps=0.02)  # fewer: the same buffers
    assert session.output.nbytes == grown
    assert_same_output(again, tessellator.tessellate(tea_table, eps=0.02))
    semi = session.tessellate(eps=0.02, pattern="semi_uniform")
    assert_same_output(semi, tessellator.tessellate(tea_table, eps=0.02, pattern="semi_uniform"))


def test_closing_a_session_lets_its_buffers_go(tessellator, tea_table):
    with cltess.Session(tea_table, tessellator=tessellator, eps=0.02) as session:
        frame = session.tessellate()
        assert session.output.nbytes > 0
    assert session.output.nbytes == 0 and session.output.capacity == (0, 0)
    with pytest.raises(StaleOutput):
        frame.fetch()
    assert_same_output(session.tessellate(eps=0.02), tessellator.tessellate(tea_table, eps=0.02))  # new buffers


def test_session_refuses_what_it_cannot_do(tessellator, tea_table):
    session = cltess.Session(tea_table, tessellator=tessellator, eps=0.02)
    with pytest.raises(ValueError, match="pixel tolerance"):
        session.tessellate(camera=tea_table.camera)
    with pytest.raises(ValueError, match="at most one"):
        session.tessellate(eps=0.1, pixels=1.0)
    with pytest.raises(ValueError, match="eps must be"):
        session.tessellate(eps=-1.0)


def test_view_matrix_is_bitwise_numpys_cross_and_norm():
    """Camera.view_matrix runs on Python floats (once per frame); it must be the same bits as
    the np.cross / np.linalg.norm formulation, or every screen-space tolerance moves."""
    def reference(camera):
        forward = np.asarray(camera.target, float) - np.asarray(camera.eye, float)
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, np.asarray(camera.up, float))
        right /= np.linalg.norm(right)
        view = np.eye(4)
        view[0, :3], view[1, :3], view[2, :3] = right, np.cross(right, forward), -forward
        view[:3, 3] = -view[:3, :3] @ np.asarray(camera.eye, float)
        return view

    rng = np.random.default_rng(15)
    for _ in range(2000):
        scale = 10.0 ** rng.uniform(-3, 4, 3)
        camera = Camera(eye=rng.normal(size=3) * scale[0], target=rng.normal(size=3) * scale[1],
                        up=rng.normal(size=3) * scale[2])
        assert reference(camera).tobytes() == camera.view_matrix().tobytes()

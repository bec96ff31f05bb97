"""A Session frame recorded once and replayed for each new camera (issue 15, a frame's host cost:
cltess/backends/opencl/recorded.py): replayed frames are bitwise the one-shot results, a record is
made again when what it was made for changes (buffers grown, the tessellator's settings), and a
frame that cannot be replayed is made the normal way."""
from types import SimpleNamespace

import numpy as np
import pyopencl as cl
import pytest

import cltess
from cltess.backends.opencl import recorded
from cltess.backends.opencl import tessellator as opencl
from cltess.backends.opencl import programs
from cltess.backends.opencl.programs import changed_arguments, same_arguments
from cltess.criteria.tolerance import ScreenSpace, camera_arguments
from cltess.scene import Camera
from cltess.tessellation import HOST_FIELDS
from support import assert_same_output

#: (work, stage 3 as on a GPU): the CPU's own path and a GPU's (stage 3 in one launch, or in two)
PATHS = [("patch", False), ("point", True), ("rows-prep", True), ("auto", True)]


def gpu_like(tessellator, work: str, as_gpu: bool, tiled: bool = False):
    own = opencl.Tessellator(tessellator.device, work=work)
    if as_gpu:
        own.fused_offsets, own.tiled_offsets, own._cpu = not tiled, True, False
    return own


def orbit(camera: Camera, count: int) -> list:
    """Cameras on a circle about the camera's target, closer and closer (more output)."""
    eye, target = np.asarray(camera.eye, float), np.asarray(camera.target, float)
    cameras = []
    for k in range(count):
        angle = 2 * np.pi * k / count
        turn = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
        cameras.append(Camera(eye=target + (1.0 - 0.08 * k) * turn @ (eye - target), target=target, up=camera.up))
    return cameras


def count_replays(monkeypatch) -> list:
    replays = []
    original = recorded.RecordedFrame.replay

    def counted(self, *args, **kwargs):
        replays.append(self)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(recorded.RecordedFrame, "replay", counted)
    return replays


@pytest.mark.parametrize("work,as_gpu", PATHS)
def test_replayed_frames_are_the_one_shot_results(tessellator, tea_table, monkeypatch, work, as_gpu):
    own = gpu_like(tessellator, work, as_gpu)
    replays = count_replays(monkeypatch)
    session = cltess.Session(tea_table, tessellator=own, pixels=0.5)
    cameras = orbit(tea_table.camera, 6)
    for camera in cameras:
        frame = session.tessellate(camera=camera)
        assert_same_output(frame, own.tessellate(tea_table, request=session.request_for(camera)))
    # the first frame is recorded; as the cameras come closer the output grows, a frame that did
    # not fit grows the buffers, and the frame after it is recorded again: the others replay
    assert session._recorded is not None and 0 < len(replays) < len(cameras)
    before = len(replays)
    overlapped = [session.tessellate(camera=camera, wait=False) for camera in cameras[::-1]]  # all fit now
    assert len(replays) >= before + len(cameras) - 1
    assert_same_output(overlapped[-1], own.tessellate(tea_table, request=session.request_for(cameras[0])))


def test_a_record_is_made_again_when_its_buffers_or_settings_change(tessellator, tea_table, monkeypatch):
    own = gpu_like(tessellator, "point", True)
    replays = count_replays(monkeypatch)
    session = cltess.Session(tea_table, tessellator=own, pixels=0.5)
    camera = tea_table.camera
    session.tessellate(camera=camera)  # sized by its totals (no buffers yet): not recorded
    assert session._recorded is None
    session.tessellate(camera=camera)  # launched on the buffers' capacity: recorded
    first = session._recorded
    session.tessellate(camera=camera)
    assert len(replays) == 1 and session._recorded is first
    fine = session.tessellate(camera=camera, pixels=0.1)  # an override: the normal way, not recorded
    assert len(replays) == 1 and session._recorded is first
    assert_same_output(fine, own.tessellate(tea_table, request=session.request_for(camera, pixels=0.1)))
    again = session.tessellate(camera=camera)  # the buffers grew for the override: recorded again
    assert len(replays) == 1 and session._recorded is not first
    assert session._recorded.key[-1] == session.output.capacity
    assert_same_output(again, own.tessellate(tea_table, request=session.request_for(camera)))
    own.work = "patch"  # another work distribution: recorded again, for it
    patch = session.tessellate(camera=camera)
    assert len(replays) == 1 and session._recorded.key[0] == "patch"
    assert_same_output(patch, again)
    assert_same_output(session.tessellate(camera=camera), again)
    assert len(replays) == 2
    own.work, own.patches_per_group = "rows-prep", 8  # patches per work-group: in the key too
    session.tessellate(camera=camera)
    own.patches_per_group = 16
    sixteen = session.tessellate(camera=camera)
    assert len(replays) == 2 and session._recorded.key[2] == 16
    assert_same_output(sixteen, again)


def test_stage_3_in_two_launches_is_replayed_too(tessellator, tea_table, monkeypatch):
    own = gpu_like(tessellator, "point", True, tiled=True)
    replays = count_replays(monkeypatch)
    session = cltess.Session(tea_table, tessellator=own, pixels=0.5)
    camera = orbit(tea_table.camera, 3)[1]
    for _ in range(4):  # the first sized by its totals, the second recorded, then replays
        assert_same_output(session.tessellate(camera=camera), own.tessellate(tea_table, request=session.request_for(camera)))
    assert len(replays) == 2 and len(session._recorded.launches["counts"]) == 2  # tiles, carries


def test_what_cannot_be_replayed_is_made_the_normal_way(tessellator, tea_table, monkeypatch):
    """Stage 3 by pyopencl's scan (not a Kernel launch) is never recorded."""
    own = gpu_like(tessellator, "patch", False)
    own.fused_offsets = own.tiled_offsets = False
    replays = count_replays(monkeypatch)
    session = cltess.Session(tea_table, tessellator=own, pixels=0.5)
    for camera in orbit(tea_table.camera, 3):
        assert_same_output(session.tessellate(camera=camera), own.tessellate(tea_table, request=session.request_for(camera)))
    assert session._recorded is None and not replays


def test_a_replay_sets_arguments_another_launch_changed(tessellator, tea_table, monkeypatch):
    """Another session's frames and one-shot calls launch the same kernels in between: the replay
    sets the arguments they changed (programs.Kernel) and each frame is still its own."""
    own = gpu_like(tessellator, "point", True)
    replays = count_replays(monkeypatch)
    cameras = orbit(tea_table.camera, 3)[:2]
    sessions = [cltess.Session(tea_table, tessellator=own, pixels=pixels) for pixels in (0.5, 2.0)]
    for turn in range(4):  # the first sized by its totals, the second recorded, then replays
        for session, camera in zip(sessions, cameras):
            frame = session.tessellate(camera=camera)
            assert_same_output(frame, own.tessellate(tea_table, request=session.request_for(camera)))
    assert len(replays) == 4  # each session's third and fourth frames


def test_the_tolerance_arguments_are_where_stage_1_takes_them(tessellator, tea_table):
    own = gpu_like(tessellator, "point", True)
    session = cltess.Session(tea_table, tessellator=own, pixels=0.5)
    for _ in range(2):
        session.tessellate(camera=tea_table.camera)
    (launch,) = session._recorded.launches["factors"]
    assert same_arguments(launch.args[opencl.TOLERANCE_ARGUMENTS],
                          ScreenSpace(0.5, tea_table.camera).kernel_args())
    other = orbit(tea_table.camera, 4)[1]
    moved = recorded.with_tolerance(launch.args, ScreenSpace(0.5, other).kernel_args())
    assert moved[:4] == launch.args[:4] and moved[9:] == launch.args[9:]
    assert not same_arguments(moved, launch.args)


def test_same_arguments_compares_values_and_structs_by_their_bytes(rng):
    def view(values):
        return np.asarray(values, np.float32).view(cl.cltypes.float16)[0]

    values = rng.normal(size=16)
    buffer = object()
    kept = (buffer, np.uint32(7), np.float32(0.5), view(values))
    assert same_arguments(kept, kept)
    assert same_arguments((buffer, np.uint32(7), np.float32(0.5), view(values)), kept)  # equal, not the same
    for at in range(16):  # one float of the struct changed by one step
        changed = values.astype(np.float32)
        changed[at] = np.nextafter(changed[at], np.float32(np.inf))
        assert not same_arguments((buffer, np.uint32(7), np.float32(0.5), view(changed)), kept)
    assert not same_arguments((object(), np.uint32(7), np.float32(0.5), view(values)), kept)
    assert not same_arguments((buffer, np.uint32(8), np.float32(0.5), view(values)), kept)
    assert not same_arguments((buffer, np.int32(7), np.float32(0.5), view(values)), kept)  # another type
    assert not same_arguments(kept[:3], kept) and not same_arguments(kept, None)
    assert changed_arguments((buffer, np.uint32(8), np.float32(0.5), view(values + 1)), kept) == (1, 3)
    assert changed_arguments(kept, kept) == () and changed_arguments(kept[:3], kept) is None


def test_a_replay_sets_the_changed_arguments_alone(tessellator, tea_table, monkeypatch):
    """A new camera changes stage 1's view matrix alone: the replay sets that argument (by its
    bytes, as pyopencl's typed launch does) and enqueues every launch without setting the
    others, and the frame is still the one-shot result; an argument of another type is set the
    normal way."""
    own = gpu_like(tessellator, "point", True)
    session = cltess.Session(tea_table, tessellator=own, pixels=0.5)
    cameras = orbit(tea_table.camera, 4)
    for camera in cameras + cameras:  # the buffers grown to the closest camera's output, then recorded
        session.tessellate(camera=camera)
    set_alone, typed = [], []
    original = programs.Kernel._set_changed
    monkeypatch.setattr(programs.Kernel, "_set_changed",
                        lambda self, args, changed: set_alone.append(changed) or original(self, args, changed))
    typed_launch = cl.Kernel.__call__
    monkeypatch.setattr(cl.Kernel, "__call__", lambda *a, **k: typed.append(a[0]) or typed_launch(*a, **k))
    view_at = opencl.TOLERANCE_ARGUMENTS.start + 1  # (eps, view, frustum, pixels, pixel size)
    frames = []
    for camera in cameras[-2::-1]:  # (each another camera than the frame before)
        set_alone.clear(), typed.clear()
        frame = session.tessellate(camera=camera)
        assert set_alone == [(view_at,)] and not typed  # a replayed frame: the view alone, no typed launch
        frames.append({name: np.copy(getattr(frame, name)) for name in HOST_FIELDS})
    # (a one-shot call launches the same kernels with its own arguments: the next frame sets them all)
    for camera, frame in zip(cameras[-2::-1], frames):
        assert_same_output(SimpleNamespace(**frame), own.tessellate(tea_table, request=session.request_for(camera)))
    (launch,) = session._recorded.launches["factors"]
    kernel = launch.kernel
    moved = list(launch.args)
    moved[view_at] = float(0.0)  # another type than the kernel's: not set alone
    assert not kernel._set_changed(tuple(moved), (view_at,))


def test_camera_arguments_are_the_formulas_bits(rng):
    """The frustum and pixel size made once per lens (lens_arguments) are the per-call formulas'
    bits, and so is the view matrix."""
    for _ in range(200):
        camera = Camera(eye=rng.normal(size=3) * 10, target=rng.normal(size=3), up=np.array([0.0, 0.0, 1.0]),
                        fov_y_deg=float(rng.uniform(10, 120)), width=int(rng.integers(64, 4096)),
                        height=int(rng.integers(64, 4096)), near=float(rng.uniform(1e-3, 1)),
                        far=float(rng.uniform(10, 1e5)))
        view, frustum, pixel_size = camera_arguments(camera)
        tan_y = np.tan(np.radians(camera.fov_y_deg) / 2)
        expected = np.array([tan_y * camera.width / camera.height, tan_y, camera.near, camera.far], np.float32)
        assert np.asarray(frustum).tobytes() == expected.tobytes()
        assert pixel_size == 2.0 * np.tan(np.radians(camera.fov_y_deg) / 2.0) / camera.height
        assert np.asarray(view).tobytes() == camera.view_matrix().astype(np.float32).tobytes()

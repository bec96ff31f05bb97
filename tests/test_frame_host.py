"""A frame's host cost (issue 15): kernels whose scalar arguments are packed by the types of
their first launch (programs.Kernel), the kernel look-up by identity, stage 3 in one launch
on CPUs for small scenes, a Session that skips the program look-up for a new camera alone,
and frames that do not wait for their stages (Session.tessellate(wait=False))."""

import numpy as np
import pyopencl as cl
import pytest

import cltess
from cltess.backends.opencl import tessellator as opencl
from cltess.backends.opencl.programs import Kernel
from cltess.scene import Camera
from cltess.tessellation import HOST_FIELDS, StaleOutput
from support import assert_same_output


ECHO = """
__kernel void echo(__global uint *u, __global int *i, __global ulong *l, __global float *f, __global float4 *v,
                   uint a, int b, ulong c, float d, float4 e)
{
    u[0] = a; i[0] = b; l[0] = c; f[0] = d; v[0] = e;
}
"""


def test_kernel_packs_each_launch_by_its_first_launchs_types(tessellator, rng):
    queue = tessellator.queue
    kernel = Kernel(cl.Kernel(cl.Program(tessellator.context, ECHO).build(), "echo"))
    outs = [cl.Buffer(tessellator.context, cl.mem_flags.READ_WRITE, 16) for _ in range(5)]
    for launch in range(6):
        a, b = np.uint32(rng.integers(0, 2 ** 32)), np.int32(rng.integers(-2 ** 31, 2 ** 31))
        c, d = np.uint64(rng.integers(0, 2 ** 63)) * np.uint64(2), np.float32(rng.normal() * 10.0 ** rng.integers(-30, 30))
        e = np.array(rng.normal(size=4), np.float32).view(cl.cltypes.float4)[0]
        if launch == 5:  # Python numbers after the first launch: packed as its types
            a, b, d = int(a), int(b), float(d)
        kernel(queue, (1,), None, *outs, a, b, c, d, e)
        got = [np.empty(1, t) for t in (np.uint32, np.int32, np.uint64, np.float32)] + [np.empty(4, np.float32)]
        for host, buffer in zip(got, outs):
            cl.enqueue_copy(queue, host, buffer)
        assert (got[0][0], got[1][0], got[2][0]) == (a, b, c)
        assert got[3].tobytes() == np.float32(d).tobytes()
        assert got[4].tobytes() == np.asarray(e).tobytes()
    assert kernel.arg_types[5:] == (np.dtype(np.uint32), np.dtype(np.int32), np.dtype(np.uint64),
                                    np.dtype(np.float32), cl.cltypes.float4)
    with pytest.raises(Exception):  # a value the first launch's type cannot hold is refused
        kernel(queue, (1,), None, *outs, np.int64(-1), b, c, d, e)
    assert kernel.function_name == "echo"  # anything else is the pyopencl kernel's


def test_kernel_look_up_by_identity_is_the_composed_one(tessellator, tea_table):
    from cltess.criteria.tolerance import ObjectSpace, ScreenSpace
    from cltess.kinds import BEZIER, PN

    programs = tessellator.programs
    screen = ScreenSpace(0.5, tea_table.camera)
    for kind in (BEZIER, PN):
        found = programs.kernel("factors", kind=kind, tolerance=screen, pattern=kind.pattern)
        assert found is programs._kernel("factors", None, kind=kind, tolerance=screen, pattern=kind.pattern)
        other = programs.kernel("factors", kind=kind, tolerance=ObjectSpace(0.1), pattern=kind.pattern)
        assert other is not found  # another tolerance kind: another program (-D TOLERANCE_SCREEN)
        assert programs.kernel("factors", kind=kind, tolerance=ScreenSpace(2.0, None), pattern=kind.pattern) is found


def test_stage_3_is_one_launch_on_cpus_for_small_scenes(tessellator, tea_table, monkeypatch):
    monkeypatch.delenv("CLTESS_FUSED_OFFSETS", raising=False)
    device = tessellator.device
    if not opencl.pure_cpu(device):
        pytest.skip("a CPU device's default")
    cpu = opencl.Tessellator(device, work="patch")
    assert cpu.fused_offsets
    small = cpu.plan(tea_table, pixels=0.5)
    assert small.num_patches <= opencl.FUSED_OFFSETS_MAX_PATCHES_CPU
    assert len(small.events["counts"]) == 1  # one launch: stages/offsets.cl
    monkeypatch.setattr(opencl, "FUSED_OFFSETS_MAX_PATCHES_CPU", small.num_patches - 1)
    scans = cpu.plan(tea_table, pixels=0.5)
    assert len(scans.events["counts"]) >= 2  # the counts kernel, then the scan
    for name in ("vertex_offsets", "index_offsets", "factors"):
        assert np.array_equal(getattr(small, name).get(), getattr(scans, name).get()), name


def test_new_cameras_and_tolerances_each_give_their_own_frame(tessellator, tea_table):
    """The arguments that change per frame (camera, tolerance) reach the kernels each time,
    with the program look-up skipped for a camera alone and done again after an override."""
    session = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5)
    camera = tea_table.camera
    near = Camera(eye=0.6 * np.asarray(camera.eye) + 0.4 * np.asarray(camera.target), target=camera.target,
                  up=camera.up)
    frames = [("far", dict(camera=camera)), ("near", dict(camera=near)), ("eps", dict(eps=0.01)),
              ("far again", dict(camera=camera)), ("coarser", dict(camera=near, pixels=4.0)),
              ("near again", dict(camera=near))]
    counts = {}
    for name, options in frames:
        frame = session.tessellate(**options)
        request = session.request_for(**options)
        assert_same_output(frame, tessellator.tessellate(tea_table, request=request))
        counts[name] = frame.num_triangles
    assert counts["far"] == counts["far again"] and counts["near"] == counts["near again"]
    assert len({counts["far"], counts["near"], counts["eps"], counts["coarser"]}) == 4


def test_a_new_work_distribution_mid_session(tessellator, tea_table):
    own = opencl.Tessellator(tessellator.device, work="patch")
    session = cltess.Session(tea_table, tessellator=own, pixels=0.5)
    first = session.tessellate(camera=tea_table.camera).fetch()
    for work in ("point-prep", "patch"):
        own.work = work
        assert_same_output(session.tessellate(camera=tea_table.camera), first)


def test_frames_that_do_not_wait(tessellator, tea_table):
    session = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5)
    waited = session.tessellate(camera=tea_table.camera).fetch()
    expected = {name: np.copy(getattr(waited, name)) for name in HOST_FIELDS}  # (the next frame reuses them)
    frame = session.tessellate(camera=tea_table.camera, wait=False)
    assert "_finish" in frame.__dict__  # nothing waited yet
    assert frame.stage_ms["vertices"] > 0 and "_finish" not in frame.__dict__  # the first look waited
    assert frame.finish() is frame  # again: nothing to do
    for name in HOST_FIELDS:
        assert np.array_equal(getattr(frame, name), expected[name]), name
    wall = frame.wall_ms
    assert 0 <= wall["waits"] <= wall["total"] and wall["total"] == pytest.approx(wall["stages"] + wall["read_back"])
    pending = session.tessellate(camera=tea_table.camera, wait=False)
    on_queue = pending.device.positions.get()  # the session's queue is in order: no wait needed
    later = session.tessellate(camera=tea_table.camera, wait=False)
    with pytest.raises(StaleOutput):
        pending.fetch()
    assert np.array_equal(on_queue, expected["positions"])
    assert np.array_equal(later.fetch().triangles, expected["triangles"])  # fetch waits for the stages
    with pytest.raises(ValueError, match="on_device"):
        plan = tessellator.plan(tea_table, pixels=0.5)
        tessellator.emit_async(plan, 0, plan.num_patches).result(on_device=False, wait=False)


def test_a_cpu_devices_output_is_one_allocation_mapped_once(tessellator, tea_table):
    """On a CPU device the output fields are sub-buffers of one allocation (one map a fetch);
    growing re-makes all of them, and every frame still reads back its own output."""
    session = cltess.Session(tea_table, tessellator=tessellator, eps=0.02)
    if not session.output.mapped:
        pytest.skip("a CPU device's buffers")
    coarse = session.tessellate()
    parent = session.output._parent
    align = max(1, tessellator.device.mem_base_addr_align // 8)
    assert all(buffer.offset % align == 0 and buffer.size >= 1 for buffer, _ in session.output._buffers.values())
    assert_same_output(coarse, tessellator.tessellate(tea_table, eps=0.02))
    fine = session.tessellate(eps=0.002)  # more output: one new allocation for every field
    assert session.output._parent is not parent and session.output.nbytes > parent.size
    assert_same_output(fine, tessellator.tessellate(tea_table, eps=0.002))
    assert len(session.output._maps) == 1  # the fetch mapped once
    again = session.tessellate(eps=0.02)  # fewer: the same allocation
    assert session.output._parent.size == session.output.nbytes
    assert_same_output(again, tessellator.tessellate(tea_table, eps=0.02))


def test_frames_keep_their_kernel_arguments_and_nothing_else_does(tessellator, tea_table, monkeypatch):
    """A Session frame's launches keep their arguments (programs.Kernel, Programs.keep_arguments),
    so the next frame's launches with the same ones only enqueue; two sessions of different scenes
    and one-shot calls on the same kernels in between still each get their own bits, and a
    launch outside a frame keeps nothing (no buffer of a one-shot call outlives it).  (Stage 2 in
    its own launch, the kernel that frames and one-shot calls share: tests/test_crack_offsets.py
    covers frames with it in stage 3's.)"""
    from cltess.scene import Scene

    monkeypatch.setattr(tessellator, "fused_crack_free", False)

    part = Scene(np.asarray(tea_table.patches)[:200] * np.array([1.0, 1.0, 1.1, 1.0]),
                 np.asarray(tea_table.object_ids)[:200], tea_table.camera, "part of the tea table, taller")
    scenes = [tea_table, part]
    sessions = [cltess.Session(scene, tessellator=tessellator, pixels=0.5) for scene in scenes]
    crack_free = tessellator.programs.kernel("crack_free")
    for turn in range(3):
        for scene, session in zip(scenes, sessions):
            frame = session.tessellate(camera=scene.camera)
            assert not tessellator.programs.keep_arguments
            assert crack_free.kept is not None  # kept for the next frame
            assert_same_output(frame, tessellator.tessellate(scene, request=session.request_for(scene.camera)))
            assert crack_free.kept is None  # the one-shot call's launch kept nothing

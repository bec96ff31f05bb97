"""Issue 15's benchmark: how close cltess gets to the memory limit, side by side in one run.

    python bench/frame_loop.py [--device NAME] [--frames 10] [--scenes small] [--json out.json]

On one OpenCL device, in this order, every figure a median (or the best, where said):

1. **Bandwidth.** A plain fill kernel (``out[i] = value``, float4) over a large buffer: the
   device's write bandwidth, best of 5 (profiling events).  Device -> host copies of the same
   buffer into a page-locked host buffer (``ALLOC_HOST_PTR``, mapped once) and into a pageable
   NumPy array: the read-back bandwidths, best of 3 (wall clock).
2. **Uniform level 16.** 1,000 teapots (32,000 patches), every edge factor 16 (``max_factor``
   16, a tolerance every patch misses): 580 MB of output.  Device time of the five stages
   through a ``Session`` (output buffers reused) and through one-shot
   ``Tessellator.tessellate`` (fresh buffers), with the device's default work distribution;
   output bytes / device time as a fraction of the fill bandwidth; the session's read-back
   (``fetch``) rate against the page-locked bandwidth.
2b. **Work distributions side by side** (``Tessellator(work=...)``: "patch", "rows", "vertex",
   "point"; tessellator.py ``WORK_DISTRIBUTIONS``; "point/N": N records per work-item): on uniform level 16 and on each suite scene (0.5 px,
   its own camera), a ``Session`` per distribution; median device ms of stages 1-5, of stage 3
   (counts and scans), 4 and 5 over ``--repeat`` frames; bytes written; GB/s and the fraction
   of the fill bandwidth; and whether every distribution wrote the same bits (a hash of the
   fetched output).  Then stage 3 in one launch (stages/offsets.cl), with one scan of (vertex,
   index) pairs, and with two scans.
   ``--variants-only`` runs sections 1, 2b and nothing else.
3. **Frame loop on the paper's scenes** (``cltess bench``'s suite, 0.5 px): a ``Session``
   follows ``--frames`` cameras on a circle around each scene's camera target.  Per frame:
   the device time (sum of the stages' profiling spans), the host wall time until the stages
   are done and the output is on the device ("device-resident"), and until the caller holds
   host arrays ("host arrays": mapped on a CPU device, copied through page-locked memory on a
   GPU); of each wall, the host time (wall minus the ms blocked waiting for the device,
   ``wall_ms["waits"]``); frames that overlap (``Session.tessellate(wait=False)``: the loop's
   wall clock / frames); and a frame's host time by step (``host_parts``).  The first pass
   over the cameras (kernel builds, uploads, buffers grown) is left out.
   ``--frames-only`` runs sections 3 and 4 and nothing else (``--grid-copies`` picks section
   4's sizes; none: no grid).
4. **Against a one-thread NumPy grid**, from 10k triangles up: P teapot patches at uniform
   factor f; NumPy evaluates the same f x f grid per patch (float32, einsum over Bernstein
   bases, positions, normals, uv, ids and triangles: the same output record) on one thread;
   cltess runs it as a session frame with host arrays, and one-shot.

The time before the first frame (scene generation, host adjacency, kernel builds) is not in
any figure; it is printed per scene as "setup".
"""
from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):  # the NumPy baseline: one thread
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import hashlib  # noqa: E402
import inspect  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pyopencl as cl  # noqa: E402

import cltess  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.tessellator import FUSED_OFFSETS_MAX_PATCHES, WORK_DISTRIBUTIONS  # noqa: E402
from cltess.bench.suite import SUITE, device_info, machine_info, resolve_scenes  # noqa: E402
from cltess.bench.scenes import PIXELS, mesh_camera  # noqa: E402
from cltess.io import load_scene  # noqa: E402
from cltess.scene import Camera, Scene  # noqa: E402
from cltess.tessellation import BYTES_PER_INDEX, BYTES_PER_VERTEX  # noqa: E402

SCENES = Path(__file__).resolve().parent.parent / "scenes"
WALL_KEYS = ("total_wall",)


def say(text: str) -> None:
    print(text, file=sys.stderr, flush=True)

FILL_SOURCE = """
__kernel void fill(__global float4 *out, const float4 value, const ulong count) {
    size_t i = get_global_id(0);
    if (i < count) out[i] = value;
}
"""


def device_ms(tess) -> float:
    return sum(ms for stage, ms in tess.stage_ms.items() if stage not in WALL_KEYS)


def output_bytes(tess) -> int:
    return tess.num_vertices * BYTES_PER_VERTEX + tess.num_triangles * 3 * BYTES_PER_INDEX


# --- 1. bandwidth ----------------------------------------------------------------------------

def bandwidths(tessellator: Tessellator, size: int) -> dict:
    """Fill-kernel write bandwidth (best of 5) and device -> host copy rates (best of 3)."""
    context, queue = tessellator.context, tessellator.queue
    fill = cl.Kernel(cl.Program(context, FILL_SOURCE).build(), "fill")
    count = size // 16
    buffer = cl.Buffer(context, cl.mem_flags.READ_WRITE, count * 16)
    fills = []
    for _ in range(6):
        event = fill(queue, (-(-count // 256) * 256,), (256,), buffer, np.zeros(4, np.float32),
                             np.uint64(count))
        event.wait()
        fills.append((event.profile.end - event.profile.start) * 1e-9)
    pinned_buffer = cl.Buffer(context, cl.mem_flags.READ_WRITE | cl.mem_flags.ALLOC_HOST_PTR, count * 16)
    pinned, _ = cl.enqueue_map_buffer(queue, pinned_buffer, cl.map_flags.READ | cl.map_flags.WRITE, 0, (count * 16,),
                                      np.uint8, is_blocking=True)
    pageable = np.empty(count * 16, np.uint8)
    copies = {"pinned": [], "pageable": []}
    for _ in range(4):
        for name, target in (("pinned", pinned), ("pageable", pageable)):
            started = time.perf_counter()
            cl.enqueue_copy(queue, target, buffer, is_blocking=True)
            copies[name].append(time.perf_counter() - started)
    del pinned
    return {"bytes": count * 16, "fill_bytes_per_s": count * 16 / min(fills[1:]),
            "pinned_read_bytes_per_s": count * 16 / min(copies["pinned"][1:]),
            "pageable_read_bytes_per_s": count * 16 / min(copies["pageable"][1:])}


# --- scenes ----------------------------------------------------------------------------------

def teapots(copies: int) -> Scene:
    """``copies`` teapots (32 patches each) on a square grid, each turned about z."""
    teapot = load_scene(SCENES / "teapot.bez")
    side = math.ceil(math.sqrt(copies))
    patches = []
    for k in range(copies):
        c, s = math.cos(0.7 * k), math.sin(0.7 * k)
        matrix = np.array([[c, -s, 0, 8.0 * (k % side)], [s, c, 0, 8.0 * (k // side)], [0, 0, 1, 0], [0, 0, 0, 1]])
        patches.append(np.asarray(teapot.patches, np.float64) @ matrix.T)
    patches = np.concatenate(patches)
    return Scene(patches, np.zeros(len(patches), np.int32), None, f"{copies} teapots")


def uniform_request(factor: int) -> dict:
    """Every edge factor ``factor``: the bound asks for more than that everywhere."""
    return {"eps": 1e-7, "max_factor": factor}


def suite_scene(key: str) -> Scene:
    spec = SUITE[key]
    built = spec.build()
    if spec.kind == "pn":
        mesh, view = built
        return Scene.from_trimesh(mesh, camera=mesh_camera(mesh, **view), name=key)
    return built


def orbit(camera: Camera, count: int):
    """``count`` cameras on the circle through ``camera``'s eye about its target (around z),
    a full turn."""
    target = np.asarray(camera.target, float)
    offset = np.asarray(camera.eye, float) - target
    for k in range(count):
        angle = 2 * math.pi * k / count
        c, s = math.cos(angle), math.sin(angle)
        turned = np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], offset[2]])
        yield Camera(eye=target + turned, target=target, up=camera.up, fov_y_deg=camera.fov_y_deg,
                     width=camera.width, height=camera.height, near=camera.near, far=camera.far)


# --- the frame loop ----------------------------------------------------------------------------

def frames(session, cameras, host: bool, **overrides) -> list[dict]:
    """Per frame: device ms, wall ms until the output is on the device, and (host) until the
    caller holds host arrays; of the wall, the ms blocked in waits for the device (the rest is
    host work: Python, launches, copies' set-up)."""
    out = []
    for camera in cameras:
        if host and HOST_FRAMES:  # the read-back enqueued with the stages (Session.tessellate(host=True))
            frame = session.tessellate(camera=camera, host=True, **overrides)
        else:
            frame = session.tessellate(camera=camera, **overrides)
        if host:
            frame.fetch()
        total = frame.wall_ms.get("total", frame.wall_ms["stages"])
        waits = frame.wall_ms.get("waits", math.nan)  # (a tree before wall_ms["waits"]: NaN)
        out.append({"device_ms": device_ms(frame), "stages_wall_ms": frame.wall_ms["stages"],
                    "total_wall_ms": total, "waits_ms": waits, "host_ms": total - waits,
                    "read_back_ms": frame.wall_ms.get("read_back", 0.0), "triangles": frame.num_triangles,
                    "bytes": output_bytes(frame)})
    return out


def overlapped(session, cameras, rounds: int = 3) -> dict:
    """Frames that overlap (``Session.tessellate(wait=False)``): each call returns once its
    stages are enqueued, so the host's next frame runs while the device works on this one.
    Wall per frame: the loop's wall clock over its frames, until the last frame is finished
    (a throughput: a call that returns at once because the device is behind is paid for by a
    later call that waits), the median over ``rounds`` loops, alternating with the same loop of
    frames that wait (``wait=True``: "looped").  (The median interval between returns, which
    an earlier version reported, undercounts once frames pipeline two deep: calls then
    alternate between returning at once and waiting for two frames.)"""
    means = {True: [], False: []}
    device, not_fit = [], 0  # not_fit: frames launched on too small buffers (Session: run again or stale)
    clock = time.perf_counter
    for _ in range(rounds):
        for wait in (True, False):
            kept = []
            started = clock()
            for camera in cameras:
                kept.append(session.tessellate(camera=camera, wait=wait))
            kept[-1].finish()
            means[wait].append((clock() - started) / len(cameras))
            device += [device_ms(frame) for frame in kept]  # (their stages are done: in-order queue)
            not_fit += sum(frame.stats.get("output_fit") is False for frame in kept)
    return {"looped_wall_ms": statistics.median(means[True]) * 1e3,
            "overlapped_wall_ms": statistics.median(means[False]) * 1e3,
            "overlapped_device_ms": statistics.median(device), "frames_not_fit": not_fit}


def session_scratch(session, key) -> dict:
    """The per-patch arrays of stages 1-3 that a Session's first buffer set keeps for ``key`` (a
    tree before ``Session(buffers=)``: the session's one dict of them)."""
    if hasattr(session, "_sets"):
        return session._sets[0].scratch.setdefault(key, {})
    return session._scratch.setdefault(key, {})


def host_parts(session, cameras, rounds: int = 3) -> dict:
    """A frame's host time split into its steps (``Session.tessellate``'s, one by one), median
    µs over the frames: the request for the camera, program look-up (skipped for a new camera
    alone where the tree does), stages 1-3 enqueued, the wait for their totals, stages 4-5
    enqueued, the wait for them and the result, and the read-back to host arrays (and its
    wait).  The waits are timed by wrapping ``pyopencl.wait_for_events``, through which every
    tree waits, so that the script gives the same split for a tree before this one.  A tree
    whose Session frames launch stages 4-5 before reading the totals (``plan_on(defer_totals=
    True)``) is timed that way: its totals are waited for within "stages 4-5 wait + result"."""
    tessellator, clock = session.tessellator, time.perf_counter_ns
    parts = {name: [] for name in ("request", "compose", "stages 1-3 (host)", "totals wait", "stages 4-5 (host)",
                                   "stages 4-5 wait + result", "of which wait", "fetch (host arrays)",
                                   "of which read-back wait", "host, total", "wall, total")}
    key = session.request.sharp_edges
    waits, wait_for_events = [], cl.wait_for_events
    deferred = {"defer_totals": True} if "defer_totals" in inspect.signature(tessellator.plan_on).parameters else {}

    def timed_wait(events):
        started = clock()
        wait_for_events(events)
        waits.append(clock() - started)

    cl.wait_for_events = timed_wait
    try:
        for _ in range(rounds):
            for camera in cameras:
                waits.clear()
                t0 = clock()
                request = session.request_for(camera)
                t1 = clock()
                if getattr(session, "_composed", None) is None:  # (a tree before the skip: every frame)
                    tessellator.compose(session.scene, request)
                t2 = clock()
                plan = tessellator.plan_on(session._scene_data[key], request, None, session_scratch(session, key),
                                           **deferred)
                t3 = clock()
                totals = sum(waits)
                pending = tessellator.emit_async(plan, 0, plan.num_patches, out=session.output)
                t4 = clock()
                frame = pending.result(on_device=True)
                t5 = clock()
                stages45 = sum(waits) - totals
                frame.fetch()
                t6 = clock()
                read_back = sum(waits) - totals - stages45
                for name, value in (("request", t1 - t0), ("compose", t2 - t1),
                                    ("stages 1-3 (host)", t3 - t2 - totals), ("totals wait", totals),
                                    ("stages 4-5 (host)", t4 - t3), ("stages 4-5 wait + result", t5 - t4),
                                    ("of which wait", stages45), ("fetch (host arrays)", t6 - t5),
                                    ("of which read-back wait", read_back),
                                    ("host, total", t6 - t0 - sum(waits)), ("wall, total", t6 - t0)):
                    parts[name].append(value / 1e3)
    finally:
        cl.wait_for_events = wait_for_events
    return {name: statistics.median(values) for name, values in parts.items()}


def median(rows: list[dict], key: str) -> float:
    return statistics.median(r[key] for r in rows)


def frame_loop(tessellator, key: str, count: int) -> dict:
    started = time.perf_counter()
    scene = suite_scene(key)
    session = cltess.Session(scene, tessellator=tessellator, pixels=PIXELS)
    path = list(orbit(scene.camera, count))
    session.tessellate(camera=path[0]).fetch()  # builds, uploads, host adjacency
    setup = time.perf_counter() - started
    for camera in path:  # the output buffers at the size the path needs
        session.tessellate(camera=camera)
    resident = frames(session, path, host=False)
    held = frames(session, path, host=True)
    return {"scene": key, "setup_s": setup, "frames": count,
            "triangles": median(resident, "triangles"), "device_ms": median(resident, "device_ms"),
            "resident_wall_ms": median(resident, "stages_wall_ms"), "resident_host_ms": median(resident, "host_ms"),
            "host_wall_ms": median(held, "total_wall_ms"), "host_host_ms": median(held, "host_ms"),
            "host_device_ms": median(held, "device_ms"), "read_back_ms": median(held, "read_back_ms"),
            **(overlapped(session, path) if OVERLAPS else {}), "parts": host_parts(session, path)}


#: Whether this cltess has Session.tessellate(wait=False) (the script also runs on older trees
#: through PYTHONPATH, for before/after figures).
OVERLAPS = "wait" in inspect.signature(cltess.Session.tessellate).parameters
#: Whether it has Session.tessellate(host=True) (frames for host arrays: the read-back enqueued
#: with the stages); the "host arrays" figures use it where there, else tessellate() and fetch().
HOST_FRAMES = "host" in inspect.signature(cltess.Session.tessellate).parameters


def frame_report(record: dict) -> list[str]:
    lines = [f"Frame loop, {record['frames']} cameras per scene, {PIXELS} px (median per frame, ms; device: the "
             "stages' profiling spans; host: wall minus the waits for the device; overlapped: "
             "Session.tessellate(wait=False), a loop's wall clock over its frames, until its last frame is finished, "
             "median of 3 loops; looped: the same loop with frames that wait):", "",
             "| scene | triangles | device | on device: wall | host | ratio | host arrays: wall | host | ratio | "
             "looped: wall | overlapped: wall | ratio | setup s |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for f in record["frame_loop"]:
        lines.append(f"| {f['scene']} | {f['triangles']:,.0f} | {f['device_ms']:.3f} | {f['resident_wall_ms']:.3f} | "
                     f"{f['resident_host_ms']:.3f} | {f['resident_wall_ms'] / f['device_ms']:.2f}x | "
                     f"{f['host_wall_ms']:.3f} | {f['host_host_ms']:.3f} | "
                     f"{f['host_wall_ms'] / f['host_device_ms']:.2f}x | {f.get('looped_wall_ms', math.nan):.3f} | "
                     f"{f.get('overlapped_wall_ms', math.nan):.3f} | "
                     f"{f.get('overlapped_wall_ms', math.nan) / f.get('overlapped_device_ms', 1.0):.2f}x | "
                     f"{f['setup_s']:.1f} |")
    not_fit = sum(f.get("frames_not_fit", 0) for f in record["frame_loop"])
    lines += ["", f"Overlapped frames launched on buffers too small for them (run again, or stale): {not_fit}."]
    names = list(record["frame_loop"][0]["parts"]) if record["frame_loop"] else []
    lines += ["", "A frame's host time by step (µs, median; Session.tessellate's steps one by one, then fetch):", "",
              "| step | " + " | ".join(f["scene"] for f in record["frame_loop"]) + " |",
              "|---|" + "---|" * len(record["frame_loop"])]
    for name in names:
        lines.append(f"| {name} | " + " | ".join(f"{f['parts'][name]:.0f}" for f in record["frame_loop"]) + " |")
    return lines


# --- 2. uniform level 16 -----------------------------------------------------------------------

def uniform(tessellator, scene, factor: int, repeat: int, band: dict) -> dict:
    session = cltess.Session(scene, tessellator=tessellator, **uniform_request(factor))
    first = session.tessellate().fetch()
    runs = [session.tessellate() for _ in range(repeat)]
    stage_ms = {stage: statistics.median(r.stage_ms[stage] for r in runs)
                for stage in runs[0].stage_ms if stage not in WALL_KEYS}
    device = statistics.median(device_ms(r) for r in runs)
    size = output_bytes(first)
    fetched = []
    for _ in range(repeat):
        frame = session.tessellate()
        frame.fetch()
        fetched.append(frame.wall_ms["read_back"])
    one_shot = []
    for _ in range(max(1, repeat // 2)):
        tess = tessellator.tessellate(scene, **uniform_request(factor))
        one_shot.append((device_ms(tess), tess.wall_ms["total"]))
        del tess
    read_back = statistics.median(fetched)
    return {            "patches": scene.num_patches, "factor": factor, "triangles": first.num_triangles, "bytes": size,
            "stage_ms": stage_ms, "device_ms": device,
            "vertices_indices_ms": stage_ms.get("vertices", 0) + stage_ms.get("indices", 0),
            "fraction_of_fill": size / (device / 1e3) / band["fill_bytes_per_s"],
            "stages45_fraction_of_fill": size / ((stage_ms.get("vertices", 0) + stage_ms.get("indices", 0)) / 1e3)
            / band["fill_bytes_per_s"],
            "read_back_ms": read_back, "read_back_bytes_per_s": size / (read_back / 1e3) if read_back else math.inf,
            "one_shot_device_ms": statistics.median(d for d, _ in one_shot),
            "one_shot_total_ms": statistics.median(t for _, t in one_shot)}


# --- 2b. the work distributions side by side ---------------------------------------------------

def output_digest(tess) -> str:
    """A hash of the fetched output (every vertex field and the triangles)."""
    digest = hashlib.blake2b(digest_size=8)
    for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles"):
        digest.update(np.ascontiguousarray(getattr(tess, field)).tobytes())
    return digest.hexdigest()


#: The side-by-side table's variants: a work distribution, "/N": N records per work-item of the
#: record kernels (Tessellator.records_per_item; without: RECORDS_PER_ITEM), ":direct": stage 4
#: by direct evaluation (forward_differencing=False; bitwise other bits than with it, so its
#: "same bits" is among the ":direct" variants of the scene).
VARIANTS = ["patch", "rows", "vertex", "point", "point/1", "point/16", "vertex-prep", "point-prep"]
#: The GPU comparison of issue 15 (stage 4 from prepared patches), forward differencing on and off.
GPU_VARIANTS = ["patch", "vertex", "point", "point/16", "vertex-prep", "point-prep", "point-prep/16", "rows-prep",
                "auto", "patch:direct", "vertex:direct", "point/16:direct", "vertex-prep:direct", "point-prep:direct",
                "point-prep/16:direct"]


def work_variants(tessellator, scenes, repeat: int, band: dict, works=VARIANTS) -> list[dict]:
    """scenes: (name, Scene, request options).  One record per (scene, work distribution)."""
    out, saved = [], (tessellator.work, tessellator.records_per_item)
    try:
        for name, scene, request in scenes:
            for work in works:
                say(f"work distributions: {name}, {work}")
                spec, _, evaluation = work.partition(":")
                tessellator.work, _, per_item = spec.partition("/")
                tessellator.records_per_item = int(per_item) if per_item else None
                options = dict(request, forward_differencing=False) if evaluation == "direct" else request
                session = cltess.Session(scene, tessellator=tessellator, **options)
                first = session.tessellate().fetch()  # builds, uploads; its bits
                digest, size, triangles = output_digest(first), output_bytes(first), first.num_triangles
                del first
                runs = [session.tessellate() for _ in range(repeat)]
                stage = {key: statistics.median(r.stage_ms.get(key, 0.0) for r in runs)
                         for key in ("counts", "vertices", "indices")}
                device = statistics.median(device_ms(r) for r in runs)
                out.append({"scene": name, "work": work, "triangles": triangles, "bytes": size, "digest": digest,
                            "device_ms": device, "counts_ms": stage["counts"], "vertices_ms": stage["vertices"],
                            "indices_ms": stage["indices"],
                            "fraction_of_fill": size / (device / 1e3) / band["fill_bytes_per_s"]})
                del runs, session
    finally:
        tessellator.work, tessellator.records_per_item = saved
    return out


def scan_variants(tessellator, scenes, repeat: int) -> list[dict]:
    """Stage 3 (counts and offsets) with one scan of (vertex, index) pairs against two scans
    (``Tessellator.one_scan``), median device ms over session frames, per scene."""
    out, saved = [], (tessellator.one_scan, tessellator.fused_offsets)
    try:
        for name, scene, request in scenes:
            row = {"scene": name, "patches": scene.num_patches}
            for key, one, fused in (("fused_ms", True, True), ("one_scan_ms", True, False),
                                    ("two_scans_ms", False, False)):
                tessellator.one_scan, tessellator.fused_offsets = one, fused
                session = cltess.Session(scene, tessellator=tessellator, **request)
                session.tessellate()
                runs = [session.tessellate() for _ in range(repeat)]
                row[key] = statistics.median(r.stage_ms["counts"] for r in runs)
                del runs, session
            out.append(row)
    finally:
        tessellator.one_scan, tessellator.fused_offsets = saved
    return out


def variants_report(rows: list[dict], band: dict) -> list[str]:
    lines = [f"Work distributions side by side (device ms, median of the frames; GB/s = bytes written / "
             f"stages 1-5; fill {band['fill_bytes_per_s'] / 1e9:.1f} GB/s):", "",
             "| scene | triangles | MB written | work | stages 1-5 ms | stage 3 ms | stage 4 ms | stage 5 ms | "
             "GB/s | % of fill | same bits |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        direct = row["work"].endswith(":direct")
        peers = {r["digest"] for r in rows if r["scene"] == row["scene"] and r["work"].endswith(":direct") == direct}
        lines.append(f"| {row['scene']} | {row['triangles']:,} | {row['bytes'] / 1e6:.1f} | {row['work']} | "
                     f"{row['device_ms']:.3f} | {row['counts_ms']:.3f} | {row['vertices_ms']:.3f} | "
                     f"{row['indices_ms']:.3f} | {row['bytes'] / (row['device_ms'] / 1e3) / 1e9:.1f} | "
                     f"{100 * row['fraction_of_fill']:.1f}% | {'yes' if len(peers) == 1 else 'NO'} |")
    return lines


# --- 4. the one-thread NumPy grid --------------------------------------------------------------

def bernstein(t):
    s = 1 - t
    return np.stack([s ** 3, 3 * t * s ** 2, 3 * t ** 2 * s, t ** 3], axis=-1)


def bernstein_derivative(t):
    s = 1 - t
    return np.stack([-3 * s ** 2, 3 * s ** 2 - 6 * t * s, 6 * t * s - 3 * t ** 2, 3 * t ** 2], axis=-1)


def numpy_grid(patches: np.ndarray, factor: int) -> dict:
    """The f x f grid of every patch in plain NumPy, float32, one thread: positions, unit
    normals, uv, patch and object ids, and 2 f^2 triangles per patch."""
    patches = np.asarray(patches, np.float32)  # (P, 4 v, 4 u, 4) homogeneous
    t = np.linspace(0, 1, factor + 1, dtype=np.float32)
    b, d = bernstein(t), bernstein_derivative(t)
    rows = np.einsum("ui,pjic->pujc", b, patches)
    rows_u = np.einsum("ui,pjic->pujc", d, patches)
    h = np.einsum("vj,pujc->pvuc", b, rows)
    h_u = np.einsum("vj,pujc->pvuc", b, rows_u)
    h_v = np.einsum("vj,pujc->pvuc", d, rows)
    w = h[..., 3:]
    positions = h[..., :3] / w
    s_u = (h_u[..., :3] - positions * h_u[..., 3:]) / w
    s_v = (h_v[..., :3] - positions * h_v[..., 3:]) / w
    normals = np.cross(s_u, s_v)
    normals /= np.maximum(np.linalg.norm(normals, axis=-1, keepdims=True), np.float32(1e-30))
    count, side = len(patches), factor + 1
    u, v = np.meshgrid(t, t)
    uv = np.broadcast_to(np.stack([u, v], -1), (count, side, side, 2)).reshape(-1, 2).copy()
    patch_ids = np.repeat(np.arange(count, dtype=np.int32), side * side)
    object_ids = np.zeros(count * side * side, np.int32)
    j, i = np.meshgrid(np.arange(factor), np.arange(factor), indexing="ij")
    corner = (j * side + i).ravel()
    cell = np.stack([corner, corner + 1, corner + side + 1, corner + side], -1)
    template = np.concatenate([cell[:, [0, 1, 2]], cell[:, [0, 2, 3]]]).astype(np.uint32)
    triangles = (template[None] + (np.arange(count, dtype=np.uint32) * side * side)[:, None, None]).reshape(-1, 3)
    return {"positions": positions.reshape(-1, 3), "normals": normals.reshape(-1, 3), "uv": uv,
            "patch_ids": patch_ids, "object_ids": object_ids, "triangles": triangles}


def grid_sizes(tessellator, sizes: list[tuple[int, int]], repeat: int) -> list[dict]:
    out = []
    teapot = teapots(1)
    for copies, factor in sizes:
        scene = teapots(copies) if copies > 1 else teapot
        session = cltess.Session(scene, tessellator=tessellator, **uniform_request(factor))
        session.tessellate().fetch()
        frames_ = []
        for _ in range(repeat):
            frame = session.tessellate()
            frame.fetch()
            frames_.append((frame.wall_ms["total"], device_ms(frame), frame.num_triangles))
        shots = []
        for _ in range(max(1, repeat // 2)):
            tess = tessellator.tessellate(scene, **uniform_request(factor))
            shots.append(tess.wall_ms["total"])
            del tess
        grid = []
        for _ in range(max(1, repeat // 2)):
            started = time.perf_counter()
            result = numpy_grid(scene.patches, factor)
            grid.append((time.perf_counter() - started) * 1e3)
            triangles_numpy = len(result["triangles"])
            del result
        out.append({"patches": scene.num_patches, "factor": factor, "triangles": frames_[0][2],
                    "numpy_triangles": triangles_numpy,
                    "session_host_ms": statistics.median(f[0] for f in frames_),
                    "session_device_ms": statistics.median(f[1] for f in frames_),
                    "one_shot_ms": statistics.median(shots), "numpy_ms": statistics.median(grid)})
    return out


# --- the report --------------------------------------------------------------------------------

def report(record: dict) -> str:
    band = record["bandwidth"]
    gb = lambda x: f"{x / 1e9:.1f}"  # noqa: E731
    lines = [f"Device: {record['device']['name']} ({record['device']['platform']}); host "
             f"{record['machine']['cpu']}, {record['machine']['cpus']} CPUs; load average before "
             f"{record['load_before']}, after {record['load_after']}; default work distribution "
             f"{record['default_work']}.", "",
             "| fill kernel write GB/s | device -> pinned host GB/s | device -> pageable host GB/s | buffer MiB |",
             "|---|---|---|---|",
             f"| {gb(band['fill_bytes_per_s'])} | {gb(band['pinned_read_bytes_per_s'])} | "
             f"{gb(band['pageable_read_bytes_per_s'])} | {band['bytes'] >> 20} |", ""]
    lines += variants_report(record["variants"], band) + [""]
    lines += ["Stage 3 (counts and offsets), device ms, default work distribution; fused: stages/offsets.cl, one "
              f"launch per range (above {FUSED_OFFSETS_MAX_PATCHES:,} patches: the one scan):", "",
              "| scene | patches | fused | one scan of (vertex, index) pairs | two scans |", "|---|---|---|---|---|"]
    lines += [f"| {r['scene']} | {r['patches']:,} | {r['fused_ms']:.3f} | {r['one_scan_ms']:.3f} | "
              f"{r['two_scans_ms']:.3f} |" for r in record["scans"]] + [""]
    if "uniform" not in record:  # --variants-only
        return "\n".join(lines)
    level = record["uniform"]
    lines += [
             f"Uniform factor {level['factor']}, {level['patches']:,} patches, {level['triangles']:,} triangles, "
             f"{level['bytes'] / 1e6:.0f} MB of output:", "",
             "| | ms | GB/s of output | % of fill bandwidth |", "|---|---|---|---|"]
    size = level["bytes"]
    for label, ms in (("device, stages 1-5 (session)", level["device_ms"]),
                      ("device, stages 4-5 (session)", level["vertices_indices_ms"]),
                      ("device, stage 4 alone (session)", level["stage_ms"].get("vertices", 0.0)),
                      ("device, stages 1-5 (one-shot, fresh buffers)", level["one_shot_device_ms"]),
                      ("one-shot end to end, host arrays", level["one_shot_total_ms"]),
                      ("session read-back (fetch)", level["read_back_ms"])):
        rate = size / (ms / 1e3) if ms else math.inf
        lines.append(f"| {label} | {ms:.2f} | {gb(rate)} | {100 * rate / band['fill_bytes_per_s']:.0f}% |")
    lines += ["", f"Read-back: {gb(level['read_back_bytes_per_s'])} GB/s = "
              f"{100 * level['read_back_bytes_per_s'] / band['pinned_read_bytes_per_s']:.0f}% of the pinned copy rate "
              f"(on a CPU device the read-back is a mapping: no copy).", ""]
    lines += frame_report(record)
    lines += grid_report(record)
    return "\n".join(lines)


def grid_report(record: dict) -> list[str]:
    lines = ["", "Against a one-thread NumPy grid (uniform factor f, ms; cltess: host arrays held):", "",
             "| patches | f | triangles | NumPy grid | cltess session frame | (its device time) | cltess one-shot | "
             "NumPy / session |", "|---|---|---|---|---|---|---|---|"]
    for g in record["grid"]:
        lines.append(f"| {g['patches']:,} | {g['factor']} | {g['triangles']:,} | {g['numpy_ms']:.2f} | "
                     f"{g['session_host_ms']:.2f} | {g['session_device_ms']:.2f} | {g['one_shot_ms']:.2f} | "
                     f"{g['numpy_ms'] / g['session_host_ms']:.1f}x |")
    return lines


def frames_only(tessellator, record: dict, keys: list, args) -> int:
    """--frames-only: section 3 (the frame loop, with the host time by step) and section 4."""
    record["frame_loop"] = []
    for key in keys:
        say(f"frame loop: {key}")
        record["frame_loop"].append(frame_loop(tessellator, key, args.frames))
    lines = [f"Device: {record['device']['name']} ({record['device']['platform']}); load average before "
             f"{record['load_before']}; default work distribution {record['default_work']}; fused stage 3 "
             f"{tessellator.fused_offsets}.", ""] + frame_report(record)
    if args.grid_copies:
        say("NumPy grid")
        record["grid"] = grid_sizes(tessellator, [(copies, 13) for copies in args.grid_copies], args.repeat)
        lines += grid_report(record)
    record["load_after"] = [round(x, 1) for x in os.getloadavg()]
    print("\n".join(lines + ["", f"Load average after: {record['load_after']}."]))
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1, default=float) + "\n")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", help="OpenCL device (substring; default as cltess picks)")
    parser.add_argument("--frames", type=int, default=10, help="cameras per scene in the frame loop")
    parser.add_argument("--repeat", type=int, default=5, help="runs per figure of the uniform and grid tables")
    parser.add_argument("--scenes", nargs="*", default=["all"], help="suite scenes or groups (all, bezier, pn, small)")
    parser.add_argument("--copies", type=int, default=1000, help="teapots of the uniform level-16 scene")
    parser.add_argument("--bandwidth-mib", type=int, default=512, help="buffer of the fill and copy measurements")
    parser.add_argument("--json", help="write the record here too")
    parser.add_argument("--work", nargs="*", default=VARIANTS,
                        help=f"work distributions of the side-by-side table ({', '.join(WORK_DISTRIBUTIONS)}; "
                             f"'point/N': N records per work-item; ':direct' suffix: no forward differencing; "
                             f"'gpu': {' '.join(GPU_VARIANTS)}; default: {' '.join(VARIANTS)})")
    parser.add_argument("--variants-only", action="store_true",
                        help="bandwidth and the work distributions side by side only (no frame loop, no NumPy grid)")
    parser.add_argument("--frames-only", action="store_true",
                        help="the frame loop (device, host and wall per frame; the host time by step) and the "
                             "NumPy grid only")
    parser.add_argument("--grid-copies", type=int, nargs="*", default=[1, 10, 100, 1000],
                        help="teapots of the NumPy grid's sizes (factor 13: 10,712 triangles per teapot)")
    args = parser.parse_args(argv)
    args.work = [w for work in args.work for w in (GPU_VARIANTS if work == "gpu" else [work])]
    for work in args.work:
        spec, _, evaluation = work.partition(":")
        name, _, per_item = spec.partition("/")
        if name not in WORK_DISTRIBUTIONS or (per_item and not per_item.isdigit()) or evaluation not in ("", "direct"):
            parser.error(f"--work {work}: expected one of {', '.join(WORK_DISTRIBUTIONS)}, optionally /N, "
                         "optionally :direct")
    tessellator = Tessellator(args.device)
    record = {"device": device_info(tessellator.device), "machine": machine_info(), "frames": args.frames,
              "command": " ".join(sys.argv), "date": time.strftime("%Y-%m-%d %H:%M:%S %z"),
              "load_before": [round(x, 1) for x in os.getloadavg()], "default_work": tessellator.work}
    keys = resolve_scenes(args.scenes)
    if args.frames_only:
        return frames_only(tessellator, record, keys, args)
    say("bandwidth")
    size = min(args.bandwidth_mib << 20, tessellator.device.max_mem_alloc_size // 2)
    record["bandwidth"] = bandwidths(tessellator, size)
    level16 = teapots(args.copies)
    scenes = [(f"uniform 16 ({level16.num_patches:,} patches)", level16, uniform_request(16))]
    scenes += [(key, suite_scene(key), {"pixels": PIXELS}) for key in keys]
    record["variants"] = work_variants(tessellator, scenes, args.repeat, record["bandwidth"], args.work)
    say("stage 3: one scan, two scans")
    record["scans"] = scan_variants(tessellator, scenes, args.repeat)
    del scenes
    if not args.variants_only:
        say("uniform level 16")
        record["uniform"] = uniform(tessellator, level16, 16, args.repeat, record["bandwidth"])
        record["frame_loop"] = []
        for key in keys:
            say(f"frame loop: {key}")
            record["frame_loop"].append(frame_loop(tessellator, key, args.frames))
        say("NumPy grid")
        sizes = [(copies, 13) for copies in args.grid_copies]  # 1, 10, 100, 1000: 10k, 100k, 1M, 10M triangles
        record["grid"] = grid_sizes(tessellator, sizes, args.repeat)
    record["load_after"] = [round(x, 1) for x in os.getloadavg()]
    print(report(record))
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1, default=float) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

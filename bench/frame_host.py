"""Issue 15, the host side of a frame: wall time per frame against device time, side by side
with another checkout (e.g. main before a change), children interleaved.

    python bench/frame_host.py [--device NAME] [--frames 20] [--repeat 3] [--scenes all]
                               [--grid] [--baseline SOURCE_TREE] [--json out.json]

Each child process (this tree, then ``PYTHONPATH=SOURCE_TREE`` for the baseline, alternating
``--repeat`` times) runs ``bench/frame_loop.py``'s frame loop: a ``cltess.Session`` per suite
scene at 0.5 px, ``--frames`` cameras on a circle (after one warm-up pass over them), and per
frame records

* device ms: the sum of the stages' OpenCL profiling spans;
* "on device": wall ms of ``session.tessellate(camera=...)``, until the stages are done and the
  output is on the device;
* "host arrays": wall ms of ``session.tessellate(camera=..., host=True).fetch()`` (a tree
  before ``host=``: ``session.tessellate(camera=...).fetch()``), until the caller holds host
  arrays (a mapping on a CPU device, a copy through page-locked memory on a GPU);
* "(host)" after each: that wall minus the ms blocked in ``pyopencl.wait_for_events`` (patched
  in the child to time it, in both trees): the host's own work per frame;
* "looped", "overlap" (a tree with ``Session.tessellate(wait=False)``): a loop over the cameras
  with frames that wait and with frames that overlap, the loop's wall clock over its frames
  until the last one is finished (``frame_loop.overlapped``);
* "piped", "ratio" (a tree with ``Session(buffers=2)``): host-array frames pipelined on two
  buffer sets, frame k+1 enqueued (``host=True, wait=False``) before frame k's arrays are
  fetched, as a renderer that uses frame k while the device computes frame k+1: the loop's wall
  clock per frame until the last frame's arrays are held (median of 3 loops), over the *device*
  column (the waited frames' device time: on a CPU device the pipelined frames' own device time
  rises, their kernels sharing the cores with the host's work);
* "host µs": the host thread's CPU time per overlapped frame less its CPU time in waits (the
  smallest of the children's medians): the frame's own host work, Python and the runtime's
  calls, measured by CPU time so that on a CPU device the device's threads do not count;
  "waits µs": in the same loops, the wall µs per frame blocked in waits (the child's shown):
  an overlapped loop whose wall is above its host work and device time waits there.

``--as-gpu`` makes the frames a GPU makes (work "point", stage 3 in one or two launches, as
``bench/frame_calls.py --as-gpu``) on a CPU device: its device times mean nothing, its host
columns are the GPU path's host work on this machine's cores.

Per scene the report gives, for each tree, the median over frames, then the *smallest* of the
``--repeat`` children's medians (the machine is shared: the least disturbed run), and the
ratio wall / device of the same child.  ``--grid`` adds ``frame_loop.py``'s one-thread NumPy
grid against a session frame with host arrays (10k .. 10M triangles; this tree only).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def child(args) -> dict:
    sys.path.insert(0, str(HERE))
    import warnings

    warnings.simplefilter("ignore")
    import frame_loop as fl
    import inspect
    import pyopencl as cl
    import cltess

    waited = [0]  # ns blocked in pyopencl.wait_for_events (both trees wait through it)
    waited_cpu = [0]  # the host thread's CPU ns in those waits (a runtime may spin)
    wait_for_events = cl.wait_for_events

    def timed_wait(events):
        started, cpu = time.perf_counter_ns(), time.thread_time_ns()
        wait_for_events(events)
        waited[0] += time.perf_counter_ns() - started
        waited_cpu[0] += time.thread_time_ns() - cpu

    def overlapped_host_cpu(session, path, rounds: int = 3) -> tuple[float, float]:
        """The host thread's CPU µs per frame in a loop of overlapped frames (until the last one
        is finished), less its CPU time in waits: the frame's host work, Python and the runtime's
        calls, whatever else runs on the machine's cores; and the wall µs per frame blocked in
        waits in the same loop (the last frame's finish included); medians of ``rounds`` loops."""
        loops, waits = [], []
        for _ in range(rounds):
            waited[0] = waited_cpu[0] = 0
            cpu = time.thread_time_ns()
            frames = [session.tessellate(camera=camera, wait=False) for camera in path]
            frames[-1].finish()
            loops.append((time.thread_time_ns() - cpu - waited_cpu[0]) / len(path) / 1e3)
            waits.append(waited[0] / len(path) / 1e3)
        return statistics.median(loops), statistics.median(waits)

    def piped(scene, path, rounds: int = 3) -> tuple[float, float]:
        """(wall ms per frame, median device ms) of host-array frames pipelined on two buffer sets
        (the module's "piped"), median of ``rounds`` loops, after a pass that sizes and records
        both sets."""
        session = cltess.Session(scene, tessellator=tessellator, pixels=fl.PIXELS, buffers=2)
        for camera in path:
            session.tessellate(camera=camera, host=True)
        walls, device = [], []
        for _ in range(rounds):
            started = time.perf_counter()
            previous = session.tessellate(camera=path[0], host=True, wait=False)
            for camera in path[1:]:
                frame = session.tessellate(camera=camera, host=True, wait=False)
                previous.fetch()
                device.append(fl.device_ms(previous))
                previous = frame
            previous.fetch()
            device.append(fl.device_ms(previous))
            walls.append((time.perf_counter() - started) / len(path) * 1e3)
        return statistics.median(walls), statistics.median(device)

    cl.wait_for_events = timed_wait
    overlaps = "wait" in inspect.signature(cltess.Session.tessellate).parameters
    pipelines = "buffers" in inspect.signature(cltess.Session).parameters
    host_frames = "host" in inspect.signature(cltess.Session.tessellate).parameters
    from cltess.backends.opencl import Tessellator
    from cltess.bench.suite import device_info, resolve_scenes

    tessellator = Tessellator(args.device, work="point" if args.as_gpu else None)
    if args.as_gpu:  # a GPU's choices on this device (bench/frame_calls.py --as-gpu)
        tessellator.fused_offsets, tessellator.tiled_offsets, tessellator._cpu = True, True, False
    rows = []
    for key in resolve_scenes(args.scenes):
        scene = fl.suite_scene(key)
        session = cltess.Session(scene, tessellator=tessellator, pixels=fl.PIXELS)
        path = list(fl.orbit(scene.camera, args.frames))
        for camera in path:  # warm-up: builds, uploads, buffers at their size
            session.tessellate(camera=camera).fetch()
        resident, held, device, resident_host, held_host = [], [], [], [], []
        for camera in path:
            waited[0] = 0
            started = time.perf_counter()
            frame = session.tessellate(camera=camera)
            resident.append((time.perf_counter() - started) * 1e3)
            resident_host.append(resident[-1] - waited[0] / 1e6)
            device.append(fl.device_ms(frame))
        for camera in path:
            waited[0] = 0
            started = time.perf_counter()
            if host_frames:  # the read-back enqueued with the stages
                session.tessellate(camera=camera, host=True).fetch()
            else:
                session.tessellate(camera=camera).fetch()
            held.append((time.perf_counter() - started) * 1e3)
            held_host.append(held[-1] - waited[0] / 1e6)
        row = {"scene": key, "triangles": frame.num_triangles, "device_ms": statistics.median(device),
               "resident_ms": statistics.median(resident), "host_ms": statistics.median(held),
               "resident_host_ms": statistics.median(resident_host), "held_host_ms": statistics.median(held_host)}
        if overlaps:
            row.update(fl.overlapped(session, path))
            row["overlapped_host_cpu_us"], row["overlapped_wait_us"] = overlapped_host_cpu(session, path)
        if pipelines:
            row["piped_wall_ms"], row["piped_device_ms"] = piped(scene, path)
        rows.append(row)
    record = {"device": device_info(tessellator.device), "rows": rows, "cltess": cltess.__file__}
    if args.grid:
        sizes = [(1, 13), (10, 13), (100, 13), (1000, 13)]
        record["grid"] = fl.grid_sizes(tessellator, sizes, 3)
    return record


def run_child(argv: list[str], tree: Path | None) -> dict:
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, (str(tree), env.get("PYTHONPATH"))))  # its cltess first
    done = subprocess.run([sys.executable, __file__, "--child", *argv], env=env, capture_output=True, text=True)
    if done.returncode:
        sys.exit(done.stderr)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device")
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--scenes", nargs="*", default=["all"])
    parser.add_argument("--grid", action="store_true", help="also the one-thread NumPy grid (this tree only)")
    parser.add_argument("--baseline", metavar="SOURCE_TREE")
    parser.add_argument("--json")
    parser.add_argument("--as-gpu", action="store_true",
                        help="frames as a GPU makes them (work 'point', stage 3 fused or tiled) on this device")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args), default=float))
        return 0
    argv = ["--frames", str(args.frames), "--scenes", *args.scenes] + (["--device", args.device] if args.device else []) \
        + (["--as-gpu"] if args.as_gpu else [])
    trees = {"this": None}
    if args.baseline:
        trees["baseline"] = Path(args.baseline).resolve()
    runs = {name: [] for name in trees}
    load_before = os.getloadavg()
    for k in range(args.repeat):
        for name, tree in trees.items():
            grid = ["--grid"] if args.grid and name == "this" and k == 0 else []
            runs[name].append(run_child(argv + grid, tree))
    device = runs["this"][0]["device"]
    for name in trees:
        print(f"{name}: cltess from {runs[name][0]['cltess']}")
    print(f"device: {device.get('name', device)}; load average before {load_before}, after {os.getloadavg()}; "
          f"{args.frames} frames, best of {args.repeat} children per tree (median per frame, ms)")
    header = f"{'scene':20} {'triangles':>10}"
    for name in trees:
        header += (f" | {name + ' device':>14} {'on device':>10} {'(host)':>7} {'ratio':>6} {'host arr.':>10} {'(host)':>7}"
                   f" {'ratio':>6} {'looped':>8} {'overlap':>8} {'ratio':>6} {'host µs':>8} {'waits µs':>8}"
                   f" {'piped':>8} {'ratio':>6}")
    print(header)
    result = {"device": device, "load": [load_before, os.getloadavg()], "command": " ".join(sys.argv), "scenes": []}
    for index, row in enumerate(runs["this"][0]["rows"]):
        line = f"{row['scene']:20} {row['triangles']:>10,}"
        entry = {"scene": row["scene"], "triangles": row["triangles"]}
        for name in trees:
            best = min((run["rows"][index] for run in runs[name]), key=lambda r: r["host_ms"])
            line += (f" | {best['device_ms']:>14.3f} {best['resident_ms']:>10.3f} {best['resident_host_ms']:>7.3f}"
                     f" {best['resident_ms'] / best['device_ms']:>5.2f}x"
                     f" {best['host_ms']:>10.3f} {best['held_host_ms']:>7.3f} {best['host_ms'] / best['device_ms']:>5.2f}x")
            if "overlapped_wall_ms" in best:
                line += (f" {best['looped_wall_ms']:>8.3f} {best['overlapped_wall_ms']:>8.3f}"
                         f" {best['overlapped_wall_ms'] / best['overlapped_device_ms']:>5.2f}x"
                         f" {min(run['rows'][index]['overlapped_host_cpu_us'] for run in runs[name]):>8.1f}"
                         f" {best['overlapped_wait_us']:>8.1f}")
            else:
                line += f" {'-':>8} {'-':>8} {'-':>6} {'-':>8} {'-':>8}"
            if "piped_wall_ms" in best:
                line += f" {best['piped_wall_ms']:>8.3f} {best['piped_wall_ms'] / best['device_ms']:>5.2f}x"
            else:
                line += f" {'-':>8} {'-':>6}"
            entry[name] = best
        print(line)
        result["scenes"].append(entry)
    if args.grid:
        grid = runs["this"][0]["grid"]
        print("one-thread NumPy grid against a session frame with host arrays (this tree, ms):")
        for g in grid:
            print(f"  {g['triangles']:>11,} triangles: NumPy {g['numpy_ms']:9.2f}  cltess frame {g['session_host_ms']:8.2f}"
                  f" (device {g['session_device_ms']:7.2f}, host/device {g['session_host_ms'] / g['session_device_ms']:.2f}x)"
                  f"  NumPy/cltess {g['numpy_ms'] / g['session_host_ms']:6.1f}x")
        result["grid"] = grid
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1, default=float) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

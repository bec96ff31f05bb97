"""Host-array frames waited one by one against frames pipelined on two buffer sets
(``Session(buffers=2)``), in one process, loops alternating with the order swapped each round.

    python bench/results/lead12-2core/piped_ab.py DEVICE SCENE [--rounds 10] [--frames 20]

Per round and loop kind, ``--frames`` cameras on the orbit of bench/frame_loop.py, wall per frame
until the last frame's host arrays are held:
* device: frames left on the device, waited one by one; their device time (sum of the stages'
  profiling spans) is the reference;
* waited: ``tessellate(camera, host=True)`` (arrays fetched before it returns), one set of buffers;
* piped: ``tessellate(camera, host=True, wait=False)`` on a two-set session, then the previous
  frame's ``fetch()``, so frame k's arrays are read while frame k+1 computes.
Every piped frame's arrays are compared with the waited frame's of the same camera (bitwise).
"""
import argparse
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

warnings.simplefilter("ignore")
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import frame_loop as fl  # noqa: E402

import cltess  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("device")
parser.add_argument("scene")
parser.add_argument("--rounds", type=int, default=10)
parser.add_argument("--frames", type=int, default=20)
args = parser.parse_args()
scene = fl.suite_scene(args.scene)
tessellator = Tessellator(args.device)
single = cltess.Session(scene, tessellator=tessellator, pixels=fl.PIXELS)
double = cltess.Session(scene, tessellator=tessellator, pixels=fl.PIXELS, buffers=2)
path = list(fl.orbit(scene.camera, args.frames))
expected = {}
for k, camera in enumerate(path):  # warm-up: builds, sizes, records (both sets of the double session)
    expected[k] = {f: np.copy(getattr(single.tessellate(camera=camera, host=True), f))
                   for f in ("positions", "normals", "triangles")}
    double.tessellate(camera=camera, host=True)


def device():
    times, started = [], time.perf_counter()
    for camera in path:
        times.append(fl.device_ms(single.tessellate(camera=camera)))
    return (time.perf_counter() - started) / len(path) * 1e3, statistics.median(times)


def waited():
    started = time.perf_counter()
    for camera in path:
        single.tessellate(camera=camera, host=True)
    return (time.perf_counter() - started) / len(path) * 1e3, None


def piped():
    started = time.perf_counter()
    previous = double.tessellate(camera=path[0], host=True, wait=False)
    for camera in path[1:]:
        frame = double.tessellate(camera=camera, host=True, wait=False)
        previous.fetch()
        previous = frame
    previous.fetch()
    return (time.perf_counter() - started) / len(path) * 1e3, None


def check():
    previous = double.tessellate(camera=path[0], host=True, wait=False)
    for k, camera in enumerate(path[1:], 1):
        frame = double.tessellate(camera=camera, host=True, wait=False)
        assert all(np.array_equal(getattr(previous, f), expected[k - 1][f]) for f in expected[k - 1])
        previous = frame
    assert all(np.array_equal(getattr(previous, f), expected[len(path) - 1][f]) for f in expected[0])


check()
kinds = {"device": device, "waited": waited, "piped": piped}
walls = {name: [] for name in kinds}
device_ms = []
for r in range(args.rounds):
    order = list(kinds) if r % 2 == 0 else list(kinds)[::-1]
    for name in order:
        wall, dev = kinds[name]()
        walls[name].append(wall)
        if dev is not None:
            device_ms.append(dev)
check()
reference = statistics.median(device_ms)
print(f"{args.scene} on {tessellator.device.name.strip()} ({tessellator.device.platform.name.strip()}), "
      f"{args.rounds} rounds of {args.frames} frames; device time {reference:.3f} ms (median); bits: the same")
for name in kinds:
    w = statistics.median(walls[name])
    print(f"  {name:7s} wall/frame {w:.3f} ms [{min(walls[name]):.3f}-{max(walls[name]):.3f}]  "
          f"over device time {w / reference:.2f}x")

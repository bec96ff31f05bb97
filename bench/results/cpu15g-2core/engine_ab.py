"""In-process interleaved A/B of the whole engine from two kernel folders: two Tessellators, each
built while cltess's kernel_dir() names its folder (the programs are built on first use and kept
per Tessellator); then ROUNDS rounds of LAUNCHES tessellations of each, alternating the order;
per tessellation the process CPU ms and the device ms of each stage (PoCL: the kernels' wall on
its threads).  Prints round medians of CPU ms and of stage 1's (factors) device ms, and the bits.

    python bench/results/cpu15g-2core/engine_ab.py --a /tmp/F/kernels --b kernels --scene model_zoo --pixels 0.01
"""
import argparse, hashlib, statistics, sys
from pathlib import Path
import numpy as np
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import cpu_stages, frame_loop  # noqa: E402
from cltess.backends.opencl import Tessellator, programs  # noqa: E402

p = argparse.ArgumentParser()
p.add_argument("--device", default="pocl"); p.add_argument("--scene", default="model_zoo")
p.add_argument("--pixels", type=float, default=0.01); p.add_argument("--rounds", type=int, default=10)
p.add_argument("--launches", type=int, default=5); p.add_argument("--a", required=True); p.add_argument("--b", required=True)
p.add_argument("--stage", default="factors")
args = p.parse_args()
scene = frame_loop.suite_scene(args.scene)
engines, bits = {}, {}
original = programs.kernel_dir
for label in ("a", "b"):
    folder = Path(getattr(args, label)).resolve()
    programs.kernel_dir = lambda folder=folder: folder
    t = Tessellator(args.device, work="patch")
    tess = t.tessellate(scene, pixels=args.pixels)
    tess = t.tessellate(scene, pixels=args.pixels)
    h = hashlib.blake2b(digest_size=8)
    for f in ("positions", "normals", "uv", "triangles", "factors"):
        h.update(np.ascontiguousarray(getattr(tess, f)).tobytes())
    engines[label], bits[label] = t, h.hexdigest()
programs.kernel_dir = original
rows = {"a": [], "b": []}
for r in range(args.rounds):
    for label in (("a", "b") if r % 2 == 0 else ("b", "a")):
        cpu, stage = [], []
        for _ in range(args.launches):
            s = cpu_stages.cpu_seconds()
            tess = engines[label].tessellate(scene, pixels=args.pixels)
            cpu.append((cpu_stages.cpu_seconds() - s) * 1e3)
            stage.append(tess.stage_ms[args.stage])
        rows[label].append((statistics.median(cpu), statistics.median(stage)))
print(f"{args.scene} at {args.pixels} px, {args.rounds} rounds x {args.launches} tessellations; bits a {bits['a']} "
      f"b {bits['b']} ({'same' if bits['a'] == bits['b'] else 'DIFFERENT'})")
for i, what in ((0, "CPU ms (whole tessellation)"), (1, f"{args.stage} device ms")):
    ma, mb = [x[i] for x in rows["a"]], [x[i] for x in rows["b"]]
    print(f"  {what}: a ({args.a}) {[round(x, 1) for x in ma]}\n    b ({args.b}) {[round(x, 1) for x in mb]}\n"
          f"    median of medians a {statistics.median(ma):.1f} b {statistics.median(mb):.1f} "
          f"({(statistics.median(ma) / statistics.median(mb) - 1) * 100:+.1f}%); a lower in "
          f"{sum(x < y for x, y in zip(ma, mb))}/{len(ma)} rounds")

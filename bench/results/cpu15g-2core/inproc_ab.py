"""In-process interleaved A/B of one stage's per-patch kernel at a given work-group size:
kernels from two folders, ROUNDS rounds of LAUNCHES launches of each, alternating order each
round; process CPU ms (cpu_stages.cpu_seconds) per launch; round medians, mins, bits.

    python bench/results/cpu15g-2core/inproc_ab.py --stage 5 --local 64 --rounds 12 --launches 20 \\
        --a kernels --b /tmp/cpu15g/base/kernels [--scene model_zoo --pixels 0.01]
"""
import argparse, hashlib, statistics, sys
from pathlib import Path
import numpy as np
import pyopencl.array as cl_array
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import cpu_stages, frame_loop  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.tessellation import VERTEX_RECORD  # noqa: E402

p = argparse.ArgumentParser()
p.add_argument("--device", default="pocl"); p.add_argument("--stage", type=int, default=5)
p.add_argument("--local", type=int, default=64); p.add_argument("--rounds", type=int, default=12)
p.add_argument("--launches", type=int, default=20); p.add_argument("--a", required=True); p.add_argument("--b", required=True)
p.add_argument("--scene"); p.add_argument("--pixels", type=float, default=0.01)
args = p.parse_args()
t = Tessellator(args.device, work="patch")
ctx, queue, dev = t.context, t.queue, t.device
plan = (t.plan(frame_loop.suite_scene(args.scene), pixels=args.pixels) if args.scene
        else t.plan(frame_loop.teapots(1000), **frame_loop.uniform_request(16)))
part = plan.parts[0]; patches, vertices = plan.num_patches, plan.num_vertices
name = "vertices" if args.stage == 4 else "indices"
kernels = {}
for label in ("a", "b"):
    folder = Path(getattr(args, label))
    kernels[label] = getattr(cpu_stages.build(ctx, dev, folder, (folder / "stages" / f"{name}.cl").read_text(), name,
                                              part.pattern, (), part.kind), name)
if args.stage == 4:
    out = [cl_array.empty(queue, (vertices, *shape), dtype) for _, dtype, shape in VERTEX_RECORD]
    arguments = (part.data["controls"].data, plan.factors.data, plan.vertex_offsets.data, plan.objects.data,
                 np.uint32(0), np.uint32(patches), np.uint32(0), np.uint64(0), np.int32(1), np.uint64(vertices),
                 *(a.data for a in out))
else:
    out = [cl_array.empty(queue, (plan.num_indices,), np.uint32)]
    arguments = (plan.factors.data, plan.vertex_offsets.data, plan.index_offsets.data, np.uint32(0),
                 np.uint32(patches), np.uint64(0), np.uint64(plan.num_indices), out[0].data)
gsize, local = (-(-patches // 64) * 64,), (args.local,)
bits, rounds = {}, {"a": [], "b": []}
for label in ("a", "b"):
    for _ in range(2):
        kernels[label](queue, gsize, local, *arguments).wait()
    h = hashlib.blake2b(digest_size=8)
    for o in out:
        h.update(o.get().tobytes())
    bits[label] = h.hexdigest()
for r in range(args.rounds):
    for label in (("a", "b") if r % 2 == 0 else ("b", "a")):
        cpu = []
        for _ in range(args.launches):
            s = cpu_stages.cpu_seconds(); kernels[label](queue, gsize, local, *arguments).wait()
            cpu.append((cpu_stages.cpu_seconds() - s) * 1e3)
        rounds[label].append((statistics.median(cpu), min(cpu)))
ma = [m for m, _ in rounds["a"]]; mb = [m for m, _ in rounds["b"]]
print(f"{args.scene or 'uniform 16, 1,000 teapots'}: stage {args.stage}, local {args.local}, {args.rounds} rounds x {args.launches}; "
      f"bits a {bits['a']} b {bits['b']} ({'same' if bits['a'] == bits['b'] else 'DIFFERENT'})")
print(f"  a ({args.a}) round medians {[round(x, 1) for x in ma]}")
print(f"  b ({args.b}) round medians {[round(x, 1) for x in mb]}")
print(f"  median of medians a {statistics.median(ma):.1f} b {statistics.median(mb):.1f} "
      f"({(statistics.median(ma) / statistics.median(mb) - 1) * 100:+.1f}%); min a {min(x for _, x in rounds['a']):.1f} "
      f"b {min(x for _, x in rounds['b']):.1f}; a lower in {sum(x < y for x, y in zip(ma, mb))}/{len(ma)} rounds")

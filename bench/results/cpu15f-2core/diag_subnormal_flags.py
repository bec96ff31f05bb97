"""Diagnostic build (not the engine): stage 4 with surface_normal returning flags of subnormal intermediates.

Record of the run behind subnormal-intermediates-stage4.txt (paths as they were): the diagnostic tree is
this branch's kernels/ copied to /tmp/cpu15f/diag/kernels with diag-subnormal-flags.diff applied; run
from the worktree with PYTHONPATH=$PWD: python diag_subnormal_flags.py 1000 [pocl|intel]."""
import sys, numpy as np, pyopencl as cl, pyopencl.array as cl_array
from pathlib import Path
sys.path.insert(0, "/work/wt/cpu15f/bench")
import frame_loop, cpu_stages
from cltess.backends.opencl import Tessellator
from cltess.tessellation import VERTEX_RECORD
t = Tessellator(sys.argv[2] if len(sys.argv) > 2 else "pocl", work="patch"); ctx, q, dev = t.context, t.queue, t.device
plan = t.plan(frame_loop.teapots(int(sys.argv[1])), **frame_loop.uniform_request(16)); part = plan.parts[0]
P, V = plan.num_patches, plan.num_vertices
out = [cl_array.empty(q, (V, *s), d) for _, d, s in VERTEX_RECORD]
args = (part.data["controls"].data, plan.factors.data, plan.vertex_offsets.data, plan.objects.data,
        np.uint32(0), np.uint32(P), np.uint32(0), np.uint64(0), np.int32(1), np.uint64(V))
real = cpu_stages.build(ctx, dev, Path("/work/wt/cpu15f/kernels"), Path("/work/wt/cpu15f/kernels/stages/vertices.cl").read_text(), "vertices", part.pattern).vertices
real(q, (-(-P // 64) * 64,), None, *args, *(a.data for a in out)).wait()
nrm = out[1].get(); pos = out[0].get()
folder = Path("/tmp/cpu15f/diag/kernels")
diag = cpu_stages.build(ctx, dev, folder, (folder / "stages/vertices.cl").read_text(), "vertices", part.pattern).vertices
diag(q, (-(-P // 64) * 64,), None, *args, *(a.data for a in out)).wait()
flags = out[1].get()[:, 0].astype(np.int32)
ring = np.zeros(V, bool)
offsets = plan.vertex_offsets.get()
for k in range(64): ring[offsets[:P] + k] = True
names = {1: "t_u, t_v or s.w p component subnormal", 2: "a cross-product term or n component subnormal",
         4: "a square, a partial dot, dot(n, n) or the degeneracy bound subnormal", 8: "n with an exact zero component",
         16: "unit normal, its length or dot(n, n) subnormal (at the end)", 32: "not ok: a fall-back taken"}
print(f"{dev.platform.name.strip()}: {P} patches, {V} vertices ({ring.sum()} ring, {(~ring).sum()} rows); points with:")
for bit, name in names.items():
    print(f"  {int(((flags & bit) != 0).sum()):9d} (ring {int(((flags & bit) != 0)[ring].sum()):8d})  {name}")
print(f"  {int((flags != 0).sum()):9d}  any")
sub = lambda a: int(((a != 0) & (np.abs(a) < np.finfo(np.float32).tiny)).sum())
print("engine output: subnormal normal components", sub(nrm), "; position components", sub(pos), "; exact-zero normal components", int((nrm == 0).sum()))

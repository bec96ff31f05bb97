# The lead's fourth H200 call, session 16: stage 5's triangles written by prepared_rows itself, two
# per point slot of each line, interleaved with the points' arithmetic (probe/fuse = git archive
# HEAD cltess kernels bench scenes with fuse.patch; a Session's index buffers from the frame
# before, so a Session's first frame has none: measurement only).  fuse-both: stage 5 also runs
# (stage 4's cost of the triangles); diag-fuse-only: stage 5's launch returns at once
# (-DPROBE_FUSED=1; "same bits" does not apply: the first frame's triangles are missing).
# From /work/main, carry [".whl", "probe/fuse"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/fuse/cltess/kernels
R=$OUT/fuse; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/fuse.json \
  --variant now rows-prep . - \
  --variant fuse-both rows-prep probe/fuse - \
  --variant diag-fuse-only rows-prep probe/fuse opt:-DPROBE_FUSED=1 \
  --variant now-again rows-prep . - \
  --variant fuse-both-again rows-prep probe/fuse - \
  --variant diag-fuse-only-again rows-prep probe/fuse opt:-DPROBE_FUSED=1 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/fuse.txt
tail -12 $R/fuse.txt

# The lead's second H200 measurement, session 14: what stage 4 of rows-prep (prepared_rows) costs
# for its rows alone and its ring edges alone, each built without the other's code path, so that
# each gets its own register allocation (probe/split = git archive of this tree, cltess kernels
# bench, with prepared_points.cl's PROBE_LINES: 1 rows only, 2 edges only; measurement only, its
# output incomplete; the change is split_lines.patch).  From /work/main, carry [".whl", "probe/split"].
. bench/gpu_setup.sh >/dev/null || exit 1
R=$OUT/split; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/split.json \
  --variant now rows-prep . - \
  --variant diag-rows rows-prep probe/split opt:-DPROBE_LINES=1 \
  --variant diag-edges rows-prep probe/split opt:-DPROBE_LINES=2 \
  --variant split-both rows-prep probe/split opt:-DPROBE_LINES=0 \
  --variant now-again rows-prep . - \
  --variant diag-rows-again rows-prep probe/split opt:-DPROBE_LINES=1 \
  --variant diag-edges-again rows-prep probe/split opt:-DPROBE_LINES=2 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/split.txt
tail -14 $R/split.txt

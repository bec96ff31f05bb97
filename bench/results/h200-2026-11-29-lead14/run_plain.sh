# The lead's third H200 measurement, session 14: rows-prep's stage 4 with its rows alone, and
# whether the rows' registers (213) come from the patch that surface_normal's fall-backs read:
# PROBE_PLAIN_ONLY takes the fall-backs out (measurement only, wrong normals where they are
# needed; split_lines.patch, second file).  From /work/main, carry [".whl", "probe/split"].
. bench/gpu_setup.sh >/dev/null || exit 1
R=$OUT/plain; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/plain.json \
  --variant now rows-prep . - \
  --variant diag-rows rows-prep probe/split opt:-DPROBE_LINES=1 \
  --variant diag-rows-plain rows-prep probe/split "opt:-DPROBE_LINES=1 -DPROBE_PLAIN_ONLY=1" \
  --variant diag-both-plain rows-prep probe/split opt:-DPROBE_PLAIN_ONLY=1 \
  --variant diag-rows-again rows-prep probe/split opt:-DPROBE_LINES=1 \
  --variant diag-rows-plain-again rows-prep probe/split "opt:-DPROBE_LINES=1 -DPROBE_PLAIN_ONLY=1" 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/plain.txt
tail -12 $R/plain.txt

# The lead's second H200 call, session 16: prepared_rows (255 registers: 8 warps per SM, and 1,000
# work-groups of 32 patches fill 1,056 slots in one wave) under register caps between session 7's
# 168 (which spilled) and none, with fewer patches per work-group so that more groups than 1,056
# can be resident.  From /work/main, carry [".whl"].
. bench/gpu_setup.sh >/dev/null || exit 1
R=$OUT/caps; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/caps.json \
  --variant now rows-prep . - \
  --variant now-24 rows-prep/24 . - \
  --variant cap224-32 rows-prep . opt:-cl-nv-maxrregcount=224 \
  --variant cap224-24 rows-prep/24 . opt:-cl-nv-maxrregcount=224 \
  --variant cap200-24 rows-prep/24 . opt:-cl-nv-maxrregcount=200 \
  --variant cap200-16 rows-prep/16 . opt:-cl-nv-maxrregcount=200 \
  --variant cap184-16 rows-prep/16 . opt:-cl-nv-maxrregcount=184 \
  --variant cap168-16 rows-prep/16 . opt:-cl-nv-maxrregcount=168 \
  --variant now-again rows-prep . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/caps.txt
tail -16 $R/caps.txt

# Session 19, H200, call 2: staged_points' registers: caps (without reqd_work_group_size), and the
# normal's fall-back left out (probe: wrong normals where needed). Carry [".whl", "probe/gpu19"].
. bench/gpu_setup.sh >/dev/null || exit 1
R=$OUT/call2; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/caps.json \
  --variant rows rows-prep . - \
  --variant staged staged-prep . - \
  --variant noreqd staged-prep . opt:-DSTAGED_NO_REQD=1 \
  --variant cap64 staged-prep . "opt:-DSTAGED_NO_REQD=1 -cl-nv-maxrregcount=64" \
  --variant cap80 staged-prep . "opt:-DSTAGED_NO_REQD=1 -cl-nv-maxrregcount=80" \
  --variant cap96 staged-prep . "opt:-DSTAGED_NO_REQD=1 -cl-nv-maxrregcount=96" \
  --variant cap128 staged-prep . "opt:-DSTAGED_NO_REQD=1 -cl-nv-maxrregcount=128" \
  --variant nofall staged-prep . opt:-DPROBE_NO_FALLBACK=1 \
  --variant nofall-cap64 staged-prep . "opt:-DPROBE_NO_FALLBACK=1 -DSTAGED_NO_REQD=1 -cl-nv-maxrregcount=64" \
  --variant cap64/8 staged-prep/8 . "opt:-DSTAGED_NO_REQD=1 -cl-nv-maxrregcount=64" 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/caps.txt
grep "registers\|^|" $R/caps.txt | tail -24

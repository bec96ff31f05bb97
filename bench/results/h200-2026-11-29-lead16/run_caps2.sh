# The lead's third H200 call, session 16: register caps on prepared_rows, which NVIDIA's compiler
# applies only without reqd_work_group_size (probe/caps = git archive HEAD cltess kernels bench
# scenes, the attribute under #if !LINE_NO_REQD), each cap with the patches per work-group that
# keeps the work-groups within one wave of the warps per SM the cap allows (W = 65536 / (32 cap);
# groups = 32,000 / patches <= 132 W).  From /work/main, carry [".whl", "probe/caps"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/caps/cltess/kernels
R=$OUT/caps2; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/caps2.json \
  --variant now rows-prep . - \
  --variant noreqd rows-prep probe/caps opt:-DLINE_NO_REQD=1 \
  --variant cap224-27 rows-prep/27 probe/caps "opt:-DLINE_NO_REQD=1 -cl-nv-maxrregcount=224" \
  --variant cap204-25 rows-prep/25 probe/caps "opt:-DLINE_NO_REQD=1 -cl-nv-maxrregcount=204" \
  --variant cap184-23 rows-prep/23 probe/caps "opt:-DLINE_NO_REQD=1 -cl-nv-maxrregcount=184" \
  --variant cap168-21 rows-prep/21 probe/caps "opt:-DLINE_NO_REQD=1 -cl-nv-maxrregcount=168" \
  --variant cap204-16 rows-prep/16 probe/caps "opt:-DLINE_NO_REQD=1 -cl-nv-maxrregcount=204" \
  --variant now-again rows-prep . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/caps2.txt
tail -14 $R/caps2.txt

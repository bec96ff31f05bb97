# gpu15g run 2 (H100): run 1's stage45 part again, after fixing bench/kernels/gpu_stage45_probe.cl (run 1's probes did
# not build: tangent_cross takes p now).  Uniform level 16, main against the branch's exact shortcuts (98cb2f6:
# projected, w only; the branch: projected + int_quotient), a no-normal diagnostic, 16 patches per group, `point`.
# From /work/main, carry .whl and the probe/gpu15g* trees: bash probe/gpu15g/bench/results/h100-2026-11-28-gpu15g/run2.sh
cd probe/gpu15g && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15g-base ../gpu15g-w ../gpu15g-diag; do (cd $t && ln -sfn ../kernels cltess/kernels); done
R=$OUT/run2; mkdir -p $R
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > $R/machine2.txt; uptime >> $R/machine2.txt
timeout 330 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/run2_stage45.json --ptx $R/ptx \
  --variant main rows-prep ../gpu15g-base - --variant weights rows-prep ../gpu15g-w - \
  --variant branch rows-prep . - --variant branch/16 rows-prep/16 . - \
  --variant diag-no-normal rows-prep ../gpu15g-diag - \
  --variant main-again rows-prep ../gpu15g-base - --variant branch-again rows-prep . - \
  --variant main-point point ../gpu15g-base - --variant branch-point point . - > $R/run2_stage45.txt 2>&1
tail -14 $R/run2_stage45.txt
uptime >> $R/machine2.txt
(cd $R && ls ptx && tar -czf ptx.tar.gz ptx && rm -rf ptx)
cd $OUT && tar -czf run2.tar.gz run2 && rm -rf run2

# gpu15g run 3 (H100): uniform level 16, main against projected alone (98cb2f6, "weights") and projected +
# int_quotient (the branch), each twice, and two diagnostics of the branch: no normal fall-back (surface_normal's
# `if (!ok)` never taken: not the engine's output) and no stores (prepared_rows' write-out never stores).
# From /work/main, carry .whl and the probe/gpu15g* trees: bash probe/gpu15g/bench/results/h100-2026-11-28-gpu15g/run3.sh
cd probe/gpu15g && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15g-base ../gpu15g-w ../gpu15g-diag2 ../gpu15g-diag3; do (cd $t && ln -sfn ../kernels cltess/kernels); done
R=$OUT/run3; mkdir -p $R
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > $R/machine3.txt; uptime >> $R/machine3.txt
timeout 330 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/run3_stage45.json \
  --variant main rows-prep ../gpu15g-base - --variant weights rows-prep ../gpu15g-w - --variant branch rows-prep . - \
  --variant diag-no-fallback rows-prep ../gpu15g-diag2 - --variant diag-no-store rows-prep ../gpu15g-diag3 - \
  --variant main-again rows-prep ../gpu15g-base - --variant weights-again rows-prep ../gpu15g-w - \
  --variant branch-again rows-prep . - > $R/run3_stage45.txt 2>&1
tail -12 $R/run3_stage45.txt
uptime >> $R/machine3.txt
cd $OUT && tar -czf run3.tar.gz run3 && rm -rf run3

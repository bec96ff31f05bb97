# gpu15g run 4 (H100): uniform level 16, main against projected alone (0f1f4ba, "weights"), projected + prepared_rows'
# rounds rotated by the group (the branch, "rotated"), and an experiment on top of that, every round's chunks offset
# by group % LINE_CHUNK points ("skewed", probe tree only); each twice.  Then the GPU tests of the branch.
# From /work/main, carry .whl and the probe/gpu15g* trees: bash probe/gpu15g/bench/results/h100-2026-11-28-gpu15g/run4.sh
cd probe/gpu15g && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15g-base ../gpu15g-w ../gpu15g-skew; do (cd $t && ln -sfn ../kernels cltess/kernels); done
R=$OUT/run4; mkdir -p $R
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > $R/machine4.txt; uptime >> $R/machine4.txt
timeout 300 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/run4_stage45.json \
  --variant main rows-prep ../gpu15g-base - --variant weights rows-prep ../gpu15g-w - \
  --variant rotated rows-prep . - --variant skewed rows-prep ../gpu15g-skew - \
  --variant main-again rows-prep ../gpu15g-base - --variant weights-again rows-prep ../gpu15g-w - \
  --variant rotated-again rows-prep . - --variant skewed-again rows-prep ../gpu15g-skew - > $R/run4_stage45.txt 2>&1
tail -11 $R/run4_stage45.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -q -p no:cacheprovider tests/contracts tests/test_projected.py \
  tests/test_work_points.py tests/test_work_auto.py tests/test_frame_capacity.py tests/test_session.py \
  tests/test_vertices.py > $R/gpu_tests4.txt 2>&1
tail -3 $R/gpu_tests4.txt
uptime >> $R/machine4.txt
cd $OUT && tar -czf run4.tar.gz run4 && rm -rf run4

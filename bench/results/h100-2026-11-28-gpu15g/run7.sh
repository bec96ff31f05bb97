# gpu15g run 7 (H100): uniform level 16, main against the final kernels of run 5 ("final") and a candidate on top:
# prepared_rows staging 8 points at a time in two buffers, writing out the previous chunk a slot per point step
# ("interleaved"); then the GPU tests of prepared_rows on the candidate tree.  From /work/main, carry .whl and the
# probe trees: bash probe/gpu15g/bench/results/h100-2026-11-28-gpu15g/run7.sh
cd probe/gpu15g && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15g-base ../gpu15g-final; do (cd $t && ln -sfn ../kernels cltess/kernels); done
R=$OUT/run7; mkdir -p $R
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > $R/machine7.txt; uptime >> $R/machine7.txt
timeout 150 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/run7_stage45.json \
  --variant main rows-prep ../gpu15g-base - --variant final rows-prep ../gpu15g-final - \
  --variant interleaved rows-prep . - --variant final-again rows-prep ../gpu15g-final - \
  --variant interleaved-again rows-prep . - > $R/run7_stage45.txt 2>&1
tail -8 $R/run7_stage45.txt
CLTESS_DEVICE=nvidia timeout 60 python3 -m pytest -q -p no:cacheprovider tests/test_work_points.py \
  tests/test_frame_capacity.py > $R/gpu_tests7.txt 2>&1
tail -2 $R/gpu_tests7.txt
uptime >> $R/machine7.txt
cd $OUT && tar -czf run7.tar.gz run7 && rm -rf run7

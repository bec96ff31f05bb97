# gpu15d run 5: work-groups of 32 work-items (one warp) for prepared_rows against 64
cd probe/gpu15d && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15d-base ../gpu15d-g32; do (cd $t && ln -sfn ../kernels cltess/kernels); done
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine.txt; uptime >> $OUT/machine.txt
timeout 300 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run5.json \
  --variant before point-prep ../gpu15d-base - \
  --variant group64 rows-prep . - \
  --variant group32/32 rows-prep/32 ../gpu15d-g32 - \
  --variant group32/64 rows-prep/64 ../gpu15d-g32 - \
  --variant group32/16 rows-prep/16 ../gpu15d-g32 - \
  --variant group64-again rows-prep . - \
  --variant group32/32-again rows-prep/32 ../gpu15d-g32 - \
  --variant group32/64-again rows-prep/64 ../gpu15d-g32 - > $OUT/run5.txt 2>&1
tail -12 $OUT/run5.txt

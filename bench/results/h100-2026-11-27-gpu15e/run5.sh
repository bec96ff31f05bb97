# gpu15e run 5: the final rule (rows-prep from 64 vertices per patch on >= 2,048 patches; 32 patches per
# group unless that leaves fewer than half of 8 warps per SM): uniform level 16 main vs branch side by side,
# the choice on a subset, the GPU tests.  H100, from /work/main (bash probe/gpu15e/bench/results/h100-2026-11-27-gpu15e/run5.sh,
# carry .whl, probe/gpu15e, probe/gpu15e-base)
cd probe/gpu15e && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15e-base && ln -sfn ../kernels cltess/kernels)
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine5.txt; uptime >> $OUT/machine5.txt
timeout 120 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run5_stage45.json \
  --variant before-point point ../gpu15e-base - \
  --variant before-rows-prep rows-prep ../gpu15e-base - \
  --variant after-auto auto . - \
  --variant after-rows-prep rows-prep . - \
  --variant before-rows-prep-again rows-prep ../gpu15e-base - \
  --variant after-auto-again auto . - > $OUT/run5_stage45.txt 2>&1
tail -9 $OUT/run5_stage45.txt
timeout 150 python3 bench/work_choice.py --device nvidia --repeat 5 --levels 8 16 --copies 100 1000 --scenes tea_table star_field --json $OUT/run5_choice.json > $OUT/run5_choice.txt 2>&1
grep "^|\|fill" $OUT/run5_choice.txt
uptime >> $OUT/machine5.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -q -p no:cacheprovider tests/test_work_auto.py tests/test_frame_capacity.py tests/test_recorded_frames.py tests/test_session.py tests/test_work_points.py > $OUT/gpu_tests5.txt 2>&1
tail -3 $OUT/gpu_tests5.txt

# gpu15e run 4: work="auto" (branch default on GPUs) against point / rows-prep per scene; uniform level 16
# main vs branch side by side; the GPU tests of the touched files.  H100, from /work/main
# (bash probe/gpu15e/bench/results/h100-2026-11-27-gpu15e/run4.sh, carry .whl, probe/gpu15e, probe/gpu15e-base)
cd probe/gpu15e && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15e-base && ln -sfn ../kernels cltess/kernels)
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine4.txt; uptime >> $OUT/machine4.txt
timeout 120 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run4_stage45.json \
  --variant before-point point ../gpu15e-base - \
  --variant before-rows-prep rows-prep ../gpu15e-base - \
  --variant after-auto auto . - \
  --variant after-rows-prep rows-prep . - > $OUT/run4_stage45.txt 2>&1
tail -7 $OUT/run4_stage45.txt
timeout 300 python3 bench/work_choice.py --device nvidia --repeat 5 --json $OUT/run4_choice.json > $OUT/run4_choice.txt 2>&1
grep "^|\|fill" $OUT/run4_choice.txt
uptime >> $OUT/machine4.txt
CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -q -p no:cacheprovider tests/test_work_auto.py tests/test_frame_capacity.py tests/test_recorded_frames.py tests/test_session.py > $OUT/gpu_tests4.txt 2>&1
tail -3 $OUT/gpu_tests4.txt

# gpu15g run 6 (H100): uniform level 16, main against the branch's final kernels of run 5 (projected: 056c25f, "final")
# and a candidate on top, prepared_rows writing positions and normals float by float (a warp's store 128 contiguous
# bytes; "words"), each twice; then the GPU tests of the words tree.  From /work/main, carry .whl and the probe trees:
# bash probe/gpu15g/bench/results/h100-2026-11-28-gpu15g/run6.sh
cd probe/gpu15g && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15g-base ../gpu15g-final; do (cd $t && ln -sfn ../kernels cltess/kernels); done
R=$OUT/run6; mkdir -p $R
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > $R/machine6.txt; uptime >> $R/machine6.txt
timeout 200 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/run6_stage45.json \
  --variant main rows-prep ../gpu15g-base - --variant final rows-prep ../gpu15g-final - --variant words rows-prep . - \
  --variant main-again rows-prep ../gpu15g-base - --variant final-again rows-prep ../gpu15g-final - \
  --variant words-again rows-prep . - > $R/run6_stage45.txt 2>&1
tail -9 $R/run6_stage45.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -q -p no:cacheprovider tests/contracts tests/test_projected.py \
  tests/test_work_points.py tests/test_work_auto.py tests/test_frame_capacity.py tests/test_session.py \
  tests/test_recorded_frames.py > $R/gpu_tests6.txt 2>&1
tail -3 $R/gpu_tests6.txt
uptime >> $R/machine6.txt
cd $OUT && tar -czf run6.tar.gz run6 && rm -rf run6

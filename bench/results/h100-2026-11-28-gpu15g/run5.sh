# gpu15g run 5 (H100): the branch's final kernels (projected in kinds/bezier.h) against main: uniform level 16 twice
# each (and `point`), the paper's scenes and uniform 8 / 12 in each tree (work_choice.py, point and rows-prep), the GPU
# tests touching the change.  From /work/main, carry .whl, probe/gpu15g, probe/gpu15g-base:
# bash probe/gpu15g/bench/results/h100-2026-11-28-gpu15g/run5.sh
cd probe/gpu15g && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15g-base && ln -sfn ../kernels cltess/kernels)
R=$OUT/run5; mkdir -p $R
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > $R/machine5.txt; uptime >> $R/machine5.txt
timeout 200 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/run5_stage45.json \
  --variant main rows-prep ../gpu15g-base - --variant branch rows-prep . - \
  --variant main-again rows-prep ../gpu15g-base - --variant branch-again rows-prep . - \
  --variant main-point point ../gpu15g-base - --variant branch-point point . - > $R/run5_stage45.txt 2>&1
tail -9 $R/run5_stage45.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -q -p no:cacheprovider tests/contracts tests/test_projected.py \
  tests/test_work_points.py tests/test_work_auto.py tests/test_frame_capacity.py tests/test_session.py \
  tests/test_vertices.py tests/test_recorded_frames.py tests/test_poles.py tests/test_pattern_normals.py > $R/gpu_tests5.txt 2>&1
tail -3 $R/gpu_tests5.txt
for pair in branch:. main:../gpu15g-base; do
  name=${pair%%:*}; tree=${pair#*:}
  (cd $tree && PYTHONPATH=/tmp/site:$PWD timeout 100 python3 bench/work_choice.py --device nvidia --repeat 5 --levels 8 12 --copies 1000 \
    --scenes tea_table killeroo spheres star_field elephant --work point rows-prep --json $R/run5_choice_$name.json > $R/run5_choice_$name.txt 2>&1)
  echo $name; grep "^| [a-z]" $R/run5_choice_$name.txt
done
uptime >> $R/machine5.txt
cd $OUT && tar -czf run5.tar.gz run5 && rm -rf run5

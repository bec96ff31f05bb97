# gpu15f run 4 (H100): the branch's final kernels (8a2582c: pattern_triangle_at by uniform_grid_index, patch_after in
# common.h) against main: uniform level 16 twice each, the paper's scenes (work_choice.py, point and rows-prep, each
# tree in its own process tree), the GPU tests of the branch.  From /work/main, carry .whl, probe/gpu15f.
# bash probe/gpu15f/bench/results/h100-2026-11-28-gpu15f/run4.sh
cd probe/gpu15f && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../.. && ln -sfn ../kernels cltess/kernels 2>/dev/null)
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine4.txt; uptime >> $OUT/machine4.txt
timeout 100 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run4_stage45.json \
  --variant main rows-prep ../.. - --variant branch rows-prep . - \
  --variant main-again rows-prep ../.. - --variant branch-again rows-prep . - > $OUT/run4_stage45.txt 2>&1
tail -7 $OUT/run4_stage45.txt
CLTESS_DEVICE=nvidia timeout 120 python3 -m pytest -q -p no:cacheprovider tests/contracts tests/test_triangles_mirror.py \
  tests/test_triangle_at.py tests/test_work_points.py tests/test_work_auto.py tests/test_frame_capacity.py \
  tests/test_recorded_frames.py tests/test_session.py > $OUT/gpu_tests4.txt 2>&1
tail -1 $OUT/gpu_tests4.txt
for pair in branch:. main:../..; do
  name=${pair%%:*}; tree=${pair#*:}
  (cd $tree && PYTHONPATH=/tmp/site:$PWD timeout 80 python3 bench/work_choice.py --device nvidia --repeat 5 --levels 16 --copies 1000 \
    --scenes tea_table killeroo herd star_field spheres elephant --work point rows-prep --json $OUT/run4_choice_$name.json > $OUT/run4_choice_$name.txt 2>&1)
  echo $name; grep "^| [a-z]" $OUT/run4_choice_$name.txt
done
uptime >> $OUT/machine4.txt

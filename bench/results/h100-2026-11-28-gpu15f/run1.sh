# gpu15f run 1 (H100): stage 5 staged stores. From /work/main (main's tree "."), carry .whl, probe/gpu15f,
# probe/gpu15f-index (main + pattern_triangle_at by uniform_grid_index only), probe/gpu15f-diag (this branch with
# pattern_triangle_at replaced by a trivial triangle: the staged stores alone, not the engine's bits).
# bash probe/gpu15f/bench/results/h100-2026-11-28-gpu15f/run1.sh
cd probe/gpu15f && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for tree in ../.. ../gpu15f-index ../gpu15f-diag; do (cd $tree && ln -sfn ../kernels cltess/kernels 2>/dev/null); done
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine1.txt; uptime >> $OUT/machine1.txt
timeout 280 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run1_stage45.json \
  --variant main rows-prep ../.. - \
  --variant staged rows-prep . - \
  --variant index-only rows-prep ../gpu15f-index - \
  --variant diag-no-triangle-math rows-prep ../gpu15f-diag - \
  --variant main-point point ../.. - \
  --variant staged-point point . - \
  --variant staged-pp4 point-prep/4 . - \
  --variant staged-pp64 point-prep/64 . - \
  --variant main-again rows-prep ../.. - \
  --variant staged-again rows-prep . - > $OUT/run1_stage45.txt 2>&1
tail -14 $OUT/run1_stage45.txt
CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -q -p no:cacheprovider tests/contracts tests/test_triangles_staged.py \
  tests/test_triangle_at.py tests/test_work_points.py tests/test_work_auto.py tests/test_frame_capacity.py \
  tests/test_recorded_frames.py tests/test_session.py > $OUT/gpu_tests1.txt 2>&1
tail -3 $OUT/gpu_tests1.txt
for tree in . ../..; do
  name=$([ $tree = . ] && echo staged || echo main)
  (cd $tree && timeout 70 python3 bench/work_choice.py --device nvidia --repeat 5 --levels 16 --copies 1000 \
    --scenes tea_table killeroo herd star_field spheres --work point rows-prep --json $OUT/run1_choice_$name.json > $OUT/run1_choice_$name.txt 2>&1)
  grep "^|" $OUT/run1_choice_$name.txt
done
uptime >> $OUT/machine1.txt

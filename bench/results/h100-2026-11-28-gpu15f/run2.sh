# gpu15f run 2 (H100): stage 5 in runs (cursor, staged coalesced words; commit c8b1b63) against main and
# index-only (main + pattern_triangle_at by uniform_grid_index: a work-item per triangle, vstore3).
# From /work/main (main's tree "../.."), carry .whl, probe/gpu15f, probe/gpu15f-index.
# bash probe/gpu15f/bench/results/h100-2026-11-28-gpu15f/run2.sh
cd probe/gpu15f && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for tree in ../.. ../gpu15f-index; do (cd $tree && ln -sfn ../kernels cltess/kernels 2>/dev/null); done
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine2.txt; uptime >> $OUT/machine2.txt
timeout 300 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run2_stage45.json \
  --variant main rows-prep ../.. - \
  --variant runs rows-prep . - \
  --variant index-only rows-prep ../gpu15f-index - \
  --variant main-point point ../.. - \
  --variant runs-point point . - \
  --variant index-only-point point ../gpu15f-index - \
  --variant runs-pp8 point-prep/8 . - \
  --variant runs-pp32 point-prep/32 . - \
  --variant main-again rows-prep ../.. - \
  --variant runs-again rows-prep . - \
  --variant index-only-again rows-prep ../gpu15f-index - > $OUT/run2_stage45.txt 2>&1
tail -15 $OUT/run2_stage45.txt
CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -q -p no:cacheprovider tests/contracts tests/test_triangles_staged.py \
  tests/test_triangle_at.py tests/test_work_points.py tests/test_work_auto.py tests/test_frame_capacity.py \
  tests/test_recorded_frames.py tests/test_session.py > $OUT/gpu_tests2.txt 2>&1
tail -3 $OUT/gpu_tests2.txt
for pair in runs:. main:../.. index-only:../gpu15f-index; do
  name=${pair%%:*}; tree=${pair#*:}
  (cd $tree && PYTHONPATH=/tmp/site:$PWD timeout 70 python3 bench/work_choice.py --device nvidia --repeat 5 --levels 16 --copies 1000 \
    --scenes tea_table killeroo herd star_field spheres --work point rows-prep --json $OUT/run2_choice_$name.json > $OUT/run2_choice_$name.txt 2>&1)
  echo $name; grep "^| [a-z]" $OUT/run2_choice_$name.txt
done
uptime >> $OUT/machine2.txt

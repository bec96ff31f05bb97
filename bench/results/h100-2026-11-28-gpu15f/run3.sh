# gpu15f run 3 (H100): this branch (pattern_triangle_at by uniform_grid_index; commit 537ef59+) against main, stage 5's
# records per work-item (point-prep/N: N triangles per work-item in stage 5), and a galloping patch search
# (probe/gpu15f-gallop: patch_after in stages/triangles.cl).  From /work/main, carry .whl, probe/gpu15f, probe/gpu15f-gallop.
# bash probe/gpu15f/bench/results/h100-2026-11-28-gpu15f/run3.sh
cd probe/gpu15f && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for tree in ../.. ../gpu15f-gallop; do (cd $tree && ln -sfn ../kernels cltess/kernels 2>/dev/null); done
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine3.txt; uptime >> $OUT/machine3.txt
timeout 300 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run3_stage45.json \
  --variant main rows-prep ../.. - \
  --variant branch rows-prep . - \
  --variant gallop rows-prep ../gpu15f-gallop - \
  --variant main-pp16 point-prep/16 ../.. - \
  --variant branch-pp16 point-prep/16 . - \
  --variant branch-pp32 point-prep/32 . - \
  --variant branch-pp64 point-prep/64 . - \
  --variant gallop-pp64 point-prep/64 ../gpu15f-gallop - \
  --variant main-again rows-prep ../.. - \
  --variant branch-again rows-prep . - \
  --variant gallop-again rows-prep ../gpu15f-gallop - > $OUT/run3_stage45.txt 2>&1
tail -15 $OUT/run3_stage45.txt
CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -q -p no:cacheprovider tests/contracts tests/test_triangles_mirror.py \
  tests/test_triangle_at.py tests/test_work_points.py tests/test_work_auto.py tests/test_frame_capacity.py \
  tests/test_recorded_frames.py tests/test_session.py > $OUT/gpu_tests3.txt 2>&1
tail -2 $OUT/gpu_tests3.txt
(cd ../gpu15f-gallop && PYTHONPATH=/tmp/site:$PWD CLTESS_DEVICE=nvidia timeout 100 python3 -m pytest -q -p no:cacheprovider \
  tests/test_triangles_mirror.py tests/test_triangle_at.py tests/test_work_points.py > $OUT/gpu_tests3_gallop.txt 2>&1)
tail -2 $OUT/gpu_tests3_gallop.txt
uptime >> $OUT/machine3.txt

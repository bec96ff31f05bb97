# gpu15d run 6: the final tree (work-groups of one warp) against main side by side, tests, the paper scenes; run from the checkout root on the H100 (bash probe/gpu15d-run6.sh, carry .whl and probe)
cd probe/gpu15d && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15d-base ../gpu15d-diag-rows ../gpu15d-diag-ring; do (cd $t && ln -sfn ../kernels cltess/kernels); done
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine.txt; uptime >> $OUT/machine.txt
timeout 300 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run6.json \
  --variant before-point point ../gpu15d-base - \
  --variant before point-prep ../gpu15d-base - \
  --variant after rows-prep . - \
  --variant after-point point . - \
  --variant diag-rows-only rows-prep ../gpu15d-diag-rows - \
  --variant diag-ring-only rows-prep ../gpu15d-diag-ring - \
  --variant before:direct point-prep:direct ../gpu15d-base - \
  --variant after:direct rows-prep:direct . - \
  --variant before-again point-prep ../gpu15d-base - \
  --variant after-again rows-prep . - \
  --variant before-point-again point ../gpu15d-base - > $OUT/run6.txt 2>&1
tail -16 $OUT/run6.txt
uptime >> $OUT/machine.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -q -p no:cacheprovider tests/test_work_points.py tests/test_frame_capacity.py tests/test_vertex_rows.py tests/test_session.py tests/test_vertices.py > $OUT/gpu_tests.txt 2>&1
tail -3 $OUT/gpu_tests.txt
timeout 200 python3 bench/frame_loop.py --device nvidia --variants-only --repeat 5 --scenes tea_table killeroo herd spheres double_torus elephant star_field model_zoo --work point point-prep rows-prep --json $OUT/frame_loop.json > $OUT/frame_loop.txt 2>&1
grep "^| " $OUT/frame_loop.txt | head -30

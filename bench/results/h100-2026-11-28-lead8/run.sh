set -x
. bench/gpu_setup.sh
S="tea_table double_torus killeroo herd spheres star_field model_zoo"
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/gpu.txt 2>&1
timeout 200 python3 bench/frame_host.py --device nvidia --frames 20 --repeat 3 --scenes $S --baseline probe/base8 --json $OUT/frame_host.json > $OUT/frame_host.txt 2>&1
for t in . probe/base8; do PYTHONPATH=/tmp/site:$PWD/$t timeout 60 python3 bench/frame_hashes.py --device nvidia $S; done > $OUT/hashes.txt 2>&1
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/contracts tests/test_triangles_mirror.py tests/test_triangle_at.py tests/test_work_points.py tests/test_work_auto.py tests/test_session.py tests/test_recorded_frames.py tests/test_frame_capacity.py tests/test_frame_host.py tests/test_quad_grid_cells.py > $OUT/tests.txt 2>&1
timeout 90 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --variant main rows-prep . - --variant base rows-prep probe/base8 - > $OUT/stage45.txt 2>&1
tail -3 $OUT/*.txt

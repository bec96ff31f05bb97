# The lead's H200 call, session 10: main after the session's merges (gpu15h, gpu15i, cpu15f, the
# backend's split) against the session's start (a58e27f in probe/base10); from /work/main, carry
# [".whl", "probe/base10"]; raw outputs tarred into $OUT/lead10.tgz.
. bench/gpu_setup.sh || exit 1
ln -sfn ../kernels probe/base10/cltess/kernels
R=$OUT/raw; mkdir -p $R
S="tea_table double_torus killeroo herd spheres star_field model_zoo elephant"
{ date -u; nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv; nproc; uptime; } > $R/gpu.txt 2>&1
for t in . probe/base10; do echo "tree $t"; PYTHONPATH=/tmp/site:$PWD/$t timeout 40 python3 bench/frame_hashes.py --device nvidia $S; done > $R/hashes.txt 2>&1
timeout 120 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --variant main rows-prep . - --variant start rows-prep probe/base10 - --variant main2 rows-prep . - --variant start2 rows-prep probe/base10 - --variant main-point point . - --variant start-point point probe/base10 - > $R/stage45.txt 2>&1
tail -14 $R/stage45.txt
CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/contracts tests/test_crack_offsets.py tests/test_projected.py tests/test_triangles_mirror.py tests/test_triangle_at.py tests/test_quad_grid_cells.py tests/test_fused_offsets.py tests/test_recorded_frames.py tests/test_session.py tests/test_frame_capacity.py tests/test_frame_host.py tests/test_work_auto.py tests/test_work_points.py tests/test_unit_normal.py tests/test_vertices.py tests/test_poles.py tests/test_packaging.py > $R/tests.txt 2>&1
tail -2 $R/tests.txt
timeout 100 python3 bench/frame_host.py --device nvidia --frames 20 --repeat 2 --scenes tea_table double_torus killeroo herd spheres star_field model_zoo --baseline probe/base10 > $R/frame_host.txt 2>&1
tail -12 $R/frame_host.txt
uptime >> $R/gpu.txt
tar -czf $OUT/lead10.tgz -C $OUT raw
grep -v "^ *$" $R/hashes.txt | tail -20

# Session 10, branch gpu15i, call 2 on the H200: from /work/main, carry [".whl", "probe/gpu15i", "probe/gpu15i-base"]:
# this branch (`git archive` of the commit that adds this script) and main (44fafbe).  Stage 4-5 side by side: main;
# the branch (stage 5's per-patch/per-triangle split, default options); the branch with -DTRIANGLE_PAIRS=1 (a cell's
# two triangles by one work-item), each twice, and under `point`; ncu of triangles in all three; frame hashes of the
# branch both ways; the GPU tests (default build: run3's list of gpu15h plus the triangle tests; the pairs build:
# the stage 5 tests).
cd probe/gpu15i && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15i-base && ln -sfn ../kernels cltess/kernels)
R=$OUT/run2; mkdir -p $R
{ date -u; nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.sm,clocks.mem --format=csv; uptime; } > $R/machine.txt 2>&1
P=opt:-DTRIANGLE_PAIRS=1
timeout 130 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/stage45.json --variant main rows-prep ../gpu15i-base - --variant branch rows-prep . - --variant pairs rows-prep . $P --variant main-again rows-prep ../gpu15i-base - --variant branch-again rows-prep . - --variant pairs-again rows-prep . $P --variant main-point point ../gpu15i-base - --variant branch-point point . - --variant pairs-point point . $P > $R/stage45.txt 2>&1
tail -12 $R/stage45.txt
N="ncu --clock-control none -k regex:^triangles$ -c 1 --set full --import-source no -f"
(cd ../gpu15i-base && PYTHONPATH=/tmp/site:$PWD timeout 50 $N -o $R/tri python3 bench/ncu_stage45.py --repeat 1 --kernels triangles) > $R/ncu_tri_log.txt 2>&1
timeout 50 $N -o $R/tri_branch python3 bench/ncu_stage45.py --repeat 1 --kernels triangles > $R/ncu_tri_branch_log.txt 2>&1
CLTESS_BUILD_OPTIONS=-DTRIANGLE_PAIRS=1 timeout 50 $N -o $R/tri_pairs python3 bench/ncu_stage45.py --repeat 1 --kernels triangles > $R/ncu_tri_pairs_log.txt 2>&1
for n in tri tri_branch tri_pairs; do ncu -i $R/$n.ncu-rep --page details --print-units base --print-details all > $R/${n}_details.txt 2>&1; ncu -i $R/$n.ncu-rep --page source --csv --print-source sass > $R/${n}_sass.csv 2>&1; done
S="tea_table double_torus killeroo herd spheres star_field model_zoo elephant"
for o in "" -DTRIANGLE_PAIRS=1; do echo "options '$o'"; CLTESS_BUILD_OPTIONS="$o" timeout 45 python3 bench/frame_hashes.py --device nvidia $S; done > $R/hashes.txt 2>&1
grep -v "^ *$" $R/hashes.txt | tail -20
T="tests/test_triangle_at.py tests/test_quad_grid_cells.py tests/test_triangles_mirror.py tests/test_work_points.py tests/test_recorded_frames.py tests/test_work_auto.py tests/test_frame_capacity.py"
CLTESS_DEVICE=nvidia timeout 130 python3 -m pytest -o addopts="" -q -p no:cacheprovider $T tests/test_unit_normal.py tests/test_projected.py tests/test_vertices.py tests/contracts tests/test_crack_offsets.py tests/test_fused_offsets.py tests/test_session.py tests/test_frame_host.py tests/test_poles.py tests/test_pattern_normals.py > $R/gpu_tests.txt 2>&1
tail -2 $R/gpu_tests.txt
CLTESS_BUILD_OPTIONS=-DTRIANGLE_PAIRS=1 CLTESS_DEVICE=nvidia timeout 60 python3 -m pytest -o addopts="" -q -p no:cacheprovider $T > $R/gpu_tests_pairs.txt 2>&1
tail -2 $R/gpu_tests_pairs.txt
uptime >> $R/machine.txt
tar -czf $OUT/gpu15i_run2.tgz -C $OUT --exclude="*.ncu-rep" run2

# Session 10, branch gpu15h, call 2 on the H200: from /work/main, carry [".whl", "probe/gpu15h",
# "probe/gpu15h-base", "probe/gpu15h-div", "probe/gpu15h-local"]: this branch (dd9db80: both
# changes), main (a58e27f), the division change alone (55ab586) and the local-memory change alone
# (a58e27f + dd9db80's prepared_points.cl), each `git archive` (bench/results dropped from the
# last three). Stage 4-5 side by side, hashes of the paper's scenes, the CUDA replay and ncu of
# the branch's prepared_rows, the GPU tests.
cd probe/gpu15h && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15h-base ../gpu15h-div ../gpu15h-local; do (cd $t && ln -sfn ../kernels cltess/kernels); done
R=$OUT/raw; mkdir -p $R
set -x
{ date -u; nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.sm,clocks.mem --format=csv; uptime; } > $R/machine.txt 2>&1
timeout 150 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/stage45.json --variant main rows-prep ../gpu15h-base - --variant branch rows-prep . - --variant div-only rows-prep ../gpu15h-div - --variant local-only rows-prep ../gpu15h-local - --variant main-again rows-prep ../gpu15h-base - --variant branch-again rows-prep . - --variant main-point point ../gpu15h-base - --variant branch-point point . - > $R/stage45.txt 2>&1
S="tea_table double_torus killeroo herd spheres star_field model_zoo elephant"
for t in ../gpu15h-base .; do PYTHONPATH=/tmp/site:$PWD/$t timeout 40 python3 bench/frame_hashes.py --device nvidia $S; done > $R/hashes.txt 2>&1
timeout 60 python3 bench/ncu_stage45.py --repeat 20 --json $R/replay_rows.json > $R/replay_rows.txt 2>&1
timeout 120 ncu --clock-control none -k 'regex:^prepared_rows$' -c 2 --set full --import-source no -f -o $R/rows python3 bench/ncu_stage45.py --repeat 1 --kernels prepared_rows > $R/ncu_rows_log.txt 2>&1
ncu -i $R/rows.ncu-rep --page details --print-units base > $R/rows_details.txt 2>&1
ncu -i $R/rows.ncu-rep --page source --csv --print-source sass > $R/rows_sass.csv 2>&1
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_unit_normal.py tests/test_projected.py tests/test_work_points.py tests/test_vertices.py tests/contracts tests/test_crack_offsets.py tests/test_triangles_mirror.py tests/test_fused_offsets.py tests/test_recorded_frames.py tests/test_session.py tests/test_frame_capacity.py tests/test_frame_host.py tests/test_work_auto.py tests/test_poles.py tests/test_pattern_normals.py > $R/gpu_tests.txt 2>&1
uptime >> $R/machine.txt
tar -czf $OUT/gpu15h_run2.tgz -C $OUT --exclude="*.ncu-rep" raw
tail -16 $R/stage45.txt; cat $R/hashes.txt | grep -v "^ *$" | tail -24; tail -12 $R/replay_rows.txt; tail -3 $R/gpu_tests.txt

# Session 10, branch gpu15h, call 1 on the H200: from /work/main, carry [".whl", "probe/gpu15h"]
# (probe/gpu15h = this branch's tree). Baseline stage 4-5 times, whether ncu sees OpenCL kernels,
# the CUDA replay of stage 4-5 (same bits, times, registers), ncu --set full on the replay
# (rows-prep: prepare_patches, prepared_rows, triangles; point: vertex_points), text exports.
cd probe/gpu15h && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
R=$OUT/raw; mkdir -p $R
set -x
{ date -u; nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.sm,clocks.mem,power.limit --format=csv; nproc; uptime; ncu --version; python3 -c "import cupy; print('cupy', cupy.__version__)"; } > $R/machine.txt 2>&1
timeout 100 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --variant main rows-prep . - --variant main-point point . - --variant main-again rows-prep . - > $R/stage45.txt 2>&1
timeout 90 ncu --clock-control none -k regex:prepared_rows -c 1 --section SpeedOfLight python3 bench/ncu_stage45.py --repeat 2 --no-replay > $R/ncu_opencl_check.txt 2>&1
timeout 90 python3 bench/ncu_stage45.py --repeat 20 --ptx $R/ptx --json $R/replay_rows.json > $R/replay_rows.txt 2>&1
timeout 90 python3 bench/ncu_stage45.py --repeat 20 --work point --kernels vertex_points triangles --json $R/replay_point.json > $R/replay_point.txt 2>&1
timeout 200 ncu --clock-control none -k 'regex:^(prepare_patches|prepared_rows|triangles)$' -c 8 --set full --import-source no -f -o $R/rows python3 bench/ncu_stage45.py --repeat 1 > $R/ncu_rows_log.txt 2>&1
timeout 120 ncu --clock-control none -k 'regex:^vertex_points$' -c 4 --set full --import-source no -f -o $R/point python3 bench/ncu_stage45.py --repeat 1 --work point --kernels vertex_points > $R/ncu_point_log.txt 2>&1
for r in rows point; do
  [ -f $R/$r.ncu-rep ] || continue
  ncu -i $R/$r.ncu-rep --page details --print-units base --print-details all > $R/${r}_details.txt 2>&1
  ncu -i $R/$r.ncu-rep --page raw --csv --print-units base --print-metric-instances values > $R/${r}_raw.csv 2>&1
  ncu -i $R/$r.ncu-rep --page source --csv --print-source sass -k regex:'^(prepared_rows|vertex_points)$' > $R/${r}_sass.csv 2>&1 || echo source page failed >> $R/${r}_sass.csv
done
ls -la $R
{ uptime; nvidia-smi --query-gpu=clocks.sm,clocks.mem,temperature.gpu --format=csv; } >> $R/machine.txt 2>&1
tar -czf $OUT/gpu15h_run1.tgz -C $OUT --exclude="*.ncu-rep" raw; tar -czf $OUT/gpu15h_run1_reps.tgz -C $OUT/raw rows.ncu-rep point.ncu-rep
tail -22 $R/stage45.txt; tail -8 $R/ncu_opencl_check.txt $R/replay_rows.txt $R/replay_point.txt; tail -4 $R/ncu_rows_log.txt $R/ncu_point_log.txt; head -c 600 $R/rows_sass.csv

# The lead's H100 call, session 9: main after the session's merges against the session's start
# (adf8eeb in probe/base9), carry [".whl", "probe/base9"]; raw outputs tarred into $OUT/lead9.tgz.
set -x
. bench/gpu_setup.sh
R=$OUT/raw; mkdir -p $R
S="tea_table double_torus killeroo herd spheres star_field model_zoo"
{ nvidia-smi --query-gpu=name,driver_version --format=csv; nproc; uptime; } > $R/gpu.txt 2>&1
for t in . probe/base9; do PYTHONPATH=/tmp/site:$PWD/$t timeout 30 python3 bench/frame_hashes.py --device nvidia $S; done > $R/hashes.txt 2>&1
timeout 70 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --variant main rows-prep . - --variant base rows-prep probe/base9 - --variant main2 rows-prep . - > $R/stage45.txt 2>&1
timeout 100 python3 bench/frame_host.py --device nvidia --frames 20 --repeat 3 --scenes $S --baseline probe/base9 --json $R/frame_host.json > $R/frame_host.txt 2>&1
timeout 60 python3 bench/frame_host.py --device nvidia --frames 50 --repeat 5 --scenes double_torus tea_table --baseline probe/base9 --json $R/frame_host_dt.json > $R/frame_host_dt.txt 2>&1
CLTESS_DEVICE=nvidia timeout 120 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/contracts tests/test_crack_offsets.py tests/test_projected.py tests/test_triangles_mirror.py tests/test_fused_offsets.py tests/test_recorded_frames.py tests/test_session.py tests/test_frame_capacity.py tests/test_frame_host.py tests/test_work_auto.py > $R/tests.txt 2>&1
uptime >> $R/gpu.txt
tar -czf $OUT/lead9.tgz -C $OUT raw
tail -5 $R/*.txt

# The one H100 call of branch host15e (run from probe/host15e, main's tree in ../base15e), carry
# [".whl", "probe/host15e", "probe/base15e"]; raw outputs tarred into $OUT/host15e.tgz.
set -x
ln -sfn ../../.whl .whl
. bench/gpu_setup.sh
[ -e ../base15e/cltess/kernels ] || ln -s ../kernels ../base15e/cltess/kernels
R=$OUT/raw; mkdir -p $R
S="tea_table double_torus killeroo herd spheres star_field model_zoo"
{ nvidia-smi --query-gpu=name,driver_version --format=csv; nproc; uptime; } > $R/gpu.txt 2>&1
for t in . ../base15e; do PYTHONPATH=/tmp/site:$PWD/$t timeout 25 python3 bench/frame_hashes.py --device nvidia $S; done > $R/hashes.txt 2>&1
timeout 55 python3 bench/frame_host.py --device nvidia --frames 50 --repeat 5 --scenes double_torus tea_table --baseline ../base15e --json $R/frame_host_dt.json > $R/frame_host_dt.txt 2>&1
CLTESS_DEVICE=nvidia timeout 60 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_crack_offsets.py tests/test_fused_offsets.py tests/test_recorded_frames.py tests/test_session.py tests/test_frame_capacity.py tests/test_frame_host.py > $R/tests.txt 2>&1
timeout 90 python3 bench/frame_host.py --device nvidia --frames 20 --repeat 2 --scenes $S --baseline ../base15e --json $R/frame_host.json > $R/frame_host.txt 2>&1
timeout 15 python3 bench/frame_calls.py --device nvidia --frames 20 --rounds 3 --scenes double_torus tea_table > $R/calls_this.txt 2>&1
PYTHONPATH=/tmp/site:$PWD/../base15e timeout 15 python3 bench/frame_calls.py --device nvidia --frames 20 --rounds 3 --scenes double_torus tea_table > $R/calls_base.txt 2>&1
uptime >> $R/gpu.txt
tar -czf $OUT/host15e.tgz -C $OUT raw
tail -4 $R/*.txt

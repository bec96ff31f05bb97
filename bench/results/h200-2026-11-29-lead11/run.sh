# The lead's H200 call, session 11: main after the stream and host-frame changes against the
# session's start (88db3df in probe/base11); from /work/main, carry [".whl", "probe/base11"];
# raw outputs tarred into $OUT/lead11.tgz.
. bench/gpu_setup.sh || exit 1
ln -sfn ../kernels probe/base11/cltess/kernels
R=$OUT/raw; mkdir -p $R
S="tea_table double_torus killeroo herd spheres star_field model_zoo elephant"
{ date -u; nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv; nproc; uptime; } > $R/gpu.txt 2>&1
for t in . probe/base11; do echo "tree $t"; PYTHONPATH=/tmp/site:$PWD/$t timeout 40 python3 bench/frame_hashes.py --device nvidia $S; done > $R/hashes.txt 2>&1
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/contracts tests/test_stream.py tests/test_stream_strips.py tests/test_session.py tests/test_frame_capacity.py tests/test_recorded_frames.py tests/test_frame_host.py tests/test_batch.py tests/test_crack_offsets.py tests/test_work_auto.py tests/test_packaging.py > $R/tests.txt 2>&1
tail -2 $R/tests.txt
timeout 100 python3 bench/frame_host.py --device nvidia --frames 20 --repeat 2 --scenes tea_table double_torus killeroo herd spheres star_field model_zoo --baseline probe/base11 > $R/frame_host.txt 2>&1
tail -10 $R/frame_host.txt
mkdir -p /tmp/t30; timeout 200 python3 bench/tessellate_30k.py --device nvidia --repeat 3 --folder /tmp/t30 --baseline probe/base11 > $R/tessellate_30k.txt 2>&1
grep -v "^ *$" $R/tessellate_30k.txt | tail -22
uptime >> $R/gpu.txt
tar -czf $OUT/lead11.tgz -C $OUT raw
grep -v "^ *$" $R/hashes.txt | tail -20

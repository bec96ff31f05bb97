# The lead's H200 call, session 12: Session(buffers=2) on the GPU (tests, the pipelined A/B, the
# frame_host columns); from /work/main, carry [".whl"].
. bench/gpu_setup.sh >/dev/null || exit 1
R=$OUT/piped; mkdir -p $R
{ date -u; nvidia-smi --query-gpu=name,driver_version --format=csv; } > $R/gpu.txt 2>&1
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_session.py tests/test_recorded_frames.py tests/test_frame_host.py tests/test_frame_capacity.py tests/test_stream.py > $R/tests.txt 2>&1
tail -2 $R/tests.txt
for s in tea_table double_torus killeroo star_field; do timeout 60 python3 bench/results/lead12-2core/piped_ab.py nvidia $s; done 2>&1 | grep -v Warn | tee $R/piped_ab.txt
timeout 120 python3 bench/frame_host.py --device nvidia --frames 20 --repeat 2 --scenes tea_table double_torus killeroo herd spheres star_field model_zoo > $R/frame_host.txt 2>&1
tail -9 $R/frame_host.txt

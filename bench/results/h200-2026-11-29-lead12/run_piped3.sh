# The lead's H200 call, session 12: two buffer sets with the copies on a second queue (OutputBuffers.copy_queue);
# from /work/main, carry [".whl"].
. bench/gpu_setup.sh >/dev/null || exit 1
R=$OUT/piped3; mkdir -p $R
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_session.py tests/test_recorded_frames.py tests/test_frame_host.py tests/test_frame_capacity.py tests/test_stream.py tests/test_batch.py > $R/tests.txt 2>&1
tail -2 $R/tests.txt
for s in tea_table double_torus killeroo star_field herd; do timeout 60 python3 bench/results/lead12-2core/piped_ab.py nvidia $s; done 2>&1 | grep -v Warn | tee $R/piped_ab.txt

# session 17, run 2: the CUDA sharing tests (with the descriptor test) and the bench again
. bench/gpu_setup.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
CLTESS_DEVICE=nvidia timeout 300 python3 -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning \
  tests/test_share_cuda.py tests/test_session.py tests/test_recorded_frames.py tests/test_frame_capacity.py tests/test_frame_host.py \
  tests/test_stream.py 2>&1 | tail -15 > $OUT/tests2.txt
cat $OUT/tests2.txt
for k in 1 2; do timeout 200 python3 bench/gpu_share.py --device nvidia --frames 20 --json $OUT/share2-$k.json > $OUT/share2-$k.txt 2>&1; tail -8 $OUT/share2-$k.txt; done

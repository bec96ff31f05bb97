# session 17: CUDA sharing tests and bench, the GL probe; from the checkout root on the H200
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
. bench/gpu_setup.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
timeout 60 python3 probe/gl/probe2.py > $OUT/gl.txt 2>&1; grep -v Warn $OUT/gl.txt | tail -12
CLTESS_DEVICE=nvidia timeout 300 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_share_cuda.py \
  tests/test_session.py tests/test_recorded_frames.py tests/test_frame_capacity.py tests/test_frame_host.py 2>&1 | tail -15 > $OUT/tests.txt
cat $OUT/tests.txt
timeout 240 python3 bench/gpu_share.py --device nvidia --frames 10 --json $OUT/share.json > $OUT/share.txt 2>&1
tail -12 $OUT/share.txt

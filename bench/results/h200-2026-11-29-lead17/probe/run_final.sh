# session 17, the closing GPU run: the sharing tests and the GPU session files, the bench
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh
CLTESS_DEVICE=nvidia timeout 400 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning \
  tests/test_share_gl.py tests/test_share_cuda.py tests/test_session.py tests/test_recorded_frames.py tests/test_frame_capacity.py \
  tests/test_frame_host.py tests/test_stream.py tests/test_work_auto.py 2>&1 | tail -8 > $OUT/tests-final.txt
cat $OUT/tests-final.txt
timeout 150 python3 bench/gpu_share.py --device nvidia --frames 20 --json $OUT/share-final.json > $OUT/share-final.txt 2>&1
tail -8 $OUT/share-final.txt

# Session 18, H200, call 13: after the review (GL's and Vulkan's hand-over tests one contract,
# test_share_handover.py; _shared_fields; the bench's receivers): the sharing tests, the GPU
# session files, the bench. From /work/main, carry [".whl", ".gl", "probe/gl"].
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export GPU_SETUP_POCL=1
. bench/gpu_setup.sh >/dev/null
CLTESS_DEVICE=nvidia timeout 300 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider \
  -W error::pytest.PytestUnraisableExceptionWarning tests/test_share_handover.py tests/test_share_vulkan.py \
  tests/test_share_gl.py tests/test_share_cuda.py tests/test_session.py tests/test_recorded_frames.py \
  tests/test_frame_capacity.py tests/test_cli.py::test_devices_lists_pocl_with_default_marker 2>&1 | tail -25 > $OUT/tests.txt
cat $OUT/tests.txt
timeout 200 python3 -X faulthandler bench/gpu_share.py --device nvidia --frames 20 --json $OUT/share.json > $OUT/share.txt 2>&1
tail -8 $OUT/share.txt
python3 -m cltess devices 2>&1 | tail -5

# Session 18, H200, call 15: after the review mend (handover.py: GL's and Vulkan's hand-over one
# base class, HandedOverBuffers; the semaphores there): the sharing tests, the GPU session files,
# /dev/nvidiactl after N sessions, the bench. From /work/main, carry [".whl", ".gl", "probe/gl"].
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null
CLTESS_DEVICE=nvidia timeout 300 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider -rs \
  -W error::pytest.PytestUnraisableExceptionWarning tests/test_share_handover.py tests/test_share_vulkan.py \
  tests/test_share_gl.py tests/test_share_cuda.py tests/test_session.py tests/test_recorded_frames.py \
  tests/test_frame_capacity.py 2>&1 | tail -15 > $OUT/tests.txt
cat $OUT/tests.txt
PYTHONPATH=$PYTHONPATH:bench timeout 200 python3 -X faulthandler probe/gl/fd_sessions.py 2>&1 | grep -v "Warn\|prg.build\|_create_built" > $OUT/fd_sessions.txt
cat $OUT/fd_sessions.txt
timeout 200 python3 -X faulthandler bench/gpu_share.py --device nvidia --frames 20 --json $OUT/share.json > $OUT/share.txt 2>&1
tail -8 $OUT/share.txt

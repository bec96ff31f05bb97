# session 17, run 10: descriptors by part, the GL and CUDA tests, the bench
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh
timeout 120 python3 -X faulthandler probe/gl/fd_steps2.py > $OUT/fd_steps2.txt 2>&1; echo "rc $?"; grep -v "Warn\|prg.build\|_create_built" $OUT/fd_steps2.txt | tail -12
CLTESS_DEVICE=nvidia timeout 300 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning \
  tests/test_share_gl.py tests/test_share_cuda.py tests/test_session.py tests/test_recorded_frames.py tests/test_frame_capacity.py 2>&1 | tail -14 > $OUT/tests5.txt
cat $OUT/tests5.txt
timeout 200 python3 bench/gpu_share.py --device nvidia --frames 20 --json $OUT/share5.json > $OUT/share5.txt 2>&1
tail -8 $OUT/share5.txt

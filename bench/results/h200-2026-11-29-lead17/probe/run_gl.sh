# session 17, runs 3-5: share="gl" (Vulkan semaphores) tests, the bench with its gl column, which Vulkan call drops the GL context
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh
timeout 60 python3 probe/gl/vk_current.py 2>&1 | grep -v Warn | tee $OUT/vk_current.txt
CLTESS_DEVICE=nvidia timeout 300 python3 -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning \
  tests/test_share_gl.py tests/test_share_cuda.py 2>&1 | tail -30 > $OUT/tests3.txt
cat $OUT/tests3.txt
timeout 200 python3 bench/gpu_share.py --device nvidia --frames 20 --json $OUT/share3.json > $OUT/share3.txt 2>&1
tail -9 $OUT/share3.txt

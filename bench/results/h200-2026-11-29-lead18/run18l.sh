# Session 18, H200, call 14: a Vulkan device made without the extensions is refused
# (vulkan.check_extensions); the hand-over tests again. From /work/main, carry [".whl", ".gl", "probe/gl"].
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null
CLTESS_DEVICE=nvidia timeout 300 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider -rs \
  -W error::pytest.PytestUnraisableExceptionWarning tests/test_share_vulkan.py tests/test_share_handover.py \
  tests/test_share_gl.py tests/test_share_cuda.py 2>&1 | tail -15 > $OUT/tests.txt
cat $OUT/tests.txt

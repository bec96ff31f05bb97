# Session 18, H200, call 3: share="vulkan" (share_vulkan.py), its tests, the GL and CUDA tests
# after the Vulkan code moved to vulkan.py, and the bench. From /work/main, carry
# [".whl", ".gl", "probe/gl"].
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null
CLTESS_DEVICE=nvidia timeout 240 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider -x \
  -W error::pytest.PytestUnraisableExceptionWarning tests/test_share_vulkan.py 2>&1 | tail -40 > $OUT/tests-vulkan.txt
cat $OUT/tests-vulkan.txt
CLTESS_DEVICE=nvidia timeout 240 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider \
  -W error::pytest.PytestUnraisableExceptionWarning tests/test_share_gl.py tests/test_share_cuda.py tests/test_session.py \
  2>&1 | tail -14 > $OUT/tests-gl-cuda.txt
cat $OUT/tests-gl-cuda.txt
timeout 200 python3 -X faulthandler bench/gpu_share.py --device nvidia --frames 20 --json $OUT/share.json > $OUT/share.txt 2>&1
tail -9 $OUT/share.txt

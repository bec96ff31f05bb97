# session 17, the last GL check: test_share_gl.py and test_share_cuda.py after the import's error path
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null || exit 1
CLTESS_DEVICE=nvidia timeout 300 python3 -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning \
  tests/test_share_gl.py tests/test_share_cuda.py tests/test_session.py 2>&1 | tail -3 | tee $OUT/tests-last.txt

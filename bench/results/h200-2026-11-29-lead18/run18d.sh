# Session 18, H200, call 4: the Vulkan tests whole (the closing test allowing the driver's one
# /dev/nvidiactl, as GL's), and /dev/nvidiactl after N closed sessions of each kind.
# From /work/main, carry [".whl", ".gl", "probe/gl"].
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null
CLTESS_DEVICE=nvidia timeout 240 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider \
  -W error::pytest.PytestUnraisableExceptionWarning tests/test_share_vulkan.py tests/test_share_gl.py 2>&1 | tail -20 > $OUT/tests-vulkan2.txt
cat $OUT/tests-vulkan2.txt
PYTHONPATH=$PYTHONPATH:bench timeout 200 python3 -X faulthandler probe/gl/fd_sessions.py 2>&1 | grep -v "Warn\|prg.build\|_create_built" > $OUT/fd_sessions.txt
cat $OUT/fd_sessions.txt

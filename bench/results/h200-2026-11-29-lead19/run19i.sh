# Session 19, H200, call 9: after the review mend (SharedBuffer, vulkan.memory_type, stage 5's pair
# branch written once): the sharing tests, stage 4-5 tests, and stage 5 against the start.
# Carry [".whl", ".gl", "probe/base19", "probe/gpu19"].
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null
ln -sfn ../kernels probe/base19/cltess/kernels
R=$OUT/call9; mkdir -p $R
CLTESS_DEVICE=nvidia timeout 240 python3 -X faulthandler -m pytest -o addopts="" -q -p no:cacheprovider -rs \
  -W error::pytest.PytestUnraisableExceptionWarning tests/test_share_handover.py tests/test_share_vulkan.py \
  tests/test_share_gl.py tests/test_share_cuda.py tests/test_triangles_mirror.py tests/test_triangle_at.py \
  tests/test_work_points.py > $R/tests.txt 2>&1
tail -4 $R/tests.txt
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/stage5.json \
  --variant base rows-prep probe/base19 - --variant mended rows-prep . - \
  --variant base-again rows-prep probe/base19 - --variant mended-again rows-prep . - 2>&1 \
  | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/stage5.txt
grep "^|\|GB/s" $R/stage5.txt

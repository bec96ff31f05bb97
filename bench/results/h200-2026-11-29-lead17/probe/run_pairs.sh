# session 17: stage 5's cell pairs as three 8-byte stores (TRIANGLE_PAIR_STORES) against six words; the new GL/CUDA tests
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null || exit 1
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/pairs.json \
  --variant words rows-prep . opt:-DTRIANGLE_PAIR_STORES=0 \
  --variant pairs rows-prep . - \
  --variant words-point point . opt:-DTRIANGLE_PAIR_STORES=0 \
  --variant pairs-point point . - \
  --variant words-again rows-prep . opt:-DTRIANGLE_PAIR_STORES=0 \
  --variant pairs-again rows-prep . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $OUT/pairs.txt
tail -22 $OUT/pairs.txt
CLTESS_DEVICE=nvidia timeout 300 python3 -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning \
  tests/test_work_points.py tests/test_triangle_at.py tests/test_share_gl.py tests/test_share_cuda.py tests/test_session.py 2>&1 | tail -4 > $OUT/tests-pairs.txt
cat $OUT/tests-pairs.txt

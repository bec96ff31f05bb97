# Session 19, H200, call 4: stage 5's cell pairs as three 8-byte stores (TRIANGLE_WORDS2) against
# the start (probe/base19), and the tests with the option. Carry [".whl", "probe/base19", "probe/gpu19"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base19/cltess/kernels
R=$OUT/call4; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/words2.json \
  --variant base rows-prep probe/base19 - \
  --variant words2 rows-prep . opt:-DTRIANGLE_WORDS2=1 \
  --variant base-again rows-prep probe/base19 - \
  --variant words2-again rows-prep . opt:-DTRIANGLE_WORDS2=1 \
  --variant base-point point probe/base19 - \
  --variant words2-point point . opt:-DTRIANGLE_WORDS2=1 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/words2.txt
grep "^|" $R/words2.txt
CLTESS_BUILD_OPTIONS=-DTRIANGLE_WORDS2=1 CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -o addopts="" -q -p no:cacheprovider \
  tests/test_work_points.py tests/test_triangles_mirror.py tests/test_triangle_at.py tests/test_recorded_frames.py > $R/tests.txt 2>&1
tail -2 $R/tests.txt

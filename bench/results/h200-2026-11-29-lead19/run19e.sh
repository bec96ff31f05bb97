# Session 19, H200, call 5: stage 5 kept (a cell's pair as 8-byte stores) and the probe of four
# triangles a work-item (TRIANGLE_QUADS: two cells as 16-byte stores) against the start
# (probe/base19); the GPU tests of stages 4-5 on both. Carry [".whl", "probe/base19", "probe/gpu19"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base19/cltess/kernels
R=$OUT/call5; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/stage5.json \
  --variant base rows-prep probe/base19 - \
  --variant pairs rows-prep . - \
  --variant quads rows-prep . opt:-DTRIANGLE_QUADS=1 \
  --variant base-again rows-prep probe/base19 - \
  --variant pairs-again rows-prep . - \
  --variant quads-again rows-prep . opt:-DTRIANGLE_QUADS=1 \
  --variant quads-point point . opt:-DTRIANGLE_QUADS=1 \
  --variant pairs-point point . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/stage5.txt
grep "^|" $R/stage5.txt
T="tests/test_work_points.py tests/test_triangles_mirror.py tests/test_triangle_at.py tests/test_recorded_frames.py tests/test_frame_capacity.py tests/test_session.py tests/test_work_auto.py"
CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning $T > $R/tests.txt 2>&1
tail -1 $R/tests.txt
CLTESS_BUILD_OPTIONS=-DTRIANGLE_QUADS=1 CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -o addopts="" -q -p no:cacheprovider $T > $R/tests-quads.txt 2>&1
tail -1 $R/tests-quads.txt

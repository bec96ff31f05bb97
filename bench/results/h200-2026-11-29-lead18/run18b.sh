# Session 18, H200, call 2: the u-edge terms alone with constant indices (kinds/bezier.h
# surface_eval_at_u_end; call 1's runtime index put the patch on the stack: 1.61 ms) against the
# session's start (probe/base18). From /work/main, carry [".whl", "probe/base18", "probe/gl"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base18/cltess/kernels
R=$OUT/edges2; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/edges2.json \
  --variant before rows-prep probe/base18 - \
  --variant u-terms rows-prep . - \
  --variant before-again rows-prep probe/base18 - \
  --variant u-terms-again rows-prep . - \
  --variant before-point point probe/base18 - \
  --variant u-terms-point point . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/edges2.txt
tail -12 $R/edges2.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_boundary_eval.py tests/test_work_points.py \
  tests/test_projected.py > $R/tests.txt 2>&1
tail -3 $R/tests.txt

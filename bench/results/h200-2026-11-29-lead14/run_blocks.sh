# The lead's H200 call, session 14: the CPU blocks change made power_form and cubic_differences one
# body for float4 and float8 (every device); NVIDIA keeps CLTESS_LANES 0.  This tree against the start
# (probe/base14 = git archive 13c5ffd cltess kernels bench); from /work/main, carry
# [".whl", "probe/base14"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base14/cltess/kernels
R=$OUT/blocks; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/blocks.json \
  --variant before rows-prep probe/base14 - \
  --variant now rows-prep . - \
  --variant before-again rows-prep probe/base14 - \
  --variant now-again rows-prep . - \
  --variant before-point point probe/base14 - \
  --variant now-point point . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/blocks.txt
tail -12 $R/blocks.txt
CLTESS_DEVICE=nvidia timeout 240 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_vertices.py tests/test_session.py tests/test_work_points.py tests/test_recorded_frames.py tests/contracts > $R/tests.txt 2>&1
tail -2 $R/tests.txt

# The lead's H200 call, session 13: the CPU lanes change touched boundary_point (loops unrolled by
# hint) for every device; NVIDIA keeps CLTESS_LANES 0.  This tree against the session's start
# (probe/base13 = git archive b2a3184 cltess kernels bench); from /work/main, carry
# [".whl", "probe/base13"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base13/cltess/kernels
R=$OUT/lanes; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/lanes.json \
  --variant before rows-prep probe/base13 - \
  --variant now rows-prep . - \
  --variant before-again rows-prep probe/base13 - \
  --variant now-again rows-prep . - \
  --variant before-point point probe/base13 - \
  --variant now-point point . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/lanes.txt
tail -12 $R/lanes.txt
CLTESS_DEVICE=nvidia timeout 240 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_vertices.py tests/test_session.py tests/test_work_points.py tests/test_recorded_frames.py tests/contracts > $R/tests.txt 2>&1
tail -2 $R/tests.txt

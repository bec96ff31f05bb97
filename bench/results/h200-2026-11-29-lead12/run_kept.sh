# The lead's H200 call, session 12: a Session's patches prepared once (the *-prep stage 4) against
# the tree before (probe/base12 = git archive 3810418); from /work/main, carry [".whl", "probe/base12"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base12/cltess/kernels
R=$OUT/kept; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/kept.json \
  --variant before rows-prep probe/base12 - \
  --variant kept rows-prep . - \
  --variant before-again rows-prep probe/base12 - \
  --variant kept-again rows-prep . - \
  --variant before-point-prep point-prep probe/base12 - \
  --variant kept-point-prep point-prep . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/kept.txt
tail -12 $R/kept.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_session.py tests/test_work_points.py tests/test_work_auto.py tests/test_recorded_frames.py tests/test_frame_capacity.py tests/contracts > $R/tests.txt 2>&1
tail -2 $R/tests.txt

# Session 19, H200, call 1: stage 4 in two phases (staged_points, work="staged-prep") against
# rows-prep, from /work/main, carry [".whl", "probe/base19", "probe/gpu19"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base19/cltess/kernels
R=$OUT/call1; mkdir -p $R
CLTESS_DEVICE=nvidia timeout 150 python3 -m pytest -o addopts="" -q -p no:cacheprovider -x tests/test_staged_probe.py -k "not torus" > $R/tests.txt 2>&1
tail -3 $R/tests.txt
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/staged.json \
  --variant base rows-prep probe/base19 - \
  --variant rows rows-prep . - \
  --variant staged staged-prep . - \
  --variant staged/16 staged-prep/16 . - \
  --variant staged/8 staged-prep/8 . - \
  --variant staged:direct staged-prep:direct . - \
  --variant rows:direct rows-prep:direct . - \
  --variant base-again rows-prep probe/base19 - \
  --variant staged-again staged-prep . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/staged.txt
tail -14 $R/staged.txt

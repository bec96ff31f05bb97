# The lead's H200 call, session 12: the same, the controls kept in the row state (second try)
# against main; from /work/main, carry [".whl", "probe/base12"] (probe/base12 = git archive 5d40d85).
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base12/cltess/kernels
R=$OUT/edge2; mkdir -p $R
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/edge.json \
  --variant main rows-prep probe/base12 - \
  --variant edge rows-prep . opt:-DLINE_EDGE_CONTROLS=1 \
  --variant main-again rows-prep probe/base12 - \
  --variant edge-again rows-prep . opt:-DLINE_EDGE_CONTROLS=1 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/edge.txt
tail -12 $R/edge.txt
CLTESS_DEVICE=nvidia CLTESS_BUILD_OPTIONS=-DLINE_EDGE_CONTROLS=1 timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_work_points.py > $R/tests_edge.txt 2>&1
tail -2 $R/tests_edge.txt

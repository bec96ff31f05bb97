# Session 20, H200, call 1: Markstein's quotient checked on all 2^46 pairs of significands; the
# shared-reciprocal normal (common.h quotients_by_positive) against the start (probe/base20) on
# uniform level 16; the GPU tests of the normal and stage 4; frame hashes of the paper scenes in
# both trees.  Carry [".whl", "probe/base20", "probe/gpu20"].
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base20/cltess/kernels
R=$OUT/call1; mkdir -p $R
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > $R/machine.txt 2>&1
timeout 280 python3 bench/reciprocal_division.py --device nvidia > $R/check.txt 2>&1; echo "check rc=$?" >> $R/check.txt
cat $R/check.txt | grep -v Warning
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/stage45.json \
  --variant base rows-prep probe/base20 - --variant shared rows-prep . - \
  --variant base-again rows-prep probe/base20 - --variant shared-again rows-prep . - \
  --variant base-point point probe/base20 - --variant shared-point point . - 2>&1 \
  | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/stage45.txt
grep "^|\|GB/s" $R/stage45.txt
T="tests/test_unit_normal.py tests/test_work_points.py tests/test_vertices.py tests/test_vertex_rows.py tests/test_pattern_normals.py tests/test_projected.py"
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning $T > $R/tests.txt 2>&1
tail -3 $R/tests.txt
S="tea_table double_torus killeroo spheres elephant"
timeout 120 python3 bench/frame_hashes.py --device nvidia --as-gpu $S > $R/hashes-shared.txt 2>&1
PYTHONPATH=/tmp/site:$PWD/probe/base20 timeout 120 python3 probe/base20/bench/frame_hashes.py --device nvidia --as-gpu $S > $R/hashes-base.txt 2>&1
diff <(grep -v Warn $R/hashes-base.txt) <(grep -v Warn $R/hashes-shared.txt) > $R/hashes.diff && echo "hashes same" || { echo "hashes differ"; head -20 $R/hashes.diff; }
tail -3 $R/hashes-shared.txt

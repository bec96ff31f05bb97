# gpu15e run 6: edge_point with kind_eval inside each unrolled edge copy (the edge's constant coordinate a
# literal) against main, uniform level 16, rows-prep ("same bits": the hashes of the two outputs).
# H100, from /work/main (bash probe/gpu15e/bench/results/h100-2026-11-27-gpu15e/run6.sh, carry .whl,
# probe/gpu15e, probe/gpu15e-base); the last of this session's device time, so no test run.
cd probe/gpu15e && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15e-base && ln -sfn ../kernels cltess/kernels)
uptime > $OUT/machine6.txt
timeout 40 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run6.json \
  --variant before rows-prep ../gpu15e-base - \
  --variant after rows-prep . - > $OUT/run6.txt 2>&1
tail -5 $OUT/run6.txt

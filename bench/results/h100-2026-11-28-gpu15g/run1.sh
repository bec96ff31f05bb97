# gpu15g run 1 (H100): uniform level 16, main against the branch's exact shortcuts (98cb2f6: projected, w only;
# c956a5d: projected + int_quotient), a no-normal diagnostic, 16 patches per group, and `point`; then the paper's
# scenes and uniform 12 (no power of two) in both trees.  From /work/main, carry .whl and the probe/gpu15g* trees:
# bash probe/gpu15g/bench/results/h100-2026-11-28-gpu15g/run1.sh
cd probe/gpu15g && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
for t in ../gpu15g-base ../gpu15g-w ../gpu15g-diag; do (cd $t && ln -sfn ../kernels cltess/kernels); done
R=$OUT/run1; mkdir -p $R
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > $R/machine1.txt; uptime >> $R/machine1.txt
timeout 330 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/run1_stage45.json --ptx $R/ptx \
  --variant main rows-prep ../gpu15g-base - --variant weights rows-prep ../gpu15g-w - \
  --variant branch rows-prep . - --variant branch/16 rows-prep/16 . - \
  --variant diag-no-normal rows-prep ../gpu15g-diag - \
  --variant main-again rows-prep ../gpu15g-base - --variant branch-again rows-prep . - \
  --variant main-point point ../gpu15g-base - --variant branch-point point . - > $R/run1_stage45.txt 2>&1
tail -14 $R/run1_stage45.txt
for pair in branch:. main:../gpu15g-base; do
  name=${pair%%:*}; tree=${pair#*:}
  (cd $tree && PYTHONPATH=/tmp/site:$PWD timeout 90 python3 bench/work_choice.py --device nvidia --repeat 5 --levels 12 --copies 1000 \
    --scenes tea_table spheres star_field --work point rows-prep --json $R/run1_choice_$name.json > $R/run1_choice_$name.txt 2>&1)
  echo $name; grep "^| [a-z]" $R/run1_choice_$name.txt
done
uptime >> $R/machine1.txt
(cd $R && ls ptx && tar -czf ptx.tar.gz ptx && rm -rf ptx)
cd $OUT && tar -czf run1.tar.gz run1 && rm -rf run1

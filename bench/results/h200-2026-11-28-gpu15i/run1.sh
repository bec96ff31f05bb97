# Session 10, branch gpu15i, call 1 on the H200: from /work/main, carry [".whl", "probe/gpu15i", "probe/gpu15i-base"]:
# this branch (`git archive` of 0104596 + this script) and main (44fafbe), each `git archive`.  Stage 4-5 side by side:
# main; the branch (stage 5's new triangle math; stage 4 as main); the branch with -DLINE_WORDS=1 (stage 4's write-out
# word by word) and -DLINE_VECTORS=1 (float4 staging), each twice; frame hashes of both trees; ncu of the branch's
# triangles and of prepared_rows under both options (the CUDA replay, bench/ncu_stage45.py).
cd probe/gpu15i && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15i-base && ln -sfn ../kernels cltess/kernels)
R=$OUT/run1; mkdir -p $R
{ date -u; nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.sm,clocks.mem --format=csv; uptime; } > $R/machine.txt 2>&1
W=opt:-DLINE_WORDS=1; V=opt:-DLINE_VECTORS=1
timeout 170 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/stage45.json --variant main rows-prep ../gpu15i-base - --variant branch rows-prep . - --variant words rows-prep . $W --variant vectors rows-prep . $V --variant main-again rows-prep ../gpu15i-base - --variant branch-again rows-prep . - --variant words-again rows-prep . $W --variant vectors-again rows-prep . $V --variant main-point point ../gpu15i-base - --variant branch-point point . - > $R/stage45.txt 2>&1
S="tea_table double_torus killeroo herd spheres star_field model_zoo elephant"
for t in ../gpu15i-base .; do PYTHONPATH=/tmp/site:$PWD/$t timeout 45 python3 bench/frame_hashes.py --device nvidia $S; done > $R/hashes.txt 2>&1
CLTESS_BUILD_OPTIONS=-DLINE_WORDS=1 timeout 100 ncu --clock-control none -k 'regex:^(prepared_rows|triangles)$' -c 2 --set full --import-source no -f -o $R/words python3 bench/ncu_stage45.py --repeat 1 --kernels prepared_rows triangles > $R/ncu_words_log.txt 2>&1
CLTESS_BUILD_OPTIONS=-DLINE_VECTORS=1 timeout 80 ncu --clock-control none -k 'regex:^prepared_rows$' -c 1 --set full --import-source no -f -o $R/vectors python3 bench/ncu_stage45.py --repeat 1 --kernels prepared_rows > $R/ncu_vectors_log.txt 2>&1
for n in words vectors; do ncu -i $R/$n.ncu-rep --page details --print-units base --print-details all > $R/${n}_details.txt 2>&1; done
ncu -i $R/words.ncu-rep --page source --csv --print-source sass -k regex:'^triangles$' > $R/triangles_sass.csv 2>&1
ncu -i $R/words.ncu-rep --page source --csv --print-source sass -k regex:'^prepared_rows$' > $R/words_sass.csv 2>&1
uptime >> $R/machine.txt
tar -czf $OUT/gpu15i_run1.tgz -C $OUT --exclude="*.ncu-rep" run1
tail -14 $R/stage45.txt; grep -v "^ *$" $R/hashes.txt | tail -20; tail -3 $R/ncu_words_log.txt $R/ncu_vectors_log.txt

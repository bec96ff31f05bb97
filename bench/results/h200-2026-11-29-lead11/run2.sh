# The lead's second H200 call, session 11: after emit's early read-back (one-shot calls), from
# /work/main, carry [".whl", "probe/base11"]; outputs under $OUT/raw2.
. bench/gpu_setup.sh || exit 1
ln -sfn ../kernels probe/base11/cltess/kernels
R=$OUT/raw2; mkdir -p $R
S="tea_table double_torus killeroo herd spheres star_field model_zoo elephant"
for t in . probe/base11; do echo "tree $t"; PYTHONPATH=/tmp/site:$PWD/$t timeout 40 python3 bench/frame_hashes.py --device nvidia $S; done > $R/hashes.txt 2>&1
CLTESS_DEVICE=nvidia timeout 240 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/contracts tests/test_stream.py tests/test_session.py tests/test_pipeline.py tests/test_batch.py tests/test_frame_capacity.py tests/test_recorded_frames.py > $R/tests.txt 2>&1
tail -2 $R/tests.txt
for s in tea_table killeroo star_field; do timeout 60 python3 bench/results/lead11-2core/oneshot_ab.py $s nvidia; done > $R/oneshot.txt 2>&1
cat $R/oneshot.txt
grep -v "^ *$" $R/hashes.txt | tail -20

# gpu15e run 3: unroll hints 2 / 4 on the point loops (ILP: two points' division chains interleaved), H100.
# From /work/main on the GPU machine (bash probe/gpu15e/bench/results/h100-2026-11-27-gpu15e/run3.sh, carry .whl, probe/gpu15e, probe/gpu15e-base)
cd probe/gpu15e && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15e-base && ln -sfn ../kernels cltess/kernels)
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv > $OUT/machine3.txt; uptime >> $OUT/machine3.txt
R="-DLINE_RING_BY_POINT=1"
timeout 450 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run3.json --ptx $OUT/ptx3 \
  --variant before rows-prep ../gpu15e-base - \
  --variant unroll2 rows-prep . "opt:-DLINE_UNROLL=2" \
  --variant unroll4 rows-prep . "opt:-DLINE_UNROLL=4" \
  --variant unroll2-ringpoint rows-prep . "opt:-DLINE_UNROLL=2 $R" \
  --variant unroll4-ringpoint rows-prep . "opt:-DLINE_UNROLL=4 $R" \
  --variant unroll2/16 rows-prep/16 . "opt:-DLINE_UNROLL=2" \
  --variant unroll2-chunk8 rows-prep . "opt:-DLINE_UNROLL=2 -DLINE_CHUNK=8" \
  --variant before-again rows-prep ../gpu15e-base - > $OUT/run3.txt 2>&1
tail -12 $OUT/run3.txt
python3 -c "
import json; r = json.load(open('$OUT/run3.json'))
for v in r['variants']: print(v['label'], v.get('registers', {}).get('prepared_rows'), v.get('spills', {}).get('prepared_rows'))
"
cd $OUT/ptx3 && rm -f *triangles.ptx before-again* && for f in *.ptx; do gzip -9 $f; done
uptime >> $OUT/machine3.txt

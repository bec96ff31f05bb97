# gpu15e run 1: prepared_rows variants (build options) against main side by side, H100.
# From /work/main on the GPU machine (bash probe/gpu15e/bench/results/h100-2026-11-27-gpu15e/run1.sh, carry .whl, probe/gpu15e, probe/gpu15e-base)
cd probe/gpu15e && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15e-base && ln -sfn ../kernels cltess/kernels)
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine1.txt; uptime >> $OUT/machine1.txt
R="-DLINE_RING_BY_POINT=1"; L="-DLINE_RELOAD_ROWS=1"
timeout 400 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run1.json \
  --variant before rows-prep ../gpu15e-base - \
  --variant after-default rows-prep . - \
  --variant ring-point rows-prep . "opt:$R" \
  --variant reload rows-prep . "opt:$L" \
  --variant both rows-prep . "opt:$R $L" \
  --variant both/16 rows-prep/16 . "opt:$R $L" \
  --variant both/8 rows-prep/8 . "opt:$R $L" \
  --variant ring-point/16 rows-prep/16 . "opt:$R" \
  --variant reload/16 rows-prep/16 . "opt:$L" \
  --variant before-again rows-prep ../gpu15e-base - > $OUT/run1.txt 2>&1
tail -16 $OUT/run1.txt
python3 -c "
import json; r = json.load(open('$OUT/run1.json'))
for v in r['variants']: print(v['label'], v.get('registers'), v.get('spills'))
"
uptime >> $OUT/machine1.txt

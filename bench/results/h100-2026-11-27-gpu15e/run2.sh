# gpu15e run 2: unroll hint 1 on the point loops, register caps (without reqd_work_group_size), H100.
# From /work/main on the GPU machine (bash probe/gpu15e/bench/results/h100-2026-11-27-gpu15e/run2.sh, carry .whl, probe/gpu15e, probe/gpu15e-base)
cd probe/gpu15e && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
(cd ../gpu15e-base && ln -sfn ../kernels cltess/kernels)
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine2.txt; uptime >> $OUT/machine2.txt
R="-DLINE_RING_BY_POINT=1"; L="-DLINE_RELOAD_ROWS=1"; U="-DLINE_UNROLL=1"; N="-DLINE_NO_REQD=1"
timeout 450 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run2.json --ptx $OUT/ptx2 \
  --variant before rows-prep ../gpu15e-base - \
  --variant unroll1 rows-prep . "opt:$U" \
  --variant unroll1-ringpoint rows-prep . "opt:$U $R" \
  --variant unroll1-ringpoint/16 rows-prep/16 . "opt:$U $R" \
  --variant unroll1-ringpoint-cap128/16 rows-prep/16 . "opt:$U $R $N -cl-nv-maxrregcount=128" \
  --variant unroll1-ringpoint-reload-cap128/16 rows-prep/16 . "opt:$U $R $L $N -cl-nv-maxrregcount=128" \
  --variant unroll1-cap128/16 rows-prep/16 . "opt:$U $N -cl-nv-maxrregcount=128" \
  --variant unroll1-ringpoint-cap168/24 rows-prep/24 . "opt:$U $R $N -cl-nv-maxrregcount=168" \
  --variant unroll1-cap168/24 rows-prep/24 . "opt:$U $N -cl-nv-maxrregcount=168" \
  --variant before-again rows-prep ../gpu15e-base - > $OUT/run2.txt 2>&1
tail -14 $OUT/run2.txt
python3 -c "
import json; r = json.load(open('$OUT/run2.json'))
for v in r['variants']: print(v['label'], v.get('registers', {}).get('prepared_rows'), v.get('spills', {}).get('prepared_rows'))
"
cd $OUT/ptx2 && for f in *prepared_points.ptx; do gzip -9 $f; done; ls -la $OUT/ptx2
uptime >> $OUT/machine2.txt

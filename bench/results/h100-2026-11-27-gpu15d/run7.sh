# gpu15d run 7: stage 5's triangles per work-item under rows-prep (PROBE_RECORDS: a probe-only hook)
cd probe/gpu15d && ln -sfn ../../.whl .whl && . bench/gpu_setup.sh || exit 1
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/machine.txt; uptime >> $OUT/machine.txt
for r in 16 32 64 8 16 32 64; do PROBE_RECORDS=$r timeout 100 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/run7-$r.json --variant records$r rows-prep . - 2>/dev/null | grep "^| records"; done | tee $OUT/run7.txt

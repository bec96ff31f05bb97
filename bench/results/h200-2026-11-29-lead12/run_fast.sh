# probe: what the bitwise-exact normals cost on the H200 (from /work/main, carry .whl and probe/fastnorm)
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/fastnorm/cltess/kernels
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/fast.json \
  --variant main rows-prep . - \
  --variant fast-normals rows-prep probe/fastnorm opt:-DCLTESS_FAST_NORMALS=1 \
  --variant main-again rows-prep . - \
  --variant fast-normals-again rows-prep probe/fastnorm opt:-DCLTESS_FAST_NORMALS=1 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build" | tail -30
CLTESS_PROBE_APPROXIMATE_DIVISION=1 python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $OUT/fast2.json \
  --variant fast-normals+approx-div rows-prep probe/fastnorm opt:-DCLTESS_FAST_NORMALS=1 \
  --variant approx-div rows-prep probe/fastnorm - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build" | tail -14

# Session 18, H200: ring normals' boundary terms alone (kinds/bezier.h surface_eval_bounded) against the
# session's start (probe/base18 = git archive HEAD cltess kernels bench scenes), and the u-edge /
# v-edge halves alone (probe/uonly, probe/vonly). From /work/main, carry [".whl", "probe/base18",
# "probe/uonly", "probe/vonly", "probe/gl"].
. bench/gpu_setup.sh >/dev/null || exit 1
for t in base18 uonly vonly; do ln -sfn ../kernels probe/$t/cltess/kernels; done
R=$OUT/edges; mkdir -p $R
nvidia-smi --query-gpu=name,clocks.max.sm,driver_version --format=csv > $R/gpu.txt 2>&1
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/edges.json \
  --variant before rows-prep probe/base18 - \
  --variant terms rows-prep . - \
  --variant u-only rows-prep probe/uonly - \
  --variant v-only rows-prep probe/vonly - \
  --variant before-again rows-prep probe/base18 - \
  --variant terms-again rows-prep . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/edges.txt
tail -30 $R/edges.txt
CLTESS_DEVICE=nvidia timeout 240 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_boundary_eval.py tests/test_work_points.py \
  tests/test_session.py tests/test_recorded_frames.py tests/test_frame_capacity.py tests/test_projected.py tests/test_unit_normal.py > $R/tests.txt 2>&1
tail -3 $R/tests.txt

# The lead's H200 measurement, session 16: rows-prep's ring points in a kernel of their own
# (prepared_ring, a work-item per ring point) beside prepared_rows walking the interior rows alone,
# against the session's start (probe/base16 = git archive HEAD cltess kernels bench scenes).
# From /work/main, carry [".whl", "probe/base16"].
# This is run 2 (ring2.*, tests2.txt). Run 1 (ring1.txt) ran an earlier form of the kernel: the
# ring's edge a runtime index into ring_position / kind_eval. Its variants were apart-32x8 and
# apart-64x16 in place of apart-128x16, and this script had no link for probe/base16, so the
# "before" rows failed there.
. bench/gpu_setup.sh >/dev/null || exit 1
ln -sfn ../kernels probe/base16/cltess/kernels
R=$OUT/ring; mkdir -p $R
nvidia-smi --query-gpu=name,clocks.max.sm,driver_version --format=csv > $R/gpu.txt 2>&1
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/ring.json \
  --variant before rows-prep probe/base16 - \
  --variant apart rows-prep . - \
  --variant apart-64x8 rows-prep . "opt:-DRING_GROUP=64 -DRING_PATCHES=8" \
  --variant apart-128x16 rows-prep . "opt:-DRING_GROUP=128 -DRING_PATCHES=16" \
  --variant together rows-prep . opt:-DLINE_RING_APART=0 \
  --variant before-again rows-prep probe/base16 - \
  --variant apart-again rows-prep . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/ring.txt
tail -24 $R/ring.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_work_points.py \
  tests/test_session.py tests/test_recorded_frames.py tests/test_frame_capacity.py > $R/tests.txt 2>&1
tail -3 $R/tests.txt

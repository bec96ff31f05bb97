#!/usr/bin/env bash
# The GPU-machine runs of the issue benchmarks (issues 11-15) on NVIDIA OpenCL, one call of the
# device tool each (a call may run 10 minutes):
#
#   bash bench/gpu_issues.sh OUTDIR speed      # bench/frame_loop.py, bench/semi_uniform.py
#   bash bench/gpu_issues.sh OUTDIR patterns   # bench/silhouette.py, bench/sd2.py, bench/esc.py
#   bash bench/gpu_issues.sh OUTDIR kernels    # issue 15's work distributions side by side, bitwise tests
#   bash bench/gpu_issues.sh OUTDIR gpu15      # the same with prepared patches, :direct, fused stage 3
#   bash bench/gpu_issues.sh OUTDIR frame15 [BASELINE_TREE]  # a frame's device, host and wall time, by step;
#                                              # with a tree before (git archive): the same for it, then frame_host
#
# Expects in .whl/ the Python 3.12 manylinux x86_64 wheels of pyopencl and its dependencies,
# mako, trimesh, tqdm (as bench/gpu_run.sh) and NVIDIA's OpenCL library in
# /usr/local/nvidia/lib64.  Each benchmark gets its own time limit so that one slow table cannot
# take the others with it; its output and exit code are in OUTDIR.
set -u
out=${1:?usage: bash bench/gpu_issues.sh OUTDIR speed|patterns}
which=${2:?usage: bash bench/gpu_issues.sh OUTDIR speed|patterns|kernels|gpu15|frame15}
. bench/gpu_setup.sh
{ nvidia-smi -L; python3 -m cltess devices; } > "$out/machine-$which.txt" 2>&1
run() {  # run NAME SECONDS COMMAND...
  local name=$1 limit=$2; shift 2
  local started=$SECONDS
  timeout "$limit" "$@" > "$out/$name.txt" 2>&1
  echo "$name rc=$? $((SECONDS - started)) s" | tee -a "$out/log.txt"
}
case $which in
  speed)
    run frame_loop 330 python3 bench/frame_loop.py --device nvidia --json "$out/frame_loop.json"
    run semi_uniform 230 python3 bench/semi_uniform.py --device nvidia --json "$out/semi_uniform.json" ;;
  patterns)
    run silhouette 200 python3 bench/silhouette.py --device nvidia --quality --json "$out/silhouette.json"
    run sd2 150 python3 bench/sd2.py --device nvidia --json "$out/sd2.json"
    run esc 200 python3 bench/esc.py --device nvidia --json "$out/esc.json" --csv "$out/esc.csv" ;;
  kernels)
    run frame_loop_variants 400 python3 bench/frame_loop.py --device nvidia --variants-only --json "$out/frame_loop_variants.json"
    run work_points_tests 150 env CLTESS_DEVICE=nvidia python3 -m pytest -q -p no:cacheprovider tests/test_work_points.py ;;
  gpu15)  # issue 15 on the GPU: prepared patches, direct evaluation, stage 3 in one launch (branch gpu15)
    run frame_loop_gpu15 500 python3 bench/frame_loop.py --device nvidia --variants-only --work gpu --scenes tea_table killeroo herd spheres model_zoo --json "$out/frame_loop_gpu15.json"
    run gpu15_tests 200 env CLTESS_DEVICE=nvidia python3 -m pytest -q -p no:cacheprovider tests/test_work_points.py tests/test_fused_offsets.py tests/test_counts.py ;;
  frame15)  # issue 15, a frame's host cost (branch frame15): the paper's scenes, then the tree before if given
    scenes="tea_table double_torus killeroo herd spheres star_field model_zoo"
    run frame_loop_frames 200 python3 bench/frame_loop.py --device nvidia --frames-only --scenes $scenes --grid-copies 1 10 --json "$out/frame_loop_frames.json"
    run frame15_tests 200 env CLTESS_DEVICE=nvidia python3 -m pytest -q -p no:cacheprovider tests/test_frame_host.py tests/test_session.py tests/test_fused_offsets.py tests/test_frame_capacity.py tests/test_work_points.py
    if [ -n "${3:-}" ]; then
      run frame_loop_frames_base 200 env PYTHONPATH="$3:$PYTHONPATH" python3 bench/frame_loop.py --device nvidia --frames-only --scenes $scenes --grid-copies 1 10 --json "$out/frame_loop_frames_base.json"
      run frame_host 240 python3 bench/frame_host.py --device nvidia --frames 20 --repeat 2 --scenes $scenes --baseline "$3" --json "$out/frame_host.json"
    fi ;;
esac

# Interleaved A/B/C of perf_stages.py (process CPU ms of the launches), PoCL, the engine's work-group size 64.
# base = main d0af15f's kernels, A = commit 8d36d52's (sqrt1f, imin, imax, cross3 in pn.h), C = this tree (+ one vdivps).
# usage: ab.sh ROUNDS  (from the worktree root, venv active)
K_base=/tmp/cpu15g/base/kernels; K_A=/tmp/cpu15g/headA/kernels; K_C=kernels
uptime
for r in $(seq "$1"); do
  for task in "--scene model_zoo --stage 4 --launches 20:base A C" "--scene model_zoo --stage 5 --launches 30:base A" \
              "--stage 4 --launches 8:base A C"; do
    args=${task%%:*}
    for k in ${task#*:}; do
      eval K=\$K_$k
      echo "round $r $k $args: $(PYTHONPATH=$PWD python bench/perf_stages.py --device pocl --local 64 --kernels $K $args 2>/dev/null | tail -1)"
    done
  done
done
uptime

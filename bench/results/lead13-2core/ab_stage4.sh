# Stage 4 of uniform level 16 on PoCL, this tree's kernels against /tmp/base13/kernels (git archive of the
# session start), alternating, each perf_stages.py run a child process: bash ab_stage4.sh ROUNDS
n=$1; shift
for r in $(seq $n); do for t in new base; do if [ $t = new ]; then k=kernels; else k=/tmp/base13/kernels; fi; printf "%s " $t; python bench/perf_stages.py --device pocl --stage 4 --launches 8 --local 64 --kernels $k "$@" 2>&1 | grep -o "CPU ms.*"; done; done

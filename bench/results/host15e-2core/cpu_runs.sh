# The CPU runs of branch host15e (this 2-vCPU VM, shared): this tree against main (git archive
# main into /tmp/host15e-base, with cltess/kernels -> ../kernels), run from the worktree.
R=bench/results/host15e-2core
B=/tmp/host15e-base
S="tea_table double_torus"
for k in 1 2; do
  uptime > $R/calls_as_gpu_this_$k.txt; python bench/frame_calls.py --as-gpu --frames 10 --rounds 3 --scenes $S >> $R/calls_as_gpu_this_$k.txt 2>&1; uptime >> $R/calls_as_gpu_this_$k.txt
  uptime > $R/calls_as_gpu_base_$k.txt; PYTHONPATH=$B python bench/frame_calls.py --as-gpu --frames 10 --rounds 3 --scenes $S >> $R/calls_as_gpu_base_$k.txt 2>&1; uptime >> $R/calls_as_gpu_base_$k.txt
done
uptime > $R/frame_host_intel.txt; python bench/frame_host.py --frames 20 --repeat 3 --scenes tea_table double_torus killeroo --baseline $B --json $R/frame_host_intel.json >> $R/frame_host_intel.txt 2>&1; uptime >> $R/frame_host_intel.txt
uptime > $R/frame_host_pocl.txt; python bench/frame_host.py --device pocl --frames 20 --repeat 3 --scenes tea_table double_torus killeroo --baseline $B --json $R/frame_host_pocl.json >> $R/frame_host_pocl.txt 2>&1; uptime >> $R/frame_host_pocl.txt
uptime > $R/frame_host_as_gpu.txt; python bench/frame_host.py --as-gpu --frames 20 --repeat 3 --scenes $S --baseline $B --json $R/frame_host_as_gpu.json >> $R/frame_host_as_gpu.txt 2>&1; uptime >> $R/frame_host_as_gpu.txt

#!/usr/bin/env bash
# The GPU-machine run of bench/batch.py (issue 17): one process against Dask workers, one GPU each.
#
#   bash bench/gpu_batch.sh OUTDIR [bench/batch.py options...]
#
# Expects in .whl/ the Python 3.12 manylinux x86_64 wheels of pyopencl and its dependencies,
# mako, trimesh, dask and distributed with theirs (pip download --only-binary=:all:
# --python-version 3.12 --platform manylinux_2_28_x86_64 ... pyopencl mako trimesh dask
# distributed), and NVIDIA's OpenCL library at /usr/local/nvidia/lib64 (as bench/gpu_run.sh).
set -u
out=${1:?usage: bash bench/gpu_batch.sh OUTDIR [options]}
shift
. bench/gpu_setup.sh
{
  echo "## nvidia-smi"; nvidia-smi -L
  echo "## lscpu"; lscpu | head -20
  echo "## disk"; df -h /tmp
  echo "## python"; python3 --version
  echo "## cltess devices"; python3 -m cltess devices
} > "$out/machine.txt" 2>&1
python3 bench/batch.py --device nvidia --json "$out/batch.json" "$@" 2>&1 | tee "$out/batch.txt"

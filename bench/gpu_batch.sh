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
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=/tmp/site:$PWD PYTHONUNBUFFERED=1
python3 -c "import cltess.kernels" 2>/dev/null || ln -s ../kernels cltess/kernels
mkdir -p /tmp/icd
echo /usr/local/nvidia/lib64/libnvidia-opencl.so.1 > /tmp/icd/nvidia.icd
export OCL_ICD_VENDORS=/tmp/icd
{
  echo "## nvidia-smi"; nvidia-smi -L
  echo "## lscpu"; lscpu | head -20
  echo "## disk"; df -h /tmp
  echo "## python"; python3 --version
  echo "## cltess devices"; python3 -m cltess devices
} > "$out/machine.txt" 2>&1
python3 bench/batch.py --device nvidia --json "$out/batch.json" "$@" 2>&1 | tee "$out/batch.txt"

#!/usr/bin/env bash
# The GPU-machine run behind bench/RESULTS.md: NVIDIA OpenCL and PoCL on the same host.
#
#   bash bench/gpu_run.sh OUTDIR
#
# Expects the wheels of pyopencl, pytools, platformdirs, siphash24, mako and trimesh (Python 3.12,
# manylinux x86_64) and data/bigguy.bez in .whl/ (numpy, markupsafe, typing_extensions
# and matplotlib were already on that machine).  Writes machine.txt (nvidia-smi, lscpu, the
# OpenCL devices), h100.{md,json}, pocl16.{md,json}, teapots.txt and log.txt into OUTDIR.
set -u
out=${1:?usage: bash bench/gpu_run.sh OUTDIR}
GPU_SETUP_POCL=1 . bench/gpu_setup.sh
export CLTESS_DATA=$PWD/.whl/data
{
  echo "## nvidia-smi"; nvidia-smi
  echo "## lscpu"; lscpu
  echo "## uname"; uname -a
  echo "## OpenCL vendors"; ls -l /etc/OpenCL/vendors; cat /etc/OpenCL/vendors/*.icd
  echo "## python"; python3 --version; python3 -c "import numpy, pyopencl; print(numpy.__version__, pyopencl.VERSION_TEXT)"
  echo "## cltess devices"; python3 -m cltess devices
} > "$out/machine.txt" 2>&1
python3 -m cltess bench --device nvidia --repeat 5 --json "$out/h100.json" > "$out/h100.md" 2>> "$out/log.txt"
echo "h100 rc=$?" >> "$out/log.txt"
{ echo "## teapots, NVIDIA"; python3 bench/teapots.py --device nvidia; } > "$out/teapots.txt" 2>> "$out/log.txt"
python3 -m cltess bench --device pocl --repeat 3 --json "$out/pocl16.json" > "$out/pocl16.md" 2>> "$out/log.txt"
echo "pocl rc=$?" >> "$out/log.txt"
{ echo "## teapots, PoCL"; python3 bench/teapots.py --device pocl; } >> "$out/teapots.txt" 2>> "$out/log.txt"
tail -3 "$out/log.txt"

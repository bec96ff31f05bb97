# Sourced by the GPU-machine scripts (bench/gpu_run.sh, gpu_batch.sh, gpu_issues.sh): installs
# the wheels carried in .whl/ to /tmp/site (Python 3.12 manylinux x86_64: pyopencl and its
# dependencies, mako, trimesh, tqdm; dask and distributed for gpu_batch.sh), puts cltess and
# kernels/ on the path without installing, and lists NVIDIA's OpenCL library (and, with
# GPU_SETUP_POCL=1, the machine's PoCL) in an ICD folder of its own.
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=/tmp/site:$PWD PYTHONUNBUFFERED=1
# cltess.kernels is the top-level kernels/ folder (an install maps it); without installing, link it
python3 -c "import cltess.kernels" 2>/dev/null || ln -s ../kernels cltess/kernels
mkdir -p /tmp/icd
echo /usr/local/nvidia/lib64/libnvidia-opencl.so.1 > /tmp/icd/nvidia.icd
if [ "${GPU_SETUP_POCL:-0}" = 1 ]; then cp /etc/OpenCL/vendors/pocl.icd /tmp/icd/; fi
export OCL_ICD_VENDORS=/tmp/icd

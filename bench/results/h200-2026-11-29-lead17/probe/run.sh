set -x
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
ls /usr/local/nvidia/share/glvnd/egl_vendor.d/ /usr/local/nvidia/lib64 | head -50
. bench/gpu_setup.sh
nvidia-smi --query-gpu=name,driver_version --format=csv
timeout 120 python3 probe/gl/probe.py 2>&1

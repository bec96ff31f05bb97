# session 17, runs 7-8: descriptors step by step, and by part
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh
timeout 120 python3 -X faulthandler probe/gl/fd_steps2.py > $OUT/fd_steps2.txt 2>&1; echo "rc $?"; grep -v "Warn\|prg.build\|_create_built" $OUT/fd_steps2.txt | tail -40

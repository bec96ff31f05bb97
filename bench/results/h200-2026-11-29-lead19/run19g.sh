# Session 19, H200, call 7: frame.vulkan()'s host time taken apart (vk_parts.py). Carry [".whl", ".gl", "probe/gpu19"].
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null
R=$OUT/call7; mkdir -p $R
timeout 200 python3 -X faulthandler probe/gpu19/vk_parts.py 2>&1 | grep -v "Warn\|prg.build\|_create_built" > $R/vk_parts.txt
cat $R/vk_parts.txt

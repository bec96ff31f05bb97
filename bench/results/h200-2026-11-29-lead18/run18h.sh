# Session 18, H200, call 9: VulkanOutputBuffers alone, parts changed: which keeps a /dev/nvidiactl (fd_parts4.py).
# From /work/main, carry [".whl", ".gl", "probe/gl"].
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
. bench/gpu_setup.sh >/dev/null
timeout 200 python3 -X faulthandler probe/gl/fd_parts4.py 2>&1 | grep -v "Warn\|prg.build\|_create_built" > $OUT/fd_parts4.txt
cat $OUT/fd_parts4.txt

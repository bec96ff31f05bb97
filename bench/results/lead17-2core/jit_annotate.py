"""Session 17: objdump of a dumped JIT region between two offsets, each instruction with its samples
(the region's base address of that run is written below)."""
import collections, subprocess, sys
base=0x7fbf3feb2000
ips=[int(l.split()[0],16)-base for l in open('/tmp/s17/jit/ips.txt') if l.strip()]
cnt=collections.Counter(i for i in ips if 0<=i<0x100000)
lo,hi=int(sys.argv[1],16),int(sys.argv[2],16)
out=subprocess.run(["objdump","-D","-b","binary","-m","i386:x86-64",f"--start-address={lo}",f"--stop-address={hi}","region-7fbf3feb2000.bin"],capture_output=True,text=True).stdout
for line in out.splitlines()[7:]:
    if not line.strip(): continue
    try: off=int(line.split(':')[0],16)
    except: continue
    print(f"{cnt.get(off,0):4d} {line}")

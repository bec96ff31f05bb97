"""Session 17: samples (perf script -F ip) per 64-byte block of the dumped JIT regions (jit_dump.py)."""
import sys, collections, glob, os
regions=[]
for f in glob.glob('/tmp/s17/jit/region-*.bin'):
    lo=int(f.split('-')[-1].split('.')[0],16); regions.append((lo, lo+os.path.getsize(f), f))
c=collections.Counter(); total=0; inr=collections.Counter(); jit=0
for line in open(sys.argv[1]):
    p=line.split()
    if not p: continue
    total+=1; ip=int(p[0],16)
    for lo,hi,f in regions:
        if lo<=ip<hi: inr[f.split('/')[-1]]+=1; c[(f,ip-lo)]+=1
print('total',total, dict(inr))
blocks=collections.Counter()
for (f,off),n in c.items(): blocks[(f.split('/')[-1],off//64*64)]+=n
for k,n in blocks.most_common(int(sys.argv[2]) if len(sys.argv)>2 else 30): print(k[0], hex(k[1]), n)

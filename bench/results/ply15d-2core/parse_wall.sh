#!/bin/bash
# The parse alone (bpt._fast_bpt of the 30k-patch scene's bytes), first call in a fresh child,
# wall and CPU, this tree and the baseline alternating: parse_wall.sh TREE BASELINE SCENE N
for i in $(seq $4); do for tree in "$1" "$2"; do
  PYTHONPATH=$tree python -c "
import resource, sys, time
from cltess.io import bpt
data = open(sys.argv[1], 'rb').read()
r0 = resource.getrusage(resource.RUSAGE_SELF); t = time.perf_counter()
bpt._fast_bpt(data)
r1 = resource.getrusage(resource.RUSAGE_SELF)
print(f'{sys.argv[2]:24} wall {time.perf_counter() - t:.3f} cpu {r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime:.3f} faults {r1.ru_minflt - r0.ru_minflt}')
" "$3" "$tree"
done; done

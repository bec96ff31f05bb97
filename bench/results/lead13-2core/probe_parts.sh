# Builds /tmp/probe13/kernels: this tree's kernels with vertices.cl able to leave out the ring
# (-D PROBE_NO_RING) or the rows (-D PROBE_NO_ROWS); then, e.g.:
#   python bench/perf_stages.py --device pocl --stage 4 --launches 8 --local 64 --kernels /tmp/probe13/kernels --define PROBE_NO_RING
mkdir -p /tmp/probe13 && rm -rf /tmp/probe13/kernels && cp -r "$(dirname "$0")/../../../kernels" /tmp/probe13/ && cd /tmp/probe13/kernels/stages && python3 - <<'PY'
p='vertices.cl'
s=open(p).read()
s=s.replace('''    at = put_ring(&patch, f, collapsed, out, at, p, object);  /* stages/rows.h */
    put_rows(''','''#ifndef PROBE_NO_RING
    at = put_ring(&patch, f, collapsed, out, at, p, object);  /* stages/rows.h */
#else
    at += 64;
#endif
#ifndef PROBE_NO_ROWS
    put_rows(''')
s=s.replace('''forward_differencing, out, at, p, object);
}''','''forward_differencing, out, at, p, object);
#endif
}''')
open(p,'w').write(s)
PY

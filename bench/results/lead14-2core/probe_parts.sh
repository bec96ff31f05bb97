# Builds /tmp/probe14/kernels: this tree's kernels with parts of stage 4 that can be left out, for
# bench/perf_stages.py --define (several names at once: --define A B), e.g.
#   python bench/perf_stages.py --device intel --stage 4 --launches 8 --kernels /tmp/probe14/kernels --define PROBE_NO_RING
# PROBE_NO_RING / PROBE_NO_ROWS: the ring / the interior rows not made (vertices.cl);
# PROBE_RING_NO_POSITION / PROBE_RING_NO_NORMAL: a ring lane set's positions are its domain points /
#   its normals are its domain points (rows.h put_ring_lanes);
# PROBE_ROWS_NO_NORMAL: a block's normal_lanes replaced by sums (bezier.h kind_rows_next);
# PROBE_NO_TRANSPOSE: a block's 8 x 8 transposes left out (rows.h put_block_points);
# PROBE_NO_UV: a block's domain points from integers, not pattern_row_point.
# Not the engine's output.
set -e
here=$(cd "$(dirname "$0")/../../.." && pwd)
mkdir -p /tmp/probe14 && rm -rf /tmp/probe14/kernels && cp -r "$here/kernels" /tmp/probe14/ && cd /tmp/probe14/kernels && python3 - <<'PY'
def edit(path, old, new):
    s = open(path).read()
    assert old in s, (path, old[:60])
    open(path, 'w').write(s.replace(old, new))

edit('stages/vertices.cl', '''    at = put_ring(&patch, f, collapsed, out, at, p, object);  /* stages/rows.h */
    put_rows(''', '''#ifndef PROBE_NO_RING
    at = put_ring(&patch, f, collapsed, out, at, p, object);  /* stages/rows.h */
#else
    at += 64;
#endif
#ifndef PROBE_NO_ROWS
    put_rows(''')
edit('stages/vertices.cl', '''forward_differencing, out, at, p, object);
}''', '''forward_differencing, out, at, p, object);
#endif
}''')
edit('stages/rows.h', '''        position[k] = ring_position(patch, f, collapsed, e, first + k, &x[k]);''', '''#ifndef PROBE_RING_NO_POSITION
        position[k] = ring_position(patch, f, collapsed, e, first + k, &x[k]);
#else
        { edge_param t = pattern_ring_param(f, e, first + k); x[k] = pattern_edge_point(e, t); position[k] = x[k]; }
#endif''')
edit('stages/rows.h', '''    kind_eval_lanes(patch, domain[0], domain[1], normal, &plain);''', '''#ifndef PROBE_RING_NO_NORMAL
    kind_eval_lanes(patch, domain[0], domain[1], normal, &plain);
#else
    normal[0] = domain[0]; normal[1] = domain[1]; normal[2] = domain[2]; plain = (int8)(-1);
#endif''')
edit('stages/rows.h', '''        transposed_lanes(by_point, along[c]);''', '''#ifndef PROBE_NO_TRANSPOSE
        transposed_lanes(by_point, along[c]);
#else
        for (int k = 0; k < KIND_LANES; ++k) along[c][k] = by_point[k];
#endif''')
edit('stages/rows.h', '''            x[k] = pattern_row_point(f, j + r, first + k);
        float8 domain[3], position[3] = {''', '''#ifndef PROBE_NO_UV
            x[k] = pattern_row_point(f, j + r, first + k);
#else
            x[k] = (float3)((float)(first + k), (float)(j + r), 0.0f);
#endif
        float8 domain[3], position[3] = {''')
s = open('kinds/bezier.h').read()
start = s.index('ALWAYS_INLINE void kind_rows_next(')
old = '''    normal_lanes(s, s_u, s_v, p, normal, plain);
    position[0] = p[0] + patch->centre.x;
    position[1] = p[1] + patch->centre.y;
    position[2] = p[2] + patch->centre.z;
}'''
at = s.index(old, start)
s = s[:at] + '''#ifndef PROBE_ROWS_NO_NORMAL
    normal_lanes(s, s_u, s_v, p, normal, plain);
#else
    p[0] = s[0] + s_v[0]; p[1] = s[1] + s_v[1]; p[2] = s[2] + s_v[3];
    normal[0] = s_u[0]; normal[1] = s_u[1]; normal[2] = s_u[2] + s[3]; *plain = (int8)(-1);
#endif
    position[0] = p[0] + patch->centre.x;
    position[1] = p[1] + patch->centre.y;
    position[2] = p[2] + patch->centre.z;
}''' + s[at + len(old):]
open('kinds/bezier.h', 'w').write(s)
PY

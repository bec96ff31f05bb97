import re, statistics, sys
rows = {}
for line in open(sys.argv[1]):
    if "|" not in line: continue
    env, rest = line.split("|", 1)
    f = dict((m.group(1), float(m.group(2))) for m in re.finditer(r"(\w+) ([\d.]+) cpu", rest))
    o = re.search(r"niced CPU ([\d.]*) s, steal ([\d.]*)", rest)
    f["others"] = float(o.group(1) or 0) + float(o.group(2) or 0)
    p = re.search(r"process ([\d.]+) user ([\d.]+) sys", rest)
    f["cpu"] = float(p.group(1)) + float(p.group(2))
    rows.setdefault(env, []).append(f)
keys = sys.argv[2].split(",") if len(sys.argv) > 2 else ["_fast_bpt", "edge_groups", "orient_scene", "prepare_scene", "plan", "tessellate_to_file", "total", "cpu", "others"]
for env, rs in rows.items():
    print(f"{env:22} n={len(rs)}", " ".join(f"{k} {statistics.median(r[k] for r in rs):.3f}/{min(r[k] for r in rs):.3f}" for k in keys if k in rs[0]))

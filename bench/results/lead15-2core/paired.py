import json, sys, statistics, re
r = json.load(open(sys.argv[1]))["figures"]
def rounds(name):
    out = {}
    for k, v in r.items():
        m = re.fullmatch(re.escape(name) + r"( \(again\)| \(round (\d+)\))?", k)
        if m:
            idx = 1 if m.group(1) is None else 2 if "again" in m.group(1) else int(m.group(2))
            out[idx] = v
    return out
for stage in ("stage 4 (vertices)", "stage 5 (indices)"):
    a, b = rounds(stage), rounds("baseline " + stage)
    for key in ("cpu_ms", "cpu_ms_median", "device_ms_median"):
        ratios = [a[i][key] / b[i][key] for i in sorted(a) if i in b]
        print(f"{stage} {key}: this/baseline per round: " + " ".join(f"{x:.3f}" for x in ratios) + f"  median {statistics.median(ratios):.3f}")

"""Round medians of a cpu_stages.py --json (after = this tree, before = --baseline-kernels)."""
import json, statistics, sys
for path in sys.argv[1:]:
    fig = json.load(open(path))["figures"]
    print(path)
    for kernel in ("stage 4 (vertices)", "stage 5 (indices)"):
        after = [v["cpu_ms_median"] for k, v in fig.items() if k.startswith(kernel)]
        before = [v["cpu_ms_median"] for k, v in fig.items() if k.startswith("baseline " + kernel)]
        amin = min(v["cpu_ms"] for k, v in fig.items() if k.startswith(kernel))
        bmin = min(v["cpu_ms"] for k, v in fig.items() if k.startswith("baseline " + kernel))
        ma, mb = statistics.median(after), statistics.median(before)
        print(f"  {kernel}: round medians after {[round(x) for x in after]} before {[round(x) for x in before]}; "
              f"median of medians {ma:.1f} vs {mb:.1f} ({(ma / mb - 1) * 100:+.0f}%); min {amin:.1f} vs {bmin:.1f}; "
              f"after lower in {sum(a < b for a, b in zip(after, before))}/{len(after)} rounds")

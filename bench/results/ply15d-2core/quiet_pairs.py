"""Cold (and warm) ``cltess tessellate`` of the 30k-patch scene, this tree and a baseline in
alternating order, each run started only when the machine's CPUs were idle for a second, and
kept only if no other process (the lead's runs are niced: /proc/stat "nice") and no steal took
more than 0.05 CPU s while it ran.  The same child command as bench/tessellate_30k.py.

    cd /tmp && python quiet_pairs.py TREE BASELINE_TREE SCENE.bpt --rounds 10 [--state cold]
"""
import argparse, os, resource, statistics, subprocess, sys, tempfile, time
from pathlib import Path

HZ = os.sysconf("SC_CLK_TCK")


def stat():
    """(idle, total, nice + steal) jiffies of all CPUs."""
    fields = [int(x) for x in open("/proc/stat").readline().split()[1:]]
    return fields[3] + fields[4], sum(fields[:8]), fields[1] + fields[7]


def wait_quiet(limit=120.0):
    end = time.time() + limit
    while time.time() < end:
        a = stat(); time.sleep(1.0); b = stat()
        if (b[0] - a[0]) >= 0.95 * (b[1] - a[1]):
            return True
    return False


def run(tree, scene, out, cache, orient):
    env = dict(os.environ, PYTHONPATH=str(tree), CLTESS_SCENE_CACHE=str(cache))
    command = [sys.executable, "-m", "cltess", "tessellate", str(scene), orient, "--eps", "0.0085", "--no-weld",
               "-q", "-o", str(out)]
    before, others = resource.getrusage(resource.RUSAGE_CHILDREN), stat()[2]
    started = time.perf_counter()
    subprocess.run(command, env=env, cwd=scene.parent, check=True, capture_output=True)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return wall, cpu, (stat()[2] - others) / HZ


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("tree"); parser.add_argument("baseline"); parser.add_argument("scene")
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--state", default="cold", choices=["cold", "warm"])
    parser.add_argument("--orient", default="--orient")
    args = parser.parse_args()
    scene = Path(args.scene).resolve()
    trees = {"this tree": Path(args.tree).resolve(), "baseline": Path(args.baseline).resolve()}
    kept = {name: [] for name in trees}
    dropped = 0
    with tempfile.TemporaryDirectory(dir=scene.parent) as folder:
        folder = Path(folder)
        for k in range(args.rounds):
            order = list(trees.items()) if k % 2 == 0 else list(trees.items())[::-1]
            for name, tree in order:
                cache = folder / (f"cache-{name}-{k}" if args.state == "cold" else f"cache-{name}")
                out = scene.parent / ("out.ply" if name == "this tree" else "out-baseline.ply")
                if args.state == "warm" and k < 2:
                    run(tree, scene, out, cache, args.orient)  # fills the warm cache
                if not wait_quiet():
                    print("not quiet", flush=True)
                wall, cpu, others = run(tree, scene, out, cache, args.orient)
                keep = others <= 0.05
                print(f"{time.strftime('%H:%M:%S')} {name:10} {args.state} {args.orient}: wall {wall:.3f} cpu {cpu:.3f} "
                      f"others {others:.2f}{'' if keep else '  (dropped)'}", flush=True)
                if keep:
                    kept[name].append((wall, cpu))
                else:
                    dropped += 1
    for name, runs in kept.items():
        if runs:
            walls, cpus = sorted(r[0] for r in runs), sorted(r[1] for r in runs)
            print(f"{name:10} {args.state} {args.orient}: n={len(runs)} wall median {statistics.median(walls):.2f} "
                  f"min {walls[0]:.2f} max {walls[-1]:.2f}; CPU median {statistics.median(cpus):.2f} min {cpus[0]:.2f}")
    print(f"dropped {dropped} runs (others > 0.05 CPU s)")


if __name__ == "__main__":
    main()

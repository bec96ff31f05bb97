"""Cold (or warm) ``cltess tessellate`` of the 30k-patch scene, this tree against a baseline in
alternating order, as a user runs it: compiled bytecode (PYTHONDONTWRITEBYTECODE unset, each
tree's bytecode under PYTHONPYCACHEPREFIX, compiled by a first untimed run), a fresh scene cache
per cold run.  Each run starts after a second of idle CPUs and is kept only if other processes
and steal took at most 0.05 CPU s while it ran: all CPUs' busy time (/proc/stat) less the
child's own (getrusage), so un-niced neighbours count too (ply15d's script saw only "nice").

    cd /tmp && python quiet_pairs.py TREE BASELINE_TREE SCENE.bpt --rounds 10 [--state warm] [--orient --no-orient]
        [--env NAME=VALUE ...]   (set for TREE's runs only; TREE = BASELINE_TREE: an A/B of a setting)
"""
import argparse, os, resource, statistics, subprocess, sys, tempfile, time
from pathlib import Path

HZ = os.sysconf("SC_CLK_TCK")


def busy():
    """(idle, total) jiffies of all CPUs (iowait counts as idle)."""
    fields = [int(x) for x in open("/proc/stat").readline().split()[1:]]
    return fields[3] + fields[4], sum(fields[:8])


def wait_quiet(limit=600.0):
    end = time.time() + limit
    while time.time() < end:
        a = busy(); time.sleep(1.0); b = busy()
        if (b[0] - a[0]) >= 0.95 * (b[1] - a[1]):
            return True
    return False


def run(tree, scene, out, cache, orient, extra_env=()):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.update(extra_env)
    env.update(PYTHONPATH=str(tree), CLTESS_SCENE_CACHE=str(cache), PYTHONPYCACHEPREFIX=f"/tmp/pycache-{tree.name}")
    command = [sys.executable, "-m", "cltess", "tessellate", str(scene), orient, "--eps", "0.0085", "--no-weld",
               "-q", "-o", str(out)]
    before, (idle0, total0) = resource.getrusage(resource.RUSAGE_CHILDREN), busy()
    started = time.perf_counter()
    subprocess.run(command, env=env, cwd=scene.parent, check=True, capture_output=True)
    wall = time.perf_counter() - started
    after, (idle1, total1) = resource.getrusage(resource.RUSAGE_CHILDREN), busy()
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    others = ((total1 - total0) - (idle1 - idle0)) / HZ - cpu
    return wall, cpu, others


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("tree"); parser.add_argument("baseline"); parser.add_argument("scene")
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--state", default="cold", choices=["cold", "warm"])
    parser.add_argument("--orient", default="--orient")
    parser.add_argument("--env", action="append", default=[], metavar="NAME=VALUE",
                        help="set in the first tree's runs only (the same tree twice: an A/B of a setting)")
    args = parser.parse_args()
    extra = dict(item.split("=", 1) for item in args.env)
    scene = Path(args.scene).resolve()
    trees = {"this tree": Path(args.tree).resolve(), "baseline": Path(args.baseline).resolve()}
    envs = {"this tree": extra, "baseline": {}}
    kept = {name: [] for name in trees}
    dropped = 0
    with tempfile.TemporaryDirectory(dir=scene.parent) as folder:
        folder = Path(folder)
        for name, tree in trees.items():  # compile each tree's bytecode (and fill a warm cache)
            run(tree, scene, scene.parent / "out-warmup.ply", folder / f"cache-{name}", args.orient, envs[name])
        for k in range(args.rounds):
            order = list(trees.items()) if k % 2 == 0 else list(trees.items())[::-1]
            for name, tree in order:
                cache = folder / (f"cache-{name}-{k}" if args.state == "cold" else f"cache-{name}")
                out = scene.parent / ("out.ply" if name == "this tree" else "out-baseline.ply")
                if not wait_quiet():
                    print("not quiet", flush=True)
                wall, cpu, others = run(tree, scene, out, cache, args.orient, envs[name])
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
            below = sum(w < 1.5 for w in walls)
            print(f"{name:10} {args.state} {args.orient}: n={len(runs)} wall median {statistics.median(walls):.2f} "
                  f"min {walls[0]:.2f} max {walls[-1]:.2f}, {below} under 1.5 s; "
                  f"CPU median {statistics.median(cpus):.2f} min {cpus[0]:.2f}")
    print(f"dropped {dropped} runs (others > 0.05 CPU s)")


if __name__ == "__main__":
    main()

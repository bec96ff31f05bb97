"""Batch runs on Dask (issue 17) against one process: many small scenes, and one huge scene.

    python bench/batch.py [--files 40] [--eps 0.002] [--workers 2]
                          [--huge scenes/bigguy.bez] [--huge-eps 0.0005] [--max-factor 256]
                          [--split-workers 1 2] [--device NAME] [--json OUT]

1. Throughput: ``--files`` copies of the bundled scenes (teapot, teacup, teaspoon, table, sphere,
   in turn) tessellated to PLY by a plain loop in this process (one Tessellator, load +
   tessellate_to_file per file), then by ``tessellate_files`` on a LocalCluster of ``--workers``
   processes.  The cluster's start-up (and each worker's first Tessellator) is timed apart.
2. One huge scene: ``tessellate_to_file`` in this process, then ``tessellate_split`` on a
   LocalCluster of each ``--split-workers`` count (one GPU per worker where there are
   several).  Every split output is checked byte for byte against the single-process file.

Times are wall-clock seconds, the best of ``--repeat`` runs after one untimed warm-up run.
"""
from __future__ import annotations

import argparse
import json
import platform
import shutil
import sys
import tempfile
import time
import warnings
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
warnings.filterwarnings("ignore", message="Non-empty compiler output")  # pyopencl, on every build
SMALL_SCENES = ("teapot.bez", "teacup.bez", "teaspoon.bez", "table.bpt", "sphere.bpt")


def best_of(repeat: int, run) -> tuple[float, object]:
    """(best wall seconds, last result) of ``repeat`` timed runs after one warm-up run."""
    result = run()
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - started)
    return min(times), result


def many_files(args, work: Path) -> dict:
    from cltess.batch import BatchOptions, dask_client, tessellate_files
    from cltess.io import load_scene
    from cltess.pipeline import Tessellator
    from cltess.stream import tessellate_to_file

    inputs = work / "inputs"
    inputs.mkdir()
    for i in range(args.files):
        name = SMALL_SCENES[i % len(SMALL_SCENES)]
        shutil.copy(REPO / "scenes" / name, inputs / f"{i:03d}-{name}")
    files = sorted(inputs.iterdir())
    tessellator = Tessellator(args.device)

    def loop():
        out = work / "loop"
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir()
        return sum(tessellate_to_file(tessellator, load_scene(f), out / f"{f.name}.ply", eps=args.eps).stats["triangles"]
                   for f in files)

    loop_s, triangles = best_of(args.repeat, loop)
    # Per-patch output as read (--no-weld --no-orient), as the loop writes it and as RESULTS.md measured.
    options = BatchOptions(eps=args.eps, device=args.device, weld=False, orient=False)
    started = time.perf_counter()
    with dask_client(workers=args.workers) as client:
        start_s = time.perf_counter() - started

        def batch():
            out = work / "batch"
            shutil.rmtree(out, ignore_errors=True)  # no skipping: every file is done each time
            rows = tessellate_files([inputs], out, options, client=client)
            assert all(row["status"] == "done" for row in rows), [r["error"] for r in rows if r["error"]]
            return sum(row["triangles"] for row in rows)

        batch_s, batch_triangles = best_of(args.repeat, batch)
    assert batch_triangles == triangles
    return {"files": args.files, "eps": args.eps, "triangles": triangles, "workers": args.workers,
            "loop_s": loop_s, "batch_s": batch_s, "cluster_start_s": start_s,
            "loop_files_per_s": args.files / loop_s, "batch_files_per_s": args.files / batch_s}


def huge_scene(args, work: Path) -> dict:
    from cltess.batch import BatchOptions, dask_client, file_sha256, tessellate_split
    from cltess.io import load_scene
    from cltess.pipeline import Tessellator
    from cltess.stream import tessellate_to_file

    scene_path = Path(args.huge)
    tessellator = Tessellator(args.device)
    scene = load_scene(scene_path)
    single = work / "single.ply"
    single_s, result = best_of(args.repeat, lambda: tessellate_to_file(
        tessellator, scene, single, eps=args.huge_eps, max_factor=args.max_factor))
    expected = file_sha256(single)
    record = {"scene": str(scene_path), "eps": args.huge_eps, "max_factor": args.max_factor,
              "patches": result.stats["patches"], "triangles": result.stats["triangles"],
              "bytes": single.stat().st_size, "single_s": single_s, "single_batches": result.batches,
              "device": tessellator.device.name.strip(), "split": []}
    single.unlink()
    options = BatchOptions(eps=args.huge_eps, max_factor=args.max_factor, device=args.device, orient=False)
    for workers in args.split_workers:
        with dask_client(workers=workers) as client:
            devices = sorted(set(client.run(_device_of, args.device).values()))
            output = work / f"split-{workers}.ply"
            split_s, row = best_of(args.repeat, lambda: tessellate_split(scene_path, output, options, client=client))
            identical = file_sha256(output) == expected
            output.unlink()
        record["split"].append({"workers": workers, "seconds": split_s, "parts": row["parts"],
                                "identical": identical, "devices": devices})
        if not identical:
            print(f"MISMATCH: the split run on {workers} workers differs from the single process", file=sys.stderr)
    return record


def _device_of(name):
    """On a worker: the device it would use (for the record)."""
    from distributed import get_worker  # noqa: F401
    from cltess.batch import worker_device
    return worker_device(name).name.strip()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--files", type=int, default=40)
    parser.add_argument("--eps", type=float, default=0.002)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--huge", default=str(REPO / "scenes" / "bigguy.bez"))
    parser.add_argument("--huge-eps", type=float, default=0.0005)
    parser.add_argument("--max-factor", type=int, default=256)
    parser.add_argument("--split-workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--device")
    parser.add_argument("--skip", choices=("files", "huge"), action="append", default=[])
    parser.add_argument("--json")
    args = parser.parse_args(argv)
    record = {"command": " ".join(["python bench/batch.py", *sys.argv[1:]]), "machine": platform.node(),
              "python": platform.python_version()}
    with tempfile.TemporaryDirectory(prefix="cltess-batch-bench-") as work:
        if "files" not in args.skip:
            record["many_files"] = many_files(args, Path(work))
            m = record["many_files"]
            print(f"{m['files']} files, {m['triangles']} triangles: loop {m['loop_s']:.2f} s "
                  f"({m['loop_files_per_s']:.1f} files/s), batch on {m['workers']} workers {m['batch_s']:.2f} s "
                  f"({m['batch_files_per_s']:.1f} files/s); cluster start {m['cluster_start_s']:.1f} s", flush=True)
        if "huge" not in args.skip:
            record["huge_scene"] = h = huge_scene(args, Path(work))
            print(f"{h['scene']} eps {h['eps']}: {h['patches']} patches, {h['triangles']} triangles, "
                  f"{h['bytes'] / 2**20:.0f} MiB; one process {h['single_s']:.2f} s on {h['device']}", flush=True)
            for s in h["split"]:
                print(f"  split on {s['workers']} workers ({', '.join(s['devices'])}): {s['seconds']:.2f} s "
                      f"in {s['parts']} parts, {'identical' if s['identical'] else 'DIFFERENT'}", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

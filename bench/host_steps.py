"""Issue 15, host side: the host steps of a command and of a frame, one by one, this tree beside
another checkout (children alternating), each the best of many runs (the machine is shared).

    python bench/host_steps.py [--baseline SOURCE_TREE] [--repeat 5] [--copies 960]

Steps (seconds or microseconds as printed; nothing here touches an OpenCL device):

* orient: ``cltess.orient.orient_scene`` of the 30k-teapot scene (bench/tessellate_30k.py's
  placement, ``--copies`` teapots), on a fresh ``Scene`` each run (edge groups included: the
  pipeline then reuses them where the tree shares them);
* edge groups: ``cltess.crack.adjacency.edge_groups`` of the same patches (what the pipeline
  computes again where orientation does not share it);
* PLY vertex records / face records: ``cltess.io.ply.ply_vertex_records`` and
  ``ply_face_records`` of 262,144 random vertices / triangles (one writer chunk);
* camera arguments: ``cltess.criteria.tolerance.camera_arguments`` of a camera (once per
  frame with a pixel tolerance).

Each child prints the best (minimum) of ``--repeat`` runs per step; the report shows the best
of the children's.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
import timeit
from pathlib import Path

HERE = Path(__file__).resolve().parent


def child(repeat: int, copies: int) -> dict:
    import warnings

    warnings.simplefilter("ignore")
    import numpy as np

    import cltess
    from cltess.crack.adjacency import edge_groups
    from cltess.criteria.tolerance import camera_arguments
    from cltess.io.ply import ply_face_records, ply_vertex_records
    from cltess.orient import orient_scene
    from cltess.scene import Camera, Scene

    sys.path.insert(0, str(HERE))
    from tessellate_30k import write_scene

    out = {"cltess": cltess.__file__}
    scene_file = Path(os.environ.get("TMPDIR", "/tmp")) / f"host_steps_{os.getpid()}.bpt"
    try:
        write_scene(scene_file, copies)
        from cltess.io import load_scene

        loaded = load_scene(scene_file)
    finally:
        scene_file.unlink(missing_ok=True)

    def fresh():
        return Scene(loaded.patches, loaded.object_ids, loaded.camera, loaded.name, loaded.meshes)

    def best(function, setup=None, number=1):
        times = []
        for _ in range(repeat):
            argument = setup() if setup else None
            started = time.perf_counter()
            for _ in range(number):
                function(argument) if setup else function()
            times.append((time.perf_counter() - started) / number)
        return min(times)

    out["orient s"] = best(orient_scene, fresh)
    out["edge groups s"] = best(lambda: edge_groups(loaded.patches))
    rng = np.random.default_rng(0)
    count = 1 << 18

    class Block:
        positions = rng.random((count, 3), dtype=np.float32)
        normals = rng.random((count, 3), dtype=np.float32)
        uv = rng.random((count, 2), dtype=np.float32)
        patch_ids = rng.integers(0, 1 << 20, count).astype(np.int32)
        object_ids = rng.integers(0, 99, count).astype(np.int32)

    triangles = rng.integers(0, 1 << 31, (count, 3)).astype(np.uint32)
    out["PLY vertex records ms"] = best(lambda: ply_vertex_records(Block), number=5) * 1e3
    out["PLY face records ms"] = best(lambda: ply_face_records(triangles), number=5) * 1e3
    camera = Camera(eye=np.array([3.0, -2.0, 1.5]), target=np.zeros(3))
    out["camera arguments us"] = min(timeit.repeat(lambda: camera_arguments(camera), number=500,
                                                   repeat=repeat)) / 500 * 1e6
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="SOURCE_TREE")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--children", type=int, default=2, help="child processes per tree, alternating")
    parser.add_argument("--copies", type=int, default=960)
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args.repeat, args.copies)))
        return 0
    trees = {"this": None}
    if args.baseline:
        trees["baseline"] = str(Path(args.baseline).resolve())
    runs = {name: [] for name in trees}
    load_before = os.getloadavg()
    for _ in range(args.children):
        for name, tree in trees.items():
            env = dict(os.environ, **({"PYTHONPATH": tree} if tree else {}))
            done = subprocess.run([sys.executable, __file__, "--child", "--repeat", str(args.repeat), "--copies",
                                   str(args.copies)], env=env, capture_output=True, text=True)
            if done.returncode:
                sys.exit(done.stderr)
            runs[name].append(json.loads(done.stdout.strip().splitlines()[-1]))
    print(f"load average before {load_before}, after {os.getloadavg()}; best of {args.repeat} runs x "
          f"{args.children} children per tree")
    for name in trees:
        print(f"  {name}: cltess from {runs[name][0]['cltess']}")
    steps = [key for key in runs["this"][0] if key != "cltess"]
    print(f"  {'step':28}" + "".join(f"{name:>12}" for name in trees))
    for step in steps:
        print(f"  {step:28}" + "".join(f"{min(run[step] for run in runs[name]):12.4g}" for name in trees))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Golden outputs: tessellate every bundled scene and every Oclgrind scenario (on the default
device, PoCL here) with forward differencing on and off, and save or compare the arrays byte for
byte.  A refactor that must not change the output runs this before and after:

    python bench/golden.py save /tmp/golden-start        # at the starting commit
    python bench/golden.py compare /tmp/golden-start     # after each step: exit 1 on any difference

Only the public API is used (``Tessellator.tessellate`` and ``tessellate_in_batches``), so the
script runs unchanged on both sides of a refactor.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ARRAYS = ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors")


#: Cases also run through tessellate_in_batches, with this output cap in bytes.
BATCH_CAPS = {"oclgrind-many_patches": 4096, "teapot.bez-eps0.001": 200_000}


def cases():
    """(name, scene, options) for every golden run."""
    sys.path.insert(0, str(ROOT / "tests"))
    import oclgrind_scenarios as scenarios
    import trimesh

    from cltess import load_scene
    from cltess.scene import Scene, TriangleMesh

    for path in sorted((ROOT / "scenes").iterdir()):
        if path.suffix not in (".bez", ".bpt", ".json"):
            continue
        scene = load_scene(path)
        size = float(np.ptp(scene.patches[..., :3] / scene.patches[..., 3:], axis=(0, 1, 2)).max()) \
            if scene.num_patches and len(scene.patches) else 1.0
        for rel in (1e-2, 1e-3):
            yield f"{path.name}-eps{rel:g}", scene, dict(eps=rel * size)
        if scene.camera is not None:
            yield f"{path.name}-px1", scene, dict(pixels=1.0)
        yield f"{path.name}-max5", scene, dict(eps=1e-4 * size, max_factor=5)
    # PN triangles: a smooth mesh, a flat-shaded (all edges sharp) one, each sharp-edge mode.
    box = trimesh.creation.box()
    capsule = trimesh.creation.capsule(height=1.0, radius=0.5, count=[8, 8])
    meshes = {"capsule": TriangleMesh(np.array(capsule.vertices), np.array(capsule.faces),
                                      np.array(capsule.vertex_normals), 0, "capsule")}
    meshes["flat box"] = TriangleMesh(box.vertices[box.faces].reshape(-1, 3), np.arange(3 * len(box.faces)).reshape(-1, 3),
                                      np.repeat(box.face_normals, 3, axis=0), 1, "box")
    for name, mesh in meshes.items():
        scene = Scene.from_meshes([mesh], name=name)
        for mode in ("straight", "average", "keep"):
            yield f"pn-{name}-{mode}", scene, dict(eps=2e-3, sharp_edges=mode)
    for name, make in scenarios.SCENARIOS.items():
        scene, options = make()
        yield f"oclgrind-{name}", scene, options


def outputs(tessellator):
    """name -> dict of arrays, for each case with FD on and off (and the batched runs)."""
    for name, scene, options in cases():
        options = dict(options)
        options.pop("forward_differencing", None)
        for fd in (True, False):
            tess = tessellator.tessellate(scene, forward_differencing=fd, **options)
            yield f"{name}-fd{int(fd)}", {k: getattr(tess, k) for k in ARRAYS}
            if name in BATCH_CAPS:
                _, batches = tessellator.tessellate_in_batches(scene, BATCH_CAPS[name], forward_differencing=fd,
                                                               **options)
                parts = list(batches)
                yield f"{name}-fd{int(fd)}-batched{len(parts)}", {
                    k: np.concatenate([getattr(b, k) for b in parts]) for k in ARRAYS}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=("save", "compare"))
    parser.add_argument("folder", type=Path)
    args = parser.parse_args(argv)
    from cltess import Tessellator

    tessellator = Tessellator()
    args.folder.mkdir(parents=True, exist_ok=True)
    runs = differ = 0
    for name, arrays in outputs(tessellator):
        runs += 1
        path = args.folder / f"{name}.npz"
        if args.mode == "save":
            np.savez(path, **arrays)
            continue
        if not path.exists():
            print(f"MISSING {name}")
            differ += 1
            continue
        with np.load(path) as saved:
            bad = [k for k in ARRAYS if saved[k].dtype != arrays[k].dtype or saved[k].shape != arrays[k].shape
                   or saved[k].tobytes() != np.ascontiguousarray(arrays[k]).tobytes()]
        if bad:
            differ += 1
            print(f"DIFFERS {name}: {', '.join(bad)}")
    if args.mode == "save":
        print(f"saved {runs} runs to {args.folder}")
        return 0
    expected = len(list(args.folder.glob("*.npz")))
    print(f"{runs - differ} of {runs} runs bitwise identical ({expected} saved)")
    return 1 if differ or runs != expected else 0


if __name__ == "__main__":
    sys.exit(main())

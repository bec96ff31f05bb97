"""Stage 1 of rational patches: the first call on a scene against the calls after it.

The rational bound's constants (M_uu, M_uv, M_vv, alpha; docs/rational-bound.md) depend on the
patch alone.  Since issue 9's follow-up stage 1 makes them for each patch it sees on the first
call and keeps them with the scene per context (``Tessellator.upload``); before, it computed
them per patch on every call.  This times, per scene (the ``cltess bench`` suite's, 0.5 px with
their cameras):

- "first": the first ``tessellate`` of the scene object.  Programs are built and the scene's
  host preparation (adjacency, ``Scene.prepared``) is done beforehand, on a copy and on the
  scene respectively, so that the figure is the pipeline itself: upload, the five stages
  (stage 1 making the constants) and the read-back;
- "later": the median of ``--repeat`` calls after it.

Columns: "factors" is device milliseconds from OpenCL profiling events,
"end to end" the pipeline's ``total_wall`` (upload to read-back, host time included).  Runs on
whatever ``cltess`` is importable, so the same script times another checkout (e.g. main,
installed in its own virtual environment; run it from outside the checkout):

    python bench/bound_constants.py [--device pocl] [--repeat 5] [--json out.json] [SCENES...]
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys


def time_scene(tessellator, spec, repeat: int) -> dict:
    from cltess.kinds import KINDS
    from cltess.scene import Scene

    scene = spec.build()
    if isinstance(scene, tuple):
        raise SystemExit(f"{spec.key}: only Bézier scenes are timed here")
    pixels = 0.5
    copy = Scene(scene.patches.copy(), scene.object_ids.copy(), scene.camera, name="warm-up")
    tessellator.tessellate(copy, pixels=pixels)  # builds every program
    for kind in KINDS:  # the once-per-scene host preparation, done before the timed call
        if kind.count(scene):
            scene.prepared((kind.name, "straight"), lambda: kind.prepare(scene, "straight"))
    first = tessellator.tessellate(scene, pixels=pixels)
    later = [tessellator.tessellate(scene, pixels=pixels) for _ in range(repeat)]
    median = lambda key: statistics.median(t.stage_ms.get(key, 0.0) for t in later)  # noqa: E731
    return {"scene": spec.key, "patches": scene.num_patches, "culled": int(first.stats["culled"]),
            "triangles": first.num_triangles,
            "first": {"factors": first.stage_ms["factors"], "end_to_end": first.stage_ms["total_wall"]},
            "later": {"factors": median("factors"),
                      "end_to_end": median("total_wall"), "runs": [t.stage_ms for t in later]},
            "same_triangles": all(t.num_triangles == first.num_triangles for t in later)}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", default=["spheres", "killeroo", "tea_table"])
    parser.add_argument("--device", default=None, help="OpenCL device, as for cltess tessellate")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)

    import cltess
    from cltess.bench.suite import SUITE
    from cltess.pipeline import Tessellator

    tessellator = Tessellator(args.device)
    device = tessellator.device.name.strip()
    print(f"cltess {cltess.__file__}, device {device}")
    print("| scene | patches | culled | triangles | first: factors / end to end ms | "
          "later (median): factors / end to end ms |")
    print("|---|---|---|---|---|---|")
    results = []
    for key in args.scenes:
        r = time_scene(tessellator, SUITE[key], args.repeat)
        results.append(r)
        f, g = r["first"], r["later"]
        print(f"| {key} | {r['patches']:,} | {r['culled']:,} | {r['triangles']:,} | {f['factors']:.2f} / "
              f"{f['end_to_end']:.1f} | {g['factors']:.2f} / {g['end_to_end']:.1f} |")
        sys.stdout.flush()
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"device": device, "cltess": cltess.__file__, "results": results}, out, indent=1)


if __name__ == "__main__":
    main()

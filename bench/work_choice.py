"""Issue 15: work="auto" (the GPU default since session 7) against "point" and "rows-prep", per scene.

    python bench/work_choice.py --device nvidia [--repeat 5] [--json out.json]
        [--levels 4 8 12 16] [--copies 10 100 1000] [--scenes tea_table killeroo ...]
        [--work point rows-prep rows-prep@32 auto]

Scenes: uniform level L (every edge factor L: (L + 1)^2 vertices per patch) on ``copies``
teapots (32 patches each, ``frame_loop.teapots``) for each level and copy count, then the
paper's suite scenes at 0.5 px (``frame_loop.suite_scene``).  For each scene and work
distribution (``Tessellator.work``; "rows-prep@N": N patches per work-group of stage 4, else
``Tessellator.line_patches_for`` the batch), a ``Session``: one frame (builds, uploads; its output
hashed: "same bits" compares the distributions of a scene), then ``--repeat`` frames: median
device ms of stages 1-5 and of stages 4 and 5.  "auto" reports what it chose
(``Tessellator.auto_work``) and the scene's vertices per patch.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import frame_loop  # noqa: E402

import cltess  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.tessellator import AUTO_ROWS_MIN_VERTICES_PER_PATCH  # noqa: E402

STAGES = ("factors", "crack_free", "counts", "vertices", "indices")


def measure(tessellator: Tessellator, name: str, scene, request: dict, works: list[str], repeat: int) -> list[dict]:
    rows = []
    for work in works:
        frame_loop.say(f"{name}: {work}")
        tessellator.work, _, per_group = work.partition("@")
        tessellator.patches_per_group = int(per_group) if per_group else None
        session = cltess.Session(scene, tessellator=tessellator, **request)
        first = session.tessellate().fetch()
        row = {"scene": name, "work": work, "patches": scene.num_patches, "vertices": first.num_vertices,
               "triangles": first.num_triangles, "bytes": frame_loop.output_bytes(first),
               "digest": frame_loop.output_digest(first)}
        del first
        runs = [session.tessellate() for _ in range(repeat)]
        row["device_ms"] = statistics.median(sum(r.stage_ms.get(s, 0.0) for s in STAGES) for r in runs)
        row["vertices_ms"] = statistics.median(r.stage_ms.get("vertices", 0.0) for r in runs)
        row["indices_ms"] = statistics.median(r.stage_ms.get("indices", 0.0) for r in runs)
        row["chose"] = tessellator.auto_work()
        row["line_patches"] = tessellator.line_patches_for(scene.num_patches)
        rows.append(row)
        del runs, session
    tessellator.work, tessellator.patches_per_group = "auto", None
    return rows


def report(record: dict) -> str:
    lines = [f"{record['device']}; fill {record['fill_bytes_per_s'] / 1e9:.1f} GB/s; load {record['load_before']} -> "
             f"{record['load_after']}; auto: rows-prep from {AUTO_ROWS_MIN_VERTICES_PER_PATCH} vertices per patch", "",
             "| scene | patches | vertices / patch | work | stages 1-5 ms | stage 4 | stage 5 | % of fill | "
             "auto chose | same bits |", "|---|---|---|---|---|---|---|---|---|---|"]
    rows = record["rows"]
    for row in rows:
        same = "yes" if len({r["digest"] for r in rows if r["scene"] == row["scene"]}) == 1 else "NO"
        fill = row["bytes"] / (row["device_ms"] / 1e3) / record["fill_bytes_per_s"]
        lines.append(f"| {row['scene']} | {row['patches']:,} | {row['vertices'] / row['patches']:.1f} | {row['work']} | "
                     f"{row['device_ms']:.3f} | {row['vertices_ms']:.3f} | {row['indices_ms']:.3f} | {fill:.1%} | "
                     f"{row['chose'] if row['work'] == 'auto' else ''} | {same} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--levels", type=int, nargs="*", default=[4, 8, 12, 16])
    parser.add_argument("--copies", type=int, nargs="*", default=[10, 100, 1000])
    parser.add_argument("--scenes", nargs="*", default=["tea_table", "killeroo", "herd", "spheres", "double_torus",
                                                          "elephant", "star_field", "model_zoo"])
    parser.add_argument("--work", nargs="*", default=["point", "rows-prep", "auto"])
    parser.add_argument("--json")
    args = parser.parse_args(argv)
    tessellator = Tessellator(args.device, work="auto")
    record = {"command": " ".join(sys.argv), "date": time.strftime("%Y-%m-%d %H:%M:%S %z"),
              "load_before": [round(x, 1) for x in os.getloadavg()],
              "device": f"{tessellator.device.name.strip()} ({tessellator.device.platform.name.strip()}, "
                        f"driver {tessellator.device.driver_version})"}
    size = min(512 << 20, tessellator.device.max_mem_alloc_size // 2)
    record["fill_bytes_per_s"] = frame_loop.bandwidths(tessellator, size)["fill_bytes_per_s"]
    record["rows"] = []
    for level in args.levels:
        for copies in args.copies:
            scene = frame_loop.teapots(copies)
            record["rows"] += measure(tessellator, f"uniform {level} x {copies} teapots", scene,
                                      frame_loop.uniform_request(level), args.work, args.repeat)
    for key in args.scenes:
        record["rows"] += measure(tessellator, key, frame_loop.suite_scene(key), {"pixels": frame_loop.PIXELS},
                                  args.work, args.repeat)
    record["load_after"] = [round(x, 1) for x in os.getloadavg()]
    text = report(record)
    print(text)
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1, default=float) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Plot triangles per second per scene and device from ``cltess bench --json`` files.

    python bench/plot.py OUT.png RESULT.json [RESULT.json ...]

One group of bars per scene, one bar per device (label: the device name, or ``NAME=`` before
the path: ``"H100=bench/h100.json"``); solid bars are end to end (upload, host adjacency,
the stages and all read-backs), the lighter bars behind them are the stages' device time
alone.  Log scale.  Needs matplotlib (``pip install -e ".[bench]"``).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def load(argument: str):
    label, _, path = argument.rpartition("=")
    record = json.loads(Path(path).read_text())
    return label or record["device"]["name"], record


def plot(output, records) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = []
    for _, record in records:
        for scene in record["scenes"]:
            if scene["key"] not in [s[0] for s in scenes]:
                scenes.append((scene["key"], scene["title"]))
    width = 0.8 / max(1, len(records))
    fig, ax = plt.subplots(figsize=(max(6, 1.4 * len(scenes) + 2), 4.8))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for d, (label, record) in enumerate(records):
        by_key = {s["key"]: s for s in record["scenes"]}
        xs, e2e, device = [], [], []
        for k, (key, _) in enumerate(scenes):
            if key in by_key:
                xs.append(k + (d - (len(records) - 1) / 2) * width)
                e2e.append(by_key[key]["triangles_per_s"] / 1e6)
                device.append(by_key[key]["triangles_per_s_device"] / 1e6)
        colour = colours[d % len(colours)]
        ax.bar(xs, device, width * 0.95, color=colour, alpha=0.3)
        bars = ax.bar(xs, e2e, width * 0.95, color=colour, label=label)
        for bar, value in zip(bars, e2e):
            ax.annotate(f"{value:.3g}", (bar.get_x() + bar.get_width() / 2, value), ha="center", va="bottom",
                        fontsize=7)
    ax.set_xticks(range(len(scenes)))
    ax.set_xticklabels([title for _, title in scenes], rotation=20, ha="right")
    ax.set_yscale("log")
    ax.set_ylabel("million triangles / s")
    ax.set_title("cltess bench, 0.5 px at 1024x768: end to end (solid), stages' device time only (light)")
    ax.legend(fontsize=8)
    ax.grid(axis="y", which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(output, dpi=110)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    plot(argv[0], [load(a) for a in argv[1:]])
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The paper-style tables and the JSON record of a suite run."""
from __future__ import annotations

import json
from pathlib import Path


from .suite import SUITE


def _ms(x: float) -> str:
    return f"{x:.3f}" if x < 10 else f"{x:.1f}" if x < 1000 else f"{x:,.0f}"


def _stage_cell(ours: float, paper: float | None) -> str:
    if paper is None:
        return _ms(ours)
    return f"{_ms(ours)} ({paper:g}, {ours / paper:.2f}x)"


def format_tables(record: dict) -> str:
    """The suite's tables as Markdown: per kind, scene statistics and the stage break-down
    with the paper's 8800 GTS figure and our ratio (ours / paper) beside each stage."""
    dev = record["device"]
    bandwidth = record["write_bandwidth_bytes_per_s"]
    lines = [f"Device: {dev['name']} ({dev['platform']}, {dev['platform_version']}; driver "
             f"{dev['driver_version']}; {dev['compute_units']} compute units). Host: "
             f"{record['machine']['cpu']}, {record['machine']['cpus']} CPUs. "
             f"{record['pixels']} px, {record['viewport'][0]}x{record['viewport'][1]}; median of "
             f"{record['repeat']} runs after {record['warmup']} warm-up. Memory-write bandwidth "
             f"(numpy fill): {bandwidth / 1e9:.2f} GB/s.", "",
             "End to end: from the call until the caller holds the output as host arrays (upload, the "
             "five stages, the totals' and the output's read-back; the host adjacency is cached per scene, "
             "timed alone). Device stages: OpenCL profiling events only. Read-back ms: the output's copy "
             "(CPU device: mapping) alone.", ""]
    for kind, title in (("bezier", "Table 1: Bézier scenes"), ("pn", "Table 2: PN-triangle scenes")):
        scenes = [s for s in record["scenes"] if s["kind"] == kind]
        skipped = [s for s in record.get("skipped", []) if SUITE.get(s["key"]) and SUITE[s["key"]].kind == kind]
        if not scenes and not skipped:
            continue
        lines.append(f"### {title}")
        lines.append("")
        if scenes:
            unit = "patches" if kind == "bezier" else "base tris"
            lines += [f"| scene | {unit} (paper) | culled | vertices | tris (paper) | indices | "
                      "end to end ms [min-max] | of which read-back ms | host adjacency ms (timed alone) | Mtri/s e2e | Mtri/s device | "
                      "peak MiB | NumPy eval ms | NumPy / our vertices stage | % of write BW |",
                      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
            for s in scenes:
                st, p, e2e = s["stats"], s["paper"], s["fd"]["total_wall"]
                numpy_ms = s.get("numpy", {}).get("median")
                vertices_ms = s.get("direct", s["fd"])["vertices"]["median"] if "vertices" in s["fd"] else None
                ratio = f"{numpy_ms / vertices_ms:.0f}x" if numpy_ms and vertices_ms else "-"
                lines.append(
                    f"| {s['title']} | {s['base_primitives']:,} ({p.get('patches', 0):,}) | {st['culled']:,} | "
                    f"{st['vertices']:,} | {st['triangles']:,} ({p.get('tris', 0):,}) | {st['indices']:,} | "
                    f"{_ms(e2e['median'])} [{_ms(e2e['min'])}-{_ms(e2e['max'])}] | "
                    f"{_ms(s['fd']['read_back']['median']) if 'read_back' in s['fd'] else '-'} | "
                    f"{_ms(s['host_adjacency_ms']['median']) if 'host_adjacency_ms' in s else '-'} | "
                    f"{s['triangles_per_s'] / 1e6:.2f} | {s['triangles_per_s_device'] / 1e6:.2f} | "
                    f"{s['peak_device_bytes'] / 2**20:.1f} | {_ms(numpy_ms) if numpy_ms else '-'} | {ratio} | "
                    f"{100 * s['bandwidth_fraction']:.2f} |")
            lines.append("")
            if kind == "bezier":
                lines += ["| scene (device ms; paper ms, ours/paper) | factors | offsets | vertices | "
                          "vertices FD | indices | sum FD | spread of sum |",
                          "|---|---|---|---|---|---|---|---|"]
            else:  # the paper gives one PN vertices figure: it stands beside ours with FD
                lines += ["| scene (device ms; paper ms, ours/paper) | factors | offsets | vertices | "
                          "vertices FD | indices | sum FD | spread of sum |", "|---|---|---|---|---|---|---|---|"]
            for s in scenes:
                fd, direct, p = s["fd"], s.get("direct"), s["paper"]
                cell = lambda run, k, pk=None: (_stage_cell(run[k]["median"], p.get(pk or k))  # noqa: E731
                                                if run and k in run else "-")
                spread = fd["device_total"]["spread"]
                if kind == "bezier":
                    row = [cell(fd, "factors"), cell(fd, "offsets"), cell(direct, "vertices"),
                           cell(fd, "vertices", "vertices_fd"), cell(fd, "indices")]
                else:
                    row = [cell(fd, "factors"), cell(fd, "offsets"), cell(direct, "vertices", "-"),
                           cell(fd, "vertices"), cell(fd, "indices")]
                lines.append(f"| {s['title']} | " + " | ".join(row) +
                             f" | {_ms(fd['device_total']['median'])} | {100 * spread:.0f}% |")
            lines.append("")
        for s in skipped:
            lines.append(f"- {SUITE[s['key']].title}: skipped: {s['reason']}")
        if skipped:
            lines.append("")
    return "\n".join(lines)


def write_json(record: dict, path) -> None:
    Path(path).write_text(json.dumps(record, indent=1, default=float) + "\n")

"""Digest of Nsight Compute text exports (issue 15): the counters bench/RESULTS.md tabulates.

    python bench/ncu_digest.py details DETAILS.txt [KERNEL ...]     # one column per kernel launch
    python bench/ncu_digest.py sass SASS.csv [KERNEL]               # where the warps' samples fall

DETAILS.txt is ``ncu -i REPORT --page details --print-units base`` (bench/ncu_stage45.py's runs
under ``ncu --set full``); each kernel's first launch in it is read.  SASS.csv is ``ncu -i REPORT
--page source --csv --print-source sass``; its first block for KERNEL (default: the first) is
read: executed warp instructions and warp-state samples by opcode, the stall reasons of all
samples, the share of the code after the kernel's last EXIT (NVIDIA's out-of-line subroutines:
here the correctly rounded division's slow path) and of the CALL sites, and the ten instructions
with the most samples.  Standard library only; prints Markdown tables.
"""
from __future__ import annotations

import collections
import csv
import re
import sys

DETAILS = [  # (row label, section, metric name)
    ("duration (ns)", "GPU Speed Of Light Throughput", "Duration"),
    ("SM frequency (Hz)", "GPU Speed Of Light Throughput", "SM Frequency"),
    ("elapsed cycles", "GPU Speed Of Light Throughput", "Elapsed Cycles"),
    ("SM active cycles", "GPU Speed Of Light Throughput", "SM Active Cycles"),
    ("compute (SM) throughput %", "GPU Speed Of Light Throughput", "Compute (SM) Throughput"),
    ("memory throughput %", "GPU Speed Of Light Throughput", "Memory Throughput"),
    ("DRAM throughput %", "GPU Speed Of Light Throughput", "DRAM Throughput"),
    ("issue slots busy %", "Compute Workload Analysis", "Issue Slots Busy"),
    ("executed IPC (active, per SM)", "Compute Workload Analysis", "Executed Ipc Active"),
    ("instructions executed (warp)", "Instruction Statistics", "Executed Instructions"),
    ("registers per thread", "Launch Statistics", "Registers Per Thread"),
    ("static shared bytes per block", "Launch Statistics", "Static Shared Memory Per Block"),
    ("grid x block", "Launch Statistics", None),
    ("waves per SM", "Launch Statistics", "Waves Per SM"),
    ("theoretical occupancy %", "Occupancy", "Theoretical Occupancy"),
    ("achieved occupancy %", "Occupancy", "Achieved Occupancy"),
    ("active warps per scheduler", "Scheduler Statistics", "Active Warps Per Scheduler"),
    ("eligible warps per scheduler", "Scheduler Statistics", "Eligible Warps Per Scheduler"),
    ("no eligible %", "Scheduler Statistics", "No Eligible"),
    ("warp cycles per issued instruction", "Warp State Statistics", "Warp Cycles Per Issued Instruction"),
    ("avg. active threads per warp", "Warp State Statistics", "Avg. Active Threads Per Warp"),
    ("DRAM bytes read", "Memory Workload Analysis Chart", "dram__bytes_read.sum"),
    ("DRAM bytes written", "Memory Workload Analysis Chart", "dram__bytes_write.sum"),
    ("L1/TEX hit rate %", "Memory Workload Analysis", "L1/TEX Hit Rate"),
    ("L2 hit rate %", "Memory Workload Analysis", "L2 Hit Rate"),
    ("bytes per sector, global stores", "Memory Workload Analysis Tables", "Average Bytes Per Sector For Global Stores"),
    ("bytes per sector, global loads", "Memory Workload Analysis Tables", "Average Bytes Per Sector For Global Loads"),
    ("shared bank conflicts", "Memory Workload Analysis Tables", "l1tex__data_bank_conflicts_pipe_lsu_mem_shared.sum"),
]
STALLS = ["Stall Wait", "Selected", "Stall Long Scoreboard", "Stall Short Scoreboard", "Stall Branch Resolving",
          "Stall Not Selected", "Stall No Instruction", "Stall Dispatch Stall", "Stall MIO Throttle", "Stall LG Throttle",
          "Stall Math Pipe Throttle", "Stall Barrier"]


def launches(path: str) -> list[tuple[str, dict, str]]:
    """(kernel name, {(section, metric): value}, header line) of each launch in a details export."""
    out, name, values, section, header = [], None, {}, None, ""
    for line in open(path, encoding="utf-8", errors="replace"):
        head = re.match(r"  (\w+) \((\d+), 1, 1\)x\((\d+), 1, 1\)", line)
        if head:
            if name:
                out.append((name, values, header))
            name, values, section, header = head.group(1), {}, None, f"{head.group(2)} x {head.group(3)}"
            continue
        sec = re.match(r"\s+Section: (.+?)\s*$", line)
        if sec:
            section = sec.group(1)
            continue
        text = line.strip()
        if section and text:
            for _, wanted_section, metric in DETAILS + [(None, "Warp State Statistics", k) for k in STALLS]:
                if metric and wanted_section == section and text.startswith(metric + " ") \
                        and (section, metric) not in values:
                    values[(section, metric)] = text.split()[-1]
    if name:
        out.append((name, values, header))
    return out


def details(path: str, kernels: list[str]) -> None:
    found = launches(path)
    chosen = []
    for kernel in kernels or sorted({n for n, _, _ in found}, key=[n for n, _, _ in found].index):
        first = next((launch for launch in found if launch[0] == kernel), None)
        if first:
            chosen.append(first)
    print("| counter | " + " | ".join(n for n, _, _ in chosen) + " |")
    print("|---|" + "---|" * len(chosen))
    for label, section, metric in DETAILS:
        cells = [header if metric is None else values.get((section, metric), "") for _, values, header in chosen]
        print(f"| {label} | " + " | ".join(cells) + " |")
    print("\nWarp state (cycles per issued instruction, all cycles):\n")
    print("| state | " + " | ".join(n for n, _, _ in chosen) + " |")
    print("|---|" + "---|" * len(chosen))
    for stall in STALLS:
        cells = [values.get(("Warp State Statistics", stall), "") for _, values, _ in chosen]
        print(f"| {stall} | " + " | ".join(cells) + " |")


def sass(path: str, kernel: str | None) -> None:
    blocks, current = [], None
    for row in csv.reader(open(path, encoding="utf-8", errors="replace").read().splitlines()):
        if row and row[0] == "Kernel Name":
            current = {"name": row[1], "rows": []}
            blocks.append(current)
        elif row and row[0] == "Address" and current is not None:
            current["header"] = row
        elif row and current is not None and "header" in current:
            current["rows"].append(row)
    block = next(b for b in blocks if kernel in (None, b["name"]))
    header, rows = block["header"], block["rows"]
    index = {k: i for i, k in enumerate(header)}

    def number(row, key) -> float:
        text = row[index[key]].replace(",", "")
        try:
            return float(text)
        except ValueError:
            return 0.0

    stalls = [k for k in header if k.startswith("stall_") and "Not Issued" not in k]
    samples = [number(r, "Warp Stall Sampling (All Samples)") for r in rows]
    executed = [number(r, "Instructions Executed") for r in rows]
    total_samples, total_executed = sum(samples), sum(executed)
    opcodes = [re.match(r"(?:@!?U?P\w+\s+)?([A-Z0-9_]+)", r[1].strip()).group(1) for r in rows]
    by_op_exec, by_op_samples = collections.Counter(), collections.Counter()
    for op, e, s in zip(opcodes, executed, samples):
        by_op_exec[op] += e
        by_op_samples[op] += s
    reasons = collections.Counter({k[6:]: sum(number(r, k) for r in rows) for k in stalls})
    last_exit = max(i for i, op in enumerate(opcodes) if op == "EXIT")
    calls = [i for i, op in enumerate(opcodes) if op == "CALL"]
    print(f"{block['name']}: {len(rows)} SASS instructions, {total_executed:,.0f} warp instructions executed, "
          f"{total_samples:,.0f} warp samples\n")
    print("Samples by stall reason: " + ", ".join(f"{k} {100 * v / total_samples:.1f}%" for k, v in reasons.most_common(10)))
    tail = sum(samples[last_exit + 1:])
    near_calls = sum(sum(samples[max(0, i - 3): i + 2]) for i in calls)
    print(f"\nAfter the last EXIT (out-of-line subroutines): {100 * tail / total_samples:.1f}% of samples, entered "
          f"{max(executed[last_exit + 1:], default=0):,.0f} times (warp); CALL sites and their 3 preceding and 1 "
          f"following instructions: {100 * near_calls / total_samples:.1f}%; calls executed "
          f"{sum(executed[i] for i in calls):,.0f}\n")
    print("| opcode | executed (M, warp) | % executed | % samples |\n|---|---|---|---|")
    for op, e in by_op_exec.most_common(16):
        print(f"| {op} | {e / 1e6:.2f} | {100 * e / total_executed:.1f} | {100 * by_op_samples[op] / total_samples:.1f} |")
    print("\n| index | instruction | % samples | executed (k) | top stall |\n|---|---|---|---|---|")
    for i in sorted(range(len(rows)), key=lambda i: -samples[i])[:10]:
        top = max(stalls, key=lambda k: number(rows[i], k))
        print(f"| {i} | `{rows[i][1].strip()}` | {100 * samples[i] / total_samples:.2f} | {executed[i] / 1e3:.0f} | {top[6:]} |")


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) < 2 or argv[0] not in ("details", "sass"):
        print(__doc__)
        return 2
    if argv[0] == "details":
        details(argv[1], argv[2:])
    else:
        sass(argv[1], argv[2] if len(argv) > 2 else None)
    return 0


if __name__ == "__main__":
    sys.exit(main())

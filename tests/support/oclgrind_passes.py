"""The two Oclgrind passes of tests/test_oclgrind.py, run as subprocesses of
tests/oclgrind_scenarios.py, and started early.

The simulator is single-threaded and slow (the uninitialised-value pass takes minutes on 2 cores)
while the rest of the suite keeps about one core busy.  So ``conftest.py`` starts both full passes
in the background as soon as the tests are collected (``start_background``) and runs
test_oclgrind.py's tests last; ``finish`` then waits for a pass and reads it.  A run of
test_oclgrind.py alone starts them the same way, at its collection.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import oclgrind_scenarios as scenarios

RUNNER = Path(scenarios.__file__).resolve()
NAMES = [*scenarios.SCENARIOS, *scenarios.BATCHED, *scenarios.BY_LEVEL, *scenarios.ROWS_IN_PARALLEL, *scenarios.POINTS,
         *scenarios.SILHOUETTE, *scenarios.FUSED_OFFSETS, *scenarios.TILED_OFFSETS, *scenarios.FRAMES]

PASSES = {
    "checks": dict(env=scenarios.OCLGRIND_ENV, args=[],
                   selftests={"selftest_oob_write": "Invalid write of size 4",
                              "selftest_race": "Write-write data race"}),
    "uninitialized": dict(env=scenarios.OCLGRIND_UNINITIALIZED_ENV, args=["--fill-by-copy", "--fresh-context"],
                          selftests={"selftest_oob_write": "Invalid write of size 4",
                                     "selftest_uninitialized": "Uninitialized value written to global memory"}),
}
TIMEOUT_S = 1800  # per pass, from its start; ~80 and ~440 CPU-seconds (2026-11-27), far more wall under load


@dataclass
class Run:
    """One finished pass: the runner's exit code, its per-scenario JSON lines, Oclgrind's
    reports by scenario (allowed ones dropped), raw stderr and the folder of the .npz meshes."""

    returncode: int
    results: dict
    reports: dict
    stderr: str
    out_dir: Path


@dataclass
class Started:
    """A pass under way: its process, whose stdout and stderr go to files in ``out_dir``."""

    process: subprocess.Popen
    out_dir: Path


def pass_names(name: str) -> list[str]:
    """What a pass runs: every scenario (the uninitialised-value pass leaves out the ones it
    skips, UNINITIALIZED_SKIPPED, to save their simulation time) and the pass's self-tests."""
    skipped = scenarios.UNINITIALIZED_SKIPPED if name == "uninitialized" else {}
    return [*(n for n in NAMES if n not in skipped), *PASSES[name]["selftests"]]


def start(name: str, out_dir: Path, names: list[str] | None = None) -> Started:
    spec = PASSES[name]
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OCLGRIND_", "PYOPENCL_BUILD"))}
    env.update(spec["env"], CLTESS_DEVICE="oclgrind", OCLGRIND_MAX_ERRORS="1000000")
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / "stdout.txt", "wb") as stdout, open(out_dir / "stderr.txt", "wb") as stderr:
        process = subprocess.Popen(
            [sys.executable, str(RUNNER), *spec["args"], "--out", str(out_dir), *(names or pass_names(name))],
            stdout=stdout, stderr=stderr, env=env)
    return Started(process, out_dir)


def finish(started: Started) -> Run:
    """Wait for a pass and read what it wrote (a pass past TIMEOUT_S is killed: its scenarios
    then read as not finished)."""
    try:
        started.process.wait(timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        started.process.kill()
        started.process.wait()
    stdout = (started.out_dir / "stdout.txt").read_text(errors="replace")
    stderr = (started.out_dir / "stderr.txt").read_text(errors="replace")
    results = {}
    for line in stdout.splitlines():
        record = json.loads(line)
        if "name" in record:
            results[record["name"]] = record
    return Run(started.process.returncode, results, scenarios.parse_stderr(stderr), stderr, started.out_dir)


# The full passes started in the background by conftest.py, and where they write.
_BACKGROUND: dict[str, Started] = {}
_FINISHED: dict[str, Run] = {}
_FOLDER: list[Path] = []


def start_background() -> None:
    """Start both full passes now (once per test session)."""
    if _BACKGROUND:
        return
    _FOLDER.append(Path(tempfile.mkdtemp(prefix="cltess-oclgrind-")))
    for name in PASSES:
        _BACKGROUND[name] = start(name, _FOLDER[0] / name)


def full_pass(name: str, out_dir: Path) -> Run:
    """The full pass ``name``: the background one if started, else run now into ``out_dir``."""
    if name not in _FINISHED:
        started = _BACKGROUND.get(name) or start(name, out_dir)
        _FINISHED[name] = finish(started)
    return _FINISHED[name]


def stop_background() -> None:
    """End of the test session: stop what still runs (a run stopped early) and remove the files."""
    for started in _BACKGROUND.values():
        if started.process.poll() is None:
            started.process.kill()
            started.process.wait()
    for folder in _FOLDER:
        shutil.rmtree(folder, ignore_errors=True)

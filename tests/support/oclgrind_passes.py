"""The two Oclgrind passes of tests/test_oclgrind.py, run as subprocesses of
tests/oclgrind_scenarios.py, and started early.

The simulator is single-threaded and slow (the uninitialised-value pass takes minutes on 2 cores).
So ``conftest.py`` starts both full passes in the background as soon as the tests are collected
(``start_background``), once per run: by pytest-xdist's controller when the tests run in workers,
which then find the passes' folder in their ``workerinput`` (``attach``).  test_oclgrind.py's
tests run last; ``finish`` waits for a pass and reads it.  A pass's wrapper writes its exit code
to a file when it ends, so a process that did not start it can wait for it too.
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import oclgrind_scenarios as scenarios

RUNNER = Path(scenarios.__file__).resolve()
NAMES = [*scenarios.SCENARIOS, *scenarios.BATCHED, *scenarios.BY_LEVEL, *scenarios.ROWS_IN_PARALLEL, *scenarios.POINTS,
         *scenarios.SILHOUETTE, *scenarios.FUSED_OFFSETS, *scenarios.TILED_OFFSETS, *scenarios.FRAMES,
         *scenarios.FUSED_CRACK_FREE, *scenarios.LANES]

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
    """A pass under way, writing into ``out_dir``: stdout.txt, stderr.txt, and ``returncode``
    when it ends (a pass past TIMEOUT_S is killed, and its scenarios read as not finished).
    ``process`` is the wrapper, in the process that started it (None in another)."""

    out_dir: Path
    process: subprocess.Popen | None = None


def pass_names(name: str) -> list[str]:
    """What a pass runs: every scenario (the uninitialised-value pass leaves out the ones it
    skips, UNINITIALIZED_SKIPPED, to save their simulation time, and those another scenario
    covers, UNINITIALIZED_COVERED_BY) and the pass's self-tests."""
    left = {**scenarios.UNINITIALIZED_SKIPPED, **scenarios.UNINITIALIZED_COVERED_BY} if name == "uninitialized" else {}
    return [*(n for n in NAMES if n not in left), *PASSES[name]["selftests"]]


def start(name: str, out_dir: Path, names: list[str] | None = None) -> Started:
    spec = PASSES[name]
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OCLGRIND_", "PYOPENCL_BUILD"))}
    env.update(spec["env"], CLTESS_DEVICE="oclgrind", OCLGRIND_MAX_ERRORS="1000000")
    out_dir.mkdir(parents=True, exist_ok=True)
    runner = [sys.executable, str(RUNNER), *spec["args"], "--out", str(out_dir), *(names or pass_names(name))]
    with open(out_dir / "stdout.txt", "wb") as stdout, open(out_dir / "stderr.txt", "wb") as stderr:
        process = subprocess.Popen([sys.executable, "-c", WRAPPER, str(TIMEOUT_S), *runner], cwd=out_dir,
                                   stdout=stdout, stderr=stderr, env=env, start_new_session=True)
    return Started(out_dir, process)


# A pass runs under this wrapper: it kills the runner past TIMEOUT_S and then writes the exit
# code (-9 when killed) into ``returncode``, renamed into place so that no waiter reads half of it.
WRAPPER = """
import os, subprocess, sys
try:
    code = subprocess.run(sys.argv[2:], timeout=float(sys.argv[1])).returncode
except subprocess.TimeoutExpired:
    code = -9
with open("returncode.part", "w") as part:
    part.write(str(code))
os.replace("returncode.part", "returncode")
"""


def finish(started: Started) -> Run:
    """Wait for a pass to end and read what it wrote."""
    if started.process is not None:
        started.process.wait()
    returncode_file = started.out_dir / "returncode"
    give_up = time.monotonic() + TIMEOUT_S + 60  # (its wrapper ends it after TIMEOUT_S)
    while not returncode_file.exists() and time.monotonic() < give_up:  # a pass another process started
        time.sleep(1)
    stdout = (started.out_dir / "stdout.txt").read_text(errors="replace")
    stderr = (started.out_dir / "stderr.txt").read_text(errors="replace")
    results = {}
    for line in stdout.splitlines():
        record = json.loads(line)
        if "name" in record:
            results[record["name"]] = record
    returncode = int(returncode_file.read_text()) if returncode_file.exists() else -9
    return Run(returncode, results, scenarios.parse_stderr(stderr), stderr, started.out_dir)


# The full passes started in the background by this process (conftest.py, or pytest-xdist's
# controller), or by the controller for this worker (``attach``), and where they write.
_BACKGROUND: dict[str, Started] = {}
_FINISHED: dict[str, Run] = {}
_FOLDER: list[Path] = []
_ATTACHED: list[Path] = []


def wanted(nodeids: list[str]) -> bool:
    """Whether a run of these tests wants the full passes: any test of test_oclgrind.py but
    the one that runs its own pass, and an Oclgrind platform to run them on."""
    simulated = [nodeid.split("::")[-1] for nodeid in nodeids if nodeid.split("::")[0].endswith("test_oclgrind.py")]
    if all(test.startswith("test_out_of_bounds_write_alone_fails_the_check") for test in simulated):
        return False
    from cltess.device import list_devices
    return any(info.matches("oclgrind") for info in list_devices())


def background_folder() -> Path:
    """The folder the background passes write into (made once per process that starts them)."""
    if not _FOLDER:
        _FOLDER.append(Path(tempfile.mkdtemp(prefix="cltess-oclgrind-")))
    return _FOLDER[0]


def start_background() -> None:
    """Start both full passes now (once per test session)."""
    if _BACKGROUND:
        return
    for name in PASSES:
        _BACKGROUND[name] = start(name, background_folder() / name)


def attach(folder: Path) -> None:
    """In a pytest-xdist worker: the passes, if the controller started them, write into ``folder``."""
    _ATTACHED.append(folder)


def full_pass(name: str, out_dir: Path) -> Run:
    """The full pass ``name``: the background one if started (here, or by the controller), else
    run now into ``out_dir``."""
    if name not in _FINISHED:
        started = _BACKGROUND.get(name)
        if started is None and _ATTACHED and (_ATTACHED[0] / name).is_dir():
            started = Started(_ATTACHED[0] / name)
        _FINISHED[name] = finish(started or start(name, out_dir))
    return _FINISHED[name]


def stop_background() -> None:
    """End of the test session: stop what still runs (a run stopped early) and remove the files."""
    for started in _BACKGROUND.values():
        if started.process.poll() is None:
            os.killpg(started.process.pid, signal.SIGKILL)
            started.process.wait()
    for folder in _FOLDER:
        shutil.rmtree(folder, ignore_errors=True)


def report_scenarios(names: list[str], out_dir: Path) -> bool:
    """Both passes on the scenarios ``names`` (started together, into ``out_dir / pass``), as
    test_oclgrind.py's test_no_oclgrind_reports reads them: a line per pass and scenario, "OK" or
    its first problems (not finished, Oclgrind's reports), and a line per pass with its exit code
    and seconds; for a session's record of the scenarios its change reaches (e.g.
    bench/results/cpu15f-2core/oclgrind_cpu15f.py).  Whether every scenario was OK."""
    assert all(name in NAMES for name in names), [name for name in names if name not in NAMES]
    print("scenarios:", names, flush=True)
    started = {name: start(name, out_dir / name, names) for name in PASSES}
    clean = True
    for name, pass_started in started.items():
        began = time.time()
        run = finish(pass_started)
        for scenario in names:
            problems = ([] if scenario in run.results else ["did not finish"]) + run.reports.get(scenario, [])
            clean = clean and not problems
            print(name, scenario, "OK" if not problems else problems[:3], flush=True)
        print(name, "exit", run.returncode, f"{time.time() - began:.0f} s", flush=True)
    return clean

import os
import zlib
from pathlib import Path

import numpy as np
import pytest

# Worst bound ratios seen by the tests, printed at the end of the run.
BOUND_RATIOS: dict[str, float] = {}


@pytest.fixture(scope="session")
def tessellator():
    from cltess.pipeline import Tessellator
    return Tessellator()


@pytest.fixture(scope="session")
def tea_table():
    """The paper's tea table scene (scenes/tea_table.json), with its camera."""
    from cltess.io import load_scene
    from support import SCENES
    return load_scene(SCENES / "tea_table.json")


@pytest.fixture
def rng(request):
    return np.random.default_rng(zlib.crc32(request.node.name.encode()))


def pytest_terminal_summary(terminalreporter):
    if BOUND_RATIOS:
        terminalreporter.section("error bound: worst |surface - mesh| / eps")
        for name, ratio in sorted(BOUND_RATIOS.items()):
            terminalreporter.write_line(f"{ratio:8.4f}  {name}")


# The suite runs in pytest-xdist workers (pyproject.toml's addopts), one per core: its
# controller starts Oclgrind's two passes once, and gathers the workers' BOUND_RATIOS.  The
# workers run at a lower priority (WORKER_NICENESS): the passes' single-threaded simulation, one
# of them about 450 CPU-seconds, is then not the run's tail behind them.
WORKER_NICENESS = 5


def pytest_configure(config):
    from support import oclgrind_passes
    if hasattr(config, "workerinput"):
        os.nice(WORKER_NICENESS)
        if "oclgrind_folder" in config.workerinput:
            oclgrind_passes.attach(Path(config.workerinput["oclgrind_folder"]))


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    from support import oclgrind_passes
    node.workerinput["oclgrind_folder"] = str(oclgrind_passes.background_folder())


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_node_collection_finished(node, ids):
    """The controller: start the passes when the first worker has collected (and deselected)."""
    from support import oclgrind_passes
    if not node.config.option.collectonly and oclgrind_passes.wanted(ids):
        oclgrind_passes.start_background()


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    for name, ratio in getattr(node, "workeroutput", {}).get("bound_ratios", {}).items():
        BOUND_RATIOS[name] = max(ratio, BOUND_RATIOS.get(name, ratio))


@pytest.hookimpl(trylast=True)  # after -k and -m have deselected
def pytest_collection_modifyitems(session, config, items):
    """Oclgrind's tests run last, and, in a run without workers, its two full passes start now in
    the background (support/oclgrind_passes.py): the simulator is single-threaded and takes minutes."""
    simulated = [item for item in items if item.path.name == "test_oclgrind.py"]
    if not simulated:
        return
    items[:] = [item for item in items if item.path.name != "test_oclgrind.py"] + simulated
    if config.option.collectonly or hasattr(config, "workerinput"):
        return
    from support import oclgrind_passes
    if oclgrind_passes.wanted([item.nodeid for item in simulated]):
        oclgrind_passes.start_background()


def pytest_sessionfinish(session):
    from support import oclgrind_passes
    if hasattr(session.config, "workeroutput"):
        session.config.workeroutput["bound_ratios"] = BOUND_RATIOS
    oclgrind_passes.stop_background()

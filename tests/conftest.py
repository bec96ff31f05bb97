import zlib

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


@pytest.hookimpl(trylast=True)  # after -k and -m have deselected
def pytest_collection_modifyitems(session, config, items):
    """Oclgrind's tests run last, and its two full passes start now in the background
    (support/oclgrind_passes.py): the simulator is single-threaded and takes minutes."""
    simulated = [item for item in items if item.path.name == "test_oclgrind.py"]
    if not simulated or config.option.collectonly:
        return
    items[:] = [item for item in items if item.path.name != "test_oclgrind.py"] + simulated
    if all(item.originalname == "test_out_of_bounds_write_alone_fails_the_check" for item in simulated):
        return  # the one test that runs its own pass
    from cltess.device import list_devices
    from support import oclgrind_passes
    if any(info.matches("oclgrind") for info in list_devices()):
        oclgrind_passes.start_background()


def pytest_sessionfinish(session):
    from support import oclgrind_passes
    oclgrind_passes.stop_background()

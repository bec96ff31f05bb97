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

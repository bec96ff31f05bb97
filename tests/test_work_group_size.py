"""Launches on PoCL name their work-group size (programs.py ``names_local_size``): PoCL compiles a
kernel once per work-group size, and left to choose it picks one from the global size, so every
scene of a new size was compiled again.  Elsewhere the runtime still chooses."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cltess.backends.opencl.programs import WORK_GROUP, named_local_size
from cltess.backends.opencl.tessellator import Tessellator
from cltess.device import list_devices, pick_device, probe_device
from cltess.io import load_scene
from cltess.scene import Scene

from support import SCENES

CPU_PLATFORMS = sorted({info.platform for info in list_devices() if info.type == "CPU" and probe_device(info).usable})


@given(st.integers(1, 1 << 24), st.integers(1, 4))
def test_named_size_divides_the_global_size(size, dims):
    global_size = (size, *([3] * (dims - 1)))
    local = named_local_size(global_size)
    assert len(local) == dims and local[1:] == (1,) * (dims - 1)
    assert global_size[0] % local[0] == 0 and WORK_GROUP % local[0] == 0
    if size % WORK_GROUP == 0:  # every tessellator._global_size
        assert local[0] == WORK_GROUP


@pytest.mark.parametrize("platform", CPU_PLATFORMS)
def test_pocl_launches_name_their_size_and_others_leave_it(platform):
    """Every launch of two scenes of different sizes, as recorded (``Programs.recording``)."""
    tessellator = Tessellator(pick_device(platform), work="patch")
    teapot = load_scene(SCENES / "teapot.bpt")
    tessellator.programs.recording = launches = []
    try:
        for copies in (1, 3):
            patches = np.concatenate([teapot.patches] * copies)
            tessellator.tessellate(Scene(patches, np.zeros(len(patches), np.int32), name="teapots"), eps=0.01)
    finally:
        tessellator.programs.recording = None
    assert len({launch.global_size for launch in launches}) > 1
    if platform == "Portable Computing Language":
        assert all(launch.local_size is not None and launch.global_size[0] % launch.local_size[0] == 0
                   for launch in launches)
    else:
        assert any(launch.local_size is None for launch in launches)

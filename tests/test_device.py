"""Device discovery and selection (runs on the PoCL CPU platform)."""
from __future__ import annotations

import numpy as np
import pyopencl as cl
import pytest

from cltess import device as device_module
from cltess.device import (
    DEVICE_ENV_VAR,
    DeviceError,
    DeviceInfo,
    default_device_info,
    list_devices,
    make_queue,
    pick_device,
)


@pytest.fixture(autouse=True)
def no_device_env(monkeypatch):
    monkeypatch.delenv(DEVICE_ENV_VAR, raising=False)


def fake_info(name: str, kind: str, platform: str = "Fake Platform") -> DeviceInfo:
    return DeviceInfo(platform=platform, platform_vendor="Fake Vendor", platform_version="OpenCL 3.0",
                      name=name, type=kind, version="OpenCL 3.0", compute_units=4,
                      global_memory_bytes=2**30, device=f"<device {name}>")


def test_list_devices_describes_pocl():
    devices = list_devices()
    assert devices, "the test environment has the PoCL CPU platform"
    pocl = [d for d in devices if d.matches("pocl")]
    assert pocl
    info = pocl[0]
    assert info.type == "CPU"
    assert info.compute_units >= 1 and info.global_memory_bytes > 0
    assert info.version.startswith("OpenCL")
    assert info.name in info.describe() and info.platform in info.describe()


@pytest.mark.parametrize("needle", ["pocl", "POCL", "portable computing", "cpu"])
def test_pick_by_substring(needle):
    chosen = pick_device(needle)
    assert isinstance(chosen, cl.Device)
    assert any(d.device == chosen and d.matches(needle) for d in list_devices())


def test_default_is_first_cpu_device():
    chosen = pick_device()
    assert chosen.type & cl.device_type.CPU
    assert chosen == default_device_info().device


def test_default_prefers_cpu_else_first():
    gpu, cpu = fake_info("Big GPU", "GPU"), fake_info("Some CPU", "CPU")
    assert default_device_info([gpu, cpu]) is cpu
    assert default_device_info([gpu, fake_info("Other GPU", "GPU")]) is gpu


def test_env_var_picks_device(monkeypatch):
    monkeypatch.setenv(DEVICE_ENV_VAR, "pocl")
    assert pick_device() == pick_device("pocl")
    gpu, cpu = fake_info("Big GPU", "GPU", "NVIDIA CUDA"), fake_info("Some CPU", "CPU")
    monkeypatch.setenv(DEVICE_ENV_VAR, "nvidia")
    assert default_device_info([cpu, gpu]) is gpu


def test_explicit_name_beats_env_var(monkeypatch):
    monkeypatch.setenv(DEVICE_ENV_VAR, "no-such-device")
    assert pick_device("pocl") is not None


def test_no_match_lists_available_devices():
    with pytest.raises(DeviceError) as error:
        pick_device("no-such-device-xyz")
    message = str(error.value)
    assert "no-such-device-xyz" in message
    for info in list_devices():
        assert info.name in message


def test_env_var_without_match_names_the_variable(monkeypatch):
    monkeypatch.setenv(DEVICE_ENV_VAR, "no-such-device-xyz")
    with pytest.raises(DeviceError, match=DEVICE_ENV_VAR):
        pick_device()


@pytest.mark.parametrize("failure", [
    cl.LogicError("clGetPlatformIDs failed: PLATFORM_NOT_FOUND_KHR"),
    RuntimeError("clGetPlatformIDs failed: PLATFORM_NOT_FOUND_KHR"),
    None,  # get_platforms() returns []
])
def test_no_platform_says_how_to_install_pocl(monkeypatch, failure):
    def get_platforms():
        if failure is not None:
            raise failure
        return []

    monkeypatch.setattr(device_module.cl, "get_platforms", get_platforms)
    assert list_devices() == []
    with pytest.raises(DeviceError) as error:
        pick_device()
    assert "pip install" in str(error.value) and "pocl" in str(error.value)


def test_other_platform_errors_become_device_errors(monkeypatch):
    def get_platforms():
        raise cl.LogicError("clGetPlatformIDs failed: OUT_OF_HOST_MEMORY")

    monkeypatch.setattr(device_module.cl, "get_platforms", get_platforms)
    with pytest.raises(DeviceError, match="OUT_OF_HOST_MEMORY"):
        list_devices()


def test_make_queue_has_profiling():
    context, queue = make_queue(pick_device())
    assert queue.properties & cl.command_queue_properties.PROFILING_ENABLE
    buffer = cl.Buffer(context, cl.mem_flags.READ_WRITE, 1024)
    event = cl.enqueue_copy(queue, buffer, np.zeros(256, np.float32))
    event.wait()
    assert event.profile.end >= event.profile.start

"""Device discovery and selection (runs on the PoCL CPU platform)."""
from __future__ import annotations

import numpy as np
import pyopencl as cl
import pytest

from cltess import device as device_module
from cltess.device import (
    DEVICE_ENV_VAR,
    FAILS_TO_BUILD,
    FAILS_TO_RUN,
    USABLE,
    DeviceError,
    DeviceInfo,
    Probe,
    default_device_info,
    list_devices,
    make_queue,
    pick_device,
    probe_device,
)

from support.device_faults import UNKNOWN_CPU_LOG, UNKNOWN_CPU_REASON, fresh_probes, pocl_fails_to_build

@pytest.fixture(autouse=True)
def isolated_probes(monkeypatch, tmp_path):
    """No device name from the environment; probe verdicts neither read nor kept across tests;
    fake devices (whose ``device`` is a string) count as usable unless a test says otherwise."""
    monkeypatch.delenv(DEVICE_ENV_VAR, raising=False)
    fresh_probes(monkeypatch, tmp_path)
    real_checks = device_module._run_checks
    monkeypatch.setattr(device_module, "_run_checks",
                        lambda info: Probe(USABLE) if isinstance(info.device, str) else real_checks(info))


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


def test_default_prefers_intel_then_pocl_then_other_cpus():
    other = fake_info("Some CPU", "CPU", "Other CPU Platform")
    pocl = fake_info("pthread-cpu", "CPU", "Portable Computing Language")
    intel = fake_info("cpu", "CPU", "Intel(R) OpenCL")
    assert default_device_info([other, pocl, intel]) is intel
    assert default_device_info([other, pocl]) is pocl
    assert default_device_info([fake_info("GPU", "GPU"), other]) is other


def test_default_skips_devices_that_fail_their_probe(monkeypatch):
    broken_cpu, gpu, good_cpu = (fake_info("Broken CPU", "CPU", "Intel(R) OpenCL"),
                                 fake_info("Big GPU", "GPU"), fake_info("Good CPU", "CPU"))
    verdicts = {"Broken CPU": Probe(FAILS_TO_BUILD, "error: unknown target CPU 'generic'", UNKNOWN_CPU_LOG)}
    monkeypatch.setattr(device_module, "_run_checks", lambda info: verdicts.get(info.name, Probe(USABLE)))
    assert default_device_info([broken_cpu, gpu, good_cpu]) is good_cpu
    assert default_device_info([broken_cpu, gpu]) is gpu  # no usable CPU: any usable device
    with pytest.raises(DeviceError) as error:
        default_device_info([broken_cpu])
    message = str(error.value)
    assert "no usable OpenCL device" in message and "unknown target CPU" in message
    assert "pip install" in message


def test_real_devices_probe_and_the_default_is_usable():
    devices = list_devices()
    for info in devices:
        probe = probe_device(info)
        assert probe.status in (USABLE, FAILS_TO_BUILD, FAILS_TO_RUN)
        assert probe.usable == (probe.reason == "")
    assert probe_device(default_device_info(devices)).usable


def test_pip_installed_intel_runtime_is_listed():
    from cltess.runtimes import pip_runtime_libraries
    if "intel-opencl-rt" not in pip_runtime_libraries():
        pytest.skip("Intel's CPU runtime is not installed here (it is on Linux x86-64)")
    intel = [info for info in list_devices() if info.matches("Intel(R) OpenCL")]
    assert intel and intel[0].type == "CPU" and probe_device(intel[0]).usable


def test_failing_build_is_reported_and_never_chosen(monkeypatch):
    pocl_fails_to_build(monkeypatch)
    pocl = [info for info in list_devices() if info.matches("pocl")]
    probe = probe_device(pocl[0])
    assert probe.status == FAILS_TO_BUILD
    assert probe.reason == UNKNOWN_CPU_REASON
    assert probe.log == UNKNOWN_CPU_LOG
    usable = [info for info in list_devices() if probe_device(info).usable]
    if usable:
        assert not default_device_info().matches("pocl")
    with pytest.raises(DeviceError) as error:
        pick_device("pocl")
    message = str(error.value)
    assert pocl[0].name in message and "fails to build: error: unknown target CPU 'generic'" in message
    assert "\n" not in message and "valid target CPU" not in message  # short; the log is separate
    assert error.value.log == UNKNOWN_CPU_LOG
    for info in usable:
        assert info.name in message


def test_verdicts_are_cached_per_driver_version(monkeypatch):
    calls = []
    monkeypatch.setattr(device_module, "_run_checks", lambda info: calls.append(info.name) or Probe(USABLE))
    info = fake_info("Some CPU", "CPU")
    assert probe_device(info).usable and probe_device(info).usable
    assert calls == ["Some CPU"]
    monkeypatch.setattr(device_module, "_verdicts", {})  # a new process: reads the cache file
    assert probe_device(info).usable and calls == ["Some CPU"]
    from dataclasses import replace
    assert probe_device(replace(info, driver_version="2.0")).usable  # a driver update probes again
    assert calls == ["Some CPU", "Some CPU"]


def test_failures_to_run_are_not_cached(monkeypatch):
    calls = []
    monkeypatch.setattr(device_module, "_run_checks",
                        lambda info: calls.append(1) or Probe(FAILS_TO_RUN, "wrong result", "wrong result"))
    info = fake_info("Flaky GPU", "GPU")
    assert probe_device(info).status == FAILS_TO_RUN
    monkeypatch.setattr(device_module, "_verdicts", {})
    probe_device(info)
    assert len(calls) == 2


def test_wrong_answers_fail_the_probe(monkeypatch):
    def run(context, program):
        raise RuntimeError("wrong result: the probe kernel is off by 1")
    monkeypatch.setattr(device_module, "_run_probe", run)
    probe = probe_device(list_devices()[0])
    assert probe.status == FAILS_TO_RUN and "off by 1" in probe.reason


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

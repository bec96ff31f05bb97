"""Simulated device failures for the probe tests (tests/test_device.py, tests/test_cli.py)."""
from __future__ import annotations

from cltess import device as device_module

# What PoCL 3.0 (LLVM 14) says on a CPU it does not know, e.g. an AMD Zen 5 (issue 8).
UNKNOWN_CPU_LOG = ("clBuildProgram failed: BUILD_PROGRAM_FAILURE - clBuildProgram failed: "
                   "BUILD_PROGRAM_FAILURE - clBuildProgram failed: BUILD_PROGRAM_FAILURE\n\n"
                   "Build on <pyopencl.Device 'pthread-AMD EPYC' on 'Portable Computing Language'>:\n\n"
                   "error: unknown target CPU 'generic'\n"
                   "note: valid target CPU values are: nocona, core2, penryn, bonnell\n(options: -I /x)")
UNKNOWN_CPU_REASON = "error: unknown target CPU 'generic'"


def fresh_probes(monkeypatch, tmp_path) -> None:
    """Probe verdicts neither read from nor kept beyond the test."""
    monkeypatch.setenv("CLTESS_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(device_module, "_verdicts", {})


def pocl_fails_to_build(monkeypatch) -> None:
    """PoCL as on a CPU its LLVM does not know: building the probe on it raises."""
    real_build = device_module._build_probe

    def build(context):
        if "Portable Computing Language" in context.devices[0].platform.name:
            raise RuntimeError(UNKNOWN_CPU_LOG)
        return real_build(context)

    monkeypatch.setattr(device_module, "_build_probe", build)

"""Registering pip-installed CPU runtimes with pyopencl's ICD loader (cltess/runtimes.py)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from cltess import runtimes
from cltess.runtimes import ICD_ENV_VAR, OPT_OUT_ENV_VAR, pip_runtime_libraries, register_pip_runtimes

FAKE_LIBRARY = "/opt/fake/lib/libintelocl.so"


@pytest.fixture
def fake_runtime(monkeypatch, tmp_path):
    monkeypatch.setenv("CLTESS_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(runtimes, "pip_runtime_libraries", lambda: {"intel-opencl-rt": Path(FAKE_LIBRARY)})


def icd_lines(folder) -> list[str]:
    return sorted(path.read_text().strip() for path in Path(folder).glob("*.icd"))


def test_user_folder_stays_visible_beside_the_pip_runtime(fake_runtime, tmp_path):
    vendors = tmp_path / "vendors"
    vendors.mkdir()
    (vendors / "nvidia.icd").write_text("libnvidia-opencl.so.1\n")
    environ = {ICD_ENV_VAR: str(vendors)}
    folder = register_pip_runtimes(environ)
    assert environ[ICD_ENV_VAR] == str(folder)
    assert icd_lines(folder) == sorted(["libnvidia-opencl.so.1", FAKE_LIBRARY])
    assert register_pip_runtimes(environ) is None  # already registered: nothing changes
    assert environ[ICD_ENV_VAR] == str(folder)


def test_empty_folder_gives_the_pip_runtime_alone(fake_runtime, tmp_path):
    """As in CI, where OCL_ICD_VENDORS hides the system's runtimes."""
    environ = {ICD_ENV_VAR: str(tmp_path)}
    assert icd_lines(register_pip_runtimes(environ)) == [FAKE_LIBRARY]


def test_single_icd_file_and_library_name_forms(fake_runtime, tmp_path):
    icd = tmp_path / "pocl.icd"
    icd.write_text("/usr/lib/libpocl.so.2\n")
    assert icd_lines(register_pip_runtimes({ICD_ENV_VAR: str(icd)})) == sorted(["/usr/lib/libpocl.so.2",
                                                                                FAKE_LIBRARY])
    assert icd_lines(register_pip_runtimes({ICD_ENV_VAR: "libOther.so"})) == sorted(["libOther.so",
                                                                                   FAKE_LIBRARY])


def test_system_folder_is_copied_when_nothing_is_set(fake_runtime, tmp_path, monkeypatch):
    system = tmp_path / "etc-vendors"
    system.mkdir()
    (system / "pocl.icd").write_text("libpocl.so.2\n")
    monkeypatch.setattr(runtimes, "SYSTEM_ICD_DIR", system)
    environ = {}
    assert icd_lines(register_pip_runtimes(environ)) == sorted(["libpocl.so.2", FAKE_LIBRARY])


def test_opt_out_leaves_the_loader_alone(fake_runtime):
    environ = {OPT_OUT_ENV_VAR: "0"}
    assert register_pip_runtimes(environ) is None and ICD_ENV_VAR not in environ


def test_no_pip_runtime_changes_nothing(monkeypatch):
    monkeypatch.setattr(runtimes, "pip_runtime_libraries", lambda: {})
    environ = {}
    assert register_pip_runtimes(environ) is None and environ == {}


def test_intel_runtime_visible_with_system_icds_hidden(tmp_path):
    """A fresh process with an empty ICD folder (no system OpenCL) still sees Intel's runtime."""
    if "intel-opencl-rt" not in pip_runtime_libraries():
        pytest.skip("Intel's CPU runtime is not installed here (it is on Linux x86-64)")
    env = {k: v for k, v in os.environ.items() if k not in ("CLTESS_DEVICE", OPT_OUT_ENV_VAR)}
    env.update({ICD_ENV_VAR: str(tmp_path), "CLTESS_CACHE_DIR": str(tmp_path / "cache")})
    child = "import cltess, pyopencl; print([p.name for p in pyopencl.get_platforms()])"
    result = subprocess.run([sys.executable, "-c", child], env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "Intel(R) OpenCL" in result.stdout

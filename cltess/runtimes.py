"""CPU OpenCL runtimes installed by pip, made visible to pyopencl's ICD loader.

pyopencl's wheel bundles an ocl-icd loader. It finds runtimes through ``.icd`` files (one line:
the path of the runtime's library) in its own ``pyopencl/.libs`` folder, where the PoCL and
Oclgrind wheels put theirs, and in ``/etc/OpenCL/vendors``, or instead in the folder named by
``OCL_ICD_VENDORS``. It ignores ``OCL_ICD_FILENAMES``. Intel's CPU runtime from PyPI
(``intel-opencl-rt``) ships an ``.icd`` naming its build machine's path, so nothing finds it.

:func:`register_pip_runtimes` writes an ICD folder holding one ``.icd`` per pip-installed
runtime plus copies of the ``.icd`` files the loader would have read otherwise (the user's
``OCL_ICD_VENDORS`` folder, else ``/etc/OpenCL/vendors``), and points ``OCL_ICD_VENDORS`` at it.
The loader reads that variable when a process first lists platforms, so this must run before
that: ``cltess/__init__.py`` calls it on import. System runtimes stay visible; a device the
user names is still picked by name (``cltess.device``).
"""
from __future__ import annotations

import hashlib
import os
import sys
from importlib import metadata
from pathlib import Path

__all__ = ["ICD_ENV_VAR", "OPT_OUT_ENV_VAR", "SYSTEM_ICD_DIR", "cache_dir", "pip_runtime_libraries", "register_pip_runtimes"]

ICD_ENV_VAR = "OCL_ICD_VENDORS"
OPT_OUT_ENV_VAR = "CLTESS_REGISTER_RUNTIMES"  # "0": leave the ICD loader's view as it is
SYSTEM_ICD_DIR = Path("/etc/OpenCL/vendors")

# Pip distributions that carry a CPU OpenCL runtime, and the library that is its ICD.
# PoCL's and Oclgrind's wheels register themselves in pyopencl/.libs; Intel's does not.
PIP_RUNTIMES = {"intel-opencl-rt": "libintelocl.so"}


def cache_dir() -> Path:
    """Where cltess keeps what it may rebuild: ``$CLTESS_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/cltess``, else ``~/.cache/cltess``."""
    if os.environ.get("CLTESS_CACHE_DIR"):
        return Path(os.environ["CLTESS_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "cltess"


def pip_runtime_libraries() -> dict[str, Path]:
    """The ICD library of each pip-installed runtime that is present: {distribution: path}."""
    found = {}
    for distribution, library in PIP_RUNTIMES.items():
        try:
            files = metadata.distribution(distribution).files or ()
        except metadata.PackageNotFoundError:
            continue
        for file in files:
            if file.name == library:
                path = Path(file.locate()).resolve()
                if path.is_file():
                    found[distribution] = path
                    break
    return found


def _icd_lines(source: str | None) -> list[str]:
    """The library lines of the ``.icd`` files the loader would read without us.

    ``source`` is the user's ``OCL_ICD_VENDORS``: a folder of ``.icd`` files, one ``.icd`` file,
    or a library name (ocl-icd accepts all three); None means the system folder."""
    if source is None:
        files = sorted(SYSTEM_ICD_DIR.glob("*.icd")) if SYSTEM_ICD_DIR.is_dir() else []
    elif Path(source).is_dir():
        files = sorted(Path(source).glob("*.icd"))
    elif source.endswith(".icd"):
        files = [Path(source)]
    else:
        return [source]
    lines = []
    for file in files:
        try:
            line = file.read_text().strip()
        except (OSError, UnicodeDecodeError):  # the loader skips unreadable files too
            continue
        if line:
            lines.append(line)
    return lines


def _write_icd_folder(lines: list[str]) -> Path:
    """A folder with one ``.icd`` file per library line, named by a hash of its content so
    that processes with the same runtimes share it; written atomically."""
    digest = hashlib.sha256("\n".join(lines).encode()).hexdigest()[:16]
    folder = cache_dir() / "icd" / digest
    if folder.is_dir():
        return folder
    staging = folder.parent / f".{digest}.{os.getpid()}"
    staging.mkdir(parents=True, exist_ok=True)
    for index, line in enumerate(lines):
        (staging / f"{index:02d}.icd").write_text(line + "\n")
    try:
        staging.rename(folder)
    except OSError:  # another process was first: theirs has the same content
        for file in staging.iterdir():
            file.unlink()
        staging.rmdir()
    return folder


def register_pip_runtimes(environ=os.environ) -> Path | None:
    """Point ``OCL_ICD_VENDORS`` at a folder that lists the pip-installed runtimes beside the
    ones the loader already knew. Returns the folder, or None when there is nothing to add
    (or it is already registered, or ``$CLTESS_REGISTER_RUNTIMES`` is "0", or the cache
    folder cannot be written)."""
    if environ.get(OPT_OUT_ENV_VAR, "").strip() == "0":
        return None
    libraries = [str(path) for path in pip_runtime_libraries().values()]
    if not libraries:
        return None
    known = _icd_lines(environ.get(ICD_ENV_VAR))
    missing = [library for library in libraries if library not in known]
    if not missing:
        return None
    try:
        folder = _write_icd_folder(known + missing)
    except OSError as error:
        print(f"cltess: warning: cannot register the pip-installed OpenCL runtimes "
              f"({', '.join(missing)}): {error}", file=sys.stderr)
        return None
    environ[ICD_ENV_VAR] = str(folder)
    return folder

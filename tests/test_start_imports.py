"""What the CLI's start imports: nothing it does not use (cltess/backends/opencl/scan_kernel.py)."""
import importlib
import subprocess
import sys

import pytest

from cltess.backends.opencl.scan_kernel import pygments_hidden


def imported_after(statement: str) -> set:
    """The modules in sys.modules after ``statement`` in a fresh interpreter."""
    child = f"{statement}\nimport sys\nprint(' '.join(name for name, m in sys.modules.items() if m is not None))"
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, check=True)
    return set(done.stdout.split())


def test_the_tessellate_path_imports_the_scan_without_pygments():
    modules = imported_after("import cltess.cli, cltess.stream, cltess.orient, cltess.io, "
                             "cltess.backends.opencl.programs, cltess.backends.opencl.levels")
    assert "pyopencl.scan" in modules and "mako.exceptions" in modules
    assert not any(name == "pygments" or name.startswith("pygments.") for name in modules)


def test_mako_takes_its_plain_fallback():
    child = ("import cltess.backends.opencl.scan_kernel, mako.exceptions as e\n"
             "print(e.pygments_html_formatter is None, e.syntax_highlight()('<a>'))")
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["True", "&lt;a&gt;"]


def test_pygments_imports_as_usual_afterwards():
    pytest.importorskip("pygments")
    modules = imported_after("import cltess.backends.opencl.scan_kernel\nimport pygments.lexer")
    assert "pygments.lexer" in modules


def test_pygments_hidden_raises_within_and_restores():
    saved = sys.modules.pop("pygments", None)
    try:
        with pygments_hidden():
            with pytest.raises(ImportError):
                importlib.import_module("pygments")
        assert "pygments" not in sys.modules
    finally:
        if saved is not None:
            sys.modules["pygments"] = saved


def test_pygments_hidden_leaves_an_imported_pygments_alone():
    pygments = pytest.importorskip("pygments")
    with pygments_hidden():
        import pygments as within
    assert within is pygments and sys.modules["pygments"] is pygments


def test_importing_cltess_leaves_its_version_until_asked():
    child = ("import cltess\nprint('__version__' in vars(cltess))\n"
             "from importlib import metadata\nprint(cltess.__version__ == metadata.version('cltess'))")
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["False", "True"]

"""What `pip install .` (a wheel, not the editable checkout the suite runs from) ships: every
package under cltess/ and every kernel source under kernels/.  The editable install finds
modules in the working tree whether pyproject.toml lists them or not, so nothing else in the
suite notices a package left out of the list (cltess.esc was, 2026-11-28: the NumPy backend's
ESC stage 1 failed with ModuleNotFoundError after a plain install)."""
import fnmatch
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SETUPTOOLS = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]


def package_folder(name: str) -> Path:
    """The folder setuptools takes package `name` from (its package-dir mapping, else the name)."""
    mapped = SETUPTOOLS.get("package-dir", {})
    for prefix in sorted(mapped, key=len, reverse=True):
        if name == prefix or name.startswith(prefix + "."):
            return REPO / mapped[prefix] / Path(*name[len(prefix):].split(".")[1:])
    return REPO / Path(*name.split("."))


def test_every_package_under_cltess_is_declared():
    on_disk = {".".join(init.parent.relative_to(REPO).parts) for init in (REPO / "cltess").rglob("__init__.py")}
    declared = set(SETUPTOOLS["packages"])
    assert on_disk - declared == set(), "add to pyproject.toml [tool.setuptools] packages"
    for name in declared:
        assert (package_folder(name) / "__init__.py").is_file(), f"{name}: no package at {package_folder(name)}"


def test_every_kernel_source_is_package_data():
    globs = SETUPTOOLS["package-data"]["cltess.kernels"]
    folder = package_folder("cltess.kernels")
    sources = [path.relative_to(folder).as_posix() for path in folder.rglob("*") if path.suffix in (".cl", ".h")]
    assert len(sources) > 30
    # setuptools matches package-data globs per path segment ("*" does not cross "/"), as fnmatch
    # does not; so compare segment by segment.
    def shipped(path):
        parts = path.split("/")
        return any(len(glob.split("/")) == len(parts) and all(map(fnmatch.fnmatch, parts, glob.split("/")))
                   for glob in globs)
    assert [path for path in sources if not shipped(path)] == []

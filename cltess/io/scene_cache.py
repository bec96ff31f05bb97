"""A binary cache of parsed patch files (issue 15): a large ``.bpt`` / ``.bez`` file read
again is loaded as the ``.npy`` of its patches, keyed by a hash of its bytes (so an edited file
is a new key, never a stale hit).  What the host derives from a large scene's patches (the
Bézier edge groups, the orientation) is kept the same way (``derived``), keyed by a hash of the
patches' bytes *and of the source files of the code that derives it*, so that an edited module
is a new key too.

Where: ``$CLTESS_SCENE_CACHE`` (a folder; ``0`` or ``off``: no cache), else
``$XDG_CACHE_HOME/cltess/scenes`` or ``~/.cache/cltess/scenes``.  Only files of at least
``MIN_BYTES`` are cached, only after they parsed without error, and a cache that cannot be read
or written is passed over silently (the file is parsed as without it).
"""
from __future__ import annotations

import hashlib
import os
import zipfile
from pathlib import Path
from typing import Callable

import numpy as np

from ..scene import check_scene_file
from .text import _decode, _Lines, _read_bytes
from .writing import atomic_write

#: Smaller files parse in milliseconds: not worth a cache entry.
MIN_BYTES = 1 << 20
#: Part of every key: a parser change that changes results must change it.
VERSION = "1"


def cache_folder() -> Path | None:
    setting = os.environ.get("CLTESS_SCENE_CACHE")
    if setting is not None:
        return None if setting.strip().lower() in ("", "0", "off", "no", "false") else Path(setting)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "cltess" / "scenes"


def _key(data) -> str:
    """The cache key of some bytes (any buffer): SHA-256 (with the CPU's SHA instructions 2x
    the rate of BLAKE2b on the VM of bench/RESULTS.md: 24 against 52 ms for 19.6 MB), 40 hex digits."""
    return hashlib.sha256(data).hexdigest()[:40]


def _entry(folder: Path, key: str, kind: str) -> Path:
    return folder / f"{key}-{kind}-v{VERSION}.npy"


def _load_entry(entry: Path) -> np.ndarray | None:
    try:
        patches = np.load(entry, allow_pickle=False)
        if patches.dtype == np.float64 and patches.ndim == 4 and patches.shape[1:] == (4, 4, 4):
            return patches
    except (OSError, ValueError, EOFError):
        pass
    return None


def cached_patches(data: bytes, kind: str, parse: Callable[[bytes], np.ndarray], key: str | None = None) -> np.ndarray:
    """``parse(data)``, or the patches a previous parse of the same bytes stored (``key``: the
    bytes' ``_key`` where the caller has it already)."""
    folder = cache_folder() if len(data) >= MIN_BYTES else None
    if folder is None:
        return parse(data)
    entry = _entry(folder, key or _key(data), kind)
    patches = _load_entry(entry)
    if patches is not None:
        return patches
    patches = parse(data)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with atomic_write(entry, "wb") as handle:
            np.save(handle, np.ascontiguousarray(patches, np.float64), allow_pickle=False)
    except OSError:
        pass
    return patches


def read_patch_file(path, kind: str, fast: Callable[[bytes], np.ndarray | None],
                    slow: Callable[[_Lines], np.ndarray]) -> np.ndarray:
    """A patch file's (P, 4, 4, 4) homogeneous patches: ``fast(data)`` (NumPy at once; None for
    anything it would not take), else ``slow`` line by line (which names the line at fault); a
    large file's from this cache when the same bytes were parsed before."""
    folder, key = cache_folder(), None
    if folder is not None:  # a hit is found from the file's mapped pages: no copy of the bytes
        check_scene_file(path)  # not a FIFO or device, which open() would block on or map
        key, version = _key_of_mapped(path)
        hit = None if key is None else _load_entry(_entry(folder, key, kind))
        if hit is not None:
            return hit
    data = _read_bytes(path)
    if key is not None and _version(path) != version:  # changed since it was hashed: hash what was read
        key = None

    def parse(data):
        patches = fast(data)
        return patches if patches is not None else slow(_Lines(str(path), _decode(path, data)))

    return cached_patches(data, kind, parse, key)


def _key_of_mapped(path) -> tuple[str | None, tuple | None]:
    """The ``_key`` of the file at ``path`` if it is large enough to be cached, hashed from a
    read-only mapping, and the file's ``_version`` then; (None, None) otherwise (also for
    anything unusual: the file is then read and reported as without the cache)."""
    import mmap

    try:
        with open(path, "rb") as handle:
            status = os.fstat(handle.fileno())
            if status.st_size < MIN_BYTES:
                return None, None
            with mmap.mmap(handle.fileno(), 0, access=mmap.ACCESS_READ) as mapped:
                return _key(mapped), _version_of(status)
    except (OSError, ValueError):
        return None, None


def _version(path) -> tuple | None:
    """What tells a changed file (device, inode, size, change and modification times in ns)."""
    try:
        return _version_of(os.stat(path))
    except OSError:
        return None


def _version_of(status: os.stat_result) -> tuple:
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns, status.st_ctime_ns


def derived(scene, what: str, sources: list, make: Callable[[], dict]) -> dict:
    """``make()`` (a dict of NumPy arrays), or the arrays a previous ``make()`` stored for a
    scene with the same patches, derived by the same source files (``sources``: paths).  Scenes
    whose patches take less than ``MIN_BYTES`` are not cached (they take milliseconds)."""
    folder = cache_folder() if scene.patches.nbytes >= MIN_BYTES else None
    if folder is None:
        return make()
    digest = hashlib.sha256(scene.prepared("patches digest", lambda: _digest([scene.patches])).encode())
    for source in sources:
        digest.update(Path(source).read_bytes())
    entry = folder / f"{digest.hexdigest()[:40]}-{what}-v{VERSION}.npz"
    try:
        with np.load(entry, allow_pickle=False) as stored:
            return {name: stored[name] for name in stored.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile):
        pass
    arrays = make()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with atomic_write(entry, "wb") as handle:
            np.savez(handle, **arrays)
    except OSError:
        pass
    return arrays


def _digest(arrays) -> str:
    digest = hashlib.sha256()
    for array in arrays:
        digest.update(str((array.dtype.str, array.shape)).encode())
        digest.update(np.ascontiguousarray(array).data)
    return digest.hexdigest()[:40]

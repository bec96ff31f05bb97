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


def cached_patches(data: bytes, kind: str, parse: Callable[[bytes], np.ndarray]) -> np.ndarray:
    """``parse(data)``, or the patches a previous parse of the same bytes stored."""
    folder = cache_folder() if len(data) >= MIN_BYTES else None
    if folder is None:
        return parse(data)
    entry = folder / f"{hashlib.blake2b(data, digest_size=20).hexdigest()}-{kind}-v{VERSION}.npy"
    try:
        patches = np.load(entry, allow_pickle=False)
        if patches.dtype == np.float64 and patches.ndim == 4 and patches.shape[1:] == (4, 4, 4):
            return patches
    except (OSError, ValueError, EOFError):
        pass
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
    data = _read_bytes(path)

    def parse(data):
        patches = fast(data)
        return patches if patches is not None else slow(_Lines(str(path), _decode(path, data)))

    return cached_patches(data, kind, parse)


def derived(scene, what: str, sources: list, make: Callable[[], dict]) -> dict:
    """``make()`` (a dict of NumPy arrays), or the arrays a previous ``make()`` stored for a
    scene with the same patches, derived by the same source files (``sources``: paths).  Scenes
    whose patches take less than ``MIN_BYTES`` are not cached (they take milliseconds)."""
    folder = cache_folder() if scene.patches.nbytes >= MIN_BYTES else None
    if folder is None:
        return make()
    digest = hashlib.blake2b(scene.prepared("patches digest", lambda: _digest([scene.patches])).encode(),
                             digest_size=20)
    for source in sources:
        digest.update(Path(source).read_bytes())
    entry = folder / f"{digest.hexdigest()}-{what}-v{VERSION}.npz"
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
    digest = hashlib.blake2b(digest_size=20)
    for array in arrays:
        digest.update(str((array.dtype.str, array.shape)).encode())
        digest.update(np.ascontiguousarray(array).data)
    return digest.hexdigest()

"""``.bpt`` ("Bézier patch text"): the patch count, then per patch a line ``3 3`` (degrees in u
and v) and 16 lines ``x y z`` or ``x y z w`` (Cartesian point and weight), rows ``j = 0..3`` of
four points ``i = 0..3``.  All 16 lines of one patch have the same arity.  ``write_bpt`` uses
``repr`` floats, so points and weights read back bitwise equal."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..limits import float32_problem
from ..scene import Scene
from .scene_cache import read_patch_file
from .text import _cartesian_rows, _floats, _homogeneous, _Lines, _Numbers

_BPT_LINES_PER_PATCH = 17  # "3 3" + 16 points

def read_bpt(path) -> Scene:
    """A ``.bpt`` file as a single-object scene (object id 0)."""
    patches = read_patches(path)
    return Scene(patches, np.zeros(len(patches), np.int32), None, str(path))


def read_patches(path) -> np.ndarray:
    """The file's (P, 4, 4, 4) homogeneous patches: parsed by NumPy at once (_fast_bpt), or line
    by line where that finds something to report (_parse_bpt, naming the line); a large file's
    from the binary cache when its bytes were parsed before (io/scene_cache.py)."""
    return read_patch_file(path, "bpt", _fast_bpt, _parse_bpt)


def _fast_bpt(data: bytes) -> np.ndarray | None:
    """A well-formed ``.bpt`` file's (P, 4, 4, 4) homogeneous patches, parsed by NumPy at once
    (``text._Numbers``), bitwise what ``_parse_bpt`` gives; None for anything ``_parse_bpt``
    would report or that is unusual (it then finds the line and says what is wrong)."""
    numbers = _Numbers.of(data)
    if numbers is None or numbers.per_line[0] != 1:
        return None
    num = numbers.integer_token(0)
    per_line = numbers.per_line
    if not num or len(per_line) != 1 + num * _BPT_LINES_PER_PATCH:
        return None
    patch_lines = per_line[1:].reshape(num, _BPT_LINES_PER_PATCH)
    first = numbers.first[1:].reshape(num, _BPT_LINES_PER_PATCH)
    degree = first[:, 0, None] + np.arange(2)  # "3 3": two tokens, each the one character 3
    if (patch_lines[:, 0] != 2).any() or (numbers.values[degree] != 3).any() or (numbers.lengths[degree] != 1).any():
        return None
    arity = patch_lines[:, 1:]
    if ((arity != 3) & (arity != 4)).any() or (arity != arity[:, :1]).any():
        return None
    rows = first[:, 1:].reshape(-1, 1) + np.arange(4)  # each point line's 3 or 4 tokens
    values = numbers.values[np.minimum(rows, len(numbers.values) - 1)]
    values[:, 3] = np.where(arity.reshape(-1) == 4, values[:, 3], 1.0)  # x y z -> weight 1
    if not (values[:, 3] > 0).all():
        return None
    homogeneous = _homogeneous(values)
    if float32_problem(homogeneous):
        return None
    return homogeneous.reshape(num, 4, 4, 4)


def _parse_bpt(lines: _Lines) -> np.ndarray:
    """``.bpt`` text -> (P, 4, 4, 4) homogeneous patches."""
    num = lines.count(0, "patch", _BPT_LINES_PER_PATCH, 0)
    for p in range(num):  # degree lines: "3 3" only (bicubic)
        k = 1 + p * _BPT_LINES_PER_PATCH
        tokens = lines.texts[k].split()
        if tokens != ["3", "3"]:
            hint = " (a point line: does the previous patch have 16 points?)" if len(tokens) in (3, 4) else ""
            raise lines.error(
                k, f"patch {p}: wrong degree {lines.texts[k].strip()[:40]!r}; only bicubic '3 3' is supported{hint}"
            )
    point_ks = [1 + p * _BPT_LINES_PER_PATCH + 1 + q for p in range(num) for q in range(16)]
    rows = [lines.texts[k].split() for k in point_ks]
    arity = np.array([len(r) for r in rows]).reshape(num, 16)
    for p in np.flatnonzero((arity != arity[:, :1]).any(axis=1) | ((arity[:, 0] != 3) & (arity[:, 0] != 4))):
        q = int(np.argmax(arity[p] != arity[p, 0])) if arity[p, 0] in (3, 4) else 0
        k = point_ks[p * 16 + q]
        raise lines.error(
            k,
            f"patch {p}: expected 'x y z' or 'x y z w' with the same arity on all 16 lines "
            f"(first line of the patch has {arity[p, 0]} values, this one {arity[p, q]})",
        )
    rows = [r if len(r) == 4 else r + ["1"] for r in rows]  # x y z -> weight 1
    values = _floats(lines, point_ks, rows)
    weights = values[:, 3]
    bad = np.flatnonzero(weights <= 0)
    if len(bad):
        r = int(bad[0])
        raise lines.error(point_ks[r], f"patch {r // 16}: weight {float(weights[r])!r} <= 0 (weights must be positive)")
    lines.no_trailing(1 + num * _BPT_LINES_PER_PATCH, "patch")
    homogeneous = _homogeneous(values)
    problem = float32_problem(homogeneous)
    if problem:
        r, what = problem
        raise lines.error(point_ks[r], f"patch {r // 16}: {what}")
    return homogeneous.reshape(num, 4, 4, 4)


def write_bpt(path, patches: np.ndarray) -> None:
    """Write (P, 4, 4, 4) homogeneous patches as ``.bpt``: ``x y z`` for a patch whose weights
    are all 1, else ``x y z w``; ``repr`` floats, so reading back gives ``w * (b.xyz / w)``."""
    patches = np.asarray(patches, dtype=np.float64)
    out = [f"{len(patches)}"]
    for patch in _cartesian_rows(patches):
        rational = not (patch[..., 3] == 1).all()
        out.append("3 3")
        for x, y, z, w in patch.reshape(16, 4).tolist():
            out.append(f"{x!r} {y!r} {z!r} {w!r}" if rational else f"{x!r} {y!r} {z!r}")
    Path(path).write_text("\n".join(out) + "\n")


EXTENSION, parse, read, write = ".bpt", _parse_bpt, read_bpt, write_bpt

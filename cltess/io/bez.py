"""Indexed ``.bez`` (Newell's files): the patch count; one line per patch of 16 comma-separated
1-based vertex indices (rows as in ``.bpt``); the vertex count; one ``x,y,z`` (or ``x,y,z,w``)
line per vertex.  ``write_bez`` shares one vertex between exactly equal control points."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..limits import float32_problem
from ..scene import Scene
from .scene_cache import read_patch_file
from .text import (_FLOAT_TOKEN, _INDEX_BLOCK_BAD, _INT_TOKEN, _byte_set, _cartesian_rows, _clamped_int,
                   _floats, _homogeneous, _Lines, _Numbers)

_INDEX_LINE_BYTES = _byte_set(b"0123456789, \t\n")

def read_bez(path) -> Scene:
    """An indexed ``.bez`` file as a single-object scene (object id 0)."""
    patches = read_patches(path)
    return Scene(patches, np.zeros(len(patches), np.int32), None, str(path))


def read_patches(path) -> np.ndarray:
    """The file's (P, 4, 4, 4) homogeneous patches: parsed by NumPy at once (_fast_bez), or line
    by line where that finds something to report (_parse_bez, naming the line); a large file's
    from the binary cache when its bytes were parsed before (io/scene_cache.py)."""
    return read_patch_file(path, "bez", _fast_bez, _parse_bez)


def _fast_bez(data: bytes) -> np.ndarray | None:
    """A well-formed ``.bez`` file's (P, 4, 4, 4) homogeneous patches, parsed by NumPy at once
    (``text._Numbers``), bitwise what ``_parse_bez`` gives; None for anything ``_parse_bez``
    would report or that is unusual (it then finds the line and says what is wrong)."""
    numbers = _Numbers.of(data, commas=True)
    if numbers is None:
        return None
    per_line, commas = numbers.per_line, numbers.commas
    num = numbers.integer_token(0) if per_line[0] == 1 and commas[0] == 0 else None
    if not num or len(per_line) < num + 3 or per_line[1 + num] != 1 or commas[1 + num]:
        return None
    num_vertices = numbers.integer_token(int(numbers.first[1 + num]))
    if not num_vertices or len(per_line) != num + 2 + num_vertices:
        return None
    index_lines, vertex_lines = slice(1, 1 + num), slice(2 + num, None)
    if (per_line[index_lines] != 16).any() or (commas[index_lines] != 15).any() \
            or not numbers.only(_INDEX_LINE_BYTES, 1, 1 + num):
        return None
    arity = per_line[vertex_lines]
    if arity[0] not in (3, 4) or (arity != arity[0]).any() or (commas[vertex_lines] != arity - 1).any():
        return None
    values = numbers.values
    indices = values[numbers.first[1]:numbers.first[1] + 16 * num]
    if ((indices < 1) | (indices > num_vertices)).any():  # in float64, before a cast that could overflow
        return None
    indices = indices.astype(np.int64)
    start = int(numbers.first[2 + num])
    vertices = values[start:start + int(arity[0]) * num_vertices].reshape(num_vertices, int(arity[0]))
    if arity[0] == 3:
        vertices = np.concatenate([vertices, np.ones((num_vertices, 1))], axis=1)
    elif (vertices[:, 3] <= 0).any():
        return None
    homogeneous = _homogeneous(vertices)
    if float32_problem(homogeneous):
        return None
    return homogeneous[indices - 1].reshape(num, 4, 4, 4)


def _parse_bez(lines: _Lines) -> np.ndarray:
    """Indexed ``.bez`` text -> (P, 4, 4, 4) homogeneous patches."""
    num = lines.count(0, "patch", 1, 2)  # + vertex count line + at least one vertex
    rows = [lines.texts[k].split(",") for k in range(1, 1 + num)]
    for r, row in enumerate(rows):
        if len(row) != 16:
            raise lines.error(
                1 + r,
                f"patch {r}: expected 16 comma-separated vertex indices, got {len(row)} "
                f"(file truncated, or the patch count {num} is wrong?)",
            )
    num_vertices = lines.count(1 + num, "vertex", 1, 0)
    indices = _indices(lines, 1, rows, num_vertices)

    first = 2 + num
    vrows = [lines.texts[k].split(",") for k in range(first, first + num_vertices)]
    arity = len(vrows[0])
    for r, row in enumerate(vrows):
        if len(row) != arity or arity not in (3, 4):
            raise lines.error(
                first + r,
                f"vertex {r + 1}: expected 'x,y,z' or 'x,y,z,w' (same arity on every vertex line), got {len(row)} values",
            )
    values = _floats(lines, range(first, first + num_vertices), vrows)
    if arity == 3:
        values = np.concatenate([values, np.ones((num_vertices, 1))], axis=1)
    elif (values[:, 3] <= 0).any():
        r = int(np.argmax(values[:, 3] <= 0))
        raise lines.error(first + r, f"vertex {r + 1}: weight {float(values[r, 3])!r} <= 0 (weights must be positive)")
    lines.no_trailing(first + num_vertices, "vertex")
    homogeneous = _homogeneous(values)
    problem = float32_problem(homogeneous)
    if problem:
        r, what = problem
        raise lines.error(first + r, f"vertex {r + 1}: {what}")
    return homogeneous[indices - 1].reshape(num, 4, 4, 4)


def _indices(lines: _Lines, first: int, rows: list[list[str]], num_vertices: int) -> np.ndarray:
    """Rows of 16 index tokens -> (R, 16) int64 in 1..num_vertices."""
    block = "\n".join(lines.texts[first : first + len(rows)])
    values = None
    if not _INDEX_BLOCK_BAD.search(block):
        try:
            values = np.array(rows, dtype=np.int64)
        except (ValueError, OverflowError):
            values = None
    if values is None:
        for r, row in enumerate(rows):
            for token in row:
                t = token.strip()
                if _INT_TOKEN.fullmatch(t):
                    continue
                kind = "non-integer vertex index" if _FLOAT_TOKEN.fullmatch(t) else "not a vertex index"
                raise lines.error(first + r, f"patch {r}: {kind}: {t[:40]!r}")
        # every token is an integer: numpy overflowed on a huge one
        values = np.array([[_clamped_int(t) for t in row] for row in rows], dtype=np.int64)
    bad = (values < 1) | (values > num_vertices)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise lines.error(
            first + int(r),
            f"patch {r}: vertex index {rows[r][c].strip()[:40]} out of range 1..{num_vertices}",
        )
    return values


def write_bez(path, patches: np.ndarray) -> None:
    """Write (P, 4, 4, 4) homogeneous patches as indexed ``.bez``; exactly equal control points
    share one vertex (numbered by first use); weights written only if some weight != 1."""
    patches = np.asarray(patches, dtype=np.float64)
    points = _cartesian_rows(patches).reshape(-1, 4)
    _, first, inverse = np.unique(points, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # vertices in order of first use
    number = np.empty(len(order), np.int64)
    number[order] = np.arange(1, len(order) + 1)
    indices = number[inverse.reshape(-1)].reshape(len(patches), 16)
    vertices = points[first[order]]
    rational = not (vertices[:, 3] == 1).all()
    out = [f"{len(patches)}"]
    out += [",".join(map(str, row)) for row in indices.tolist()]
    out.append(f"{len(vertices)}")
    for x, y, z, w in vertices.tolist():
        out.append(f"{x!r},{y!r},{z!r},{w!r}" if rational else f"{x!r},{y!r},{z!r}")
    Path(path).write_text("\n".join(out) + "\n")


EXTENSION, parse, read, write = ".bez", _parse_bez, read_bez, write_bez

"""The ESC pattern (cltess/patterns/esc.py), exhaustively: every candidate mask of a coarse
triangle for L <= 3 (512 at L = 3), and random masks of whole patches (docs/esc.md)."""

import numpy as np
import pytest

from cltess.patterns import esc
from cltess.strips import expand_strips, split_strips


def lattice_xy(point):
    """Doubled coordinates of coarse-triangle point (j, i): apex (0, 0), B0 (-n, -2n), B1 (n, -2n)
    (counter-clockwise), integers, so areas are exact."""
    j, i = point
    return np.array([2 * i - j, -2 * j], np.int64)


def doubled_area(a, b, c):
    (ax, ay), (bx, by), (cx, cy) = a, b, c
    return int((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))


def expected_points(level, left, right, base):
    n = level + 1
    bit = lambda mask, k: (mask >> (k - 1)) & 1  # noqa: E731
    points = {(0, 0), (n, 0), (n, n)} | {(n, i) for i in range(1, n) if bit(base, i)}
    for j in range(1, n):
        points |= {(j, 0)} if bit(left, j) else set()
        points |= {(j, j)} if bit(right, j) else set()
        if bit(left, j) or bit(right, j):
            points |= {(j, i) for i in range(1, j)}
    return points


def boundary_segments(points, n):
    """The segments between consecutive points on each edge of the coarse triangle."""
    edges = [sorted(p for p in points if p[1] == 0), sorted(p for p in points if p[0] == p[1]),
             sorted((p for p in points if p[0] == n), key=lambda p: p[1])]
    return {frozenset(pair) for edge in edges for pair in zip(edge[:-1], edge[1:])}


def check_triangulation(points, triangles, boundary, whole_area, xy):
    """Counter-clockwise, no fold-over, areas sum to the whole, every edge shared by two
    triangles in opposite directions or on the boundary, the boundary exactly `boundary` (so
    no T-junction with the neighbours), every point used."""
    areas = [doubled_area(*(xy(p) for p in t)) for t in triangles]
    assert min(areas) > 0, "fold-over or zero area"
    assert sum(areas) == whole_area
    directed = [(t[k], t[(k + 1) % 3]) for t in triangles for k in range(3)]
    assert len(set(directed)) == len(directed), "an edge used twice in one direction"
    once = {frozenset(e) for e in directed if (e[1], e[0]) not in set(directed)}
    assert once == boundary
    assert {p for t in triangles for p in t} == set(points)


def uniform_triangles(n):
    out = set()
    for j in range(n):
        for i in range(j + 1):
            out.add(frozenset([(j, i), (j + 1, i), (j + 1, i + 1)]))
            if i < j:
                out.add(frozenset([(j, i), (j + 1, i + 1), (j, i + 1)]))
    return out


@pytest.mark.parametrize("level", [0, 1, 2, 3])
def test_every_mask_of_a_coarse_triangle(level):
    n = level + 1
    whole = doubled_area(lattice_xy((0, 0)), lattice_xy((n, 0)), lattice_xy((n, n)))
    for mask in range(1 << 3 * level):
        bits = esc.triangle_bits(mask, level)
        points, triangles, strips = esc.coarse_triangle(level, *bits)
        assert set(points) == expected_points(level, *bits)
        check_triangulation(points, triangles, boundary_segments(points, n), whole, lattice_xy)
        # count == emit: Euler's count of a triangulated polygon, 2V - B - 2, from the mask alone
        on_boundary = sum(1 for p in points if p[1] == 0 or p[0] == p[1] or p[0] == n)
        assert len(triangles) == 2 * len(points) - on_boundary - 2
        # strips expand to the list, triangle for triangle, in order and winding
        index = {p: k for k, p in enumerate(points)}
        joined = np.concatenate([[index[p] for p in s] + [0xFFFFFFFF] for s in strips])[:-1]
        expanded = expand_strips(joined.astype(np.uint32), drop_degenerate=True)
        listed = np.array([[index[p] for p in t] for t in triangles])
        rotate = lambda t: tuple(np.roll(t, -int(np.argmin(t))))  # noqa: E731
        assert [rotate(t) for t in expanded] == [rotate(t) for t in listed]
        assert len(split_strips(joined.astype(np.uint32))) == len(strips)
    full = (1 << 3 * level) - 1
    all_in = esc.coarse_triangle(level, *esc.triangle_bits(full, level))
    assert {frozenset(t) for t in all_in[1]} == uniform_triangles(n)
    assert len(all_in[1]) == n * n
    assert esc.coarse_triangle(level, 0, 0, 0)[1] == (((n, n), (0, 0), (n, 0)),)


def test_fig_5a_three_strips_and_eight_triangles():
    """Hu et al. Fig. 5a: rows {v1}, {v2 v3}, {v4 v5 v6}, {v7 .. v10}, v6 missing.  Our rows run
    right to left (the mirror image: v6 is our left end of row 2)."""
    names = {(0, 0): 1, (1, 1): 2, (1, 0): 3, (2, 2): 4, (2, 1): 5, (2, 0): 6, (3, 3): 7, (3, 2): 8,
             (3, 1): 9, (3, 0): 10}
    _, triangles, strips = esc.coarse_triangle(2, 0b01, 0b11, 0b11)
    assert len(triangles) == 8
    assert [[names[p] for p in s] for s in strips] == [[2, 1, 3], [4, 2, 5, 3, 10], [7, 4, 8, 5, 9, 5, 10]]


def random_masks(rng, level, density):
    return (rng.random((33, max(level, 1))) < density)[:, :level] @ (1 << np.arange(level)) if level \
        else np.zeros(33, np.int64)


def uniform_grid(m):
    out = set()
    for y in range(m):
        for x in range(m):
            out.add(frozenset([(x, y), (x + 1, y), (x + 1, y + 1)]))
            out.add(frozenset([(x, y), (x + 1, y + 1), (x, y + 1)]))
    return out


@pytest.mark.parametrize("level", [0, 1, 2, 3])
def test_patches_of_random_masks(rng, level):
    m = 3 * (level + 1)
    for density in (0.0, 0.2, 0.5, 0.8, 1.0):
        for _ in range(6):
            masks = random_masks(rng, level, density)
            reversed_edges = tuple(rng.random(4) < 0.5)
            record = esc.pack(level, masks, reversed_edges)
            assert (record > 0).all()
            got_level, got_masks = esc.unpack(record)
            assert got_level == level and np.array_equal(got_masks, masks)
            points, triangles, strips = esc.patch_mesh(level, masks)
            pts = [tuple(p) for p in points]
            tris = [tuple(pts[k] for k in t) for t in triangles]
            ring = [p for p in pts if 0 in p or m in p]
            corners = [(0, 0), (m, 0), (m, m), (0, m)]
            around = sorted(ring, key=lambda p: (p[1], p[0]) if p[1] == 0 else (m, m + p[1]) if p[0] == m
                            else (2 * m, 2 * m + m - p[0]) if p[1] == m else (3 * m, 3 * m + m - p[1]))
            boundary = {frozenset(pair) for pair in zip(around, around[1:] + around[:1])}
            check_triangulation(pts, tris, boundary, 2 * m * m, lambda p: np.array(p, np.int64))
            assert pts[:len(ring)] == ring and pts[0] == corners[0]  # the ring first
            expanded = expand_strips(strips, drop_degenerate=True)
            assert sorted(map(tuple, np.sort(expanded, 1))) == sorted(map(tuple, np.sort(triangles, 1)))
            if density == 1.0:
                assert {frozenset(t) for t in tris} == uniform_grid(m)
                assert len(tris) == 2 * m * m  # 288 at L = 3
            if density == 0.0:
                assert len(tris) == 18
            uv, listed = esc.layout(record)
            assert np.array_equal(listed, triangles) and np.allclose(uv * m, points)


def test_a_culled_record_has_nothing():
    uv, triangles = esc.layout(np.zeros(4, np.int32))
    assert uv.shape == (0, 2) and triangles.shape == (0, 3)


def test_levels_above_the_record_are_refused():
    with pytest.raises(ValueError, match="level 4"):
        esc.pack(4, np.zeros(33, np.int64))


def test_record_constants_equal_the_header():
    import re
    from cltess.backends.opencl.programs import kernel_dir
    text = (kernel_dir() / "patterns" / "esc.h").read_text()
    found = {}
    for name, value in re.findall(r"^#define (ESC_[A-Z_]+) (.+)$", text, re.MULTILINE):
        shifted = re.fullmatch(r"\((\d+) << (\d+)\)", value)
        found[name] = int(shifted[1]) << int(shifted[2]) if shifted else int(value, 0)
    assert found == {"ESC_BOUNDARY_BITS": esc.BOUNDARY_BITS, "ESC_REVERSED": esc.REVERSED,
                     "ESC_INTERIOR_SHIFT": esc.INTERIOR_SHIFT, "ESC_INTERIOR_BITS": esc.INTERIOR_BITS,
                     "ESC_LEVEL_SHIFT": esc.LEVEL_SHIFT, "ESC_ALIVE": esc.ALIVE, "ESC_MAX_LEVEL": esc.MAX_LEVEL}

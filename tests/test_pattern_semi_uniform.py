"""The semi-uniform pattern's NumPy mirror (cltess/patterns/semi_uniform.py), exhaustively for all
levels m <= 5 and all edge levels p_e <= m, quads and triangles, in exact integer arithmetic on
the 2^m lattice (SEEDS.md 1.4)."""
import functools
import itertools
import math
from fractions import Fraction

import numpy as np
import pytest

from cltess import reference
from cltess.patterns import semi_uniform as su

MAX_TESTED_LEVEL = 5


def all_cases(domain):
    for m in range(MAX_TESTED_LEVEL + 1):
        for levels in itertools.product(range(m + 1), repeat=su.EDGES[domain]):
            yield m, levels


def twice_areas(points, triangles):
    """Twice the signed areas of the triangles, in lattice units (exact integers)."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def domain_twice_area(domain, m):
    return (2 if domain == "quad" else 1) * 4 ** m


def check_pattern(domain, m, levels):
    """Every property of SEEDS.md 1.4 for one case; returns nothing, asserts."""
    n, edges = 1 << m, su.EDGES[domain]
    points, triangles = su.lattice_layout(domain, m, levels)
    case = f"{domain} m={m} p={levels}"

    # closed-form counts equal the layout
    assert len(points) == su.vertex_count(domain, m, levels), case
    assert len(triangles) == su.triangle_count(domain, m, levels), case
    assert np.bincount(points[:, 0] * (n + 1) + points[:, 1]).max() == 1, case

    # no fold-over, and the areas sum to the domain: exact integers
    areas = twice_areas(points, triangles)
    assert (areas > 0).all(), case
    assert areas.sum() == domain_twice_area(domain, m), case

    # a proper triangulation: each directed edge once, each inner edge used once each way, and
    # the edges used once are exactly the ring's segments (the boundary, counter-clockwise)
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    keys = np.sort(directed[:, 0] * len(points) + directed[:, 1])
    assert (np.diff(keys) > 0).all(), case
    reverse = directed[:, 1] * len(points) + directed[:, 0]
    paired = keys[np.minimum(np.searchsorted(keys, reverse), len(keys) - 1)] == reverse
    boundary = directed[~paired]
    ring_size = sum(1 << p for p in levels)
    ring = np.arange(ring_size)
    assert np.array_equal(boundary[np.argsort(boundary[:, 0])], np.stack([ring, (ring + 1) % ring_size], 1)), case

    # the ring: edge e holds exactly its p_e-dyadic points, in order, from its start corner
    start = 0
    for e, p in enumerate(levels):
        expected = su.edge_point(domain, e, np.arange(1 << p) << (m - p), m)
        assert np.array_equal(points[start:start + (1 << p)], expected), case
        on, a = su.edge_parameter(domain, e, points, m)
        assert sorted(a[on].tolist()) == [k << (m - p) for k in range((1 << p) + 1)], case
        start += 1 << p
    # then the interior lattice points, row by row
    assert np.array_equal(points[ring_size:], interior_rows(domain, m)), case


@functools.lru_cache(maxsize=None)
def interior_rows(domain, m):
    n = 1 << m
    rows = [(i, j) for j in range(1, n) for i in range(1, n if domain == "quad" else n - j)]
    return np.array(rows, np.int64).reshape(-1, 2)


@pytest.mark.parametrize("domain", ["quad", "tri"])
def test_every_case_up_to_level_5(domain):
    cases = list(all_cases(domain))
    assert len(cases) == sum((m + 1) ** su.EDGES[domain] for m in range(MAX_TESTED_LEVEL + 1))
    for m, levels in cases:
        check_pattern(domain, m, levels)


@pytest.mark.parametrize("domain", ["quad", "tri"])
def test_all_edges_at_the_patch_level_is_the_uniform_transition_pattern(domain):
    """Nothing snaps: vertex for vertex today's pattern at 2^m, and its triangles (the interior
    ones first, su.emit_order)."""
    transition = {"quad": reference.quad_pattern, "tri": reference.tri_pattern}[domain]
    for m in range(MAX_TESTED_LEVEL + 1):
        record = [1 << m] * su.EDGES[domain] + [0] * (4 - su.EDGES[domain])
        uv, triangles = su.pattern(domain, record)
        uv_t, triangles_t = transition(record)
        order = np.concatenate([np.flatnonzero(su.interior_mask(domain, m)),
                                np.flatnonzero(~su.interior_mask(domain, m))])
        assert np.array_equal(uv, uv_t) and np.array_equal(triangles, triangles_t[order])


@pytest.mark.parametrize("domain", ["quad", "tri"])
def test_interior_triangles_come_first_and_are_the_template(domain):
    """For every case up to level 5 the pattern's first triangles are the level's interior
    template (past the ring), so stage 5 by level writes them without looking at the edges."""
    for m, levels in all_cases(domain):
        points, triangles = su.lattice_layout(domain, m, levels)
        template = su.interior_template(domain, m).astype(np.int64) + sum(1 << p for p in levels)
        assert np.array_equal(triangles[:len(template)], template), (m, levels)
        assert not su.inside(domain, points[triangles[len(template):]], m).all(axis=1).any(), (m, levels)
    for m in range(MAX_TESTED_LEVEL + 1):  # the vertex template: every lattice point once, row by row
        points = su.point_template(domain, m)
        assert len(points) == su.vertex_count(domain, m, [m] * su.EDGES[domain])
        assert np.array_equal(points[np.lexsort((points[:, 0], points[:, 1]))], points)


@pytest.mark.parametrize("domain", ["quad", "tri"])
def test_ring_points_are_the_transition_patterns_ring_points(domain):
    """An edge of level p is sampled where a transition pattern's edge of factor 2^p is: the
    same uv, bitwise, so shared edges between the two patterns agree."""
    transition = {"quad": reference.quad_pattern, "tri": reference.tri_pattern}[domain]
    edges = su.EDGES[domain]
    for m in range(4):
        for levels in itertools.product(range(m + 1), repeat=edges):
            record = [1 << p for p in levels] + [0] * (4 - edges)
            ring = sum(record)
            assert np.array_equal(su.pattern(domain, record)[0][:ring], transition(record)[0][:ring])


def paper_sigma(p, t):
    """Eq. 1 verbatim on a Fraction t."""
    x = (1 << p) * t
    return Fraction(math.ceil(x - Fraction(1, 2)) if t < Fraction(1, 2) else math.floor(x + Fraction(1, 2)), 1 << p)


def test_snap_is_eq_1_nearest_and_symmetric():
    for m in range(MAX_TESTED_LEVEL + 2):
        n = 1 << m
        for p in range(m + 1):
            snapped = su.snap(np.arange(n + 1), m, p)
            for a in range(n + 1):
                t, s = Fraction(a, n), Fraction(int(snapped[a]), n)
                assert s == paper_sigma(p, t)
                assert s.denominator <= 1 << p                           # p-dyadic
                assert abs(s - t) <= Fraction(1, 2 << p)                 # nearest
                if p >= 1 or 2 * a != n:                                  # sigma(1 - t) = 1 - sigma(t)
                    assert snapped[n - a] == n - snapped[a]
            assert np.array_equal(su.snap(snapped, m, p), snapped)      # idempotent
            assert np.array_equal(su.snap(np.arange(0, n + 1, n >> p), m, p), np.arange(0, n + 1, n >> p))


def paper_phi(u, levels):
    """Section 3's phi on a barycentric Fraction triple, eq. 1 applied to every coordinate.  The
    paper's edge i is where u_i = 0, our edge e where u_{(e+2) % 3} = 0."""
    for e, p in enumerate(levels):
        if u[(e + 2) % 3] == 0:
            return tuple(paper_sigma(p, x) for x in u)
    return u


def test_level_0_tie_paper_phi_leaves_the_simplex_ours_does_not():
    """SEEDS.md 1.4: at p = 0 the edge midpoint (1/2, 1/2) takes eq. 1's "otherwise" branch for
    both coordinates and goes to (1, 1, 0), which folds triangles.  Ours snaps the edge parameter
    alone; everywhere else the two agree."""
    assert paper_phi((Fraction(1, 2), Fraction(1, 2), Fraction(0)), (0, 1, 1)) == (1, 1, 0)
    for m in range(1, 4):
        n = 1 << m
        lattice = [(i, j) for j in range(n + 1) for i in range(n + 1 - j)]
        for levels in itertools.product(range(m + 1), repeat=3):
            ours = su.phi("tri", np.array(lattice), m, levels)
            for (i, j), (si, sj) in zip(lattice, ours):
                u = (Fraction(i, n), Fraction(j, n), Fraction(n - i - j, n))
                theirs = paper_phi(u, levels)
                mine = (Fraction(int(si), n), Fraction(int(sj), n), Fraction(n - int(si) - int(sj), n))
                midpoint_of_level_0_edge = any(u[(e + 2) % 3] == 0 and levels[e] == 0
                                               and Fraction(1, 2) in u for e in range(3))
                if midpoint_of_level_0_edge:
                    assert sum(theirs) == 2 and sum(mine) == 1 and min(mine) >= 0
                else:
                    assert theirs == mine


@pytest.mark.parametrize("domain", ["quad", "tri"])
def test_level_0_tie_explicitly(domain):
    """m = 1 with every edge at level 0: each edge midpoint goes to its edge's end corner, the
    triangles that touch a corner collapse, and what remains covers the domain: the one
    triangle (tri) or the fan of 4 around the centre (quad)."""
    edges = su.EDGES[domain]
    points, triangles = su.lattice_layout(domain, 1, [0] * edges)
    if domain == "tri":
        assert points.tolist() == [[2, 0], [0, 2], [0, 0]] and triangles.tolist() == [[0, 1, 2]]
    else:
        assert points.tolist() == [[0, 0], [2, 0], [2, 2], [0, 2], [1, 1]]
        assert sorted(map(tuple, triangles.tolist())) == [(0, 1, 4), (0, 4, 3), (1, 2, 4), (4, 2, 3)]
    midpoints = [su.edge_point(domain, e, 1, 1) for e in range(edges)]
    ends = [su.edge_point(domain, (e + 1) % edges, 0, 1) for e in range(edges)]
    assert np.array_equal(su.phi(domain, np.array(midpoints), 1, [0] * edges), np.array(ends))
    # one edge at level 0 among finer ones, at every patch level: still valid (the case that
    # folds with the paper's tie rule)
    for m in range(1, MAX_TESTED_LEVEL + 1):
        check_pattern(domain, m, [0] + [m] * (edges - 1))


def test_exact_levels_from_factors():
    """ceil(log2 f) without floating point: exact where a float log2 is not."""
    f = np.array([1, 2, 3, 4, 5, 63, 64, 65, 2 ** 49, 2 ** 49 + 1, 2 ** 62])
    assert su.ceil_log2(f).tolist() == [(int(x) - 1).bit_length() for x in f]
    assert math.ceil(math.log2(2 ** 49 + 1)) == 49  # why: the float answer is wrong here
    assert su.ceil_log2(2 ** 49 + 1) == 50
    with pytest.raises(ValueError):
        su.ceil_log2([0])


def test_edge_levels_and_records(rng):
    factors = rng.integers(1, 200, size=(500, 4))
    factors[rng.random(500) < 0.1] = 0
    factors[:50, 3] = 0  # PN records (f0, f1, f2, 0) keep their 0
    levels, patch = su.edge_levels(factors, max_level=6)
    alive = factors > 0
    assert np.array_equal(levels[alive], np.minimum([(int(x) - 1).bit_length() for x in factors[alive]], 6))
    assert (levels[~alive] == -1).all()
    assert np.array_equal(patch, levels.max(axis=1))
    record = su.dyadic_factors(factors, max_level=6)
    assert record.dtype == np.int32
    assert np.array_equal(record == 0, factors == 0)
    assert ((record >= np.minimum(factors, 64)) & (record <= np.maximum(2 * factors - 1, 1))).all()
    # rounding up to a power of two commutes with the crack-free max over an edge group
    pairs = factors[:, :2]
    assert np.array_equal(su.dyadic_factors(pairs.max(axis=1)), su.dyadic_factors(pairs).max(axis=1))
    for row, m in zip(record[:60], patch[:60]):
        domain = "tri" if row[3] == 0 else "quad"
        got_m, got_levels = su.record_levels(row, domain)
        assert got_m == (m if row[:su.EDGES[domain]].min() > 0 else -1)


def test_counts_of_records_and_culled():
    records = np.array([[8, 2, 1, 8], [0, 0, 0, 0], [1, 1, 1, 1]])
    vertices, indices = su.counts(records, "quad")
    assert vertices.tolist() == [81 - 6 - 7, 0, 4] and indices.tolist() == [3 * (128 - 13), 0, 6]
    assert su.pattern("quad", [0, 0, 0, 0])[0].shape == (0, 2)
    with pytest.raises(ValueError):
        su.record_levels([3, 4, 4, 4], "quad")
    with pytest.raises(ValueError):
        su.lattice_layout("tri", 2, [3, 0, 0])

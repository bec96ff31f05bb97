"""ESC (Hu et al., GRAPP 2014, section 3): the pattern of a bicubic patch from its candidate masks
alone.  NumPy mirror of kernels/patterns/esc.h; the decisions the paper leaves open are in
docs/esc.md (section 3 here).

**Coarse mesh.**  The patch domain is split into 3 x 3 cells (I, J) (the cells of the control
net), each into two coarse triangles by the diagonal (I, J)-(I+1, J+1): 18 coarse triangles.
The 33 coarse edges (12 horizontal, 12 vertical, 9 diagonal) each carry L candidates at
k / (L+1), k = 1..L, in the edge's canonical direction (+u, +v, and (0,0)->(1,1)); a mask of L
bits per edge says which are inserted (bit k-1: candidate k).  All candidates of level L lie on
the lattice of n = L + 1 steps per coarse edge, m = 3 n per patch side: integers (x, y),
uv = (x, y) / m.  All candidates inserted: the uniform 12 x 12 grid split along the diagonals
(288 triangles at L = 3); none: the 18 coarse triangles.

**Coarse triangle** (apex A, base B0 -> B1, counter-clockwise): the lattice (j, i),
0 <= i <= j <= n, point A + (j - i)/n (B0 - A) + i/n (B1 - A); row j is parallel to the base.
Its 3L bits: left edge A->B0 (bit j-1: row j's point (j, 0)), right edge A->B1 (bit j-1: (j, j)),
base B0->B1 (bit i-1: (n, i)).  Row j (1..L) is *active* when its left or right bit is set; its
interior points (j, 1..j-1) are inserted exactly then (the paper: "the whole row follows its edge
candidate").  Base candidates stand alone.

**Reconstruction** (virtual vertices, rules 1-4 of section 3): the chain of an active row is its
points left to right, a missing end replaced by its *virtual vertex*: the next inserted point
below it on the same edge (the base corners count; rule 1, applied to groups of missing ends
too, where rule 2's "nearest" would fold a chain back over its row: docs/esc.md).  The
base row's chain is its inserted points.  Between consecutive active rows (a missing row merges
two bands), the upper and lower chains are zipped from right to left: advance the side whose next
point lies first along the row ((j - i) / j; on a tie the higher point first, the lower side when
both are one point), a triangle per step; an upper chain whose right end is a virtual vertex
starts after it (that point is the lower chain's start too); triangles with a repeated point are
dropped (rule 3).  Each band is one strip of the cltess.strips convention, lower and upper chain
alternating (even positions lower), a copy of the other side's current point inserted where the
zipper advances one side twice (rule 4), trailing zero-area steps trimmed.  The paper's Fig. 5a example gives
its 3 strips and 8 triangles (tests/test_esc_pattern.py).

**Record** (the int4 of the patch, one int per patch edge e, read by stages 3-5): bits 0..3L-1
the patch edge's boundary mask (its 3 coarse edges, in the edge's canonical direction:
counter-clockwise unless bit 9, REVERSED, is set), bits 10..25 the 16 bits 16e.. of the 21
interior coarse edges' masks (21 L <= 63 bits), bits 26..27 L, bit 28 ALIVE (so an all-zero mask
is still a live patch, factor > 0).  Stage 2 ORs the boundary bits over each edge group
(crack/or_masks.h): both sides store their edge in the same canonical direction, so "the bit
order reversed on flipped edges" happens when a patch stores and reads its own edge.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..strips import STRIP_RESTART, join_strips
from .base import Pattern

#: --max-level default for ESC (Table 1: "Lmax = 3 (16 x 18 triangles per surface)").
DEFAULT_MAX_LEVEL = 3
#: The largest L a record holds (3L boundary bits <= 9, 21 L interior bits <= 64).
MAX_LEVEL = 3
#: Record bits (kernels/patterns/esc.h ESC_*; tests/contracts/test_constants checks them equal).
BOUNDARY_BITS = 0x1FF
REVERSED = 1 << 9
INTERIOR_SHIFT = 10
INTERIOR_BITS = 16
LEVEL_SHIFT = 26
ALIVE = 1 << 28

# --- the 33 coarse edges, canonical directions ---------------------------------------------------

#: (start corner (I, J), end corner) of each coarse edge: horizontal (J, I), vertical (I, J),
#: diagonal (J, I), in that order.
COARSE_EDGES: tuple = tuple([((i, j), (i + 1, j)) for j in range(4) for i in range(3)]
                            + [((i, j), (i, j + 1)) for i in range(4) for j in range(3)]
                            + [((i, j), (i + 1, j + 1)) for j in range(3) for i in range(3)])


def horizontal(i: int, j: int) -> int:
    return 3 * j + i


def vertical(i: int, j: int) -> int:
    return 12 + 3 * i + j


def diagonal(i: int, j: int) -> int:
    return 24 + 3 * j + i


#: Patch edge e (counter-clockwise 0: v=0, 1: u=1, 2: v=1, 3: u=0): its coarse edges in the
#: counter-clockwise order, and whether counter-clockwise runs against their canonical direction.
PATCH_EDGE_COARSE = ((horizontal(0, 0), horizontal(1, 0), horizontal(2, 0)),
                     (vertical(3, 0), vertical(3, 1), vertical(3, 2)),
                     (horizontal(2, 3), horizontal(1, 3), horizontal(0, 3)),
                     (vertical(0, 2), vertical(0, 1), vertical(0, 0)))
PATCH_EDGE_AGAINST = (False, False, True, True)
BOUNDARY_EDGES = frozenset(c for e in PATCH_EDGE_COARSE for c in e)
#: The 21 interior coarse edges, in the order of their bits in the record.
INTERIOR_EDGES = tuple(c for c in range(33) if c not in BOUNDARY_EDGES)


#: Patch edge e's coarse corners (I, J), 0..3: v = 0, u = 1, v = 1, u = 0.
ON_PATCH_EDGE = (lambda p: p[1] == 0, lambda p: p[0] == 3, lambda p: p[1] == 3, lambda p: p[0] == 0)


def pole_edges(collapsed: int) -> tuple:
    """**The pole rule** (docs/esc.md): the coarse edges that run into a collapsed patch edge (bit
    e of `collapsed`: a pole), i.e. with an end on it and not lying on it.  Stage 1 inserts all
    their candidates (criteria/esc_distance.h; kernels/patterns/esc.h esc_pole_edge), so the
    coarse triangles along a pole are the uniform level-L pattern on their sides into the patch."""
    def on(e, p):
        return (collapsed >> e) & 1 and ON_PATCH_EDGE[e](p)
    return tuple(c for c, (start, end) in enumerate(COARSE_EDGES)
                 if any(on(e, start) or on(e, end) for e in range(4))
                 and not any(on(e, start) and on(e, end) for e in range(4)))


def reverse_bits(mask: int, count: int) -> int:
    """The `count` low bits of mask in reverse order."""
    return int(sum(((mask >> k) & 1) << (count - 1 - k) for k in range(count)))


# --- a coarse triangle ---------------------------------------------------------------------------

def triangle_bits(mask: int, level: int) -> tuple[int, int, int]:
    """(left, right, base) of a coarse triangle's 3L-bit mask: left | right << L | base << 2L."""
    full = (1 << level) - 1
    return mask & full, (mask >> level) & full, (mask >> 2 * level) & full


def _next_inserted(j: int, inserted: list[int]) -> int:
    """Row of the virtual vertex of a missing end at row j: the next inserted row below it on the
    same edge (rule 1; for a group of missing ends too: docs/esc.md, the nearest one above would
    fold the chain back over the row)."""
    return min(r for r in inserted if r > j)


@lru_cache(maxsize=None)
def coarse_triangle(level: int, left: int, right: int, base: int):
    """(points, triangles, strips) of a coarse triangle: its inserted lattice points (j, i), its
    triangles as point triples counter-clockwise (for A, B0, B1 counter-clockwise), its strips as
    point lists (one per band, rule 4 copies included)."""
    n = level + 1
    bit = lambda mask, k: (mask >> (k - 1)) & 1  # noqa: E731
    left_rows = [0] + [j for j in range(1, n) if bit(left, j)] + [n]
    right_rows = [0] + [j for j in range(1, n) if bit(right, j)] + [n]
    active = [0] + [j for j in range(1, n) if bit(left, j) or bit(right, j)] + [n]

    def chain(j):
        if j == 0:
            return [(0, 0)]
        if j == n:
            return [(n, 0)] + [(n, i) for i in range(1, n) if bit(base, i)] + [(n, n)]
        first = (j, 0) if bit(left, j) else (_next_inserted(j, left_rows), 0)
        last_row = j if bit(right, j) else _next_inserted(j, right_rows)
        return [first] + [(j, i) for i in range(1, j)] + [(last_row, last_row)]

    def along(point):  # how far along the row from its right end: (j - i) / j, as a fraction
        j, i = point
        return j - i, j

    triangles, strips = [], []
    for a, b in zip(active[:-1], active[1:]):
        upper, lower = chain(a)[::-1], chain(b)[::-1]  # right to left
        u = 1 if upper[0][0] != a else 0  # a shared virtual start: the pair (lower[0], upper[1])
        w = 0
        assert u == 0 or upper[0] == lower[0]  # virtual ends are monotone down the edge
        strip, band = [lower[0], upper[u]], []
        while u < len(upper) - 1 or w < len(lower) - 1:
            if w == len(lower) - 1:
                advance_upper = True
            elif u == len(upper) - 1:
                advance_upper = False
            else:
                pu, qu = along(upper[u + 1])
                pw, qw = along(lower[w + 1])
                if pu * qw != pw * qu:
                    advance_upper = pu * qw < pw * qu
                else:  # a tie: the higher point first, the lower side on the same point
                    advance_upper = upper[u + 1][0] < lower[w + 1][0]
            if advance_upper:
                triangle = (lower[w], upper[u], upper[u + 1])
                u += 1
                if not len(strip) % 2:  # upper points sit at odd positions: copy the lower one
                    strip.append(lower[w])
                strip.append(upper[u])
            else:
                triangle = (lower[w], upper[u], lower[w + 1])
                w += 1
                if len(strip) % 2:
                    strip.append(upper[u])
                strip.append(lower[w])
            if len(set(triangle)) == 3:
                band.append(triangle)
        while len(strip) >= 3 and len(set(strip[-3:])) < 3:  # trailing zero-area steps
            strip.pop()
        if band:
            triangles.extend(band)
            strips.append(strip)
    points = sorted({p for t in triangles for p in t})
    return tuple(points), tuple(triangles), tuple(tuple(s) for s in strips)


def triangle_point_uv(point, apex, b0, b1, n: int) -> tuple[int, int]:
    """Patch lattice point (x, y) of coarse-triangle point (j, i), corners in coarse units."""
    j, i = point
    return tuple(n * apex[c] + (j - i) * (b0[c] - apex[c]) + i * (b1[c] - apex[c]) for c in range(2))


# --- counts from the masks alone: one table row per coarse-triangle mask --------------------------

#: First row of level L in COUNT_TABLE (levels 0..3 have 1, 8, 64, 512 masks of 3L bits).
TABLE_START = (0, 1, 9, 73)
TABLE_ROWS = 585


@lru_cache(maxsize=None)
def count_table() -> np.ndarray:
    """(585, 2) int: (triangles, strip indices with one restart per strip) of coarse_triangle for
    every level L and 3L-bit mask (row TABLE_START[L] + mask).  Stage 3 sums it over the 18 coarse
    triangles instead of walking them (kernels/patterns/esc_counts.h, generated from this)."""
    rows = []
    for level in range(MAX_LEVEL + 1):
        for mask in range(1 << 3 * level):
            _, triangles, strip_list = coarse_triangle(level, *triangle_bits(mask, level))
            rows.append((len(triangles), sum(len(s) + 1 for s in strip_list)))
    return np.array(rows, np.int64)


#: A strip point (j, i) of a coarse triangle in the strip table: j * STRIP_POINT_BASE + i; a
#: restart: STRIP_TABLE_RESTART.
STRIP_POINT_BASE = 5
STRIP_TABLE_RESTART = 255


@lru_cache(maxsize=None)
def strip_table() -> tuple[np.ndarray, np.ndarray]:
    """(points (N,) uint8, first (585,) int): every row's strips (coarse_triangle's, rule-4 copies
    included) as coded points, each strip followed by STRIP_TABLE_RESTART, row r's from first[r]
    (count_table()[r, 1] of them).  Stage 5 maps them through the patch's vertex numbering
    instead of zipping the bands again (kernels/patterns/esc.h esc_table_strips)."""
    points, first = [], []
    for level in range(MAX_LEVEL + 1):
        for mask in range(1 << 3 * level):
            first.append(len(points))
            for strip in coarse_triangle(level, *triangle_bits(mask, level))[2]:
                points.extend([j * STRIP_POINT_BASE + i for j, i in strip] + [STRIP_TABLE_RESTART])
    return np.array(points, np.uint8), np.array(first, np.int64)


@lru_cache(maxsize=None)
def triangle_table() -> tuple[np.ndarray, np.ndarray]:
    """(points (N,) uint8, first (585,) int): every row's triangles (coarse_triangle's, in order)
    as 3 coded points each, row r's from first[r] (3 count_table()[r, 0] of them).  Stage 5's
    triangle list maps them through the patch's vertex numbering (esc.h esc_table_triangles)."""
    points, first = [], []
    for level in range(MAX_LEVEL + 1):
        for mask in range(1 << 3 * level):
            first.append(len(points))
            for triangle in coarse_triangle(level, *triangle_bits(mask, level))[1]:
                points.extend(j * STRIP_POINT_BASE + i for j, i in triangle)
    return np.array(points, np.uint8), np.array(first, np.int64)


def count_table_header() -> str:
    """The text of kernels/patterns/esc_counts.h (tests/test_esc_counts.py checks the file equals it)."""
    table = count_table()
    points, first = strip_table()
    triangle_points, triangle_first = triangle_table()

    def lines(values):
        values = [str(int(v)) for v in values]
        return ",\n".join("    " + ", ".join(values[k:k + 24]) for k in range(0, len(values), 24))

    def rows(column):
        return lines(table[:, column])

    return (
        "/* Generated by cltess/patterns/esc.py count_table_header(): do not edit; regenerate with\n"
        " *   python -c \"from cltess.patterns import esc; esc.write_count_table_header()\"\n"
        " * Per coarse-triangle mask (row ESC_TABLE_START[L] + left | right << L | base << 2L): its\n"
        " * triangles and its strip indices (one restart per strip), as esc_coarse_triangle walks them;\n"
        " * and its strips' and triangles' points. */\n"
        "#ifndef CLTESS_PATTERNS_ESC_COUNTS_H\n#define CLTESS_PATTERNS_ESC_COUNTS_H\n\n"
        f"__constant int ESC_TABLE_START[4] = {{{', '.join(map(str, TABLE_START))}}};\n\n"
        f"__constant uchar ESC_TABLE_TRIANGLES[{TABLE_ROWS}] = {{\n{rows(0)}}};\n\n"
        f"__constant uchar ESC_TABLE_STRIP_INDICES[{TABLE_ROWS}] = {{\n{rows(1)}}};\n\n"
        "/* Each row's strip points j * ESC_STRIP_POINT_BASE + i, ESC_STRIP_TABLE_RESTART after each strip,\n"
        " * from ESC_TABLE_STRIP_FIRST[row] (esc.py strip_table). */\n"
        f"#define ESC_STRIP_POINT_BASE {STRIP_POINT_BASE}\n#define ESC_STRIP_TABLE_RESTART {STRIP_TABLE_RESTART}\n\n"
        f"__constant ushort ESC_TABLE_STRIP_FIRST[{TABLE_ROWS}] = {{\n{lines(first)}}};\n\n"
        f"__constant uchar ESC_TABLE_STRIP_POINTS[{len(points)}] = {{\n{lines(points)}}};\n\n"
        "/* Each row's triangles, 3 coded points each, from ESC_TABLE_TRIANGLE_FIRST[row] (esc.py triangle_table). */\n"
        f"__constant ushort ESC_TABLE_TRIANGLE_FIRST[{TABLE_ROWS}] = {{\n{lines(triangle_first)}}};\n\n"
        f"__constant uchar ESC_TABLE_TRIANGLE_POINTS[{len(triangle_points)}] = {{\n{lines(triangle_points)}}};\n\n"
        "#endif\n")


def write_count_table_header() -> None:
    from ..backends.opencl.programs import kernel_dir  # noqa: PLC0415
    (kernel_dir() / "patterns" / "esc_counts.h").write_text(count_table_header())


def collapsed_sides(triangle, collapsed: int) -> tuple[bool, bool]:
    """(left, right) side of a COARSE_TRIANGLES row on a collapsed patch edge (bit e of collapsed)."""
    _, apex, b0, b1, *_ = triangle
    on = lambda p, q: any((collapsed >> e) & 1 and ON_PATCH_EDGE[e](p) and ON_PATCH_EDGE[e](q)  # noqa: E731
                          for e in range(4))
    return on(apex, b0), on(apex, b1)


def counts(level: int, edge_masks, collapsed: int = 0) -> tuple[int, int] | None:
    """(triangles, strip indices) of a patch from the table alone (kernels/patterns/esc.h esc_counts):
    each coarse triangle's row, less, for a side on a collapsed edge, its segments there (popcount
    of the side's mask + 1: each is one triangle's side, and those triangles have two points in one
    and are left out).  None where two adjacent patch edges are collapsed (their shared corner
    numbers as one edge's point only: the device walks those patches)."""
    if collapsed & (((collapsed << 1) | (collapsed >> 3)) & 15):
        return None
    table = count_table()
    triangles = strip_indices = 0
    for triangle in COARSE_TRIANGLES:
        _, _, _, _, left, right, base = triangle
        masks = [local_mask(edge_masks, e, level) for e in (left, right, base)]
        row = table[TABLE_START[level] + (masks[0] | masks[1] << level | masks[2] << 2 * level)]
        triangles += int(row[0])
        strip_indices += int(row[1])
        for side, on in enumerate(collapsed_sides(triangle, collapsed)):
            triangles -= (bin(masks[side]).count("1") + 1) if on else 0
    return triangles, strip_indices


# --- a patch -------------------------------------------------------------------------------------

#: The 18 coarse triangles: (cell (I, J), apex, B0, B1, left edge, right edge, base edge) with each
#: edge as (coarse edge, whether A->B0 / A->B1 / B0->B1 runs against its canonical direction).
def _coarse_triangles():
    out = []
    for j in range(3):
        for i in range(3):
            c00, c10, c11, c01 = (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)
            out.append(((i, j), c10, c11, c00, (vertical(i + 1, j), False), (horizontal(i, j), True),
                        (diagonal(i, j), True)))
            out.append(((i, j), c01, c00, c11, (vertical(i, j), True), (horizontal(i, j + 1), False),
                        (diagonal(i, j), False)))
    return tuple(out)


COARSE_TRIANGLES = _coarse_triangles()


def local_mask(edge_masks, edge, level: int) -> int:
    coarse, against = edge
    mask = int(edge_masks[coarse])
    return reverse_bits(mask, level) if against else mask


def patch_mesh(level: int, edge_masks, collapsed: int = 0):
    """(lattice points (V, 2) int in the device's vertex order, triangles (T, 3) local indices,
    strips uint32 restart-separated local indices) of a patch at level L with the 33 coarse edges'
    masks (canonical directions).  collapsed: bit e for a collapsed patch edge (its points are one
    position): triangles with a side on it are left out, as the other patterns do.  Read-only
    arrays, shared by the patches with the same record (``_patch_mesh``)."""
    return _patch_mesh(int(level), tuple(int(mask) for mask in edge_masks), int(collapsed))


@lru_cache(maxsize=4096)  # a level-3 record's mesh is about 10 kB
def _patch_mesh(level: int, edge_masks: tuple, collapsed: int):
    n, m = level + 1, 3 * (level + 1)
    tri_points, tris, strips = [], [], []
    for cell, apex, b0, b1, left, right, base in COARSE_TRIANGLES:
        masks = [local_mask(edge_masks, e, level) for e in (left, right, base)]
        points, triangles, strip_list = coarse_triangle(level, *masks)
        to_lattice = lambda p: triangle_point_uv(p, apex, b0, b1, n)  # noqa: E731
        tris.extend([tuple(to_lattice(p) for p in t) for t in triangles])
        strips.extend([[to_lattice(p) for p in s] for s in strip_list])
        tri_points.extend(to_lattice(p) for p in points)
    order = vertex_order(level, edge_masks)
    index = {p: k for k, p in enumerate(order)}
    on_edge = [lambda x, y: y == 0, lambda x, y: x == m, lambda x, y: y == m, lambda x, y: x == 0]
    first_corner = [(0, 0), (m, 0), (m, m), (0, m)]

    def remap(p):  # a collapsed edge: every point is its first corner
        for e in range(4):
            if (collapsed >> e) & 1 and on_edge[e](*p):
                return index[first_corner[e]]
        return index[p]

    triangles = np.array([[remap(p) for p in t] for t in tris], np.int64).reshape(-1, 3)
    keep = (triangles[:, 0] != triangles[:, 1]) & (triangles[:, 1] != triangles[:, 2]) & (triangles[:, 0] != triangles[:, 2])
    strip_indices = join_strips([[remap(p) for p in s] for s in strips])
    mesh = np.array(order, np.int64).reshape(-1, 2), triangles[keep], strip_indices
    for array in mesh:
        array.flags.writeable = False
    return mesh


def inserted_points(level: int, edge_masks) -> set:
    """The inserted lattice points (x, y) of a patch (corners and coarse corners included)."""
    n = level + 1
    out = set()
    for cell, apex, b0, b1, left, right, base in COARSE_TRIANGLES:
        masks = [local_mask(edge_masks, e, level) for e in (left, right, base)]
        out.update(triangle_point_uv(p, apex, b0, b1, n) for p in coarse_triangle(level, *masks)[0])
    return out


def vertex_order(level: int, edge_masks) -> list:
    """The device's vertex layout: the ring (edge e's inserted points counter-clockwise from its
    first corner, its last corner excluded), then the inserted interior points row by row."""
    m = 3 * (level + 1)
    present = inserted_points(level, edge_masks)
    ring = [(k, 0) for k in range(m)] + [(m, k) for k in range(m)] + \
           [(m - k, m) for k in range(m)] + [(0, m - k) for k in range(m)]
    inside = [(x, y) for y in range(1, m) for x in range(1, m)]
    return [p for p in ring if p in present] + [p for p in inside if p in present]


# --- the record ------------------------------------------------------------------------------------

def pack(level: int, edge_masks, reversed_edges=(False, False, False, False)) -> np.ndarray:
    """The int4 record of a patch (module docstring): level, the 33 masks (canonical directions),
    and for each patch edge whether its boundary bits are stored against counter-clockwise."""
    if not 0 <= level <= MAX_LEVEL:
        raise ValueError(f"ESC level {level} outside 0..{MAX_LEVEL}")
    interior = 0
    for k, c in enumerate(INTERIOR_EDGES):
        interior |= int(edge_masks[c]) << (k * level)
    record = np.zeros(4, np.int64)
    for e in range(4):
        ccw = 0
        for s, c in enumerate(PATCH_EDGE_COARSE[e]):
            mask = int(edge_masks[c])
            ccw |= (reverse_bits(mask, level) if PATCH_EDGE_AGAINST[e] else mask) << (s * level)
        boundary = reverse_bits(ccw, 3 * level) if reversed_edges[e] else ccw
        chunk = (interior >> (INTERIOR_BITS * e)) & ((1 << INTERIOR_BITS) - 1)
        record[e] = (boundary | (REVERSED if reversed_edges[e] else 0) | chunk << INTERIOR_SHIFT
                     | level << LEVEL_SHIFT | ALIVE)
    return record.astype(np.int32)


def unpack(record) -> tuple[int, np.ndarray]:
    """(level, the 33 masks in canonical directions) of a record (its crack-free boundary bits)."""
    record = [int(r) for r in record]
    level = (record[0] >> LEVEL_SHIFT) & 3
    full = (1 << level) - 1
    masks = np.zeros(33, np.int64)
    interior = 0
    for e in range(4):
        interior |= ((record[e] >> INTERIOR_SHIFT) & ((1 << INTERIOR_BITS) - 1)) << (INTERIOR_BITS * e)
    for k, c in enumerate(INTERIOR_EDGES):
        masks[c] = (interior >> (k * level)) & full
    for e in range(4):
        boundary = record[e] & BOUNDARY_BITS & ((1 << 3 * level) - 1)
        ccw = reverse_bits(boundary, 3 * level) if record[e] & REVERSED else boundary
        for s, c in enumerate(PATCH_EDGE_COARSE[e]):
            mask = (ccw >> (s * level)) & full
            masks[c] = reverse_bits(mask, level) if PATCH_EDGE_AGAINST[e] else mask
    return level, masks


def _collapsed(f) -> tuple[np.ndarray, int]:
    """(the record's absolute values, bit e for a collapsed edge e: stored negated by stage 2)."""
    f = np.asarray(f, np.int64)
    return np.abs(f), int(sum(1 << e for e in range(4) if f[e] < 0))


def layout(f) -> tuple[np.ndarray, np.ndarray]:
    """The Pattern mirror: (uv (V, 2), triangles (T, 3)) of a record (a collapsed edge's slot
    negated); 0: nothing (culled)."""
    record, collapsed = _collapsed(f)
    if record[0] == 0:
        return np.zeros((0, 2)), np.zeros((0, 3), np.int64)
    level, masks = unpack(record)
    points, triangles, _ = patch_mesh(level, masks, collapsed)
    return points / (3.0 * (level + 1)), triangles


def strips(f) -> np.ndarray:
    """The record's strips (uint32, restart-separated, local indices); expand_strips(...,
    drop_degenerate=True) gives layout(f)'s triangles."""
    record, collapsed = _collapsed(f)
    if record[0] == 0:
        return np.zeros(0, np.uint32)
    level, masks = unpack(record)
    return patch_mesh(level, masks, collapsed)[2]


def strip_indices(f) -> np.ndarray:
    """The record's strips as the device emits them (kernels/patterns/esc.h pattern_strips): local
    numbers, each strip followed by one restart marker (so patches concatenate; the host drops the
    last marker), int64."""
    local = strips(f).astype(np.int64)
    return np.append(local, np.int64(STRIP_RESTART)) if len(local) else local


def _stage1(patches, tolerance, max_level, max_factor):
    from ..esc.masks import esc_stage  # noqa: PLC0415 (esc.masks imports this module)
    return esc_stage(patches, tolerance, max_level, max_factor)


def _stage1_one_level(patches, tolerance, max_level, max_factor):
    from ..esc.masks import esc_stage  # noqa: PLC0415
    return esc_stage(patches, tolerance, max_level, max_factor, levels=np.full(len(patches), min(max_level, MAX_LEVEL)))


ESC = Pattern("esc", "quad", 4, "patterns/esc.h", layout, crack="crack/or_masks.h", primitive="strips",
              stage1=((("PATTERN_ESC", 1),), _stage1), strips=strip_indices)

#: ESC with one level per run (every patch at L = max level, as before per-patch levels): not in
#: the registry; bench/esc.py adds it to PATTERNS to measure what per-patch levels change.
ESC_ONE_LEVEL = Pattern("esc_one_level", "quad", 4, "patterns/esc.h", layout, crack="crack/or_masks.h",
                        primitive="strips", stage1=((("PATTERN_ESC", 1), ("ESC_ONE_LEVEL", 1)), _stage1_one_level),
                        strips=strip_indices)

#: ESC as before the tables (kernels/patterns/esc_walk.h): stage 3's counts and stage 5's triangles
#: and strips walked band by band; not in the registry: bench/esc.py --stages adds it to PATTERNS.
ESC_WALK = Pattern("esc_walk", "quad", 4, "patterns/esc_walk.h", layout, crack="crack/or_masks.h",
                          primitive="strips", stage1=((("PATTERN_ESC", 1),), _stage1), strips=strip_indices,
                          counts_walk=True)

"""ESC's stage 3 counts and stage 5 triangles and strips from tables of the coarse-triangle masks
(kernels/patterns/esc_counts.h, generated from cltess/patterns/esc.py): the header is the
generator's output, the tables are the mirror's coarse triangles, the table sums equal the walked
pattern for every collapsed-edge combination, and on the device the tables give bitwise what the
walk gives (docs/esc.md "Counts and emission from tables")."""
from types import SimpleNamespace

import numpy as np
import pyopencl.array as cl_array

from cltess.backends.opencl.programs import kernel_dir
from cltess.backends.opencl.strips import emit_strips, strip_offsets
from cltess.patterns import esc


def test_the_header_is_the_generated_table():
    text = (kernel_dir() / "patterns" / "esc_counts.h").read_text()
    assert text == esc.count_table_header(), "regenerate: python -c \"from cltess.patterns import esc; esc.write_count_table_header()\""


def test_the_table_is_the_walk_for_every_mask():
    """Row L, mask: the triangles and the strip indices (one restart per strip) of
    coarse_triangle, for all 585 masks of L = 0..3; the all-ones row of L is the uniform (L+1)^2."""
    table = esc.count_table()
    assert table.shape == (esc.TABLE_ROWS, 2) and esc.TABLE_START == (0, 1, 9, 73)
    for level in range(4):
        for mask in range(1 << 3 * level):
            _, triangles, strips = esc.coarse_triangle(level, *esc.triangle_bits(mask, level))
            assert tuple(table[esc.TABLE_START[level] + mask]) == (len(triangles), sum(len(s) + 1 for s in strips))
        assert table[esc.TABLE_START[level] + (1 << 3 * level) - 1, 0] == (level + 1) ** 2
    assert table.max() < 256  # uchar in the header


def random_masks(rng, level):
    density = rng.choice([0.0, 0.2, 0.5, 0.8, 1.0])
    return (rng.random((33, 3)) < density)[:, :level] @ (1 << np.arange(level)) if level else np.zeros(33, np.int64)


def test_table_counts_equal_the_mesh_for_every_collapsed_combination(rng):
    """esc.counts (the table, less the segments on collapsed sides) equals patch_mesh's triangles
    and strips for every combination of collapsed edges but adjacent pairs, where it declines."""
    adjacent = {c for c in range(16) if c & ((c << 1) | (c >> 3)) & 15}
    assert adjacent == {3, 6, 7, 9, 11, 12, 13, 14, 15}
    for _ in range(60):
        level = int(rng.integers(0, 4))
        masks = random_masks(rng, level)
        for collapsed in range(16):
            got = esc.counts(level, masks, collapsed)
            if collapsed in adjacent:
                assert got is None
                continue
            _, triangles, strips = esc.patch_mesh(level, masks, collapsed)
            assert got == (len(triangles), len(strips) + 1 if len(strips) else 0), (level, collapsed)


def records_with_every_collapse(rng, count):
    """Random records (levels 0..3, every density, either stored direction, some culled) with
    every combination of collapsed edges (negated slots)."""
    records = np.zeros((count, 4), np.int32)
    for p in range(count):
        level = int(rng.integers(0, 4))
        records[p] = esc.pack(level, random_masks(rng, level), tuple(rng.random(4) < 0.5))
        records[p] *= np.where((p % 16 >> np.arange(4)) & 1, -1, 1).astype(np.int32)
    records[rng.random(count) < 0.05] = 0
    return records


def test_device_counts_equal_the_emission_and_the_mirror(tessellator, rng):
    """Stage 3's index and strip counts (the table) equal the mirror's, and stages 5 emit exactly
    that many (the walk), for 320 random records with every collapsed-edge combination."""
    factors = records_with_every_collapse(rng, 320)
    count = len(factors)
    device = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(device, [(esc.ESC, 0, count)])
    assert np.array_equal(np.diff(index_offsets.get()), [3 * len(esc.layout(f)[1]) for f in factors])
    part = SimpleNamespace(pattern=esc.ESC, base=0, count=count)
    offsets, _ = strip_offsets(tessellator, device, [part])
    assert np.array_equal(np.diff(offsets.get()), [len(esc.strip_indices(f)) for f in factors])
    plan = SimpleNamespace(num_patches=count, num_strip_indices=int(offsets[count].get()), strip_offsets=offsets,
                           parts=[part], factors=device, vertex_offsets=vertex_offsets)
    strips, _ = emit_strips(tessellator, plan, 0, count)
    assert len(strips) == int(offsets[count].get()) - 1 and (strips != 0xFFFFFFFF).sum() > 0
    total = int(index_offsets[count].get())
    triangles, _ = tessellator.stage_indices(device, vertex_offsets, index_offsets, (0, total), (0, count), kind=esc.ESC)
    firsts = vertex_offsets.get()
    expected = np.concatenate([esc.layout(f)[1] + firsts[p] for p, f in enumerate(factors)])
    assert np.array_equal(triangles.get().reshape(-1, 3), expected)


def test_the_strip_table_decodes_to_the_strips():
    """Row r's coded points, split at the restarts, are coarse_triangle's strips in order."""
    points, first = esc.strip_table()
    table = esc.count_table()
    row = 0
    for level in range(4):
        for mask in range(1 << 3 * level):
            coded = points[first[row]:first[row] + table[row, 1]]
            strips = esc.coarse_triangle(level, *esc.triangle_bits(mask, level))[2]
            expected = [c for s in strips for c in [j * esc.STRIP_POINT_BASE + i for j, i in s] + [esc.STRIP_TABLE_RESTART]]
            assert coded.tolist() == expected
            row += 1
    assert first[-1] + table[-1, 1] == len(points) and len(points) < 1 << 16  # ushort offsets


def test_the_triangle_table_decodes_to_the_triangles():
    points, first = esc.triangle_table()
    table = esc.count_table()
    row = 0
    for level in range(4):
        for mask in range(1 << 3 * level):
            coded = points[first[row]:first[row] + 3 * table[row, 0]].reshape(-1, 3)
            triangles = esc.coarse_triangle(level, *esc.triangle_bits(mask, level))[1]
            assert coded.tolist() == [[j * esc.STRIP_POINT_BASE + i for j, i in t] for t in triangles]
            row += 1
    assert len(points) == 3 * table[:, 0].sum() < 1 << 16


def test_device_table_strips_and_counts_equal_the_walk(tessellator, rng):
    """The table path (esc) against the walk (esc.ESC_WALK: counts, triangles and strips zipped
    band by band) on the device: bitwise the same counts, strips and triangles."""
    from cltess.patterns import PATTERNS
    PATTERNS.setdefault(esc.ESC_WALK.name, esc.ESC_WALK)
    factors = records_with_every_collapse(rng, 320)
    count = len(factors)
    device = cl_array.to_device(tessellator.queue, factors)
    results = []
    for pattern in (esc.ESC, esc.ESC_WALK):
        vertex_offsets, index_offsets, _ = tessellator.stage_counts(device, [(pattern, 0, count)])
        part = SimpleNamespace(pattern=pattern, base=0, count=count)
        offsets, _ = strip_offsets(tessellator, device, [part])
        plan = SimpleNamespace(num_patches=count, num_strip_indices=int(offsets[count].get()), strip_offsets=offsets,
                               parts=[part], factors=device, vertex_offsets=vertex_offsets)
        strips, _ = emit_strips(tessellator, plan, 0, count)
        middle, _ = emit_strips(tessellator, plan, 37, 211)
        total = int(index_offsets[count].get())
        triangles, _ = tessellator.stage_indices(device, vertex_offsets, index_offsets, (0, total), (0, count),
                                                 kind=pattern)
        results.append((index_offsets.get(), offsets.get(), strips, middle, triangles.get()))
    for table, walk in zip(*results):
        assert np.array_equal(table, walk)

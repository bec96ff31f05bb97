"""Random final factors for each domain, covering every branch of the patterns (uniform,
transitions, all 1, culled), and per registered pattern."""
from __future__ import annotations

import numpy as np

from cltess.patterns.semi_uniform import dyadic_factors


def random_factors(rng, count, high=70):
    """(count, 4) quad factors: random (transitions), uniform, culled (0), all 1."""
    factors = rng.integers(1, high, size=(count, 4)).astype(np.int32)
    uniform = rng.random(count) < 0.3
    factors[uniform, 2], factors[uniform, 3] = factors[uniform, 0], factors[uniform, 1]
    factors[rng.random(count) < 0.1] = 0
    factors[rng.random(count) < 0.05] = 1
    return factors


def random_triangle_factors(rng, count, high=40):
    """(count, 4) PN factors (f0, f1, f2, 0): random (often two transition edges), uniform, one
    transition edge (the other two at the core factor), all 1, culled (0)."""
    factors = np.zeros((count, 4), np.int32)
    factors[:, :3] = rng.integers(1, high, size=(count, 3))
    top = factors[:, :3].max(axis=1)
    pattern = rng.integers(0, 3, count)
    factors[pattern == 1, :3] = top[pattern == 1, None]
    keep = rng.integers(0, 3, count)  # pattern 2: only this edge may stay below the core factor
    for e in range(3):
        raise_it = (pattern == 2) & (keep != e)
        factors[raise_it, e] = top[raise_it]
    factors[rng.random(count) < 0.05, :3] = 1
    factors[rng.random(count) < 0.1] = 0
    return factors


def random_fixed_factors(rng, count, high=40):
    """(count, 4) 16.16 fixed-point triangle factors (f0, f1, f2, 0) in [1, high]: three
    different, two equal (each pair), all equal, odd whole numbers, all 1, culled (0)."""
    from cltess.patterns.fractional import FIXED_ONE, to_fixed
    factors = np.zeros((count, 4), np.int32)
    factors[:, :3] = to_fixed(rng.uniform(1.0, high, size=(count, 3)))
    shape = rng.integers(0, 6, count)
    for pair in range(3):  # shapes 0-2: edges pair and pair+1 equal
        equal = shape == pair
        factors[equal, (pair + 1) % 3] = factors[equal, pair]
    factors[shape == 3, 1:3] = factors[shape == 3, 0:1]
    whole = rng.random(count) < 0.2
    factors[whole, :3] = (2 * (factors[whole, :3] // (2 * FIXED_ONE)) + 1) * FIXED_ONE
    factors[rng.random(count) < 0.05, :3] = FIXED_ONE
    # a level function's records (edge = the larger of its ends' phi, the hint in slot 3; docs/sd2.md
    # section 5), most in the tie zone (tip edges less than 1.0 above the base), ties included
    from cltess.patterns.sd2 import HINT_SHIFT
    for p in np.flatnonzero(rng.random(count) < 0.3):
        top = int(rng.integers(FIXED_ONE, high * FIXED_ONE))
        phi = [top, max(top - int(rng.choice([0, rng.integers(0, FIXED_ONE), rng.integers(0, 3 * FIXED_ONE)])), FIXED_ONE),
               max(top - int(rng.integers(0, 4 * FIXED_ONE)), FIXED_ONE)]
        if rng.random() < 0.3:  # the base corners tied with each other (a plateau left by the tip)
            phi[2] = phi[1]
        elif rng.random() < 0.3:  # an odd plateau of 3 or more left by two corners (docs/sd2.md section 5,
            plateau = int(2 * rng.integers(1, max(high // 2, 2)) + 1) * FIXED_ONE  # "Seventh pass": lam sharpened)
            d = int(rng.integers(0, FIXED_ONE // 4))
            phi = [plateau + d, plateau + int(rng.integers(0, d + 1)), plateau]
        phi = [phi[k] for k in rng.permutation(3)]
        m = int(np.argmin(phi))
        factors[p] = [max(phi[e], phi[(e + 1) % 3]) for e in range(3)] + [(phi[m] << HINT_SHIFT) | m]
    factors[rng.random(count) < 0.1] = 0
    return factors


def random_esc_records(rng, count):
    """(count, 4) ESC records (cltess/patterns/esc.py): levels 0..3, masks of every density,
    either stored direction, some culled (0), some with a collapsed edge (negated slot)."""
    from cltess.patterns.esc import pack
    records = np.zeros((count, 4), np.int32)
    for p in range(count):
        level = int(rng.integers(0, 4))
        masks = (rng.random((33, 3)) < rng.choice([0.0, 0.3, 0.7, 1.0]))[:, :level] @ (1 << np.arange(level))
        records[p] = pack(level, masks if level else np.zeros(33, np.int64), tuple(rng.random(4) < 0.5))
    records[rng.random(count) < 0.1] = 0
    collapsed = (rng.random(count) < 0.1) & (records[:, 0] > 0)
    records[collapsed, 0] = -records[collapsed, 0]
    return records


def random_pattern_factors(rng, pattern, count, high=40):
    """Random final factors for a registered pattern (by its domain); a dyadic pattern's rounded
    up to powers of two as stage 1 does (levels up to ceil(log2 high)); ESC's records."""
    if pattern.fixed_point:
        return random_fixed_factors(rng, count, high)
    if pattern.name == "esc":
        return random_esc_records(rng, count)
    factors = {"quad": random_factors, "tri": random_triangle_factors}[pattern.domain](rng, count, high)
    return dyadic_factors(factors, max_level=30) if pattern.dyadic else factors


def offsets(counts) -> np.ndarray:
    """Stage 3's offsets of these counts: 0, then their running sums (the last one the total)."""
    return np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)


def device_counts_and_indices(tessellator, pattern, factors, work=None):
    """Stages 3 and 5 of ``pattern`` on the device for ``factors``, their offsets checked equal
    to the mirror's layouts (``pattern.layout``).  Returns (layouts, each patch's first vertex,
    the (T, 3) triangles of the whole batch, global vertex numbers)."""
    import pyopencl.array as cl_array

    count = len(factors)
    device_factors = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(device_factors, [(pattern, 0, count)])
    layouts = [pattern.layout(f) for f in factors]
    firsts = offsets([len(uv) for uv, _ in layouts])
    assert np.array_equal(vertex_offsets.get(), firsts)
    assert np.array_equal(index_offsets.get(), offsets([3 * len(t) for _, t in layouts]))
    total = int(index_offsets[count].get())
    triangles, _ = tessellator.stage_indices(device_factors, vertex_offsets, index_offsets, (0, total), (0, count),
                                             kind=pattern, work=work)
    return layouts, firsts, triangles.get().reshape(-1, 3)

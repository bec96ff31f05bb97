"""Stage 2 (kernels/crack_free.cl, Tessellator.stage_crack_free) against reference.crack_free_factors."""
import numpy as np
import pyopencl.array as cl_array

from cltess import reference
from cltess.adjacency import EdgeGroups, edge_groups
from support import closed_torus_grid


def device_crack_free(tessellator, factors, groups):
    final, _ = tessellator.stage_crack_free(cl_array.to_device(tessellator.queue, factors), groups)
    return final.get()


def test_crack_free_matches_reference_on_a_closed_grid(tessellator, rng):
    scene = closed_torus_grid(rng, 12, 8)
    groups = edge_groups(scene.patches)
    factors = rng.integers(1, 40, size=(scene.num_patches, 4)).astype(np.int32)
    factors[rng.random(scene.num_patches) < 0.2] = 0  # culled patches
    got = device_crack_free(tessellator, factors, groups)
    assert np.array_equal(got, reference.crack_free_factors(factors, groups.group_of, groups.group_start, groups.members))
    shared = groups.group_sizes[groups.group_of] == 2
    assert (got.reshape(-1) >= factors.reshape(-1)).all()
    # Every shared edge of two visible patches now carries the same factor on both sides.
    for g in np.nonzero(groups.group_sizes == 2)[0]:
        a, b = groups.members[groups.group_start[g]:groups.group_start[g + 1]]
        if factors.reshape(-1)[a] and factors.reshape(-1)[b]:
            assert got.reshape(-1)[a] == got.reshape(-1)[b]
    assert shared.all()


def test_crack_free_takes_the_max_over_random_groups_of_any_size(tessellator, rng):
    """Non-manifold groups (3+ patch edges) and singletons, random CSR partitions."""
    edges = 4 * 700
    members = rng.permutation(edges).astype(np.int32)
    cuts = np.sort(rng.choice(np.arange(1, edges), size=900, replace=False))
    group_start = np.concatenate([[0], cuts, [edges]]).astype(np.int32)
    group_of = np.empty(edges, np.int32)
    for g in range(len(group_start) - 1):
        group_of[members[group_start[g]:group_start[g + 1]]] = g
    groups = EdgeGroups(group_of, group_start, members, np.zeros(edges, bool), 0, 0, 0, 0, 0, 0)
    factors = rng.integers(0, 64, size=(edges // 4, 4)).astype(np.int32)
    got = device_crack_free(tessellator, factors, groups)
    assert np.array_equal(got, reference.crack_free_factors(factors, group_of, group_start, members))

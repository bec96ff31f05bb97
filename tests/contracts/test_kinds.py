"""Every registered kind (cltess.kinds.KINDS), against its NumPy reference: stage 1 on random
input, stage 4 against the surface at the vertices' parameters, and on a closed surface of the
kind: shared boundary points bitwise equal (watertight after exact welding) and the error
bound, measured densely inside every triangle."""
import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess.criteria import ObjectSpace
from cltess.kinds import KINDS
from cltess.request import BOUNDS, Request
from support import bound_ratio, weld_exact
from support.kinds import closed_scene, random_source


@pytest.fixture(params=KINDS, ids=[k.name for k in KINDS])
def kind(request):
    return request.param


def device_factors(tessellator, kind, source, eps, max_factor=64):
    count = len(source)
    data = tessellator.upload(kind, source)
    factors = cl_array.empty(tessellator.queue, (count, 4), np.int32)
    flags = cl_array.empty(tessellator.queue, count, np.int32)
    tessellator.stage_factors_of(kind, data, ObjectSpace(eps), max_factor, factors, flags, 0)
    return data, factors, flags


@pytest.mark.parametrize("eps", [0.01, 0.3])
def test_factors_and_flags_equal_the_reference(tessellator, rng, kind, eps):
    source = random_source(rng, kind, 1000)
    _, factors, flags = device_factors(tessellator, kind, source, eps)
    _, expected, expected_flags = kind.reference_factors(source, ObjectSpace(eps), 64)
    got = factors.get()
    differs = (got != expected).any(axis=1)
    # float32 against float64: a factor may round the other way where 1/step is an integer.
    assert differs.sum() <= max(2, len(got) // 200) and np.abs(got - expected).max() <= 1
    assert np.array_equal(flags.get()[~differs], expected_flags[~differs])


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
def test_vertices_are_the_surface_at_their_parameters(tessellator, rng, kind, fd):
    scene, eps = closed_scene(rng, kind)
    tess = tessellator.tessellate(scene, eps=eps, forward_differencing=fd)
    host = kind.prepare(scene)
    controls, _, _ = kind.reference_factors(host.source, ObjectSpace(eps), 64)
    base = sum(k.count(scene) for k in KINDS[:KINDS.index(kind)])
    ids = tess.patch_ids - base
    uv = tess.uv.astype(float)
    positions = kind.surface.surface_points(controls, ids, uv[:, 0], uv[:, 1])
    size = np.ptp(positions, axis=0).max()
    assert np.abs(tess.positions - positions).max() < 2e-5 * size
    for p in np.unique(ids)[::7]:
        at = ids == p
        _, normals = kind.surface.evaluate(controls[p], uv[at, 0], uv[at, 1])
        assert (np.einsum("nc,nc->n", normals, tess.normals[at]) > 0.999).all()


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
def test_closed_surfaces_are_watertight_and_within_the_bound(tessellator, rng, kind, fd):
    scene, eps = closed_scene(rng, kind)
    tess = tessellator.tessellate(scene, Request.of(eps=eps, forward_differencing=fd))
    assert len(np.unique(tess.factors[:, :kind.edges])) > 1  # neighbours with different factors met
    assert tess.stats["saturated"] == 0
    welded = weld_exact(tess.positions, tess.triangles)
    assert welded.is_watertight and welded.is_winding_consistent
    controls, _, _ = kind.reference_factors(kind.prepare(scene).source, ObjectSpace(eps), 64)
    assert bound_ratio(controls, tess, eps, surface=kind.surface.surface_points) <= 1.0


@pytest.mark.parametrize("bound", BOUNDS)
def test_closed_surfaces_are_watertight_and_within_the_bound_under_every_bound(tessellator, rng, kind, bound):
    """Request.bound changes the factors (per-triangle certified trials), never the crack-free
    contract: shared boundary points bitwise equal, and the mesh within eps."""
    scene, eps = closed_scene(rng, kind)
    tess = tessellator.tessellate(scene, Request.of(eps=eps, bound=bound))
    welded = weld_exact(tess.positions, tess.triangles)
    assert welded.is_watertight and welded.is_winding_consistent
    controls, _, _ = kind.reference_factors(kind.prepare(scene).source, ObjectSpace(eps), 64)
    assert bound_ratio(controls, tess, eps, surface=kind.surface.surface_points) <= 1.0

"""The error bound with dyadic levels (issue 11), ahead of the pipeline integration: today's final
factors f_e rounded up to 2^p_e, p_e = ceil(log2 f_e) (no cap reached), the semi-uniform pattern's
NumPy mirror evaluated by the reference evaluators, |surface(u,v) - mesh(u,v)| <= eps sampled
densely inside every triangle (snapped ones included)."""
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from cltess import reference
from cltess.io import load_scene
from cltess.patterns import semi_uniform as su
from cltess.scene import Scene
from conftest import BOUND_RATIOS
from support import as_float32, bound_ratio, closed_torus_grid, genus2

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def semi_uniform_ratio(domain, controls, factors, eps, evaluator, surface):
    """(worst bound ratio, triangles, patches with snapped edges)."""
    records = su.dyadic_factors(factors, max_level=30)
    assert (records >= factors).all()
    snapped = (records[:, :su.EDGES[domain]].min(1) < records.max(1)).sum()
    assert snapped > 0  # some patches have edges below their level
    mesh = reference.tessellate(controls, records, pattern=lambda record: su.pattern(domain, record),
                                evaluator=evaluator)
    return bound_ratio(controls, SimpleNamespace(**mesh), eps, surface=surface), len(mesh["triangles"]), snapped


@pytest.mark.parametrize("name, eps", [("teapot.bez", 5e-2), ("teapot.bez", 5e-3), ("teacup.bez", 2e-3)])
def test_bound_on_bezier_scenes(tessellator, name, eps):
    scene = load_scene(SCENES / name)
    tess = tessellator.tessellate(scene, eps=eps)
    assert tess.stats["saturated"] == 0
    patches = as_float32(scene.patches)
    ratio, triangles, snapped = semi_uniform_ratio("quad", patches, tess.factors, eps, reference.evaluate,
                                                   reference.surface_points)
    BOUND_RATIOS[f"semi-uniform {name} eps={eps} ({triangles} triangles, {snapped} snapped patches)"] = ratio
    assert ratio <= 1.0


def test_bound_on_a_closed_grid(tessellator, rng):
    scene = closed_torus_grid(rng, 10, 6, noise=0.1)
    tess = tessellator.tessellate(scene, eps=0.3, max_factor=512)
    assert tess.stats["saturated"] == 0
    ratio, triangles, snapped = semi_uniform_ratio("quad", as_float32(scene.patches), tess.factors, 0.3,
                                                   reference.evaluate, reference.surface_points)
    BOUND_RATIOS[f"semi-uniform torus grid eps=0.3 ({triangles} triangles, {snapped} snapped patches)"] = ratio
    assert ratio <= 1.0


@pytest.mark.parametrize("eps", [1e-2, 3e-3])
def test_bound_on_pn_meshes(tessellator, eps):
    from cltess.pipeline import PN

    name = "genus 2"  # regular meshes (icosphere, torus) round to equal levels: nothing snaps
    scene = Scene.from_trimesh(genus2(), name=name)
    tess = tessellator.tessellate(scene, eps=eps)
    assert tess.stats["saturated"] == 0
    controls = reference.pn_control_points(PN.prepare(scene, "straight").source.astype(np.float64))
    ratio, triangles, snapped = semi_uniform_ratio("tri", controls, tess.factors, eps, reference.pn_evaluate,
                                                   reference.pn_surface_points)
    BOUND_RATIOS[f"semi-uniform PN {name} eps={eps} ({triangles} triangles, {snapped} snapped)"] = ratio
    assert ratio <= 1.0

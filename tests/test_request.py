"""The Request: one frozen, validated value for what a tessellation is asked for."""
import dataclasses

import numpy as np
import pytest

from cltess import load_scene
from cltess.criteria import ObjectSpace, ScreenSpace
from cltess.kinds import BEZIER, PN
from cltess.patterns import QUAD_TRANSITION, TRI_TRANSITION
from cltess.request import Request
from support import SCENES


@pytest.mark.parametrize("options, message", [
    ({}, "exactly one"), ({"eps": 0.1, "pixels": 1.0}, "exactly one"), ({"eps": -1.0}, "eps must be"),
    ({"pixels": float("nan")}, "pixels must be"), ({"eps": 0.1, "max_factor": 0}, "max_factor"),
    ({"eps": 0.1, "sharp_edges": "round"}, "sharp_edges"), ({"eps": 0.1, "pattern": "hexagons"}, "unknown pattern")])
def test_invalid_requests_are_refused_when_made(options, message):
    with pytest.raises(ValueError, match=message):
        Request.of(**options)


def test_a_request_is_frozen_and_picks_its_tolerance():
    request = Request.of(eps=0.01, max_factor=8)
    assert request.tolerance == ObjectSpace(0.01) and request.max_factor == 8
    with pytest.raises(dataclasses.FrozenInstanceError):
        request.max_factor = 9
    assert isinstance(Request.of(pixels=1.0).tolerance, ScreenSpace)


def test_a_pattern_applies_to_the_kinds_of_its_domain():
    request = Request.of(eps=0.01, pattern="quad_transition")
    assert request.pattern_for(BEZIER) is QUAD_TRANSITION and request.pattern_for(PN) is TRI_TRANSITION


def test_keywords_and_a_request_give_the_same_mesh(tessellator):
    scene = load_scene(SCENES / "teapot.bez")
    by_keywords = tessellator.tessellate(scene, eps=0.01, forward_differencing=False)
    by_request = tessellator.tessellate(scene, Request.of(eps=0.01, forward_differencing=False))
    for name in ("positions", "normals", "uv", "triangles", "factors"):
        assert np.array_equal(getattr(by_keywords, name), getattr(by_request, name))

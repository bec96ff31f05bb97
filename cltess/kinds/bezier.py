"""Rational bicubic Bézier patches (docs/design.md section 2): the host side of
kernels/kinds/bezier.h.  Source = controls = (P, 16, 4) homogeneous control points; on the
device stage 1 reads them as controls and its source is the bound's constants, one float4 per
patch that stage 1 makes on first use and keeps with the scene (per_patch_constants;
criteria/zheng_sederberg.py, zs_constants)."""
from __future__ import annotations

import numpy as np

from ..criteria.zheng_sederberg import zs_factors
from ..crack.adjacency import scene_edge_groups
from ..patterns import QUAD_TRANSITION
from ..scene import device_patches
from ..surfaces import bezier as surface
from .base import FLAG_CULLED, KindInput, PatchKind


class BezierKind(PatchKind):
    name = "bezier"
    domain = "quad"
    edges = 4
    header = "kinds/bezier.h"
    pattern = QUAD_TRANSITION
    per_patch_constants = True
    surface = surface

    def count(self, scene):
        return scene.num_bezier

    def prepare(self, scene, sharp_edges="straight"):
        return KindInput(device_patches(scene.patches), scene.object_ids,
                         scene_edge_groups(scene))

    def reference_factors(self, source, tolerance, max_factor):
        patches = np.asarray(source, np.float64).reshape(-1, 4, 4, 4)
        points = (patches[..., :3] / patches[..., 3:]).reshape(len(patches), -1, 3)
        eps, culled = tolerance.reference(points.min(axis=1), points.max(axis=1))
        factors, _, saturated = zs_factors(patches, eps, culled, max_factor)
        flags = np.where(culled, FLAG_CULLED, saturated.astype(np.int32)).astype(np.int32)
        return patches, factors, flags


BEZIER = BezierKind()

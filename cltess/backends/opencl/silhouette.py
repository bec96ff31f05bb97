"""Silhouette refinement with blended levels on the OpenCL backend (Dyken, Reimers and Seland,
CGF 2008; docs/design.md, "Silhouette refinement"), on the semi-uniform pattern's levels, snap and
layout (Dyken, Reimers and Seland 2009).

What does not depend on the camera is done once, in ``SilhouetteRefiner(tessellator, scene)``:
the scene's host preparation and edge groups (cached on the scene, ``Scene.prepared``), stages
1-3 of the semi-uniform pattern for the error bound (the control points and the crack-free
dyadic records), and each edge group's midpoint, facet normals, beta and rule
(cltess.criteria.silhouette), uploaded.  ``frame(camera)`` then runs, per camera:

    silhouette_alpha.cl     alpha per edge group (one work-item per group)
    silhouette_levels.cl    s_e = M alpha_e per patch edge (max with the bound's level), records
    counts.cl + scan        the semi-uniform pattern's counts, offsets; totals read back
    silhouette_vertices.cl  blended vertices (eq. 9-11) and their lod s(p)
    indices.cl              the semi-uniform pattern's triangles

``recompute_controls=True`` also reruns stage 1 each frame (the paper's dynamic meshes, whose
control points change every frame; bench/silhouette.py's "adaptive dynamic").
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pyopencl.array as cl_array

from ...criteria.silhouette import EdgeSilhouetteData, check_phi, edge_silhouette_data
from ...criteria.tolerance import ObjectSpace
from ...crack.adjacency import merge_edge_groups
from ...kinds import FACTOR_SLOTS, KINDS, PN
from ...kinds.pn import CENTRE_RULES, with_centre
from ...limits import check_totals
from ...patterns.semi_uniform import level_histogram
from ...request import Request
from ...scene import Camera, Scene
from ...tessellation import Tessellation
from .events import span_ms
from .tessellator import WORK_GROUP, Tessellator, _global_size

#: The paper's typical maximum level M (section 5).
DEFAULT_SILHOUETTE_LEVEL = 3


@dataclass
class SilhouetteFrame:
    """One frame's result: ``tessellation`` (the mesh, in the semi-uniform pattern's layout;
    ``factors`` its records' absolute values), ``lod`` (V,) float32 each vertex's geometric level
    s(p) (eq. 10), ``alpha`` (G,) float32 per edge group, ``levels`` (P, 4) float32 each patch
    edge's s_e, ``eye`` (3,) the eye it was made for."""

    tessellation: Tessellation
    lod: np.ndarray
    alpha: np.ndarray
    levels: np.ndarray
    eye: np.ndarray
    stats: dict = field(default_factory=dict)


def eye_of(camera) -> np.ndarray:
    """The eye position (3,) of a Camera, or a point given directly."""
    eye = np.asarray(camera.eye if isinstance(camera, Camera) else camera, np.float64).reshape(-1)
    if eye.shape != (3,) or not np.isfinite(eye).all():
        raise ValueError(f"an eye is a finite point (x, y, z), got {eye.tolist()}")
    return eye


class SilhouetteRefiner:
    """Per-frame silhouette refinement of one scene (module docstring).

    max_level: M, the level of a silhouette edge (s_e = M alpha_e).  phi: the wedge angle in
    degrees (None: the paper's beta = 1/4).  eps: an object-space tolerance whose semi-uniform
    level each edge keeps at least (criteria combine: the larger level), or None for silhouettes
    alone.  blend: eq. 9 (False: each vertex at its level ceil(s), the popping ablation).  snap:
    the semi-uniform snap (False: every edge of a patch at its level m, the paper's hanging
    nodes).  sharp_edges: the PN sharp-edge mode.  recompute_controls: rerun stage 1 per frame.
    centre: PN's centre control point, "pn" (eq. 4, Vlachos') or "average" (eq. 5, the mean of
    the six edge points: flatter).
    """

    def __init__(self, tessellator: Tessellator, scene: Scene, max_level: int = DEFAULT_SILHOUETTE_LEVEL,
                 phi: float | None = None, eps: float | None = None, blend: bool = True, snap: bool = True,
                 sharp_edges: str = "straight", recompute_controls: bool = False, centre: str = "pn"):
        check_phi(phi)
        if centre not in CENTRE_RULES:
            raise ValueError(f"centre must be one of {', '.join(CENTRE_RULES)}, got {centre!r}")
        self.tessellator, self.scene = tessellator, scene
        self.max_level, self.phi, self.eps = int(max_level), phi, eps
        self.blend, self.snap, self.recompute_controls = bool(blend), bool(snap), bool(recompute_controls)
        started = time.perf_counter()
        # Without eps the bound only supplies the control points and which patches have output:
        # the scene's diagonal as tolerance gives every edge level 0.
        tolerance = eps if eps is not None else max(scene.diagonal, 1e-30)
        self.request = Request(ObjectSpace(tolerance), forward_differencing=False, sharp_edges=sharp_edges,
                               pattern="semi_uniform", max_level=self.max_level)
        queue = tessellator.queue
        kinds = [kind for kind in KINDS if kind.count(scene)]
        # Every program is built before the first buffer exists (as Tessellator.plan does: a build
        # in between made Oclgrind's uninitialised-value plugin report the scans' output).
        programs = tessellator.programs
        self._alpha_kernel = programs.kernel("silhouette_alpha")
        self._levels_kernel = programs.kernel("silhouette_levels")
        self._crack_free_kernel = programs.kernel("crack_free")
        for kind in kinds:
            programs.kernel("silhouette_vertices", kind=kind, pattern=self.request.pattern_for(kind))
        self.plan = tessellator.plan(scene, self.request)
        hosts = [scene.prepared((kind.name, sharp_edges), lambda kind=kind: kind.prepare(scene, sharp_edges))
                 for kind in kinds]
        count = self.plan.num_patches
        self._scratch_factors = cl_array.empty(queue, (count, FACTOR_SLOTS), np.int32)
        self._scratch_flags = cl_array.empty(queue, count, np.int32)
        groups = scene.prepared(("edge groups", sharp_edges), lambda: merge_edge_groups(
            [(host.groups, part.kind.edges, part.base) for host, part in zip(hosts, self.plan.parts)],
            count, FACTOR_SLOTS))
        self.edges: EdgeSilhouetteData = scene.prepared(
            ("silhouette edges", sharp_edges, phi),
            lambda: edge_silhouette_data([(part.kind, host.source, part.base) for host, part in zip(hosts, self.plan.parts)],
                                         groups, count, phi))
        collapsed = (np.zeros(len(groups.group_of), bool) if groups.collapsed_edges is None
                     else np.asarray(groups.collapsed_edges, bool))
        self._group_start, self._members, self._collapsed = (
            cl_array.to_device(queue, a.astype(np.int32)) for a in (groups.group_start, groups.members, collapsed))
        mids, normals, rules = self.edges.device_arrays()
        self._mids, self._normals, self._rules, self._group_of = (
            cl_array.to_device(queue, a) for a in (mids, normals, rules, groups.group_of.astype(np.int32)))
        self.groups, self.group_of = groups, groups.group_of
        if centre != "pn":  # eq. 5: PN sources flagged, stages 1-2 again (controls and bound)
            for host, part in zip(hosts, self.plan.parts):
                if part.kind is PN:
                    part.data["source"].set(with_centre(host.source, centre))
            for part in self.plan.parts:
                tessellator.stage_factors_of(part.kind, part.data, self.request.tolerance_for(scene),
                                             self.request.max_factor, self._scratch_factors, self._scratch_flags,
                                             part.base, part.pattern, self.max_level)
            self.plan.factors, _ = tessellator.stage_crack_free(self._scratch_factors, groups)
        self._alpha = cl_array.empty(queue, max(self.edges.num_groups, 1), np.float32)
        self._levels = cl_array.empty(queue, (count, FACTOR_SLOTS), np.float32)
        self._patch_records = cl_array.empty(queue, (count, FACTOR_SLOTS), np.int32)
        self._records = cl_array.empty(queue, (count, FACTOR_SLOTS), np.int32)
        queue.finish()
        self.prepare_ms = (time.perf_counter() - started) * 1e3

    def group_members(self, group: int) -> np.ndarray:
        """The patch-edges (entries of the (P, 4) factor array) of an edge group."""
        start = self.groups.group_start
        return self.groups.members[start[group]:start[group + 1]]

    # --- per frame -------------------------------------------------------------------------------

    def alpha(self, camera) -> np.ndarray:
        """alpha (G,) float32 per edge group for a camera (or an eye point), on the device."""
        self._run_alpha(eye_of(camera))
        return self._alpha.get()[:self.edges.num_groups]

    def _run_alpha(self, eye) -> list:
        groups = self.edges.num_groups
        if not groups:
            return []
        return [self._alpha_kernel(self.tessellator.queue, _global_size(groups), None, self._mids.data,
                                   self._normals.data, self._rules.data, np.uint32(groups),
                                   *(np.float32(x) for x in eye), self._alpha.data)]

    def frame(self, camera, blend: bool | None = None, snap: bool | None = None,
              alpha: np.ndarray | None = None) -> SilhouetteFrame:
        """Tessellate for one camera (a Camera or an eye point); blend/snap: this frame's, else
        the refiner's; alpha: (G,) values in [0, 1] to use instead of the camera's (the blending
        identities: alpha = 1 is uniform level M, alpha = 0 the coarse mesh)."""
        blend = self.blend if blend is None else bool(blend)
        snap = self.snap if snap is None else bool(snap)
        tess = self.tessellator
        queue, plan = tess.queue, self.plan
        started = time.perf_counter()
        eye = eye_of(camera)
        if alpha is None:
            events = {"alpha": self._run_alpha(eye), "levels": []}
        else:
            alpha = np.asarray(alpha, np.float32)
            if alpha.shape != (self.edges.num_groups,) or not ((alpha >= 0) & (alpha <= 1)).all():
                raise ValueError(f"alpha must be {self.edges.num_groups} values in [0, 1]")
            if len(alpha):
                self._alpha[:len(alpha)].set(alpha)
            events = {"levels": []}
        if self.recompute_controls:  # the paper's dynamic meshes: control points anew each frame
            events["factors"] = []
            for part in plan.parts:
                events["factors"] += tess.stage_factors_of(
                    part.kind, part.data, self.request.tolerance_for(self.scene), self.request.max_factor,
                    self._scratch_factors, self._scratch_flags, part.base, part.pattern, self.max_level)
        for part in plan.parts:
            events["levels"].append(self._levels_kernel(
                queue, _global_size(part.count), None, self._alpha.data, self._group_of.data, plan.factors.data,
                np.uint32(part.base), np.uint32(part.count), np.int32(part.kind.edges), np.float32(self.max_level),
                np.int32(self.eps is not None), np.int32(snap), self._levels.data,
                (self._patch_records if snap else self._records).data))
        if snap:  # each edge at the larger level of its patches (crack/max.h), collapsed ones negated
            edges = self._records.size
            events["levels"].append(self._crack_free_kernel(
                queue, _global_size(edges), None, self._patch_records.data, self._group_of.data,
                self._group_start.data, self._members.data, self._collapsed.data, np.uint32(edges),
                self._records.data))
        vertex_offsets, index_offsets, events["counts"] = tess.stage_counts(
            self._records, [(part.pattern, part.base, part.count) for part in plan.parts])
        num_vertices = int(vertex_offsets[plan.num_patches].get())
        num_indices = int(index_offsets[plan.num_patches].get())
        check_totals(self.scene.name, num_vertices)
        vertices = tess._vertex_arrays(num_vertices)
        lod = cl_array.empty(queue, num_vertices, np.float32)
        triangles = cl_array.empty(queue, (num_indices // 3, 3), np.uint32)
        events["vertices"], events["indices"] = [], []
        for part in plan.parts:
            if num_vertices:
                kernel = tess.programs.kernel("silhouette_vertices", kind=part.kind, pattern=part.pattern)
                # An explicit work-group size: PoCL otherwise picks large groups whose work-items'
                # private state (this kernel's is large) overflowed its thread stack (segfaults
                # from about 5k patches on).
                events["vertices"].append(kernel(
                    queue, _global_size(part.count), (WORK_GROUP,), part.data["controls"].data, self._records.data,
                    vertex_offsets.data, plan.objects.data, self._levels.data, np.uint32(part.base),
                    np.uint32(part.count), np.uint32(part.base), np.uint64(0), np.int32(blend),
                    *(a.data for a in vertices.values()), lod.data))
            events["indices"] += tess.stage_indices(self._records, vertex_offsets, index_offsets, (0, num_indices),
                                                    (part.base, part.base + part.count), kind=part.pattern,
                                                    out=triangles)[1]
        queue.finish()
        stage_ms = {stage: span_ms(evs) for stage, evs in events.items() if evs}
        records = self._records.get()
        alpha = self._alpha.get()[:self.edges.num_groups]
        stage_ms["total_wall"] = (time.perf_counter() - started) * 1e3
        pairs = self.edges.rule == 0
        stats = {
            "patches": plan.num_patches, "vertices": num_vertices, "triangles": num_indices // 3,
            "patch_levels": level_histogram(records),
            "silhouette_edges": int(np.count_nonzero(pairs & (alpha >= 1.0))),
            "transition_edges": int(np.count_nonzero(pairs & (alpha > 0.0) & (alpha < 1.0))),
            "max_level": self.max_level, "blend": blend, "snap": snap,
        }
        result = Tessellation(triangles=triangles.get(), factors=np.abs(records), stage_ms=stage_ms,
                              stats=dict(stats), **{k: a.get() for k, a in vertices.items()})
        return SilhouetteFrame(result, lod.get(), alpha, self._levels.get(), eye, stats)

    def frames(self, cameras, **options):
        """One SilhouetteFrame per camera, in turn (a generator: each frame is read back before
        the next is made)."""
        for camera in cameras:
            yield self.frame(camera, **options)


def silhouette_refiner(tessellator: Tessellator, scene: Scene, **options) -> SilhouetteRefiner:
    """The scene's refiner for these options on this tessellator, made once and kept on the scene
    (``Scene.prepared``, as adjacency is), so a sequence of calls per camera prepares nothing
    again."""
    key = ("silhouette refiner", id(tessellator.context), tuple(sorted(options.items())))
    return scene.prepared(key, lambda: SilhouetteRefiner(tessellator, scene, **options))


def tessellate_silhouette(tessellator: Tessellator, scene: Scene, camera, **options):
    """The per-camera entry point: one SilhouetteFrame for a camera (or a list of cameras: a list
    of frames), the camera-independent work done once per (scene, options)
    (``silhouette_refiner``)."""
    refiner = silhouette_refiner(tessellator, scene, **options)
    if isinstance(camera, (list, tuple)) and camera and not np.isscalar(camera[0]):
        return list(refiner.frames(camera))
    return refiner.frame(camera)


__all__ = ["DEFAULT_SILHOUETTE_LEVEL", "SilhouetteFrame", "SilhouetteRefiner", "eye_of", "silhouette_refiner",
           "tessellate_silhouette"]

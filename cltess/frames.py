"""Per-frame tessellation along a camera path (``cltess tessellate --camera-path FILE.json``): one
mesh per frame (the output name holds ``{frame}``, e.g. ``out_{frame:04d}.ply``) or one summary
per frame (``-o frames.json``), the camera-independent work done once.

Per-frame criteria: ``--silhouette [M]`` (silhouette refinement with blended levels, Dyken,
Reimers and Seland 2008: ``cltess.backends.opencl.silhouette``; every edge keeps at least the
``--eps`` error bound's level unless ``--no-bound``) or ``--pixels`` (the screen-space tolerance of each frame's
camera).  The camera-path file format is ``cltess.io.camera_path``.

``--pixels`` frames come from a ``cltess.Session`` with two buffer sets: the scene's device data
made once, and frame k+1 computed while frame k is written (its arrays stay valid until the
session's second call after it).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

#: Options that belong to --silhouette.
SILHOUETTE_ONLY = ("phi", "no_blend", "no_snap", "no_bound", "centre")


class FramesError(ValueError):
    """A bad combination of per-frame options (the CLI turns it into a usage error)."""


def frame_path(pattern: str, frame: int) -> Path:
    """The output of one frame: ``pattern.format(frame=frame)``."""
    try:
        return Path(pattern.format(frame=frame))
    except (KeyError, IndexError, ValueError) as error:
        raise FramesError(f"{pattern}: the output name takes {{frame}} (e.g. out_{{frame:04d}}.ply), "
                          f"nothing else in braces: {error}") from None


def check_options(args, frames: int) -> str:
    """What the run writes: "summary" (-o *.json) or "meshes"; FramesError for what cannot go
    together."""
    if args.silhouette is None:
        used = [f"--{name.replace('_', '-')}" for name in SILHOUETTE_ONLY if getattr(args, name)]
        if used:
            raise FramesError(f"{', '.join(used)} {'is' if len(used) == 1 else 'are'} for --silhouette")
        if args.pixels is None:
            raise FramesError("--camera-path needs a per-frame criterion: --silhouette or --pixels "
                              "(with --eps alone every frame is the same mesh)")
    elif args.pixels is not None:
        raise FramesError("--silhouette takes --eps (the error bound every edge keeps at least, or "
                          "--no-bound), not --pixels")
    if args.verify or args.preview or args.check_t_junctions:
        raise FramesError("--camera-path writes frames: --verify, --preview and --check-t-junctions "
                          "are for single meshes")
    if Path(args.output).suffix.lower() == ".json":
        return "summary"
    if frames > 1 and "{frame" not in args.output:
        raise FramesError(f"{args.output}: {frames} frames need {{frame}} in the output name, "
                          "e.g. out_{frame:04d}.ply (or -o frames.json for a summary per frame)")
    return "meshes"


def frame_summary(frame: int, camera, stats: dict, stage_ms: dict) -> dict:
    eye = np.asarray(camera.eye, float)
    out = {"frame": frame, "eye": [round(float(x), 6) for x in eye],
           "vertices": int(stats.get("vertices", 0)), "triangles": int(stats.get("triangles", 0)),
           "patch_levels": stats.get("patch_levels", []), "device_ms": round(sum(
               v for k, v in stage_ms.items() if k != "total_wall"), 4),
           "wall_ms": round(float(stage_ms.get("total_wall", 0.0)), 3)}
    for key in ("silhouette_edges", "transition_edges", "welded_boundary_edges", "welded_t_junctions"):
        if key in stats:
            out[key] = int(stats[key])
    return out


def write_frame(tess, lod, path: Path, weld: bool, uv: str) -> dict:
    """Write one frame's mesh (welded when asked; per-patch .npz output also holds ``lod``);
    returns the welded stats (or {})."""
    from .io.export import export

    if weld:
        welded = tess.welded(uv=uv, check_t_junctions=False)
        export(welded, path)
        return {k: v for k, v in welded.stats.items() if k.startswith("welded_")}
    if path.suffix.lower() == ".npz" and lod is not None:
        from .io.npz import NPZ_ARRAYS, _jsonable
        from .io.writing import atomic_write

        meta = {"stats": _jsonable(tess.stats), "stage_ms": _jsonable(tess.stage_ms)}
        with atomic_write(path, "wb") as handle:
            np.savez(handle, **{name: np.asarray(getattr(tess, name)) for name in NPZ_ARRAYS}, lod=lod,
                     stats_json=np.array(json.dumps(meta)))
        return {}
    export(tess, path)
    return {}


def run_frames(args, scene, cameras, tessellator, weld: bool, say) -> list[dict]:
    """Tessellate ``scene`` for each camera and write each frame (or the summaries); returns the
    summaries.  ``say(text)`` prints progress lines."""
    what = check_options(args, len(cameras))
    summaries = []
    mesh_options = {"sharp_edges": args.sharp_edges} if scene.meshes else {}
    if args.silhouette is not None:
        from .backends.opencl.silhouette import SilhouetteRefiner

        refiner = SilhouetteRefiner(tessellator, scene, max_level=args.silhouette, phi=args.phi,
                                    eps=None if args.no_bound else args.eps,
                                    blend=not args.no_blend, snap=not args.no_snap, centre=args.centre or "pn",
                                    **mesh_options)
        say(f"prepared once: {refiner.prepare_ms:.1f} ms (stages 1-3, edge data)")
        results = (refiner.frame(camera) for camera in cameras)
    else:
        from .criteria.tolerance import ScreenSpace
        from .request import Request
        from .session import Session

        request = Request(ScreenSpace(args.pixels, cameras[0]), max_factor=args.max_factor,
                          forward_differencing=not args.no_fd, pattern=args.pattern_name,
                          max_level=args.max_level, **mesh_options)
        results = _pipelined(Session(scene, tessellator=tessellator, request=request, buffers=2), cameras)
    for index, (camera, result) in enumerate(zip(cameras, results)):
        tess, lod = (result.tessellation, result.lod) if hasattr(result, "tessellation") else (result, None)
        stats = dict(tess.stats)
        if what == "meshes":
            stats.update(write_frame(tess, lod, frame_path(args.output, index), weld, args.uv))
        summary = frame_summary(index, camera, stats, tess.stage_ms)
        summaries.append(summary)
        levels = f", patches per level {summary['patch_levels']}" if summary["patch_levels"] else ""
        say(f"frame {index:4d}: {summary['triangles']} triangles, {summary['vertices']} vertices{levels}, "
            f"{summary['device_ms']:.2f} ms on the device"
            + (f" -> {frame_path(args.output, index)}" if what == "meshes" else ""))
    if what == "summary":
        from .io.writing import atomic_write

        with atomic_write(args.output, "w") as handle:
            json.dump({"frames": summaries}, handle, indent=1)
    return summaries


def _pipelined(session, cameras):
    """Each camera's frame with its host arrays, frame k+1 enqueued before frame k is given (two
    buffer sets: frame k stays valid until the session's second call after it, by when the
    caller has written it)."""
    frame = session.tessellate(camera=cameras[0], host=True, wait=False)
    for following in cameras[1:]:
        after = session.tessellate(camera=following, host=True, wait=False)
        yield frame.fetch()
        frame = after
    yield frame.fetch()


def parse_phi(text: str) -> float:
    import argparse

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(value) and 0 < value < 90):
        raise argparse.ArgumentTypeError(f"must be in (0, 90) degrees, got {text}")
    return value

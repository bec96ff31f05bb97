"""The ``cltess`` command line.

    cltess devices [--verbose]
    cltess tessellate SCENE (--eps E | --eps P% | --pixels PX) [--no-fd] [--max-factor N]
                      [--max-memory SIZE] [--sharp-edges {straight,average,keep}] [--crease-angle DEG]
                      [--no-orient] [--no-weld] [--uv {drop,seam}] [--max-output SIZE]
                      [--preview PNG] [--pattern {transition,semi-uniform,sd2,esc}] [--max-level L]
                      [--emit {per-patch,by-level}]
                      [--check-t-junctions] [--device NAME] [--quiet] -o OUT
    cltess render SCENE (--eps E | --eps P% | --pixels PX) [--size W[xH]] [--color {shade,factor}]
                  [the scene options of tessellate] -o PNG
    cltess bench [SCENES...] [--device NAME] [--repeat N] [--warmup N] [--no-baseline] [--json OUT]
    cltess batch INPUTS... (--eps E | --pixels PX) -o OUTDIR [--format {ply,obj,npz}] [--split N]
                 [--scheduler ADDRESS] [--workers N] [tessellate's options, --pattern, --max-level
                 and --emit among them]

Exit codes: 0 success, 1 OpenCL / device failure, 2 usage or input error, 130 interrupted
(Ctrl-C), 143 and 129 for SIGTERM and SIGHUP, which are handled like Ctrl-C; batch: 3 when
some inputs failed (each failure is in its manifest row).
Expected errors print ``cltess: error: <message>`` on stderr, without a traceback, and leave
no output file behind (exports are atomic).
"""
from __future__ import annotations

import argparse
import contextlib
import math
import os
import signal
import sys
import threading
import warnings
from pathlib import Path

from cltess.io.export import MESH_FORMATS, SUPPORTED_EXTENSIONS, check_extension
from cltess.levels import DEFAULT_SILHOUETTE_BAND
from cltess.scene import DEFAULT_CREASE_ANGLE

PROG = "cltess"
DEFAULT_MAX_FACTOR = 64
DEFAULT_MAX_OUTPUT = 4 * 2**30  # --max-output: a wrong unit of --eps must not fill a disk
NOTE_OUTPUT_SIZE = 64 * 2**20  # larger outputs are announced before they are written
PROGRESS_DELAY = 1.0  # seconds before a progress bar appears: short runs print none
EXIT_OK, EXIT_DEVICE, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130

#: The stats printed on their own summary lines; any other int stat is listed after them.
_MAIN_STATS = ("patches", "culled", "saturated", "vertices", "triangles")
#: Bookkeeping of a batch, not of the result.
_HIDDEN_STATS = ("first_patch", "last_patch", "output_fit")


class UsageError(Exception):
    """Bad arguments or input, reported as ``cltess: error: ...`` with exit code 2."""

    def __init__(self, message: str, usage: str | None = None):
        super().__init__(message)
        self.usage = usage


class _Parser(argparse.ArgumentParser):
    """argparse that raises UsageError instead of printing and calling sys.exit(2)."""

    def error(self, message):
        raise UsageError(message, usage=self.format_usage().rstrip())


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


class Percent(float):
    """An --eps given as a percentage of the scene's bounding-box diagonal (its value: the
    percentage); it becomes a distance once the scene is loaded."""


def _tolerance(text: str) -> float:
    """--eps: a distance, or a percentage of the scene's bounding-box diagonal ("0.1%")."""
    relative = text.strip().endswith("%")
    value = _positive_float(text.strip()[:-1] if relative else text)
    if relative and value >= 100:
        raise argparse.ArgumentTypeError(f"a percentage of the scene's diagonal must be below 100%, got {text!r}")
    return Percent(value) if relative else value


def _image_size(text: str) -> tuple[int, int | None]:
    """'800' or '800x600': width and optional height, each 16..8192 pixels."""
    parts = text.lower().split("x")
    try:
        if len(parts) > 2:
            raise ValueError
        sizes = [int(part) for part in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an image size like 800 or 800x600: {text!r}") from None
    if not all(16 <= size <= 8192 for size in sizes):
        raise argparse.ArgumentTypeError(f"sizes must be 16..8192 pixels, got {text!r}")
    return sizes[0], (sizes[1] if len(sizes) == 2 else None)


def _output_cap(text: str) -> int | None:
    if text.strip().lower() in ("none", "0"):
        return None
    return _memory_size(text)


def _factor(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value


def _max_factor(text: str) -> int:
    from cltess.limits import check_max_factor

    try:
        return check_max_factor(_factor(text))
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error).removeprefix("max_factor ")) from None


def _crease_angle(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number of degrees: {text!r}") from None
    if not 0 <= value <= 180:  # NaN fails too
        raise argparse.ArgumentTypeError(f"must be an angle in 0..180 degrees, got {text!r}")
    return value


#: --pattern's choices: the pattern families (cltess.patterns.FAMILIES), as the command line spells them.
PATTERN_CHOICES = {"transition": "transition", "semi-uniform": "semi_uniform", "sd2": "sd2", "esc": "esc"}
#: --emit's choices: cltess.request.EMIT_MODES, as the command line spells them.
EMIT_CHOICES = {"per-patch": "per_patch", "by-level": "by_level"}


def _max_level(text: str) -> int:
    from cltess.request import MAX_LEVEL

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if not 0 <= value <= MAX_LEVEL:
        raise argparse.ArgumentTypeError(f"must be in 0..{MAX_LEVEL}, got {value}")
    return value


def _phi(text: str) -> float:
    from cltess.frames import parse_phi

    return parse_phi(text)


def _memory_size(text: str) -> int:
    from cltess.stream import parse_size

    try:
        return parse_size(text)
    except (ValueError, IndexError):
        raise argparse.ArgumentTypeError(f"not a memory size like 512M or 2G: {text!r}") from None


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("cltess")
    except metadata.PackageNotFoundError:
        return "(not installed)"


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog=PROG,
        description="Crack-free, error-bounded tessellation of rational bicubic Bezier patches with OpenCL.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    # Every command takes --verbose: full OpenCL build logs and compiler output.
    verbose = _Parser(add_help=False)
    verbose.add_argument("-v", "--verbose", action="store_true",
                         help="show full OpenCL build logs and compiler warnings")

    commands.add_parser(
        "devices", help="list OpenCL platforms and devices, and whether each is usable",
        parents=[verbose],
        description="List OpenCL platforms and devices, each probed with a small kernel: usable, "
                    "fails to build or fails to run, with the reason. '*' marks the default "
                    "($CLTESS_DEVICE, else the first usable CPU device, else the first usable device).",
    )

    # What tessellate and render share: the scene and how it is tessellated.
    shared = _Parser(add_help=False)
    shared.add_argument("scene", metavar="SCENE", help="scene file: .bpt, .bez, .json or a triangle mesh")
    tolerance = shared.add_mutually_exclusive_group(required=True)
    tolerance.add_argument("--eps", type=_tolerance, metavar="E",
                           help="object-space tolerance: max distance from surface to mesh, in scene units, "
                                "or as a percentage of the scene's bounding-box diagonal (0.1%%)")
    tolerance.add_argument("--pixels", type=_positive_float, metavar="PX",
                           help="screen-space tolerance in pixels (needs a camera in the scene)")
    shared.add_argument("--no-fd", action="store_true",
                        help="evaluate every vertex directly instead of by forward differencing")
    shared.add_argument("--max-factor", type=_max_factor, default=DEFAULT_MAX_FACTOR, metavar="N",
                        help=f"largest edge factor per patch (default {DEFAULT_MAX_FACTOR})")
    shared.add_argument("--device", metavar="NAME",
                        help="OpenCL device: substring of platform or device name (default $CLTESS_DEVICE, "
                             "else the first usable CPU device; see 'cltess devices')")
    shared.add_argument("--max-memory", type=_memory_size, metavar="SIZE",
                        help="cap on the memory the output may take at once (e.g. 512M, 2G); a larger "
                             "output is tessellated in batches (streamed to a per-patch .ply, .obj or .npz). "
                             "Default: half the device's memory")
    shared.add_argument("--sharp-edges", choices=("straight", "average", "keep", "crease"), default="straight",
                        help="meshes: an edge whose two sides have different vertex normals becomes a "
                             "straight crease (default), a curve from the averaged normals, keeps "
                             "each side's own PN curve (may crack), or follows the crease direction "
                             "n_s x n_t at its sharp ends (crease; Dyken et al. 2008)")
    shared.add_argument("--crease-angle", type=_crease_angle, default=DEFAULT_CREASE_ANGLE, metavar="DEG",
                        help="meshes without normals in the file: edges whose faces meet at more than DEG "
                             f"degrees stay sharp creases (default {DEFAULT_CREASE_ANGLE:g}; 180: all smooth)")
    shared.add_argument("--orient", action=argparse.BooleanOptionalAction, default=True,
                        help="turn patches to face one way across shared edges and outwards (signed volume); "
                             "on by default, --no-orient leaves them as the file has them")
    shared.add_argument("--pattern", choices=tuple(PATTERN_CHOICES), default="transition",
                        help="tessellation pattern of every patch: transition strips between edge factors "
                             "(default), or semi-uniform (Dyken et al. 2009: a uniform 2^m grid per patch, "
                             "edges snapped to their own dyadic level; factors rounded up to powers of two), or esc "
                             "(Bezier patches: Hu et al. 2014's distance test on the candidates of a level-L "
                             "pattern, docs/esc.md)")
    shared.add_argument("--bound", choices=("hull", "integral", "error-hull"), default="hull",
                        help="Bezier patches: hull (default) takes the hull bound's factors; integral (rational "
                             "patches) and error-hull (all) try smaller ones and bound every emitted triangle, by the "
                             "integral form of the remainder or by the Bernstein net of the error itself, keeping "
                             "the smallest that pass (fewer triangles, slower; docs/rational-bound.md; transition "
                             "pattern only)")
    shared.add_argument("--max-level", type=_max_level, default=6, metavar="L",
                        help="semi-uniform: the largest level (edge factor 2^L; default 6); a patch that "
                             "needs more is saturated.  esc: the candidate level L (L+1 steps per coarse edge, "
                             "at most 3, the default)")
    shared.add_argument("--emit", choices=tuple(EMIT_CHOICES), default="per-patch",
                        help="semi-uniform: run stages 4-5 per patch (default), or by level: the patches in one "
                             "queue per level, each level evaluated from one shared template (Dyken et al. "
                             "2009, section 4.2; direct evaluation, the same mesh as --no-fd)")
    # SD-2 (issue 13, docs/sd2.md): real edge factors from a per-vertex level function
    shared.add_argument("--level-function", choices=("depth", "silhouette", "bound"),
                        help="sd2: edge factors from the distance to the camera's eye plane, the silhouette "
                             "(crossed edges get the high factor), or the error bound kept (the default "
                             "with --pattern sd2); implies --pattern sd2 for meshes")
    shared.add_argument("--level-factors", type=float, nargs=2, default=(1.0, 7.0), metavar=("LOW", "HIGH"),
                        help="sd2 depth: the factors at the far and near end; silhouette: of plain and "
                             "crossed edges (default 1 7)")
    shared.add_argument("--depth-map", choices=("linear", "quadratic"), default="linear",
                        help="sd2 depth: the paper's g1 (linear, default) or g2 (quadratic) map")
    shared.add_argument("--silhouette-band", type=float, default=DEFAULT_SILHOUETTE_BAND, metavar="COS",
                        help="sd2 silhouette: width (in cosine of the normal-view angle) of the ramp from the "
                             "high factor at the silhouette to the low one, so factors change continuously "
                             "with the view (default %(default)s); 0: the paper's classes, which pop")
    shared.add_argument("-q", "--quiet", action="store_true",
                        help="print nothing on success, no progress bar (warnings still go to stderr)")

    run = commands.add_parser(
        "tessellate", help="tessellate a scene and export the mesh", parents=[verbose, shared],
        description="Tessellate a scene (.bpt, .bez or .json, or a triangle mesh as PN triangles: "
                    ".obj, .ply, .stl, .off, .glb, .gltf) and write the mesh "
                    f"({', '.join(SUPPORTED_EXTENSIONS)}).",
    )
    run.add_argument("--weld", action=argparse.BooleanOptionalAction, default=None,
                     help="write one indexed mesh per object, shared boundary vertices merged exactly "
                          f"(default for {', '.join(MESH_FORMATS)}; --no-weld: every patch's own vertices, "
                          "streamed in batches when large; .npz: the Tessellation's arrays unless --weld)")
    run.add_argument("--uv", choices=("drop", "seam"), default="drop",
                     help="welded output: drop the per-patch (u, v) (default) or keep them per triangle "
                          "corner as a seam (.ply face texcoord, .obj vt)")
    run.add_argument("--max-output", type=_output_cap, default=DEFAULT_MAX_OUTPUT, metavar="SIZE",
                     help="refuse (before writing) an output file estimated larger than SIZE (e.g. 500M, 20G; "
                          f"default {DEFAULT_MAX_OUTPUT // 2**30}G; none: no limit)")
    run.add_argument("--preview", metavar="PNG",
                     help="also draw the result into this .png (as 'cltess render' does)")
    run.add_argument("--check-t-junctions", action="store_true",
                     help="read the output back (.ply, .npz) and count its T-junctions after exact "
                          "welding (cltess.checks; slow on large meshes)")
    run.add_argument("-o", "--output", required=True, metavar="OUT",
                     help=f"output mesh: {', '.join(SUPPORTED_EXTENSIONS)}")
    run.add_argument("--verify", action="store_true",
                     help="after tessellating, measure on the device the worst distance between surface and "
                          "mesh at equal (u, v), at 28 points in every triangle (every k-th triangle above "
                          "4 million), and print it beside the requested tolerance")

    # Per-frame cameras (issue 12): one tessellation per camera of a path (cltess/frames.py).
    frames = run.add_argument_group("per-frame cameras")
    frames.add_argument("--camera-path", metavar="FILE.json",
                        help="tessellate once per camera of this path (a list of cameras or an orbit; "
                             "cltess.io.camera_path), preparing the scene once; -o names each frame's "
                             "mesh with {frame} (out_{frame:04d}.ply), or -o FILE.json writes a summary "
                             "per frame; needs --silhouette or --pixels")
    frames.add_argument("--silhouette", type=_max_level, nargs="?", const=3, metavar="M",
                        help="silhouette refinement with blended levels (Dyken et al. 2008): edges at "
                             "level M (default 3) where the surface turns away from the eye, 0 far from "
                             "it, watertight (semi-uniform snap); every edge keeps at least --eps's level "
                             "unless --no-bound; the scene's camera without --camera-path")
    frames.add_argument("--centre", choices=("pn", "average"),
                        help="--silhouette, meshes: the PN centre control point, PN's (eq. 4, default) or "
                             "the mean of the six edge points (eq. 5 of Dyken et al. 2008: flatter)")
    frames.add_argument("--no-bound", action="store_true",
                        help="--silhouette: levels from the silhouettes alone (the paper), --eps not kept")
    frames.add_argument("--phi", type=_phi, metavar="DEG",
                        help="--silhouette: the transition wedge's angle about the faces (default: the "
                             "paper's constant beta = 1/4)")
    frames.add_argument("--no-blend", action="store_true",
                        help="--silhouette: each vertex at its integer level (pops between frames; the ablation)")
    frames.add_argument("--no-snap", action="store_true",
                        help="--silhouette: no snap, the paper's hanging nodes (T-junctions; the ablation)")

    render = commands.add_parser(
        "render", help="tessellate a scene and draw it into a PNG (no display needed)",
        parents=[verbose, shared],
        description="Tessellate a scene and draw it, shaded on the CPU, into a .png: front faces "
                    "grey-blue (or coloured by edge factor), back faces red. The view is the scene's "
                    "camera if it has one, else one that frames the scene (z up).",
    )
    render.add_argument("--size", type=_image_size, default=(800, None), metavar="W[xH]",
                        help="image size in pixels (default 800 wide, the camera's aspect or 4:3)")
    render.add_argument("--color", choices=("shade", "factor"), default="shade",
                        help="front faces in one colour (shade, default) or by their patch's largest edge "
                             "factor (factor: dark blue 1 to yellow --max-factor, log scale)")
    render.add_argument("-o", "--output", required=True, metavar="PNG", help="output image (.png)")

    batch = commands.add_parser(
        "batch", help="tessellate many scenes (or one huge scene) on Dask workers", parents=[verbose],
        description="Tessellate every input (files, folders, globs) with the same options on a Dask "
                    "cluster, one output per input in OUTDIR plus OUTDIR/manifest.json (one row per "
                    "input: status, counts, stage times, the error if it failed). A rerun skips the "
                    "inputs whose output is up to date. Needs the 'dist' extra: pip install 'cltess[dist]'.",
    )
    batch.add_argument("inputs", nargs="+", metavar="INPUTS", help="scene files, folders or globs")
    batch_tolerance = batch.add_mutually_exclusive_group(required=True)
    batch_tolerance.add_argument("--eps", type=_positive_float, metavar="E", help="as for tessellate")
    batch_tolerance.add_argument("--pixels", type=_positive_float, metavar="PX", help="as for tessellate")
    batch.add_argument("--no-fd", action="store_true", help="as for tessellate")
    batch.add_argument("--max-factor", type=_factor, default=DEFAULT_MAX_FACTOR, metavar="N",
                       help=f"as for tessellate (default {DEFAULT_MAX_FACTOR})")
    batch.add_argument("--sharp-edges", choices=("straight", "average", "keep", "crease"), default="straight",
                       help="as for tessellate")
    batch.add_argument("--pattern", choices=tuple(PATTERN_CHOICES), default="transition", help="as for tessellate")
    batch.add_argument("--max-level", type=_max_level, default=6, metavar="L", help="as for tessellate (default 6)")
    batch.add_argument("--emit", choices=tuple(EMIT_CHOICES), default="per-patch", help="as for tessellate")
    batch.add_argument("--device", metavar="NAME",
                       help="OpenCL device of every worker (default: one GPU per worker where there are "
                            "several, else the device tessellate would use)")
    batch.add_argument("--max-memory", type=_memory_size, metavar="SIZE",
                       help="output a worker may hold at once (default: half its device's memory)")
    batch.add_argument("--format", choices=[e[1:] for e in SUPPORTED_EXTENSIONS], default="ply",
                       help="output format (default ply): OUTDIR/NAME.EXT for an input NAME.EXT")
    batch.add_argument("--weld", action=argparse.BooleanOptionalAction, default=None,
                       help="as for tessellate: one welded mesh per output (default for "
                            f"{', '.join(MESH_FORMATS)}; not with --split, which writes per patch)")
    batch.add_argument("--orient", action=argparse.BooleanOptionalAction, default=True,
                       help="as for tessellate: patches turned consistently and outwards (default)")
    batch.add_argument("--split", type=_factor, metavar="N",
                       help="tessellate each input across all workers in about N patch ranges, joined into "
                            "one PLY (for a scene too large for one worker)")
    batch.add_argument("--scheduler", metavar="ADDRESS",
                       help="Dask scheduler to run on (e.g. tcp://host:8786); default: a local cluster")
    batch.add_argument("--workers", type=_factor, metavar="N",
                       help="worker processes of the local cluster (default: one per GPU where there are "
                            "several, else one per CPU core)")
    batch.add_argument("--check-bound", action="store_true",
                       help="measure each output's worst distance to the surface / tolerance into the "
                            "manifest (NumPy, on a sample of its triangles; .ply and .npz with --no-weld, "
                            "not with --split)")
    batch.add_argument("--verify", action="store_true",
                       help="measure each output's worst surface-to-mesh distance / tolerance on the device "
                            "(as tessellate --verify) into the manifest (not with --split)")
    batch.add_argument("-o", "--output", required=True, metavar="OUTDIR", help="output folder")
    batch.add_argument("-q", "--quiet", action="store_true", help="no progress bar or summary on success")

    bench = commands.add_parser(
        "bench", help="benchmark suite: the CudaTess paper's Tables 1 and 2 on one device",
        parents=[verbose],
        description="Generate the benchmark scenes (0.5 px, 1024x768, a camera each), time every "
                    "stage on one OpenCL device and print the paper-style tables (cltess.bench).",
    )
    bench.add_argument("scenes", nargs="*", metavar="SCENES",
                       help="scene keys or groups (all, bezier, pn, small); default all")
    bench.add_argument("--device", metavar="NAME", help="OpenCL device, as for tessellate")
    bench.add_argument("--repeat", type=_factor, default=3, metavar="N",
                       help="timed runs per scene and variant; the median is reported (default 3)")
    bench.add_argument("--warmup", type=int, default=1, metavar="N", help="untimed runs first (default 1)")
    bench.add_argument("--no-baseline", action="store_true", help="skip the NumPy evaluation baseline")
    bench.add_argument("--json", metavar="OUT", help="also write every measurement to this JSON file")
    bench.add_argument("-q", "--quiet", action="store_true", help="no progress lines on stderr")
    return parser


# --------------------------------------------------------------------------- commands


def cmd_devices(args) -> int:
    """One line per platform, one per device under it with its probe verdict; '*' marks the
    default device."""
    from cltess.backends.opencl.share_cuda import sharing_apis
    from cltess.device import DEVICE_ENV_VAR, DeviceError, default_device_info, list_devices, probe_device

    devices = list_devices()
    try:
        default = default_device_info(devices)
    except DeviceError:
        if not devices:
            raise  # no platform: the install hint
        if os.environ.get(DEVICE_ENV_VAR):
            print(f"{PROG}: warning: ${DEVICE_ENV_VAR}={os.environ.get(DEVICE_ENV_VAR)!r} names no usable "
                  "device below, so there is no default", file=sys.stderr)
        else:
            print(f"{PROG}: warning: no device below is usable, so there is no default; see the "
                  "README's Troubleshooting", file=sys.stderr)
        default = None
    platform = None
    for info in devices:
        if info.platform != platform:
            platform = info.platform
            print(f"{info.platform} ({info.platform_vendor}; {info.platform_version})")
        marker = "*" if default is not None and info.device == default.device else " "
        memory_gib = info.global_memory_bytes / 2**30
        probe = probe_device(info)
        shares = sharing_apis(info.device) if not isinstance(info.device, str) else []
        shares_with = f"  shares with {', '.join(shares)}" if shares else ""  # Session(share=...)
        print(f"  {marker} {info.name}  [{info.type}]  {info.version}  "
              f"{info.compute_units} compute units  {memory_gib:.1f} GiB{shares_with}  {probe.describe()}")
        if args.verbose and probe.log:
            print("      " + probe.log.strip().replace("\n", "\n      "))
    return EXIT_OK


def _check_output_path(path: Path) -> None:
    check_extension(path)
    if path.is_dir():
        raise UsageError(f"{path}: is a directory")
    if not path.parent.is_dir():
        raise UsageError(f"{path}: folder {str(path.parent)!r} does not exist")


def _inputs(scene_path: Path) -> list[Path]:
    """The scene file and, for a JSON scene, the object files it names (as far as it parses)."""
    import json
    import stat

    inputs = [scene_path]
    if scene_path.suffix.lower() == ".json":
        try:
            if not stat.S_ISREG(os.stat(scene_path).st_mode):
                return inputs  # a device or FIFO: never read here; the reader refuses it
            objects = json.loads(scene_path.read_text()).get("objects", [])
            inputs += [scene_path.parent / obj["file"] for obj in objects
                       if isinstance(obj, dict) and isinstance(obj.get("file"), str)]
        except (OSError, ValueError, AttributeError, TypeError, RecursionError):
            pass  # the reader reports what is wrong with it
    return inputs


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b) or a.resolve() == b.resolve()
    except (OSError, RuntimeError, ValueError):
        return False


def _refuse_overwriting_an_input(output: Path, scene: str) -> None:
    for source in _inputs(Path(scene)):
        if _same_file(output, source):
            raise UsageError(f"{output}: is an input of this run ({source}); choose another -o")


def _check_emit(args) -> None:
    """--emit by-level runs the semi-uniform patterns' templates: refuse it for another pattern."""
    if args.emit == "by-level" and args.pattern != "semi-uniform":
        raise UsageError("--emit by-level needs --pattern semi-uniform (the levels' templates are that pattern's)")


def _prepare_scene(args, loaded=None):
    """Load, check and orient the scene; turn a relative --eps into a distance.  Returns (scene,
    orientation report or None, the tolerance as the summary shows it).  ``loaded(scene)`` is
    called once the scene is read and checked, before it is oriented (orientation changes no
    bounding box, camera or coordinate magnitude the checks look at)."""
    _check_emit(args)
    from cltess.io import load_scene
    from cltess.limits import eps_below_float32

    scene = load_scene(args.scene, crease_angle=args.crease_angle)
    if args.pixels is not None and scene.camera is None and getattr(args, "camera_path", None) is None:
        raise UsageError(f"{args.scene}: --pixels needs a camera in the scene (use a .json scene "
                         "with a \"camera\", or give --eps)")
    eps_text = None
    if args.eps is not None:
        value, relative = float(args.eps), isinstance(args.eps, Percent)
        args.eps = value / 100 * scene.diagonal if relative else value
        eps_text = f"eps {args.eps:.6g}" + (f" = {value:g}% of the diagonal {scene.diagonal:.6g}" if relative else "")
        if not args.eps > 0:
            raise UsageError(f"{args.scene}: --eps {value:g}% of the scene's diagonal is 0 (a scene of one point)")
        too_fine = eps_below_float32(scene, args.eps)
        if too_fine:
            print(f"{PROG}: warning: {args.scene}: {too_fine}", file=sys.stderr)
    if args.pixels is not None and scene.camera is not None:  # per patch: shrinks with depth (issue 9 item 3)
        from cltess.bound import tolerances_below_float32

        too_fine = tolerances_below_float32(scene, pixels=args.pixels, sharp_edges=getattr(args, "sharp_edges", "straight"))
        if too_fine:
            print(f"{PROG}: warning: {args.scene}: {too_fine}", file=sys.stderr)
    tolerance = eps_text if args.eps is not None else f"{args.pixels:g} px"
    if loaded is not None:
        loaded(scene)
    orientation = None
    if args.orient:
        from cltess.orient import orient_scene

        scene, orientation = orient_scene(scene)
    return scene, orientation, tolerance


def _check_preview(name: str, scene: str) -> Path:
    path = Path(name)
    if path.suffix.lower() != ".png":
        raise UsageError(f"{path}: a preview is a .png image")
    if path.is_dir() or not path.parent.is_dir():
        raise UsageError(f"{path}: is a directory" if path.is_dir() else
                         f"{path}: folder {str(path.parent)!r} does not exist")
    _refuse_overwriting_an_input(path, scene)
    return path


def _progress(args, what: str):
    """A progress callback (stage, done, total) drawing a tqdm bar on stderr that appears only
    for runs longer than about a second, or None: with -q, or when stderr is not a terminal."""
    if args.quiet or not sys.stderr.isatty():
        return None, contextlib.nullcontext()
    from tqdm import tqdm

    bar = tqdm(total=1, desc=what, delay=PROGRESS_DELAY, file=sys.stderr, leave=False, unit="patch",
               bar_format="{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} [{elapsed}]")

    def update(stage, done, total):
        if bar.total != total:
            bar.total = total
        bar.set_description_str(f"{what}: {stage}", refresh=False)
        bar.n = done
        bar.refresh()

    return update, bar


def cmd_tessellate(args) -> int:
    """Load, tessellate, export, summarise."""
    if args.camera_path is not None or args.silhouette is not None:
        _level_options(args, None)  # refuses --bound integral and error-hull
        return cmd_tessellate_frames(args)
    from cltess.device import pick_device
    from cltess.io.export import estimate_output_bytes, estimate_write_seconds
    from cltess.limits import OutputTooLarge
    from cltess.stream import tessellate_to_file

    output = Path(args.output)
    _check_output_path(output)
    _refuse_overwriting_an_input(output, args.scene)
    weld = args.weld if args.weld is not None else output.suffix.lower() in MESH_FORMATS
    if args.uv == "seam" and not weld:
        raise UsageError("--uv seam is for welded output (per-patch output keeps every vertex's (u, v))")
    if args.uv == "seam" and output.suffix.lower() not in (".ply", ".obj", ".npz"):
        raise UsageError(f"{output}: --uv seam can be written to .ply, .obj or .npz only")
    preview = _check_preview(args.preview, args.scene) if args.preview else None
    from cltess.pipeline import Tessellator  # lazy: builds OpenCL programs

    # The scene is read and checked first; then OpenCL starts on a thread (platforms, device,
    # context, and the programs the plan will want) while this one orients the scene.  Not while
    # the scene is read: Python's warning filters are one global list, and the text parser's
    # catch_warnings(simplefilter("error")) (io/text.py, where long double is not x87) turned
    # pyopencl's compiler-output warning on the other thread into an exception (a KeyError from
    # pyopencl's cache).  Orientation changes no warning filter.
    opening, options = [], {}

    def loaded(scene):
        options.update({"sharp_edges": args.sharp_edges} if scene.meshes else {})
        options.update(_level_options(args, scene))
        options.update(eps=args.eps, pixels=args.pixels, max_factor=args.max_factor,
                       pattern=PATTERN_CHOICES[args.pattern], max_level=args.max_level, emit=EMIT_CHOICES[args.emit])
        opening.append(_in_background(lambda: _opened(Tessellator(device=pick_device(args.device)), scene, options)))

    try:
        scene, orientation, eps_text = _prepare_scene(args, loaded)
    except BaseException:
        for thread in opening:
            thread.join()  # nothing left running; the scene's error is the one reported
        raise
    tessellator = opening[0].result()
    def before_writing(plan):
        """After stages 1-3, before anything big exists: warn, estimate, refuse."""
        _warn_saturated(int(plan.stats.get("saturated", 0)), args)
        size = estimate_output_bytes(output.suffix, plan.num_vertices, plan.num_indices // 3, weld,
                                     args.uv == "seam")
        seconds = estimate_write_seconds(output.suffix, size, plan.num_indices // 3, weld)
        what = (f"about {_human(size)} ({plan.num_vertices} vertices{' before welding' if weld else ''}, "
                f"{plan.num_indices // 3} triangles; about {_duration(seconds)} to write)")
        if args.max_output is not None and size > args.max_output:
            raise OutputTooLarge(f"{output}: the output would be {what}, more than --max-output "
                                 f"{_human(args.max_output)}; check --eps (its units: the scene's diagonal is "
                                 f"{scene.diagonal:.6g}), or raise --max-output (or give --max-output none)")
        if size >= NOTE_OUTPUT_SIZE and not args.quiet:
            print(f"{PROG}: writing {what} to {output}", file=sys.stderr)

        if progress is not None:
            progress(f"writing {_human(size)}", 0, plan.num_patches)

    drawing = None
    if preview is not None:
        from cltess.render import Rasteriser, view_for

        drawing = Rasteriser(view_for(scene))
    progress, bar = _progress(args, str(output))
    with bar:
        result = tessellate_to_file(
            tessellator, scene, output, max_memory_bytes=args.max_memory, weld=weld, uv=args.uv,
            on_plan=before_writing, progress=progress,
            on_batch=(lambda batch: drawing.add(batch.positions, batch.triangles, normals=batch.normals))
            if drawing else None,
            forward_differencing=not args.no_fd, verify=args.verify, **options)
    if drawing is not None:
        from cltess.render import write_png

        write_png(preview, drawing.image())
    if result.batches > 1:
        result.stats["batches"] = result.batches
    if args.check_t_junctions:
        result.stats["t_junctions"] = _count_t_junctions(output, weld)
    if orientation is not None:
        result.stats.update(orientation.stats())

    if result.stats.get("verify_ratio", 0.0) > 1.0:
        print(f"{PROG}: warning: {args.scene}: measured deviation {result.stats['verify_ratio']:.4g} times the "
              f"tolerance at patch {result.stats['verify_patch']} (--verify)", file=sys.stderr)
    if not int(result.stats.get("triangles", 0)):
        reasons = [f"{result.stats[key]} {label}" for key, label in
                   (("culled", "outside the camera's view"), ("folded_triangles", "folded mesh triangles"))
                   if result.stats.get(key)]
        print(f"{PROG}: warning: {output}: the mesh has no triangles (of {result.stats.get('patches', 0)} "
              f"patches{': ' + ', '.join(reasons) if reasons else ''})", file=sys.stderr)
    sharp = int(result.stats.get("sharp_edges", 0))
    if sharp and args.sharp_edges == "keep":
        print(f"{PROG}: warning: {sharp} sharp mesh edge{'s' if sharp > 1 else ''} keep each side's own PN "
              "curve, so the mesh may crack there; --sharp-edges straight or average keeps it closed",
              file=sys.stderr)
    if not args.quiet:
        print(format_summary(result.stats, result.stage_ms, scene=args.scene, device=tessellator.device.name.strip(),
                             tolerance=eps_text, output=output if preview is None else f"{output}, {preview}"))
    return EXIT_OK


def _opened(tessellator, scene, options: dict):
    """The tessellator, with the programs ``plan(scene, **options)`` will want already built: a
    warm-up on the OpenCL thread (``Tessellator.compose``, about 0.09 s for the 30k-patch
    scene); whatever fails here fails again in the plan, which reports it."""
    from cltess.request import Request

    try:
        tessellator.compose(scene, Request.of(**options))
    except Exception:  # noqa: BLE001 (the plan composes again and reports it)
        pass
    return tessellator


class _in_background:
    """``make()`` on a thread started now; ``result()`` joins it and returns its value or
    raises its exception (``join()``: waits only)."""

    def __init__(self, make):
        self._value, self._error = None, None
        self._thread = threading.Thread(target=self._run, args=(make,), name="cltess-opencl", daemon=True)
        self._thread.start()

    def _run(self, make):
        try:
            self._value = make()
        except BaseException as error:  # handed to result()
            self._error = error

    def join(self) -> None:
        self._thread.join()

    def result(self):
        self._thread.join()
        if self._error is not None:
            raise self._error
        return self._value


def cmd_tessellate_frames(args) -> int:
    """--camera-path / --silhouette: one tessellation per camera (cltess/frames.py)."""
    from cltess.device import pick_device
    from cltess.frames import FramesError, check_options, frame_path, run_frames
    from cltess.io.camera_path import read_camera_path

    cameras = read_camera_path(args.camera_path) if args.camera_path is not None else None
    try:
        what = check_options(args, len(cameras) if cameras else 1)
        first = Path(args.output) if what == "summary" else frame_path(args.output, 0)
    except FramesError as error:
        raise UsageError(str(error)) from None
    if what == "meshes":
        _check_output_path(first)
    elif not first.parent.is_dir():
        raise UsageError(f"{first}: folder {str(first.parent)!r} does not exist")
    for index in range(len(cameras) if cameras else 1):
        _refuse_overwriting_an_input(Path(args.output) if what == "summary" else frame_path(args.output, index),
                                     args.scene)
    scene, orientation, eps_text = _prepare_scene(args)
    if cameras is None:
        if scene.camera is None:
            raise UsageError(f"{args.scene}: --silhouette needs a camera: a .json scene with a \"camera\", "
                             "or --camera-path")
        cameras = [scene.camera]
    device = pick_device(args.device)
    from cltess.pipeline import Tessellator  # lazy: builds OpenCL programs

    args.pattern_name = PATTERN_CHOICES[args.pattern]
    weld = args.weld if args.weld is not None else first.suffix.lower() in MESH_FORMATS
    say = (lambda text: None) if args.quiet else (lambda text: print(text))
    summaries = run_frames(args, scene, cameras, Tessellator(device=device), weld, say)
    if not args.quiet:
        total = sum(s["device_ms"] for s in summaries)
        print(f"{len(summaries)} frame{'s' if len(summaries) != 1 else ''} of {args.scene} on "
              f"{device.name.strip()} ({eps_text}): {total:.2f} ms on the device in all"
              + (f"; summary in {args.output}" if what == "summary" else ""))
    return EXIT_OK


def cmd_render(args) -> int:
    """Tessellate in memory-bounded batches, draw each into one z-buffer, write the PNG."""
    from cltess.device import pick_device
    from cltess.render import Rasteriser, factor_colours, view_for, write_png
    from cltess.stream import COPIES_IN_FLIGHT, default_budget

    output = _check_preview(args.output, args.scene)
    scene, orientation, tolerance = _prepare_scene(args)
    device = pick_device(args.device)

    from cltess.pipeline import Tessellator  # lazy: builds OpenCL programs

    tessellator = Tessellator(device=device)
    mesh_options = {"sharp_edges": args.sharp_edges} if scene.meshes else {}
    mesh_options.update(_level_options(args, scene))
    plan = tessellator.plan(scene, eps=args.eps, pixels=args.pixels, max_factor=args.max_factor,
                            pattern=PATTERN_CHOICES[args.pattern], max_level=args.max_level,
                            emit=EMIT_CHOICES[args.emit], **mesh_options)
    _warn_saturated(int(plan.stats.get("saturated", 0)), args)
    budget = args.max_memory or default_budget(tessellator.device)
    drawing = Rasteriser(view_for(scene, *args.size))
    progress, bar = _progress(args, str(output))
    with bar:
        for first, last in plan.batch_ranges(max(budget // COPIES_IN_FLIGHT, 1)):
            batch = tessellator.emit(plan, first, last, not args.no_fd)
            colours = None
            if args.color == "factor" and batch.num_triangles:
                patch = batch.patch_ids[batch.triangles[:, 0]] - first
                colours = factor_colours(batch.factors, patch, args.max_factor)
            drawing.add(batch.positions, batch.triangles, colours, batch.normals)
            if progress is not None:
                progress("drawing", last, plan.num_patches)
    image = drawing.image()
    write_png(output, image)
    if not args.quiet:
        stats = dict(plan.stats, **(orientation.stats() if orientation else {}))
        print(format_summary(stats, {}, scene=args.scene, device=device.name.strip(), tolerance=tolerance,
                             output=f"{output} ({image.shape[1]}x{image.shape[0]})"))
    return EXIT_OK


def _level_options(args, scene) -> dict:
    """The SD-2 level-function options of a run (none unless --pattern sd2 or --level-function),
    and --bound integral or error-hull."""
    if args.level_function is not None and args.pattern == "transition":
        args.pattern = "sd2"  # --level-function implies it (transition is only the default)
    from cltess.request import TRIAL_BOUNDS

    if args.bound in TRIAL_BOUNDS and (args.pattern != "transition" or getattr(args, "camera_path", None) is not None
                                       or getattr(args, "silhouette", None) is not None):
        raise UsageError(f"--bound {args.bound} scales the transition pattern's factors once per run: it cannot be "
                         "used with --pattern other than transition, --level-function, --camera-path or --silhouette")
    if args.pattern != "sd2":
        return {"bound": args.bound} if args.bound in TRIAL_BOUNDS else {}
    return {"level_function": args.level_function, "level_factors": tuple(args.level_factors),
            "depth_map": args.depth_map, "silhouette_band": args.silhouette_band}


def _warn_saturated(saturated: int, args) -> None:
    if saturated:
        patches = "1 patch reaches" if saturated == 1 else f"{saturated} patches reach"
        verb = "does" if saturated == 1 else "do"
        cap = f"--max-factor {args.max_factor}" if args.pattern != "semi-uniform" else \
            f"--max-factor {args.max_factor} or 2^--max-level {args.max_level}"
        raise_it = "--max-factor" if args.pattern != "semi-uniform" else "them"
        print(f"{PROG}: warning: {patches} {cap} and {verb} not meet the error bound; raise {raise_it}",
              file=sys.stderr)


def _duration(seconds: float) -> str:
    if seconds < 1:
        return "a second"
    if seconds < 120:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.0f} min" if seconds < 7200 else f"{seconds / 3600:.0f} h"


def _human(size: int) -> str:
    """Bytes as 812 B, 3.4 MiB, 1.2 GiB."""
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if size >= scale:
            return f"{size / scale:.1f} {unit}"
    return f"{size} B"


def _count_t_junctions(output: Path, welded: bool) -> int | str:
    """T-junctions of the written mesh (cltess.checks.t_junctions), or why not: a per-patch
    .ply or .npz is read back with its object ids, a welded mesh through trimesh (one object)."""
    from cltess.batch import read_output
    from cltess.checks import t_junctions

    if welded:
        import numpy as np
        import trimesh

        mesh = trimesh.load(output, process=False, force="mesh")
        return len(t_junctions(np.asarray(mesh.vertices, np.float32), np.asarray(mesh.faces)))
    mesh = read_output(output)
    if mesh is None:
        return f"not checked ({output.suffix} is not read back; write .ply or .npz)"
    return len(t_junctions(mesh.positions, mesh.triangles, mesh.object_ids))


def verified_summary(stats: dict, tolerance: str) -> str:
    """The --verify line: the worst measured |S - mesh| / tolerance beside the requested one."""
    sampled = (f"every {stats['verify_stride']}-th triangle ({stats['verify_triangles']})"
               if stats["verify_stride"] > 1 else f"all {stats['verify_triangles']} triangles")
    return (f"worst |S(u,v) - mesh(u,v)| = {stats['verify_ratio']:.4f} x tolerance (requested {tolerance}) "
            f"at patch {stats['verify_patch']}, triangle {stats['verify_triangle']}; "
            f"{sampled} at {(stats['verify_order'] + 1) * (stats['verify_order'] + 2) // 2} points each, "
            f"{stats['verify_ms']:.1f} ms on the device")


def format_summary(stats: dict, stage_ms: dict, scene, device: str, tolerance: str, output) -> str:
    """The tessellate summary: counts, extra int stats, the semi-uniform level histogram, the
    T-junction count when checked, per-stage ms, output path."""
    rows = [
        ("scene", f"{scene}  ({tolerance}, device {device})"),
        ("patches", f"{stats.get('patches', '?')}  (culled {stats.get('culled', '?')}, "
                    f"saturated {stats.get('saturated', '?')})"),
        ("vertices", stats.get("vertices", "?")),
        ("triangles", stats.get("triangles", "?")),
    ]
    for name, value in stats.items():
        if name not in _MAIN_STATS + _HIDDEN_STATS and not name.startswith("verify_") \
                and isinstance(value, int) and not isinstance(value, bool):
            rows.append((name.replace("_", " "), value))
    if stats.get("patch_levels"):
        rows.append(("patch levels", ", ".join(f"{level}: {count}" for level, count in
                                               enumerate(stats["patch_levels"]) if count)))
    if isinstance(stats.get("t_junctions"), str):
        rows.append(("t junctions", stats["t_junctions"]))
    if "verify_ratio" in stats:
        rows.append(("verified", verified_summary(stats, tolerance)))
    if stage_ms:
        rows.append(("stage ms", ", ".join(f"{name} {ms:.3f}" for name, ms in stage_ms.items())))
    rows.append(("wrote", output))
    width = max(len(label) for label, _ in rows) + 2
    return "\n".join(f"{label:<{width}}{value}" for label, value in rows)


def cmd_bench(args) -> int:
    """Run the benchmark suite on one device and print its tables (cltess.bench)."""
    from cltess import bench
    from cltess.device import pick_device

    try:
        bench.resolve_scenes(args.scenes)
    except ValueError as error:
        raise UsageError(str(error)) from None
    if args.warmup < 0:
        raise UsageError(f"--warmup must be >= 0, got {args.warmup}")
    if args.json and not Path(args.json).parent.is_dir():
        raise UsageError(f"{args.json}: folder {str(Path(args.json).parent)!r} does not exist")
    device = pick_device(args.device)
    command = " ".join([PROG, "bench", *sys.argv[2:]]) if sys.argv[1:2] == ["bench"] else None
    record = bench.run_suite(args.scenes, device=device, repeat=args.repeat, warmup=args.warmup,
                             progress=bench.Progress(enabled=not args.quiet),
                             numpy_baseline=not args.no_baseline, command=command)
    print(bench.format_tables(record))
    if args.json:
        bench.write_json(record, args.json)
    return EXIT_OK


EXIT_SOME_FAILED = 3  # batch: some inputs failed


def cmd_batch(args) -> int:
    """Tessellate many inputs on a Dask cluster (cltess.batch); exit 3 if any input failed."""
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise UsageError("cltess batch needs Dask: pip install 'cltess[dist]'") from None
    from cltess.batch import BatchOptions, Progress, summarize, tessellate_files
    from cltess.device import DeviceError

    if args.scheduler and args.workers:
        raise UsageError("--workers sizes the local cluster; it cannot be used with --scheduler")
    _check_emit(args)
    options = BatchOptions(eps=args.eps, pixels=args.pixels, max_factor=args.max_factor,
                           forward_differencing=not args.no_fd, sharp_edges=args.sharp_edges,
                           format=args.format, device=args.device, max_memory=args.max_memory,
                           check_bound=args.check_bound, weld=args.weld, orient=args.orient, verify=args.verify,
                           pattern=PATTERN_CHOICES[args.pattern], max_level=args.max_level,
                           emit=EMIT_CHOICES[args.emit])
    try:
        rows = tessellate_files(args.inputs, args.output, options, scheduler=args.scheduler,
                                workers=args.workers, split=args.split, progress=Progress(enabled=not args.quiet))
    except (OSError, TimeoutError) as error:
        if args.scheduler and not getattr(error, "filename", None):
            raise DeviceError(f"cannot reach the Dask scheduler at {args.scheduler}: {error}") from None
        raise
    manifest = Path(args.output) / "manifest.json"
    counts = summarize(rows)
    saturated = sum(1 for row in rows if row.get("saturated"))
    if saturated:
        print(f"{PROG}: warning: {saturated} input{'s' if saturated > 1 else ''} have patches that reach "
              f"--max-factor {args.max_factor} and do not meet the error bound; raise --max-factor", file=sys.stderr)
    if not args.quiet:
        print(f"{counts['done']} done, {counts['skipped']} up to date, {counts['failed']} failed; "
              f"manifest {manifest}")
    failed = [row for row in rows if row["status"] == "failed"]
    if failed:
        shown = "".join(f"\n  {row['error']}" if row["input"] in str(row["error"])
                        else f"\n  {row['input']}: {row['error']}" for row in failed[:10])
        more = f"\n  ... and {len(failed) - 10} more" if len(failed) > 10 else ""
        print(f"{PROG}: error: {len(failed)} of {len(rows)} inputs failed (every row is in {manifest}):"
              f"{shown}{more}", file=sys.stderr)
        return EXIT_SOME_FAILED
    return EXIT_OK


_COMMANDS = {"devices": cmd_devices, "tessellate": cmd_tessellate, "render": cmd_render, "bench": cmd_bench,
             "batch": cmd_batch}


# --------------------------------------------------------------------------- entry point


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (the console script exits with it)."""
    import pyopencl as cl

    from cltess.device import DeviceError
    from cltess.limits import OutputTooLarge
    from cltess.scene import SceneError

    args = None
    try:
        with _terminate_like_ctrl_c():
            args = build_parser().parse_args(argv)
            _RAN[:] = [args.command]
            if not args.verbose:  # pyopencl's "non-empty compiler output" means nothing to a user
                warnings.filterwarnings("ignore", category=cl.CompilerWarning)
            return _COMMANDS[args.command](args)
    except SystemExit as done:  # --help / --version
        return done.code if isinstance(done.code, int) else EXIT_OK
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Terminated as stop:
        print(f"{PROG}: {signal.Signals(stop.signum).name}: stopped, nothing written", file=sys.stderr)
        return 128 + stop.signum
    except OutputTooLarge as error:  # a cap or limit the user chose: before MemoryError
        return _fail(error, EXIT_USAGE)
    except DeviceError as error:
        if error.log and args is not None and args.verbose:
            print(error.log, file=sys.stderr)
        return _fail(error, EXIT_DEVICE)
    except (cl.Error, MemoryError) as error:
        return _fail(error, EXIT_DEVICE)
    except UsageError as error:
        if error.usage:
            print(error.usage, file=sys.stderr)
        return _fail(error, EXIT_USAGE)
    except (SceneError, ValueError) as error:
        return _fail(error, EXIT_USAGE)
    except OSError as error:  # unreadable scene, unwritable output
        message = f"{error.filename}: {error.strerror}" if error.filename and error.strerror else str(error)
        return _fail(message, EXIT_USAGE)
    except RuntimeError as error:  # e.g. an OpenCL program that failed to build
        return _fail(error, EXIT_DEVICE)


#: The command main() ran last (for ``run``).
_RAN: list = []
#: Commands after which the process exits at once (``os._exit``): their files are complete
#: (fsync'd, renamed) when main returns, and what Python's shutdown would still do (collect
#: every object, release the OpenCL runtime's buffers, programs and threads) took 0.1-0.3 s
#: of the 30k-patch PLY's wall time (bench/RESULTS.md, "Issue 15: the 30k-patch PLY").  Not
#: ``batch``: its Dask cluster is closed by handlers at exit.
QUICK_EXIT_COMMANDS = ("tessellate", "render", "devices")


def run() -> None:
    """The ``cltess`` console command and ``python -m cltess``: ``main()``, then the exit."""
    code = main()
    if _RAN and _RAN[0] in QUICK_EXIT_COMMANDS and os.environ.get("CLTESS_QUICK_EXIT", "1") != "0":
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        except OSError:  # e.g. a closed pipe: let Python's own exit report it
            sys.exit(code)
        os._exit(code)
    sys.exit(code)


class Terminated(BaseException):
    """SIGTERM or SIGHUP arrived: unwinds like Ctrl-C (KeyboardInterrupt), so that the atomic
    export removes its temporary file, and main exits with 128 + the signal number."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


@contextlib.contextmanager
def _terminate_like_ctrl_c():
    """SIGTERM and SIGHUP raise Terminated for as long as the command runs (main thread only;
    the previous handlers come back after)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, frame):
        raise Terminated(signum)

    signals = [signal.SIGTERM] + ([signal.SIGHUP] if hasattr(signal, "SIGHUP") else [])
    previous = {signum: signal.signal(signum, stop) for signum in signals}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _fail(error, code: int) -> int:
    print(f"{PROG}: error: {error}", file=sys.stderr)
    return code

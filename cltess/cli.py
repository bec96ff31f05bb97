"""The ``cltess`` command line.

    cltess devices [--verbose]
    cltess tessellate SCENE (--eps E | --pixels PX) [--no-fd] [--max-factor N] [--max-memory SIZE]
                      [--sharp-edges {straight,average,keep}] [--device NAME] [--quiet] -o OUT
    cltess bench [SCENES...] [--device NAME] [--repeat N] [--warmup N] [--no-baseline] [--json OUT]
    cltess batch INPUTS... (--eps E | --pixels PX) -o OUTDIR [--format {ply,obj,npz}] [--split N]
                 [--scheduler ADDRESS] [--workers N] [tessellate's options]

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

from cltess.export import SUPPORTED_EXTENSIONS, check_extension

PROG = "cltess"
DEFAULT_MAX_FACTOR = 64
EXIT_OK, EXIT_DEVICE, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130

#: The stats printed on their own summary lines; any other int stat is listed after them.
_MAIN_STATS = ("patches", "culled", "saturated", "vertices", "triangles")


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

    run = commands.add_parser(
        "tessellate", help="tessellate a scene and export the mesh", parents=[verbose],
        description="Tessellate a scene (.bpt, .bez or .json, or a triangle mesh as PN triangles: "
                    ".obj, .ply, .stl, .off, .glb, .gltf) and write the mesh "
                    f"({', '.join(SUPPORTED_EXTENSIONS)}).",
    )
    run.add_argument("scene", metavar="SCENE", help="scene file: .bpt, .bez, .json or a triangle mesh")
    tolerance = run.add_mutually_exclusive_group(required=True)
    tolerance.add_argument("--eps", type=_positive_float, metavar="E",
                           help="object-space tolerance: max distance from surface to mesh")
    tolerance.add_argument("--pixels", type=_positive_float, metavar="PX",
                           help="screen-space tolerance in pixels (needs a camera in the scene)")
    run.add_argument("--no-fd", action="store_true",
                     help="evaluate every vertex directly instead of by forward differencing")
    run.add_argument("--max-factor", type=_max_factor, default=DEFAULT_MAX_FACTOR, metavar="N",
                     help=f"largest edge factor per patch (default {DEFAULT_MAX_FACTOR})")
    run.add_argument("--device", metavar="NAME",
                     help="OpenCL device: substring of platform or device name (default $CLTESS_DEVICE, "
                          "else the first usable CPU device; see 'cltess devices')")
    run.add_argument("--max-memory", type=_memory_size, metavar="SIZE",
                     help="cap on the memory the output may take at once (e.g. 512M, 2G); a larger "
                          "output is tessellated in batches streamed to the file (.ply, .obj). "
                          "Default: half the device's memory")
    run.add_argument("--sharp-edges", choices=("straight", "average", "keep"), default="straight",
                     help="meshes: an edge whose two sides have different vertex normals becomes a "
                          "straight crease (default), a curve from the averaged normals, or keeps "
                          "each side's own PN curve (may crack)")
    run.add_argument("-o", "--output", required=True, metavar="OUT",
                     help=f"output mesh: {', '.join(SUPPORTED_EXTENSIONS)}")
    run.add_argument("--verify", action="store_true",
                     help="after tessellating, measure on the device the worst distance between surface and "
                          "mesh at equal (u, v), at 28 points in every triangle (every k-th triangle above "
                          "4 million), and print it beside the requested tolerance")
    run.add_argument("-q", "--quiet", action="store_true", help="print nothing on success (warnings still go to stderr)")

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
    batch.add_argument("--sharp-edges", choices=("straight", "average", "keep"), default="straight",
                       help="as for tessellate")
    batch.add_argument("--device", metavar="NAME",
                       help="OpenCL device of every worker (default: one GPU per worker where there are "
                            "several, else the device tessellate would use)")
    batch.add_argument("--max-memory", type=_memory_size, metavar="SIZE",
                       help="output a worker may hold at once (default: half its device's memory)")
    batch.add_argument("--format", choices=[e[1:] for e in SUPPORTED_EXTENSIONS], default="ply",
                       help="output format (default ply): OUTDIR/NAME.EXT for an input NAME.EXT")
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
                            "manifest (NumPy, on a sample of its triangles; .ply and .npz, not with --split)")
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
        print(f"  {marker} {info.name}  [{info.type}]  {info.version}  "
              f"{info.compute_units} compute units  {memory_gib:.1f} GiB  {probe.describe()}")
        if args.verbose and probe.log:
            print("      " + probe.log.strip().replace("\n", "\n      "))
    return EXIT_OK


def _check_output_path(path: Path) -> None:
    check_extension(path)
    if path.is_dir():
        raise UsageError(f"{path}: is a directory")
    if not path.parent.is_dir():
        raise UsageError(f"{path}: folder {str(path.parent)!r} does not exist")


def cmd_tessellate(args) -> int:
    """Load, tessellate, export, summarise."""
    from cltess.device import pick_device
    from cltess.formats import load_scene
    from cltess.limits import eps_below_float32
    from cltess.stream import tessellate_to_file

    output = Path(args.output)
    _check_output_path(output)
    scene = load_scene(args.scene)
    if args.pixels is not None and scene.camera is None:
        raise UsageError(f"{args.scene}: --pixels needs a camera in the scene (use a .json scene "
                         "with a \"camera\", or give --eps)")
    if args.eps is not None:
        too_fine = eps_below_float32(scene, args.eps)
        if too_fine:
            print(f"{PROG}: warning: {args.scene}: {too_fine}", file=sys.stderr)
    device = pick_device(args.device)

    from cltess.pipeline import Tessellator  # lazy: builds OpenCL programs

    tessellator = Tessellator(device=device)
    mesh_options = {"sharp_edges": args.sharp_edges} if scene.meshes else {}
    result = tessellate_to_file(tessellator, scene, output, max_memory_bytes=args.max_memory, eps=args.eps,
                                pixels=args.pixels, max_factor=args.max_factor,
                                forward_differencing=not args.no_fd, verify=args.verify, **mesh_options)
    if result.batches > 1:
        result.stats["batches"] = result.batches

    saturated = int(result.stats.get("saturated", 0))
    if saturated:
        patches = "1 patch reaches" if saturated == 1 else f"{saturated} patches reach"
        verb = "does" if saturated == 1 else "do"
        print(f"{PROG}: warning: {patches} --max-factor {args.max_factor} and {verb} not meet the error "
              "bound; raise --max-factor", file=sys.stderr)
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
        tolerance = f"eps {args.eps:g}" if args.eps is not None else f"{args.pixels:g} px"
        print(format_summary(result.stats, result.stage_ms, scene=args.scene, device=device.name.strip(),
                             tolerance=tolerance, output=output))
    return EXIT_OK


def verified_summary(stats: dict, tolerance: str) -> str:
    """The --verify line: the worst measured |S - mesh| / tolerance beside the requested one."""
    sampled = (f"every {stats['verify_stride']}-th triangle ({stats['verify_triangles']})"
               if stats["verify_stride"] > 1 else f"all {stats['verify_triangles']} triangles")
    return (f"worst |S(u,v) - mesh(u,v)| = {stats['verify_ratio']:.4f} x tolerance (requested {tolerance}) "
            f"at patch {stats['verify_patch']}, triangle {stats['verify_triangle']}; "
            f"{sampled} at {(stats['verify_order'] + 1) * (stats['verify_order'] + 2) // 2} points each, "
            f"{stats['verify_ms']:.1f} ms on the device")


def format_summary(stats: dict, stage_ms: dict, scene, device: str, tolerance: str, output) -> str:
    """The tessellate summary: counts, extra int stats, per-stage ms, output path."""
    rows = [
        ("scene", f"{scene}  ({tolerance}, device {device})"),
        ("patches", f"{stats.get('patches', '?')}  (culled {stats.get('culled', '?')}, "
                    f"saturated {stats.get('saturated', '?')})"),
        ("vertices", stats.get("vertices", "?")),
        ("triangles", stats.get("triangles", "?")),
    ]
    for name, value in stats.items():
        if name not in _MAIN_STATS and not name.startswith("verify_") and isinstance(value, int) \
                and not isinstance(value, bool):
            rows.append((name.replace("_", " "), value))
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
    options = BatchOptions(eps=args.eps, pixels=args.pixels, max_factor=args.max_factor,
                           forward_differencing=not args.no_fd, sharp_edges=args.sharp_edges,
                           format=args.format, device=args.device, max_memory=args.max_memory,
                           check_bound=args.check_bound, verify=args.verify)
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


_COMMANDS = {"devices": cmd_devices, "tessellate": cmd_tessellate, "bench": cmd_bench, "batch": cmd_batch}


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

"""Batch tessellation on Dask (issue 17): many scenes, or one huge scene, over many workers.

Both run on a ``dask.distributed`` cluster: a ``LocalCluster`` of worker processes sized to the
machine, or an existing scheduler given by its address.  Each worker process holds one OpenCL
device (one GPU per worker where a host has several, ``worker_device``) and one Tessellator,
kept for all the tasks it runs.

- :func:`tessellate_files`: one task per input file; each writes its own output (atomically,
  ``io.writing.atomic_write``) and returns its manifest row.  A bad input fails its own row only.
  The manifest (``OUTDIR/manifest.json``) records the options and each input's size, mtime and
  SHA-256, so a rerun skips the inputs whose output is up to date.
- :func:`tessellate_split`: one scene across the workers.  Stages 1-3 run once, on one worker
  (``Tessellator.plan``; read back with ``Plan.to_host``: final factors, 16 bytes a patch, and the
  vertex and index offsets), and the plan is copied to every worker.  Stages 4-5 then run per
  range of patches (``Tessellator.upload_plan`` + ``emit``): each range writes its PLY vertex
  records and face records as two part files.  Triangles number the vertices globally
  (``Tessellator.tessellate_in_batches``), so the header followed by the vertex parts and then
  the face parts, in order, is byte for byte the file one process writes.

The part files and the outputs are written by the workers, so on a real cluster ``OUTDIR`` must
be on a file system that the workers and this process share.
"""
from __future__ import annotations

import contextlib
import glob
import hashlib
import json
import logging
import os
import shutil
import sys
import tempfile
import time
import warnings
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from .io.export import MESH_FORMATS, SUPPORTED_EXTENSIONS
from .io.ply import ply_face_records, ply_header, ply_vertex_records
from .io.writing import atomic_write
from .io.meshes import MESH_EXTENSIONS
from .criteria.base import DEFAULT_MAX_FACTOR
from .patterns.semi_uniform import DEFAULT_MAX_LEVEL

MANIFEST_NAME = "manifest.json"
MANIFEST_VERSION = 1
PARTS_PER_WORKER = 4  # ranges per worker in a split run: some slack for uneven ranges
SCENE_EXTENSIONS = (".bpt", ".bez", ".json") + MESH_EXTENSIONS  # what a folder input takes (formats.load_scene)
STAGE_COLUMNS = ("factors", "crack_free", "counts", "vertices", "indices")
CONNECT_TIMEOUT_S = 30

# --------------------------------------------------------------------------- options and inputs


@dataclass(frozen=True)
class BatchOptions:
    """The tessellation options of a batch, as for ``cltess tessellate``; ``format`` is the
    output extension without the dot (ply, obj, npz), ``device`` a ``--device`` name or None
    (each worker picks its own: ``worker_device``), ``max_memory`` the output bytes a worker may
    hold at once (None: half its device's memory)."""

    eps: float | None = None
    pixels: float | None = None
    max_factor: int = DEFAULT_MAX_FACTOR
    forward_differencing: bool = True
    sharp_edges: str = "straight"
    format: str = "ply"
    device: str | None = None
    max_memory: int | None = None
    check_bound: bool = False  # measure each output's worst error / tolerance (cltess.bound)
    weld: bool | None = None  # as tessellate --weld: None welds the mesh formats (MESH_FORMATS)
    orient: bool = True  # as tessellate --orient (cltess.orient)
    verify: bool = False  # measure it on the device (Tessellator.verify): verify_ratio, verify_patch
    pattern: str | None = None  # as tessellate --pattern: a pattern or family name (Request.pattern)
    max_level: int = DEFAULT_MAX_LEVEL  # as tessellate --max-level (semi-uniform)
    emit: str = "per_patch"  # as tessellate --emit (Request.emit)

    def __post_init__(self):
        if (self.eps is None) == (self.pixels is None):
            raise ValueError("give exactly one of eps (object space) and pixels (screen space)")
        if f".{self.format}" not in SUPPORTED_EXTENSIONS:
            raise ValueError(f"unknown output format {self.format!r}; "
                             f"supported: {', '.join(e[1:] for e in SUPPORTED_EXTENSIONS)}")
        if self.check_bound and self.welded:
            raise ValueError("the bound is measured on per-patch output (its vertices keep their patch and "
                             "(u, v)); add --no-weld (weld=False) to --check-bound")

    @property
    def welded(self) -> bool:
        """Whether outputs are welded: ``weld``, else the default of ``cltess tessellate``."""
        return self.weld if self.weld is not None else f".{self.format}" in MESH_FORMATS

    def output_key(self) -> dict:
        """What the output bytes depend on (not the device choice nor the memory cap), with the
        cltess version: a rerun redoes an input whose key differs."""
        return {"eps": self.eps, "pixels": self.pixels, "max_factor": self.max_factor,
                "forward_differencing": self.forward_differencing, "sharp_edges": self.sharp_edges,
                "format": self.format, "weld": self.welded, "orient": self.orient, "pattern": self.pattern,
                "max_level": self.max_level, "emit": self.emit, "cltess": _version()}

    def tessellation_kwargs(self) -> dict:
        return {"eps": self.eps, "pixels": self.pixels, "max_factor": self.max_factor,
                "forward_differencing": self.forward_differencing, "sharp_edges": self.sharp_edges,
                "pattern": self.pattern, "max_level": self.max_level, "emit": self.emit}


def _version() -> str:
    from importlib import metadata
    try:
        return metadata.version("cltess")
    except metadata.PackageNotFoundError:
        return "unknown"


def expand_inputs(patterns, exclude=None) -> list[tuple[Path, str]]:
    """(input path, output name) for every file that ``patterns`` name, in order, once each.

    A pattern is a file (taken whatever its extension: a bad one fails its own row), a folder
    (its scene files, recursively, sorted) or a glob (``*``, ``?``, ``[``, ``**``).  The output
    name keeps the input's name and its path under the folder it was found in, and appends the
    format: ``scenes/teapot.bez`` -> ``teapot.bez.ply``.  Files under the folder ``exclude``
    (the output folder: its .ply files are meshes too) are left out of folders and globs.
    Raises ValueError for a pattern that names nothing, and for two inputs that would write
    the same output.
    """
    skip = Path(exclude).resolve() if exclude is not None else None
    found: dict[Path, str] = {}
    for pattern in map(str, patterns):
        path = Path(pattern)
        if path.is_dir():
            names = [(p, p.relative_to(path).as_posix()) for p in sorted(path.rglob("*"))
                     if p.is_file() and p.suffix.lower() in SCENE_EXTENSIONS and not p.name.startswith(".")]
        elif path.is_file():
            names = [(path, path.name)]
        elif glob.has_magic(pattern):
            names = [(Path(p), Path(p).name) for p in sorted(glob.glob(pattern, recursive=True))
                     if Path(p).is_file()]
        else:
            raise ValueError(f"{pattern}: no such file or folder")
        if skip is not None and not path.is_file():
            names = [(file, name) for file, name in names if not file.resolve().is_relative_to(skip)]
        if not names:
            raise ValueError(f"{pattern}: names no scene file ({', '.join(SCENE_EXTENSIONS)})")
        for file, name in names:
            found.setdefault(file.resolve(), name)
    by_output: dict[str, Path] = {}
    for file, name in found.items():
        if name in by_output:
            raise ValueError(f"{by_output[name]} and {file} would both write {name}.*; "
                             "run them into different output folders")
        by_output[name] = file
    return list(found.items())


# --------------------------------------------------------------------------- fingerprints


def file_sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _scene_files(path: Path) -> list[Path]:
    """The input and, for a .json scene, the files its objects name (a change to those must
    redo it too)."""
    files = [path]
    if path.suffix.lower() == ".json":
        with contextlib.suppress(OSError, ValueError, TypeError, AttributeError):
            objects = json.loads(path.read_text()).get("objects", [])
            files += [path.parent / str(o["file"]) for o in objects if isinstance(o, dict) and "file" in o]
    return files


def fingerprint(path: Path) -> list[dict]:
    """Size, mtime (ns) and SHA-256 of the scene's files (``_scene_files``)."""
    prints = []
    for file in _scene_files(Path(path)):
        with contextlib.suppress(OSError):
            stat = file.stat()
            prints.append({"file": str(file), "size": stat.st_size, "mtime_ns": stat.st_mtime_ns,
                           "sha256": file_sha256(file)})
    return prints


def _unchanged(prints: list[dict]) -> bool:
    """Whether every file is as recorded: same size and mtime, or (touched) same content."""
    for recorded in prints:
        try:
            stat = os.stat(recorded["file"])
        except OSError:
            return False
        if (stat.st_size, stat.st_mtime_ns) == (recorded["size"], recorded["mtime_ns"]):
            continue
        if stat.st_size != recorded["size"] or file_sha256(Path(recorded["file"])) != recorded["sha256"]:
            return False
    return True


def up_to_date(row: dict | None, path: Path, output: Path, key: dict, check_bound: bool = False,
               verify: bool = False) -> bool:
    """Whether a previous manifest row still describes ``output``: it succeeded with the same
    output key, its input files are unchanged and the output has the size it recorded."""
    if not row or row.get("status") not in ("done", "skipped") or row.get("options") != key:
        return False
    try:
        if output.stat().st_size != row.get("output_bytes"):
            return False
    except OSError:
        return False
    if check_bound and row.get("worst_bound_ratio") is None and output.suffix != ".obj":
        return False  # asked for now, not measured then
    if verify and row.get("verify_ratio") is None:
        return False
    prints = row.get("fingerprint") or []
    return bool(prints) and prints[0]["file"] == str(path) and _unchanged(prints)


# --------------------------------------------------------------------------- manifest


def read_manifest(outdir) -> dict:
    """The manifest of ``outdir`` ({"options", "rows"}), or an empty one."""
    try:
        manifest = json.loads((Path(outdir) / MANIFEST_NAME).read_text())
    except (OSError, ValueError):
        return {"rows": []}
    return manifest if isinstance(manifest, dict) and isinstance(manifest.get("rows"), list) else {"rows": []}


def write_manifest(outdir, rows: list[dict], options: BatchOptions) -> Path:
    """Write ``OUTDIR/manifest.json`` atomically; keeps the rows of a previous manifest whose
    inputs this batch did not name."""
    path = Path(outdir) / MANIFEST_NAME
    named = {row["input"] for row in rows}
    kept = [row for row in read_manifest(outdir)["rows"] if row.get("input") not in named]
    manifest = {"version": MANIFEST_VERSION, "options": asdict(options), "rows": rows + kept}
    with atomic_write(path, "w", encoding="utf-8") as handle:
        json.dump(manifest, handle, indent=1, default=_json_default)
        handle.write("\n")
    return path


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def as_table(rows: list[dict]):
    """The manifest rows as a pandas DataFrame where pandas is installed, else the list."""
    try:
        import pandas
    except ImportError:
        return rows
    return pandas.DataFrame(rows)


def _row(path: Path, output: Path, key: dict, **fields) -> dict:
    row = {"input": str(path), "output": str(output), "status": "failed", "error": None,
           "patches": None, "culled": None, "saturated": None, "vertices": None, "triangles": None,
           "output_bytes": None, "worst_bound_ratio": None, "verify_ratio": None, "verify_patch": None,
           "parts": None, "seconds": None,
           **{f"{stage}_ms": None for stage in STAGE_COLUMNS}, "worker": None, "device": None,
           "options": key, "fingerprint": []}
    row.update(fields)
    return row


def _counts(stats: dict) -> dict:
    return {name: int(stats[name]) for name in ("patches", "culled", "saturated", "vertices", "triangles")
            if name in stats}


# --------------------------------------------------------------------------- workers


_TESSELLATORS: dict = {}  # per worker process: (device name, slot) -> Tessellator


def worker_device(name: str | None = None, slot: int = 0):
    """The OpenCL device of the worker in ``slot`` (its rank among the workers of its host).

    With several usable GPUs among the devices that ``name`` matches (all devices when ``name``
    and ``$CLTESS_DEVICE`` are unset), worker ``slot`` takes GPU ``slot mod count``; otherwise
    every worker takes ``pick_device(name)``, the device ``cltess tessellate`` would use."""
    from .device import DEVICE_ENV_VAR, list_devices, pick_device, probe_device

    wanted = name or os.environ.get(DEVICE_ENV_VAR) or None
    gpus = [info for info in list_devices() if info.type == "GPU" and (wanted is None or info.matches(wanted))
            and probe_device(info).usable]
    if len(gpus) >= 2:
        return gpus[slot % len(gpus)].device
    return pick_device(name)


def _worker_tessellator(device_name: str | None, slots: dict):
    from distributed import get_worker

    from .backends.opencl import Tessellator

    key = (device_name, slots.get(get_worker().address, 0))
    if key not in _TESSELLATORS:
        import pyopencl as cl
        warnings.filterwarnings("ignore", category=cl.CompilerWarning)  # as the CLI does
        _TESSELLATORS[key] = Tessellator(worker_device(*key))
    return _TESSELLATORS[key]


def device_slots(client) -> dict:
    """{worker address: its rank among the workers on its host}, for ``worker_device``."""
    try:
        workers = client.scheduler_info(n_workers=-1)["workers"]  # all of them (newer Dask lists 5 by default)
    except TypeError:  # a Dask before the n_workers argument, which lists all
        workers = client.scheduler_info()["workers"]
    by_host: dict = {}
    for address, info in sorted(workers.items()):
        by_host.setdefault(info.get("host", address.rsplit(":", 1)[0]), []).append(address)
    return {address: rank for addresses in by_host.values() for rank, address in enumerate(addresses)}


def _worker_name() -> str:
    from distributed import get_worker
    return str(get_worker().name)


def tessellate_file_task(path: str, output: str, options: BatchOptions, slots: dict) -> dict:
    """On a worker: tessellate one input into ``output``; its manifest row, failed or not."""
    from .stream import tessellate_to_file

    started = time.perf_counter()
    path, output = Path(path), Path(output)
    row = _row(path, output, options.output_key(), worker=_worker_name())
    try:
        row["fingerprint"] = fingerprint(path)
        scene = _load(path, options)
        tessellator = _worker_tessellator(options.device, slots)
        row["device"] = tessellator.device.name.strip()
        kwargs = options.tessellation_kwargs()
        if not scene.meshes:
            kwargs.pop("sharp_edges")
        output.parent.mkdir(parents=True, exist_ok=True)
        result = tessellate_to_file(tessellator, scene, output, max_memory_bytes=options.max_memory,
                                    weld=options.welded, verify=options.verify, **kwargs)
        row.update(_counts(result.stats), status="done", output_bytes=output.stat().st_size,
                   parts=result.batches, **{f"{s}_ms": result.stage_ms.get(s) for s in STAGE_COLUMNS},
                   **{k: result.stats[k] for k in ("verify_ratio", "verify_patch") if k in result.stats})
        if options.check_bound:
            row["worst_bound_ratio"] = measure_output(scene, output, options)
    except Exception as error:  # noqa: BLE001 - any failure is this input's own, reported in its row
        row["error"] = _describe(error)
    row["seconds"] = time.perf_counter() - started
    return row


BOUND_TRIANGLES = 20_000  # --check-bound samples every k-th triangle, about this many in all


def read_output(output: Path):
    """The mesh of a .ply (as cltess writes it) or .npz output, for measuring; None for .obj,
    which has no patch ids."""
    from .io.npz import load_npz
    from .io.ply import PLY_FACE_DTYPE, PLY_VERTEX_DTYPE
    from .tessellation import Tessellation

    if output.suffix == ".npz":
        return load_npz(output)
    if output.suffix != ".ply":
        return None
    counts = {}
    with open(output, "rb") as handle:
        for line in iter(handle.readline, b""):
            if line.startswith(b"element "):
                counts[line.split()[1]] = int(line.split()[2])
            if line == b"end_header\n":
                break
        vertices = np.fromfile(handle, PLY_VERTEX_DTYPE, counts[b"vertex"])
        faces = np.fromfile(handle, PLY_FACE_DTYPE, counts[b"face"])
    field = lambda *names: np.stack([vertices[n] for n in names], axis=1)  # noqa: E731
    return Tessellation(positions=field("x", "y", "z"), normals=field("nx", "ny", "nz"), uv=field("u", "v"),
                        patch_ids=vertices["patch"], object_ids=vertices["object"],
                        triangles=faces["vertex_indices"], factors=np.zeros((0, 4), np.int32))


def measure_output(scene, output: Path, options: BatchOptions) -> float | None:
    """The worst bound ratio of a written output (``cltess.bound``, sampled), None for OBJ."""
    from .bound import worst_bound_ratio

    mesh = read_output(output)
    if mesh is None:
        return None
    return worst_bound_ratio(scene, mesh, options.eps, options.pixels, options.sharp_edges,
                             max_triangles=BOUND_TRIANGLES)


def _describe(error: BaseException) -> str:
    if isinstance(error, OSError) and error.filename and error.strerror:
        return f"{error.filename}: {error.strerror}"
    from .scene import SceneError
    text = str(error) or type(error).__name__
    return text if isinstance(error, (SceneError, ValueError, MemoryError)) else f"{type(error).__name__}: {text}"


# --------------------------------------------------------------------------- one scene, split


def output_sizes(host) -> np.ndarray:
    """(P+1,) bytes of output before each patch of a HostPlan (the last entry: the total)."""
    from .tessellation import BYTES_PER_INDEX, BYTES_PER_VERTEX
    return (host.vertex_offsets.astype(np.int64) * BYTES_PER_VERTEX
            + host.index_offsets.astype(np.int64) * BYTES_PER_INDEX)


def split_ranges(sizes: np.ndarray, first: int, last: int, parts: int, max_bytes: int) -> list[tuple[int, int]]:
    """Patches ``first .. last-1`` cut into consecutive ranges of about equal output: at least
    ``parts`` ranges and as many as needed for each to hold about ``max_bytes`` (a range is
    never empty; one patch may exceed it: ``stream._emit_fitting`` then halves it on the
    device).  ``sizes``: cumulative output bytes per patch (``output_sizes``)."""
    total = int(sizes[last] - sizes[first])
    count = max(1, min(last - first, max(parts, -(-total // max(max_bytes, 1)))))
    targets = sizes[first] + total * np.arange(1, count) / count
    cuts = np.searchsorted(sizes[first:last + 1], targets, side="left") + first
    bounds = np.unique(np.concatenate([[first], np.clip(cuts, first + 1, last), [last]]))
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]


def _worker_budget(tessellator, options: BatchOptions) -> int:
    from .stream import COPIES_IN_FLIGHT, default_budget
    return max((options.max_memory or default_budget(tessellator.device)) // COPIES_IN_FLIGHT, 1)


def _load(path, options: BatchOptions):
    """The scene as ``cltess tessellate`` prepares it: read, then oriented unless told not to."""
    from .io import load_scene
    from .orient import orient_scene

    scene = load_scene(path)
    return orient_scene(scene)[0] if options.orient else scene


def plan_task(path: str, options: BatchOptions, slots: dict):
    """On a worker: load the scene and run stages 1-3 once; the HostPlan (kept on the
    cluster) and its stage times."""
    from .backends.opencl.events import span_ms

    scene = _load(path, options)
    tessellator = _worker_tessellator(options.device, slots)
    kwargs = options.tessellation_kwargs()
    kwargs.pop("forward_differencing")
    if not scene.meshes:
        kwargs.pop("sharp_edges")
    plan = tessellator.plan(scene, **kwargs)
    tessellator.queue.finish()
    stage_ms = {stage: span_ms(events) for stage, events in plan.events.items() if events}
    return plan.to_host(), stage_ms, _worker_budget(tessellator, options), tessellator.device.name.strip()


def plan_summary(planned, parts: int) -> dict:
    """On the worker that holds the plan: totals, stats, stage times and the patch ranges."""
    host, stage_ms, budget, device = planned
    ranges = split_ranges(output_sizes(host), 0, host.num_patches, parts, budget)
    return {"num_vertices": host.num_vertices, "num_faces": host.num_indices // 3, "stats": host.stats,
            "stage_ms": stage_ms, "ranges": ranges, "device": device}


def emit_part_task(planned, index: int, first: int, last: int, parts_dir: str, options: BatchOptions,
                   slots: dict) -> dict:
    """On a worker: stages 4-5 for patches ``first .. last-1`` of the plan (never stages 1-3),
    written as ``vertices-INDEX.bin`` and ``faces-INDEX.bin`` (PLY records) in ``parts_dir``."""
    from .stream import _emit_fitting

    started = time.perf_counter()
    host = planned[0]
    tessellator = _worker_tessellator(options.device, slots)
    plan = tessellator.upload_plan(host, first, last)
    sizes = output_sizes(host)
    stage_ms = {"vertices": 0.0, "indices": 0.0}
    vertices = faces = 0
    folder = Path(parts_dir)
    with atomic_write(folder / f"vertices-{index:06d}.bin") as vertex_file, \
            atomic_write(folder / f"faces-{index:06d}.bin") as face_file:
        for a, b in split_ranges(sizes, first, last, 1, _worker_budget(tessellator, options)):
            for batch in _emit_fitting(tessellator, plan, a, b, options.forward_differencing):
                vertex_file.write(ply_vertex_records(batch).view(np.uint8))
                face_file.write(ply_face_records(batch.triangles).view(np.uint8))
                vertices, faces = vertices + batch.num_vertices, faces + batch.num_triangles
                for stage in stage_ms:
                    stage_ms[stage] += batch.stage_ms.get(stage, 0.0)
    return {"index": index, "first": first, "last": last, "vertices": vertices, "faces": faces,
            "stage_ms": stage_ms, "seconds": time.perf_counter() - started, "worker": _worker_name()}


def join_ply_parts(output, num_vertices: int, num_faces: int, parts_dir, count: int) -> int:
    """Write ``output`` (atomically): the PLY header, vertex parts 0..count-1, face parts
    0..count-1.  Checks each part's length first; returns the file's size."""
    from .io.ply import PLY_FACE_DTYPE, PLY_VERTEX_DTYPE

    folder = Path(parts_dir)
    vertex_parts = [folder / f"vertices-{i:06d}.bin" for i in range(count)]
    face_parts = [folder / f"faces-{i:06d}.bin" for i in range(count)]
    for parts, total, dtype in ((vertex_parts, num_vertices, PLY_VERTEX_DTYPE),
                                (face_parts, num_faces, PLY_FACE_DTYPE)):
        size = sum(part.stat().st_size for part in parts)
        if size != total * dtype.itemsize:
            raise ValueError(f"{output}: the parts hold {size} bytes, the header declares "
                             f"{total} records of {dtype.itemsize} bytes")
    with atomic_write(output) as handle:
        handle.write(ply_header(num_vertices, num_faces))
        for part in vertex_parts + face_parts:
            _append(part, handle)
        size = handle.tell()
    return size


def _append(part: Path, target) -> None:
    """Append the file ``part`` to the open binary file ``target``: in the kernel
    (``os.copy_file_range``, no copy through this process) where it can, else by blocks."""
    with open(part, "rb") as source:
        target.flush()
        remaining = os.fstat(source.fileno()).st_size
        with contextlib.suppress(AttributeError, OSError):  # no such call, or not across these files
            while remaining:
                copied = os.copy_file_range(source.fileno(), target.fileno(), remaining)
                if not copied:
                    break
                remaining -= copied
        if remaining:
            source.seek(-remaining, os.SEEK_END)
            shutil.copyfileobj(source, target, 1 << 24)


def _tessellate_split_row(client, path: Path, output: Path, options: BatchOptions, parts: int | None,
                          slots: dict, progress=None) -> dict:
    """One scene across the workers (module docstring); its manifest row."""
    started = time.perf_counter()
    row = _row(path, output, options.output_key(), fingerprint=fingerprint(path))
    if options.format != "ply":
        raise ValueError(f"a split scene is joined as PLY, not {options.format}")
    workers = max(1, len(slots))
    planned = client.submit(plan_task, str(path), options, slots, pure=False)
    try:
        summary = client.submit(plan_summary, planned, parts or PARTS_PER_WORKER * workers, pure=False).result()
        if workers > 1:
            client.replicate([planned])  # every worker reads the plan locally: ranges spread evenly
        output.parent.mkdir(parents=True, exist_ok=True)
        parts_dir = Path(tempfile.mkdtemp(prefix=f".{output.name}.parts-", dir=output.parent))
        try:
            ranges = summary["ranges"]
            futures = [client.submit(emit_part_task, planned, i, a, b, str(parts_dir), options, slots, pure=False)
                       for i, (a, b) in enumerate(ranges)]
            if progress is not None:
                progress.add(len(futures))
            from distributed import as_completed
            done = []
            for future in as_completed(futures):
                done.append(future.result())
                if progress is not None:
                    progress.step(f"{path.name} part {done[-1]['index'] + 1}/{len(ranges)}")
            size = join_ply_parts(output, summary["num_vertices"], summary["num_faces"], parts_dir, len(ranges))
        finally:
            shutil.rmtree(parts_dir, ignore_errors=True)
    finally:
        client.cancel([planned])
    stage_ms = dict(summary["stage_ms"])
    for stage in ("vertices", "indices"):
        stage_ms[stage] = sum(part["stage_ms"][stage] for part in done)
    row.update(_counts(summary["stats"]), status="done", output_bytes=size, parts=len(ranges),
               device=summary["device"], worker=",".join(sorted({part["worker"] for part in done})),
               seconds=time.perf_counter() - started, **{f"{s}_ms": stage_ms.get(s) for s in STAGE_COLUMNS})
    return row


# --------------------------------------------------------------------------- the cluster


def default_workers() -> int:
    """Workers for a local cluster: one per usable GPU where there are several, else one per
    CPU core this process may use."""
    from .device import list_devices, probe_device

    with contextlib.suppress(Exception):
        gpus = [info for info in list_devices() if info.type == "GPU" and probe_device(info).usable]
        if len(gpus) >= 2:
            return len(gpus)
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None, timeout: float = CONNECT_TIMEOUT_S):
    """A Client of the scheduler at ``scheduler``, or of a new LocalCluster of ``workers``
    processes (default ``default_workers()``, one thread each: one task at a time per device),
    closed (workers stopped) on leaving, whatever happened."""
    import dask
    from distributed import Client, LocalCluster

    if scheduler:
        with Client(scheduler, timeout=timeout) as client:
            yield client
        return
    # A task that kills its worker (a crashing driver) fails its input after two tries, not four.
    with dask.config.set({"distributed.scheduler.allowed-failures": 1}), warnings.catch_warnings():
        # Its HTTP server (no dashboard) takes another port where 8787 is taken: nothing to say.
        warnings.filterwarnings("ignore", message="Port .* is already in use")
        cluster = LocalCluster(n_workers=workers or default_workers(), threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
    try:
        with Client(cluster, timeout=timeout) as client:
            client.wait_for_workers(len(cluster.workers), timeout=timeout)
            yield client
    finally:
        cluster.close(timeout=timeout)


# --------------------------------------------------------------------------- progress


class Progress:
    """A progress bar on stderr (redrawn in place on a terminal, one line per step
    otherwise); ``enabled=False`` prints nothing."""

    def __init__(self, total: int = 0, enabled: bool = True, stream=None, width: int = 30):
        self.total, self.done, self.failed = total, 0, 0
        self.enabled, self.stream, self.width = enabled, stream or sys.stderr, width
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()

    def add(self, count: int) -> None:
        self.total += count

    def step(self, label: str, failed: bool = False) -> None:
        self.done += 1
        self.failed += failed
        if not self.enabled:
            return
        filled = self.width * self.done // max(self.total, 1)
        bar = "#" * filled + "-" * (self.width - filled)
        failures = f", {self.failed} failed" if self.failed else ""
        line = f"[{bar}] {self.done}/{self.total}{failures}  {label}"
        if self.tty:
            self.stream.write("\r\033[K" + line + ("\n" if self.done >= self.total else ""))
        else:
            self.stream.write(line + "\n")
        self.stream.flush()


# --------------------------------------------------------------------------- the API


def tessellate_files(inputs, outdir, options: BatchOptions | None = None, *, client=None,
                     scheduler: str | None = None, workers: int | None = None, split: int | None = None,
                     progress: bool | Progress = False, **option_fields) -> list[dict]:
    """Tessellate every input (files, folders, globs: ``expand_inputs``) into ``outdir``;
    returns the manifest rows of these inputs, in input order (``as_table`` for a DataFrame).

    options: a BatchOptions, or its fields as keywords (``eps=1e-3``, ...).  Runs on
    ``client``, else on the scheduler at ``scheduler``, else on a new local cluster of
    ``workers`` processes.  ``split``: tessellate each input across all workers in about this
    many patch ranges (``tessellate_split``; PLY only) instead of one input per worker.
    Rows: status "done", "skipped" (up to date, its previous row) or "failed" (with
    ``error``); counts, output bytes, ``<stage>_ms`` device times, seconds, worker, device,
    options and the input fingerprint.  The manifest is written even when interrupted.
    """
    options = options or BatchOptions(**option_fields)
    outdir = Path(outdir)
    if outdir.exists() and not outdir.is_dir():
        raise ValueError(f"{outdir}: not a folder")
    jobs = [(path, outdir / f"{name}.{options.format}") for path, name in expand_inputs(inputs, exclude=outdir)]
    if split is not None and options.format != "ply":
        raise ValueError(f"a split scene is joined as PLY; --format {options.format} cannot be split")
    if split is not None and options.check_bound:
        raise ValueError("--check-bound measures whole outputs on one worker; it cannot be used with --split")
    if split is not None and options.verify:
        raise ValueError("--verify measures whole outputs on one worker; it cannot be used with --split")
    if split is not None:
        if options.weld:
            raise ValueError("a split scene is written per patch, not welded (welding needs the whole mesh in "
                             "one memory); --weld cannot be used with --split")
        options = replace(options, weld=False)
    outdir.mkdir(parents=True, exist_ok=True)
    key = options.output_key()
    previous = {row.get("input"): row for row in read_manifest(outdir)["rows"]}
    rows: dict[Path, dict] = {}
    for path, output in jobs:
        if up_to_date(previous.get(str(path)), path, output, key, options.check_bound, options.verify):
            rows[path] = dict(previous[str(path)], status="skipped")
    todo = [(path, output) for path, output in jobs if path not in rows]
    bar = progress if isinstance(progress, Progress) else Progress(enabled=bool(progress))
    try:
        if todo:
            with contextlib.ExitStack() as stack:
                if client is None:
                    client = stack.enter_context(dask_client(scheduler, workers))
                slots = device_slots(client)
                if split is None:
                    _run_files(client, todo, options, slots, rows, bar)
                else:
                    _run_split(client, todo, options, split, slots, rows, bar)
    finally:
        ordered = [rows[path] for path, _ in jobs if path in rows]
        write_manifest(outdir, ordered, options)
    return ordered


def _run_files(client, todo, options, slots, rows, bar) -> None:
    from distributed import as_completed

    bar.add(len(todo))
    futures = {client.submit(tessellate_file_task, str(path), str(output), options, slots, pure=False,
                             retries=0): (path, output) for path, output in todo}
    try:
        for future in as_completed(futures):
            path, output = futures[future]
            try:
                row = future.result()
            except Exception as error:  # noqa: BLE001 - the worker died (or was lost) on this input
                row = _row(path, output, options.output_key(), error=f"worker failed: {_describe(error)}")
            rows[path] = row
            bar.step(path.name, failed=row["status"] == "failed")
    finally:
        client.cancel(list(futures))


def _run_split(client, todo, options, split, slots, rows, bar) -> None:
    for path, output in todo:
        try:
            row = _tessellate_split_row(client, path, output, options, split, slots, bar)
        except Exception as error:  # noqa: BLE001
            row = _row(path, output, options.output_key(), error=_describe(error), fingerprint=fingerprint(path))
        rows[path] = row


def tessellate_split(scene, output, options: BatchOptions | None = None, *, parts: int | None = None,
                     client=None, scheduler: str | None = None, workers: int | None = None,
                     progress: bool | Progress = False, **option_fields) -> dict:
    """One scene file across the workers (module docstring) into the PLY ``output``: the same
    file, byte for byte, as ``cltess tessellate --no-weld`` writes (a split scene is written per
    patch: welding needs the whole mesh in one memory).  ``parts``: patch ranges (default
    4 per worker, more where a range would not fit a worker's memory cap).  Returns its
    manifest row; raises on failure (nothing is left at ``output``)."""
    options = options or BatchOptions(**option_fields)
    output = Path(output)
    if output.suffix.lower() != ".ply" or options.format != "ply":
        raise ValueError(f"{output}: a split scene is joined as PLY (.ply)")
    if options.weld:
        raise ValueError(f"{output}: a split scene is written per patch, not welded (welding needs the "
                         "whole mesh in one memory); leave out weld")
    options = replace(options, weld=False)
    bar = progress if isinstance(progress, Progress) else Progress(enabled=bool(progress))
    with contextlib.ExitStack() as stack:
        if client is None:
            client = stack.enter_context(dask_client(scheduler, workers))
        return _tessellate_split_row(client, Path(scene).resolve(), output, options, parts,
                                     device_slots(client), bar)


def summarize(rows: list[dict]) -> dict:
    """Counts of done, skipped and failed rows."""
    return {status: sum(row["status"] == status for row in rows) for status in ("done", "skipped", "failed")}


__all__ = ["BatchOptions", "Progress", "as_table", "dask_client", "default_workers", "device_slots",
           "expand_inputs", "file_sha256", "join_ply_parts", "read_manifest", "split_ranges", "summarize",
           "tessellate_files", "tessellate_split", "worker_device", "write_manifest"]

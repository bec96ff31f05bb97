"""The suite: its scenes with the paper's figures, timing each scene on one OpenCL device, and
the device-memory tracker."""
from __future__ import annotations

import copy

import os
import platform
import statistics
import subprocess
import sys
import time
import weakref
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..scene import Scene
from .baselines import numpy_evaluate, pn_numpy_evaluate, write_bandwidth
from ..tessellation import BYTES_PER_INDEX, BYTES_PER_VERTEX
from .scenes import (HEIGHT, PIXELS, WIDTH, _bounds, bigguy_copies, double_torus, elephant, mesh_camera, model_zoo,
                     sphere_field, star_field, tea_table)


#: Host wall-clock figures recorded beside the device stages (Tessellation.wall_ms): "stages_wall"
#: from the call until the stages finish, "read_back" the output to host arrays, "total_wall"
#: both, until the caller holds the host arrays (what "end to end" means here).
WALL_KEYS = ("total_wall", "stages_wall", "read_back")

#: Bytes the pipeline writes per output vertex (the vertex record) and per triangle (3 uint32).
VERTEX_BYTES = BYTES_PER_VERTEX
TRIANGLE_BYTES = 3 * BYTES_PER_INDEX


#: CudaTess (Schwarz & Stamminger 2009), Table 1, GeForce 8800 GTS, ms.  "offsets" is the
#: paper's scan stage: ours is crack_free + counts (counts kernel + pyopencl scan).
PAPER_BEZIER = {
    "tea_table": dict(title="Tea table", patches=332, tris=41_372,
                      factors=0.39, offsets=0.09, vertices=2.40, vertices_fd=1.40, indices=0.56),
    "killeroo": dict(title="Killeroo", patches=11_532, tris=100_930,
                     factors=0.82, offsets=0.16, vertices=3.32, vertices_fd=2.04, indices=0.61),
    "herd": dict(title="Killeroo herd", patches=92_256, tris=345_751,
                 factors=4.18, offsets=0.42, vertices=12.22, vertices_fd=7.38, indices=1.19),
    "spheres": dict(title="Spheres", patches=32_000, tris=402_000,
                    factors=1.62, offsets=0.20, vertices=4.54, vertices_fd=3.54, indices=0.96),
    "spheres_closeup": dict(title="Spheres close-up", patches=32_000, tris=272_301,
                            factors=1.04, offsets=0.19, vertices=5.54, vertices_fd=2.92, indices=0.77),
}


#: Table 2 (PN triangles), same GPU, ms.
PAPER_PN = {
    "double_torus": dict(title="Double torus", patches=1_536, tris=15_320,
                         factors=0.39, offsets=0.21, vertices=0.60, indices=0.48),
    "elephant": dict(title="Elephant", patches=21_540, tris=79_208,
                     factors=0.91, offsets=0.26, vertices=1.49, indices=0.68),
    "star_field": dict(title="Star field", patches=41_496, tris=1_050_688,
                       factors=1.41, offsets=0.33, vertices=6.81, indices=2.57),
    "star_field_closeup": dict(title="Star field close-up", patches=41_496, tris=379_982,
                               factors=0.75, offsets=0.30, vertices=2.84, indices=1.11),
    "model_zoo": dict(title="Model zoo", patches=80_578, tris=160_200,
                      factors=2.42, offsets=0.50, vertices=3.33, indices=0.93),
}


PAPER_DEVICE = "GeForce 8800 GTS (CudaTess paper)"


@dataclass
class BenchScene:
    key: str
    kind: str  # "bezier" or "pn"
    build: Callable
    note: str
    paper: dict = field(default_factory=dict)

    @property
    def title(self) -> str:
        return self.paper.get("title", self.key)


SUITE: dict[str, BenchScene] = {s.key: s for s in [
    BenchScene("tea_table", "bezier", tea_table,
               "scenes/tea_table.json (teapot, 6 cups, 6 spoons, table) and its camera",
               PAPER_BEZIER["tea_table"]),
    BenchScene("killeroo", "bezier", lambda: bigguy_copies(11_532, columns=4),
               "bigguy.bez x 3 + the first 822 patches of a 4th copy = 11,532 patches, one row",
               PAPER_BEZIER["killeroo"]),
    BenchScene("herd", "bezier", lambda: bigguy_copies(92_256, distance_scale=1.8),
               "bigguy.bez x 25 + 3,006 patches of a 26th = 92,256 patches on a 6 x 5 grid, "
               "seen from 1.8x the framing distance",
               PAPER_BEZIER["herd"]),
    BenchScene("spheres", "bezier", lambda: sphere_field(1000),
               "1,000 exact rational spheres (scenes/sphere.bpt, 32 patches), radius 0.1-0.25, "
               "randomly rotated, on a 10^3 grid of spacing 3",
               PAPER_BEZIER["spheres"]),
    BenchScene("spheres_closeup", "bezier", lambda: sphere_field(1000, closeup=True),
               "the same spheres, camera inside the grid (30% along the diagonal)", PAPER_BEZIER["spheres_closeup"]),
    BenchScene("double_torus", "pn", lambda: (double_torus(), {}),
               "two overlapping tori, 1,536 triangles", PAPER_PN["double_torus"]),
    BenchScene("elephant", "pn", lambda: (elephant(), {"distance_scale": 0.6}),
               "bumpy ellipsoid + torus trunk, 21,540 triangles; camera at 0.6x the framing distance", PAPER_PN["elephant"]),
    BenchScene("star_field", "pn", lambda: (star_field(), {}),
               "1,729 spiky stars of 24 triangles = 41,496", PAPER_PN["star_field"]),
    BenchScene("star_field_closeup", "pn", lambda: (star_field(), {"closeup": True, "eye_at": 0.6}),
               "the same stars, camera inside the field (60% along the diagonal)", PAPER_PN["star_field_closeup"]),
    BenchScene("model_zoo", "pn", lambda: (model_zoo(), {"distance_scale": 0.75}),
               "2 elephants, 2 double tori, a blob, a snake: 80,578 triangles; camera at 0.75x", PAPER_PN["model_zoo"]),
]}


GROUPS = {
    "all": list(SUITE),
    "bezier": [k for k, s in SUITE.items() if s.kind == "bezier"],
    "pn": [k for k, s in SUITE.items() if s.kind == "pn"],
    "small": ["tea_table", "double_torus"],
}


def resolve_scenes(names) -> list[str]:
    """Scene keys and group names (all, bezier, pn, small) -> scene keys in suite order."""
    names = list(names) or ["all"]
    wanted = set()
    for name in names:
        key = name.replace("-", "_").lower()
        if key in GROUPS:
            wanted.update(GROUPS[key])
        elif key in SUITE:
            wanted.add(key)
        else:
            raise ValueError(f"unknown bench scene {name!r}; choose from "
                             f"{', '.join(list(SUITE) + list(GROUPS))}")
    return [k for k in SUITE if k in wanted]


class AllocationTracker:
    """Peak live bytes of ``pyopencl.Buffer`` objects while active (a context manager).

    ``pyopencl.Buffer`` is replaced by a subclass that counts each buffer's size when it is
    created and uncounts it when the Python object is freed; every buffer pyopencl.array,
    pyopencl.scan and the pipeline create goes through it.  It does not see memory the driver
    allocates on its own (kernel binaries, the scan's stack, PoCL's host copies).
    """

    def __init__(self):
        self.live = self.peak = self.total = self.count = 0

    def _free(self, size):
        self.live -= size

    def __enter__(self):
        import pyopencl as cl

        self._cl, self._original = cl, cl.Buffer
        tracker = self

        class TrackedBuffer(self._original):
            def __init__(buf, *args, **kwargs):
                super().__init__(*args, **kwargs)
                size = int(buf.size)
                tracker.live += size
                tracker.total += size
                tracker.count += 1
                tracker.peak = max(tracker.peak, tracker.live)
                weakref.finalize(buf, tracker._free, size)

        cl.Buffer = TrackedBuffer
        return self

    def __exit__(self, *exc):
        self._cl.Buffer = self._original
        return False


def _median_spread(values):
    values = [float(v) for v in values]
    median = statistics.median(values)
    spread = (max(values) - min(values)) / median if median > 0 else 0.0
    return {"median": median, "min": min(values), "max": max(values), "spread": spread, "runs": values}


def _stages_summary(runs: list[dict]) -> dict:
    keys = [k for k in runs[0] if all(k in r for r in runs)]
    out = {k: _median_spread([r[k] for r in runs]) for k in keys}
    offsets = [r.get("crack_free", 0.0) + r.get("counts", 0.0) for r in runs]
    out["offsets"] = _median_spread(offsets)
    device = [sum(v for k, v in r.items() if k not in WALL_KEYS) for r in runs]
    out["device_total"] = _median_spread(device)
    return out


def machine_info() -> dict:
    """Host facts for the record: CPU model and count, OS, Python, numpy, pyopencl."""
    import pyopencl as cl

    model = platform.processor()
    try:
        text = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10).stdout
        for line in text.splitlines():
            if line.startswith("Model name:"):
                model = line.split(":", 1)[1].strip()
    except (OSError, subprocess.SubprocessError):
        pass
    return {"cpu": model, "cpus": os.cpu_count(), "os": platform.platform(),
            "python": platform.python_version(), "numpy": np.__version__, "pyopencl": cl.VERSION_TEXT,
            "hostname": platform.node(),
            "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}


def device_info(device) -> dict:
    return {"name": device.name.strip(), "platform": device.platform.name.strip(),
            "platform_version": device.platform.version.strip(), "vendor": device.vendor.strip(),
            "version": device.version.strip(), "driver_version": device.driver_version.strip(),
            "compute_units": device.max_compute_units,
            "global_memory_gib": round(device.global_mem_size / 2**30, 2)}


class Progress:
    """Progress lines on a stream (stderr): updated in place on a terminal, one per step else."""

    def __init__(self, stream=None, enabled: bool = True):
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = enabled and hasattr(self.stream, "isatty") and self.stream.isatty()
        self._width = 0

    def step(self, text: str) -> None:
        if not self.enabled:
            return
        if self.tty:
            self.stream.write("\r" + text.ljust(self._width))
            self._width = len(text)
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def done(self, text: str) -> None:
        if not self.enabled:
            return
        if self.tty:
            self.stream.write("\r" + text.ljust(self._width) + "\n")
            self._width = 0
        else:
            self.stream.write(text + "\n")
        self.stream.flush()


def _host_preparation(scene):
    """The host work the pipeline does once per scene (then cached), to time it alone: every
    kind's ``prepare`` (adjacency, welding, packing the upload; cltess.kinds)."""
    from ..kinds import KINDS

    kinds = [kind for kind in KINDS if kind.count(scene)]

    def prepare_all():
        uncached = copy.copy(scene)  # the same arrays without what Scene.prepared keeps (the
        uncached._prepared = {}      # Bézier edge groups, shared with orientation): timed afresh
        return [kind.prepare(uncached) for kind in kinds]

    return prepare_all


def run_scene(tessellator, spec: BenchScene, repeat: int = 3, warmup: int = 1,
              progress: Progress | None = None, label: str = "", numpy_baseline: bool = True) -> dict:
    """Generate one suite scene and time it; returns the scene's result record."""
    progress = progress or Progress(enabled=False)
    say = lambda text: progress.step(f"{label}{spec.key}: {text}")  # noqa: E731
    say("generating")
    started = time.perf_counter()
    built = spec.build()
    if spec.kind == "pn":
        mesh, view = built
        camera = mesh_camera(mesh, **view)
        scene = Scene.from_trimesh(mesh, camera=camera, name=spec.key)
        base_count = len(mesh.faces)
    else:
        scene = built
        base_count = scene.num_patches
    generate_s = time.perf_counter() - started

    def once(fd: bool):
        return tessellator.tessellate(scene, pixels=PIXELS, forward_differencing=fd)

    record = {"key": spec.key, "title": spec.title, "kind": spec.kind, "note": spec.note,
              "paper": spec.paper, "generate_s": generate_s, "base_primitives": base_count,
              "repeat": repeat, "warmup": warmup}
    variants = [True, False]  # forward differencing on, then off (direct evaluation)
    runs = {True: [], False: []}
    last = None
    for fd in variants:
        tag = "FD" if fd else "direct"
        for k in range(warmup):
            say(f"warm-up {k + 1}/{warmup} ({tag})")
            if fd and k == 0:
                with AllocationTracker() as tracker:
                    result = once(fd)
                    del result
                record["peak_device_bytes"] = tracker.peak
                record["allocated_device_bytes"] = tracker.total
                record["device_buffers"] = tracker.count
            else:
                once(fd)
        for k in range(repeat):
            say(f"run {k + 1}/{repeat} ({tag})")
            result = once(fd)
            runs[fd].append(dict(result.stage_ms, stages_wall=result.wall_ms["stages"],
                                 read_back=result.wall_ms["read_back"]))
            if fd:
                last = result
    if "peak_device_bytes" not in record:  # no warm-up: measure on one more run
        with AllocationTracker() as tracker:
            once(True)
        record["peak_device_bytes"], record["allocated_device_bytes"] = tracker.peak, tracker.total
        record["device_buffers"] = tracker.count

    stats = dict(last.stats)
    stats["indices"] = 3 * int(stats["triangles"])
    record["stats"] = stats
    record["fd"] = _stages_summary(runs[True])
    if runs[False]:
        record["direct"] = _stages_summary(runs[False])
    e2e_s = record["fd"]["total_wall"]["median"] / 1e3
    device_s = record["fd"]["device_total"]["median"] / 1e3
    triangles = int(stats["triangles"])
    record["triangles_per_s"] = triangles / e2e_s if e2e_s > 0 else 0.0
    record["triangles_per_s_device"] = triangles / device_s if device_s > 0 else 0.0
    record["output_bytes"] = int(stats["vertices"]) * VERTEX_BYTES + triangles * TRIANGLE_BYTES
    record["output_bytes_per_s"] = record["output_bytes"] / e2e_s if e2e_s > 0 else 0.0

    adjacency = _host_preparation(scene)
    if adjacency is not None:
        times = []
        for k in range(max(1, repeat)):
            say(f"host adjacency {k + 1}/{max(1, repeat)}")
            started = time.perf_counter()
            adjacency()
            times.append((time.perf_counter() - started) * 1e3)
        record["host_adjacency_ms"] = _median_spread(times)

    if numpy_baseline and last.num_vertices:
        if spec.kind == "bezier":
            evaluate = lambda: numpy_evaluate(scene.patches, last.patch_ids, last.uv)  # noqa: E731
            size = float(np.linalg.norm(np.subtract(*_bounds(scene))))
        else:  # a PN scene of one mesh: patch id = face index
            evaluate = lambda: pn_numpy_evaluate(mesh.vertices, mesh.vertex_normals, mesh.faces,  # noqa: E731
                                                 last.patch_ids, last.uv)
            size = float(np.linalg.norm(np.subtract(*mesh.bounds)))
        times = []
        for k in range(max(1, repeat)):
            say(f"NumPy baseline {k + 1}/{max(1, repeat)}")
            started = time.perf_counter()
            positions, normals = evaluate()
            times.append((time.perf_counter() - started) * 1e3)
        normal_gap = np.abs(normals - last.normals).max(axis=1)
        record["numpy"] = _median_spread(times)
        record["numpy"].update(
            dtype="float64", vertices=int(last.num_vertices),
            max_position_error_rel=float(np.abs(positions - last.positions).max() / size),
            normals_off_by_0_1=int(np.count_nonzero(normal_gap > 0.1)),
            normals_off_by_1=int(np.count_nonzero(normal_gap > 1.0)))
    progress.done(f"{label}{spec.key}: {triangles:,} triangles, {e2e_s * 1e3:.1f} ms end to end, "
                  f"{record['triangles_per_s'] / 1e6:.2f} Mtri/s")
    return record


def run_suite(names=(), device=None, repeat: int = 3, warmup: int = 1, progress: Progress | None = None,
              numpy_baseline: bool = True, bandwidth_bytes: int = 512 << 20, command: str | None = None) -> dict:
    """Run the named scenes (keys or groups; default all) on one device; returns the record
    that ``--json`` writes and the table formatters read."""
    from ..backends.opencl import Tessellator

    progress = progress or Progress()
    keys = resolve_scenes(names)
    tessellator = Tessellator(device=device)
    progress.step(f"measuring memory-write bandwidth ({bandwidth_bytes >> 20} MiB numpy fill)")
    bandwidth = write_bandwidth(bandwidth_bytes)
    progress.done(f"memory-write bandwidth: {bandwidth / 1e9:.2f} GB/s (single numpy fill)")
    record = {"device": device_info(tessellator.device), "machine": machine_info(),
              "write_bandwidth_bytes_per_s": bandwidth, "pixels": PIXELS, "viewport": [WIDTH, HEIGHT],
              "repeat": repeat, "warmup": warmup, "command": command or " ".join(sys.argv),
              "date": time.strftime("%Y-%m-%d %H:%M:%S %z"), "scenes": [], "skipped": []}
    for n, key in enumerate(keys, 1):
        spec = SUITE[key]
        label = f"[{n}/{len(keys)}] "
        result = run_scene(tessellator, spec, repeat, warmup, progress, label, numpy_baseline)
        result["bandwidth_fraction"] = result["output_bytes_per_s"] / bandwidth
        record["scenes"].append(result)
    if hasattr(os, "getloadavg"):  # other work on the machine during the run shows here
        record["load_average_after"] = list(os.getloadavg())
    return record

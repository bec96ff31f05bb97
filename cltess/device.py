"""Finding an OpenCL device: list what the ICD loader offers, probe it, pick one by name, make a queue.

A device is *usable* when a small kernel builds and runs on it and gives the right answer
(:func:`probe_device`). The verdict is cached per device and driver version in
``cache_dir()/probes.json``, so only the first run on a machine (or after a driver update) pays
for it. A PoCL too old for the CPU, for example, lists its device but fails every build
(``error: unknown target CPU 'generic'``): it is listed as such and never chosen by default.

Default device: the one named by the ``CLTESS_DEVICE`` environment variable if set (a name, as
for ``pick_device``), else the first usable CPU device (runtimes in ``CPU_RUNTIME_ORDER``
first), else the first usable device of any kind.
"""
from __future__ import annotations

import json
import os
import re
import warnings
from dataclasses import dataclass, field

import numpy as np
import pyopencl as cl

from .runtimes import cache_dir

__all__ = ["DEVICE_ENV_VAR", "BuildError", "DeviceError", "DeviceInfo", "Probe", "list_devices",
           "make_queue", "pick_device", "probe_device"]

DEVICE_ENV_VAR = "CLTESS_DEVICE"

INSTALL_HINT = (
    "install a CPU runtime into this environment: 'pip install intel-opencl-rt' (Intel's, "
    "which cltess installs on Linux x86-64; it runs on AMD CPUs too) or 'pip install \"pyopencl[pocl]\"', "
    "or a vendor OpenCL driver with its ICD file; see the README's Troubleshooting"
)

class DeviceError(RuntimeError):
    """No usable OpenCL platform or device; the message says what to do about it.

    ``log`` holds the full build log or error text behind a short message, if any."""

    def __init__(self, message: str, log: str = ""):
        super().__init__(message)
        self.log = log


class BuildError(DeviceError):
    """A cltess program failed to build on a device that passed its probe."""


_DEVICE_TYPE_NAMES = (
    (cl.device_type.GPU, "GPU"),
    (cl.device_type.CPU, "CPU"),
    (cl.device_type.ACCELERATOR, "accelerator"),
)

# Usable CPU devices are preferred in this order of platform names (substrings), then in the
# loader's order. Chosen by measurement on the test suite and `cltess bench` (bench/RESULTS.md,
# "CPU runtimes").
CPU_RUNTIME_ORDER = ("Intel(R) OpenCL", "Portable Computing Language")


def _device_type_name(device_type: int) -> str:
    """"CPU", "GPU" or "accelerator"; "other" for none of them, or for a device that claims
    several (the Oclgrind simulator says CPU | GPU | ACCELERATOR: it must not be taken for a
    GPU by ``--device gpu``, nor for the default CPU device)."""
    names = [name for flag, name in _DEVICE_TYPE_NAMES if device_type & flag]
    return names[0] if len(names) == 1 else "other"


@dataclass(frozen=True)
class DeviceInfo:
    """One OpenCL device and the platform it belongs to."""

    platform: str  # platform name, e.g. "Portable Computing Language"
    platform_vendor: str  # e.g. "The pocl project"
    platform_version: str  # e.g. "OpenCL 3.0 PoCL 3.0 ..."
    name: str  # device name
    type: str  # "CPU", "GPU", "accelerator" or "other"
    version: str  # device OpenCL version string
    compute_units: int
    global_memory_bytes: int
    device: cl.Device = field(repr=False, compare=False)
    driver_version: str = ""

    def matches(self, needle: str) -> bool:
        """Whether ``needle`` occurs, case-insensitively, in the platform's name, vendor or
        version, or in the device's name or type (so ``pocl``, ``nvidia``, ``cpu`` all work)."""
        haystack = (self.platform, self.platform_vendor, self.platform_version, self.name, self.type)
        return needle.strip().lower() in " | ".join(haystack).lower()

    def describe(self) -> str:
        """One line: device, type, platform, compute units, memory."""
        memory_gib = self.global_memory_bytes / 2**30
        return (f"{self.name} [{self.type}] on {self.platform} ({self.version}, "
                f"{self.compute_units} compute units, {memory_gib:.1f} GiB)")

    @property
    def cache_key(self) -> str:
        """What identifies the device and its driver for the probe cache."""
        return " | ".join((self.platform, self.platform_version, self.name, self.version,
                           self.driver_version, f"probe {PROBE_VERSION}"))


def _platforms() -> list:
    """``cl.get_platforms()``, or [] when the ICD loader finds no platform at all."""
    try:
        return list(cl.get_platforms())
    except (cl.Error, RuntimeError) as error:
        if "PLATFORM_NOT_FOUND" in str(error):
            return []
        raise DeviceError(f"cannot list OpenCL platforms: {error}") from error


def list_devices() -> list[DeviceInfo]:
    """Every device of every platform, in platform order; [] when there is none."""
    devices = []
    for platform in _platforms():
        try:
            platform_devices = platform.get_devices()
        except cl.Error:  # e.g. DEVICE_NOT_FOUND: a platform with no device behind it
            continue
        for device in platform_devices:
            devices.append(DeviceInfo(
                platform=platform.name.strip(),
                platform_vendor=platform.vendor.strip(),
                platform_version=platform.version.strip(),
                name=device.name.strip(),
                type=_device_type_name(device.type),
                version=device.version.strip(),
                compute_units=int(device.max_compute_units),
                global_memory_bytes=int(device.global_mem_size),
                device=device,
                driver_version=device.driver_version.strip(),
            ))
    return devices


# --- probing --------------------------------------------------------------------------------

USABLE, FAILS_TO_BUILD, FAILS_TO_RUN = "usable", "fails to build", "fails to run"
PROBE_VERSION = 1  # bump when the probe kernel changes: old verdicts no longer apply

# Uses what the cltess kernels rely on: the FP_CONTRACT pragma, float4 and its built-ins,
# integer atomics on global memory, a loop.
PROBE_SOURCE = """
#pragma OPENCL FP_CONTRACT OFF
__kernel void cltess_probe(__global const float4 *points, __global float *lengths,
                           __global uint *visits) {
    uint i = get_global_id(0);
    float4 p = points[i];
    float sum = 0.0f;
    for (int k = 0; k < 4; ++k)
        sum += p.x * p.x;
    lengths[i] = sqrt(dot(p, p)) + sum - 4.0f * p.x * p.x;
    atomic_inc(visits);
}
"""
PROBE_ITEMS = 256


@dataclass(frozen=True)
class Probe:
    """Whether a device runs cltess kernels: ``status`` is "usable", "fails to build" or
    "fails to run"; ``reason`` is one line (empty when usable), ``log`` the full text."""

    status: str
    reason: str = ""
    log: str = ""

    @property
    def usable(self) -> bool:
        return self.status == USABLE

    def describe(self) -> str:
        return self.status + (f": {self.reason}" if self.reason else "")


def first_error_line(log: str) -> str:
    """The line of a build log (or error text) that says what went wrong, shortened."""
    lines = [line.strip() for line in str(log).splitlines() if line.strip()]
    for line in lines:
        if re.search(r"\berror\b", line, re.IGNORECASE) and not line.startswith("clBuildProgram failed"):
            return line[:200]
    return (lines[0] if lines else "unknown error")[:200]


def _build_probe(context: cl.Context) -> cl.Program:
    with warnings.catch_warnings():  # compiler chatter is no failure
        warnings.simplefilter("ignore", cl.CompilerWarning)
        return cl.Program(context, PROBE_SOURCE).build()


def _run_probe(context: cl.Context, program: cl.Program) -> None:
    """Runs the probe kernel; raises RuntimeError when the answer is wrong."""
    rng = np.random.default_rng(1)
    points = rng.uniform(-2.0, 2.0, (PROBE_ITEMS, 4)).astype(np.float32)
    queue = cl.CommandQueue(context)
    flags = cl.mem_flags
    points_buffer = cl.Buffer(context, flags.READ_ONLY | flags.COPY_HOST_PTR, hostbuf=points)
    lengths_buffer = cl.Buffer(context, flags.WRITE_ONLY, points[:, 0].nbytes)
    visits = np.zeros(1, np.uint32)
    visits_buffer = cl.Buffer(context, flags.READ_WRITE | flags.COPY_HOST_PTR, hostbuf=visits)
    program.cltess_probe(queue, (PROBE_ITEMS,), None, points_buffer, lengths_buffer, visits_buffer)
    lengths = np.empty(PROBE_ITEMS, np.float32)
    cl.enqueue_copy(queue, lengths, lengths_buffer)
    cl.enqueue_copy(queue, visits, visits_buffer)
    queue.finish()
    expected = np.linalg.norm(points.astype(np.float64), axis=1)
    if int(visits[0]) != PROBE_ITEMS:
        raise RuntimeError(f"wrong result: {int(visits[0])} of {PROBE_ITEMS} work-items ran")
    if not np.allclose(lengths, expected, rtol=1e-5, atol=1e-5):
        worst = float(np.max(np.abs(lengths - expected)))
        raise RuntimeError(f"wrong result: the probe kernel is off by {worst:.3g}")


def _run_checks(info: DeviceInfo) -> Probe:
    try:
        context = cl.Context([info.device])
        program = _build_probe(context)
    except Exception as error:  # noqa: BLE001  any failure here means "cannot build"
        return Probe(FAILS_TO_BUILD, first_error_line(error), str(error))
    try:
        _run_probe(context, program)
    except Exception as error:  # noqa: BLE001
        return Probe(FAILS_TO_RUN, first_error_line(error), str(error))
    return Probe(USABLE)


_verdicts: dict[str, Probe] = {}  # this process's verdicts, by DeviceInfo.cache_key


def _probe_file():
    return cache_dir() / "probes.json"


def _load_verdicts() -> dict:
    try:
        return json.loads(_probe_file().read_text())
    except (OSError, ValueError):
        return {}


def _save_verdict(key: str, probe: Probe) -> None:
    """Adds one verdict to the cache file (atomically; silently skipped when unwritable)."""
    path = _probe_file()
    verdicts = _load_verdicts()
    verdicts[key] = {"status": probe.status, "reason": probe.reason, "log": probe.log[:20000]}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        staging = path.with_name(f".{path.name}.{os.getpid()}")
        staging.write_text(json.dumps(verdicts, indent=1))
        os.replace(staging, path)
    except OSError:
        pass


def probe_device(info: DeviceInfo) -> Probe:
    """Whether the device builds and runs a small kernel correctly; cached per device and
    driver version. A failure to run is not cached (it may be passing, e.g. a busy device)."""
    key = info.cache_key
    if key in _verdicts:
        return _verdicts[key]
    stored = _load_verdicts().get(key)
    if stored is not None:
        probe = Probe(stored["status"], stored.get("reason", ""), stored.get("log", ""))
    else:
        probe = _run_checks(info)
        if probe.status != FAILS_TO_RUN:
            _save_verdict(key, probe)
    _verdicts[key] = probe
    return probe


# --- choosing -------------------------------------------------------------------------------

def _describe_all(devices: list[DeviceInfo]) -> str:
    return "\n".join(f"  {info.describe()}: {probe_device(info).describe()}" for info in devices)


def _available(devices: list[DeviceInfo]) -> str:
    return "available devices:\n" + _describe_all(devices)


def default_order(devices: list[DeviceInfo]) -> list[DeviceInfo]:
    """Candidates for the default, best first: CPUs (by ``CPU_RUNTIME_ORDER``), then the rest."""
    def rank(indexed):
        index, info = indexed
        if info.type != "CPU":
            return (1, 0, index)
        order = [i for i, name in enumerate(CPU_RUNTIME_ORDER) if name.lower() in info.platform.lower()]
        return (0, order[0] if order else len(CPU_RUNTIME_ORDER), index)
    return [info for _, info in sorted(enumerate(devices), key=rank)]


def default_device_info(devices: list[DeviceInfo] | None = None) -> DeviceInfo:
    """The entry of ``devices`` (default: ``list_devices()``) that ``pick_device()`` returns."""
    return _pick(None, list_devices() if devices is None else devices)


def pick_device(name: str | None = None) -> cl.Device:
    """The first device whose platform or device name contains ``name`` (case-insensitive).

    With ``name=None``: ``$CLTESS_DEVICE`` if set, else the first usable CPU device, else the
    first usable device. Raises :class:`DeviceError` when there is no platform, nothing
    matches, or the device asked for fails its probe (``error.log`` has the build log).
    """
    return _pick(name, list_devices()).device


def _pick(name: str | None, devices: list[DeviceInfo]) -> DeviceInfo:
    if not devices:
        raise DeviceError("no OpenCL platform found; " + INSTALL_HINT)
    source = ""
    if name is None:
        name = os.environ.get(DEVICE_ENV_VAR) or None
        source = f" (from ${DEVICE_ENV_VAR})"
    if name is None:
        for info in default_order(devices):
            if probe_device(info).usable:
                return info
        raise DeviceError("no usable OpenCL device:\n" + _describe_all(devices) + "\n" + INSTALL_HINT)
    if not name.strip():
        raise DeviceError(f"empty device name; {_available(devices)}")
    for info in devices:
        if info.matches(name):
            return _checked(info, devices, source)
    raise DeviceError(f"no OpenCL device matches {name!r}{source}; {_available(devices)}")


def _checked(info: DeviceInfo, devices: list[DeviceInfo], source: str) -> DeviceInfo:
    """``info`` if it passes its probe, else a short error saying what to do instead."""
    probe = probe_device(info)
    if probe.usable:
        return info
    others = [other for other in devices if other is not info and probe_device(other).usable]
    instead = ("usable devices: " + "; ".join(f"{o.name} on {o.platform}" for o in others)
               + " (pick one with --device NAME or $" + DEVICE_ENV_VAR + ")") if others else INSTALL_HINT
    raise DeviceError(f"OpenCL device {info.name!r} on {info.platform}{source} {probe.describe()}; "
                      f"{instead}. The full log: --verbose", log=probe.log)


def make_queue(device: cl.Device) -> tuple[cl.Context, cl.CommandQueue]:
    """A context on ``device`` and an in-order command queue with profiling enabled."""
    try:
        context = cl.Context([device])
        queue = cl.CommandQueue(context, device, properties=cl.command_queue_properties.PROFILING_ENABLE)
    except cl.Error as error:
        raise DeviceError(f"cannot open OpenCL device {device.name.strip()!r}: {error}") from error
    return context, queue

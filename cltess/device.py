"""Finding an OpenCL device: list what the ICD loader offers, pick one by name, make a queue.

Default device: the ``CLTESS_DEVICE`` environment variable if set (a name, as for
``pick_device``), else the first CPU device (PoCL when installed with ``cltess[pocl]``),
else the first device of any kind.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

import pyopencl as cl

__all__ = ["DEVICE_ENV_VAR", "DeviceError", "DeviceInfo", "list_devices", "make_queue", "pick_device"]

DEVICE_ENV_VAR = "CLTESS_DEVICE"

INSTALL_HINT = (
    "no OpenCL platform found. Install the CPU runtime PoCL into this environment with "
    "'pip install \"pyopencl[pocl]\"' (or 'pip install cltess[pocl]'), "
    "or install a vendor OpenCL driver and its ICD file"
)


class DeviceError(RuntimeError):
    """No usable OpenCL platform or device; the message says what to do about it."""


_DEVICE_TYPE_NAMES = (
    (cl.device_type.GPU, "GPU"),
    (cl.device_type.CPU, "CPU"),
    (cl.device_type.ACCELERATOR, "accelerator"),
)


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
            ))
    return devices


def _available(devices: list[DeviceInfo]) -> str:
    return "available devices:\n" + "\n".join(f"  {info.describe()}" for info in devices)


def default_device_info(devices: list[DeviceInfo] | None = None) -> DeviceInfo:
    """The entry of ``devices`` (default: ``list_devices()``) that ``pick_device()`` returns."""
    return _pick(None, list_devices() if devices is None else devices)


def pick_device(name: str | None = None) -> cl.Device:
    """The first device whose platform or device name contains ``name`` (case-insensitive).

    With ``name=None``: ``$CLTESS_DEVICE`` if set, else the first CPU device, else the first
    device.  Raises :class:`DeviceError` when there is no platform or nothing matches.
    """
    return _pick(name, list_devices()).device


def _pick(name: str | None, devices: list[DeviceInfo]) -> DeviceInfo:
    if not devices:
        raise DeviceError(INSTALL_HINT)
    source = ""
    if name is None:
        name = os.environ.get(DEVICE_ENV_VAR) or None
        source = f" (from ${DEVICE_ENV_VAR})"
    if name is None:
        cpus = [info for info in devices if info.type == "CPU"]
        return (cpus or devices)[0]
    if not name.strip():
        raise DeviceError(f"empty device name; {_available(devices)}")
    for info in devices:
        if info.matches(name):
            return info
    raise DeviceError(f"no OpenCL device matches {name!r}{source}; {_available(devices)}")


def make_queue(device: cl.Device) -> tuple[cl.Context, cl.CommandQueue]:
    """A context on ``device`` and an in-order command queue with profiling enabled."""
    try:
        context = cl.Context([device])
        queue = cl.CommandQueue(context, device, properties=cl.command_queue_properties.PROFILING_ENABLE)
    except cl.Error as error:
        raise DeviceError(f"cannot open OpenCL device {device.name.strip()!r}: {error}") from error
    return context, queue

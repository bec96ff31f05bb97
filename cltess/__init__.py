"""cltess: crack-free, error-bounded tessellation of curved patches with OpenCL (CudaTess port).

>>> from cltess import load_scene, Tessellator, export
>>> tess = Tessellator().tessellate(load_scene("scenes/teapot.bez"), eps=1e-3)
>>> export(tess, "teapot.ply")
"""
from .runtimes import register_pip_runtimes

# Before anything lists OpenCL platforms: let the ICD loader see pip-installed CPU runtimes.
register_pip_runtimes()

from .export import export  # noqa: E402  (the module first: a later import of it cannot hide this function)
from .request import Request  # noqa: E402
from .scene import Camera, Scene, SceneError  # noqa: E402
from .tessellation import Tessellation  # noqa: E402


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("cltess")
    except metadata.PackageNotFoundError:  # run from a source tree that was never installed
        return "0+unknown"


def __getattr__(name):
    # Lazy: importing cltess must not need an OpenCL platform.  __version__: reading the
    # package's metadata (an email parse) is left to whoever asks.
    if name == "__version__":
        global __version__
        __version__ = _version()
        return __version__
    if name == "Tessellator":
        from .backends.opencl import Tessellator
        return Tessellator
    if name == "Session":
        from .session import Session
        return Session
    if name == "VulkanQueue":  # Session(share="vulkan", vulkan=VulkanQueue(...))
        from .backends.opencl.share_vulkan import VulkanQueue
        return VulkanQueue
    if name == "load_scene":
        from .io import load_scene
        return load_scene
    raise AttributeError(name)


__all__ = ["__version__", "Camera", "Request", "Scene", "SceneError", "Tessellation", "Tessellator", "Session",
           "VulkanQueue", "load_scene", "export"]

"""cltess: crack-free, error-bounded tessellation of curved patches with OpenCL (CudaTess port).

>>> from cltess import load_scene, Tessellator, export
>>> tess = Tessellator().tessellate(load_scene("scenes/teapot.bez"), eps=1e-3)
>>> export(tess, "teapot.ply")
"""
from .export import export
from .request import Request
from .scene import Camera, Scene, SceneError
from .tessellation import Tessellation


def __getattr__(name):
    # Lazy: importing cltess must not need an OpenCL platform.
    if name == "Tessellator":
        from .backends.opencl import Tessellator
        return Tessellator
    if name == "load_scene":
        from .formats import load_scene
        return load_scene
    raise AttributeError(name)


__all__ = ["Camera", "Request", "Scene", "SceneError", "Tessellation", "Tessellator", "load_scene", "export"]

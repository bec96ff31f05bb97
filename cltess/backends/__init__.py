"""Backends by name: each runs the five stages (``plan`` / ``emit``, cltess.backends.base)."""


def backends() -> dict:
    """name -> backend class (the OpenCL one imported lazily: it needs a platform to run)."""
    from .numpy import NumpyBackend
    from .opencl import Tessellator
    return {"opencl": Tessellator, "numpy": NumpyBackend}

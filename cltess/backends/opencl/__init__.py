"""The OpenCL backend."""
from .plan import Plan
from .tessellator import Tessellator

__all__ = ["Plan", "Tessellator"]

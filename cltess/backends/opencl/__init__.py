"""The OpenCL backend."""
from .tessellator import Plan, Tessellator

__all__ = ["Plan", "Tessellator"]

"""Criteria: how much error where (tolerances) and how fine for that error (bounds)."""
from .base import DEFAULT_MAX_FACTOR, combine
from .tolerance import ObjectSpace, ScreenSpace

__all__ = ["DEFAULT_MAX_FACTOR", "ObjectSpace", "ScreenSpace", "combine"]

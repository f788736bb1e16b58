"""Small-strain element laws in the element frame (no knowledge of frames or DOLFINx)."""
from . import line2d

__all__ = ["line2d"]

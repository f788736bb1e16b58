"""Small-strain element laws in the element frame (no knowledge of frames or DOLFINx)."""
from . import beam3d, line2d

__all__ = ["beam3d", "line2d"]

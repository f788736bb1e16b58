"""Small-strain element laws in the element frame (no knowledge of frames or DOLFINx)."""
from . import beam3d, line2d, shell_triangle

__all__ = ["beam3d", "line2d", "shell_triangle"]

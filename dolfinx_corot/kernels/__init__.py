"""Element kernels: gather ► co-rotational frame ► local law ► scatter (numba)."""
from . import beam3d, line2d

__all__ = ["beam3d", "line2d"]

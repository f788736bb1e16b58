"""Element kernels: gather ► co-rotational frame ► local law ► scatter (numba)."""
from . import line2d

__all__ = ["line2d"]

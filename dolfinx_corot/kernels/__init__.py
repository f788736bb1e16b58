"""Element kernels: gather ► co-rotational frame ► local law ► scatter (numba).

Each module's DOLFINx kernels come from :func:`.ufcx.tabulate_tensor_kernels`.
"""
from . import beam3d, line2d, membrane_quad, shell3d

__all__ = ["beam3d", "line2d", "membrane_quad", "shell3d"]

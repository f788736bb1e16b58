"""Element kernels: gather ► co-rotational frame ► local law ► scatter (numba).

Each module's DOLFINx kernels come from :func:`.ufcx.tabulate_tensor_kernels`. A module is
imported, and its compiled kernels loaded from numba's cache, when a part of its kind first asks
for it (:class:`OnFirstUse`): a scene of beams loads no shell kernels.
"""
from __future__ import annotations

import importlib
import sys

import numpy as np

__all__ = ["CCW", "NSTATE", "OnFirstUse", "RESULTANTS", "SYMMETRIZED", "beam3d", "line2d", "membrane_quad",
           "shell3d", "shell_quad"]

#: the number of values of a node's state in 3D: displacement (3) and unit quaternion (4)
NSTATE = 7
#: the kernels' constant c[0] of a co-rotational analysis whose part asks for the symmetric part
#: of the tangent, ½(K + Kᵀ) (0: geometrically linear, 1: co-rotational with K)
SYMMETRIZED = 2.0
#: DOLFINx's vertex order of a quadrilateral → counter-clockwise
CCW = np.array([0, 1, 3, 2])
#: the components of a shell's or membrane's element results (see :func:`.shell3d.resultants`)
RESULTANTS = ("Nxx", "Nyy", "Nxy", "Mxx", "Myy", "Mxy", "Qx", "Qy", "sxx_top", "syy_top", "sxy_top",
              "sxx_bottom", "syy_bottom", "sxy_bottom", "mises_top", "mises_bottom")


class OnFirstUse:
    """A class attribute that is the kernel module ``name`` of this package, imported when first
    read (``kernels = OnFirstUse("line2d")`` on a part class)."""

    def __init__(self, name: str):
        self.name = name

    def __get__(self, instance, owner):
        module = f"{__name__}.{self.name}"
        if module not in sys.modules:
            from ..console import announce_compilation

            announce_compilation(self.name)
        return importlib.import_module(module)


def __getattr__(name: str):
    if name in ("beam3d", "line2d", "membrane_quad", "shell3d", "shell_quad"):
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

"""dolfinx_corot: large-rotation structures and contact on DOLFINx 0.5.2.

The user's model is a :class:`Scene`; a driver (:class:`LoadControl`)
follows the load path; :func:`solve` returns a :class:`Result` with the
per-step history.

Importing the package does no work: each name below is imported when it is first used
(``dc.Scene`` brings DOLFINx and the scene's modules, a part's element kernels come with the
first part of their kind, gmsh with the first gmsh model read, PyVista with the first picture).
"""
from __future__ import annotations

import importlib as _importlib
import os as _os

# one thread per MPI rank: a threaded BLAS/OpenMP runtime spins idle threads that take the
# second core from the other rank (set before numpy loads BLAS; an explicit setting wins)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

from .console import show_compiler_output  # noqa: E402

show_compiler_output(_os.environ.get("DC_COMPILER_OUTPUT", "") not in ("", "0"))

__version__ = "0.1.0"

#: public name → the module that defines it
_WHERE = {
    "Amplitude": "amplitudes",
    "AugmentedLagrangian": "contact.laws", "ContactError": "contact.laws", "Coulomb": "contact.laws",
    "Penalty": "contact.laws",
    "ContactPair": "contact.pair",
    "GroupNotFoundError": "io.mesh", "TaggedMesh": "io.mesh", "from_gmsh": "io.mesh",
    "Elastic": "materials", "NeoHookean": "materials", "Orthotropic": "materials",
    "SaintVenantKirchhoff": "materials",
    "MeshError": "parts",
    "History": "result", "Result": "result",
    "Scene": "scene",
    "Circle": "sections", "Laminate": "sections", "Pipe": "sections", "Ply": "sections", "Rectangle": "sections",
    "Section": "sections",
    "ArcLength": "solvers", "CheckpointError": "solvers", "ConvergenceError": "solvers",
    "CriticalPoint": "solvers", "CriticalPointError": "solvers", "LoadControl": "solvers",
    "NewtonOptions": "solvers", "SingularModelError": "solvers", "solve": "solvers",
}
#: subpackages and modules reachable as attributes (``dc.plot``, ``dc.io``, …)
_MODULES = ("amplitudes", "closed_forms", "contact", "gallery", "io", "materials", "plot", "result", "rotations",
            "scene", "sections", "solvers", "staging")

__all__ = sorted(_WHERE) + ["plot", "rotations", "show_compiler_output"]


def __getattr__(name: str):
    if name in _WHERE:
        value = getattr(_importlib.import_module(f".{_WHERE[name]}", __name__), name)
    elif name in _MODULES:
        value = _importlib.import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # once imported, an ordinary attribute
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE) | set(_MODULES))

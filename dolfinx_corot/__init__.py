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

#: Open MPI's settings for a process started without a launcher (a singleton: one rank, no peer)
SINGLETON_MPI = {"OMPI_MCA_ess_singleton_isolated": "1", "OMPI_MCA_pml": "ob1"}
#: variables of the launchers (mpirun, PMIx, PMI, Slurm): with any of them the process is not a singleton
LAUNCHED_BY = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID")


def _singleton_mpi(environ) -> dict:
    """The settings :data:`SINGLETON_MPI` puts into ``environ`` (those it sets: a setting of the
    user's wins, and a launched process gets none). Open MPI starts a singleton by forking a local
    daemon (orted) for dynamic processes and by probing the high-speed fabrics (libfabric's
    providers, through its 'cm' layer) before it settles for shared memory: 0.33 of the 0.39 s that
    ``from mpi4py import MPI`` took here. A process with no peer needs neither: with the daemon
    left out (no MPI_Comm_spawn then) and the point-to-point layer ob1 chosen, MPI starts in
    0.05 s. Read when MPI starts, so only when this package is imported before mpi4py's ``MPI``
    (as a script's ``import dolfinx_corot as dc`` in its first lines); MPICH ignores them."""
    if any(name in environ for name in LAUNCHED_BY):
        return {}
    made = {name: value for name, value in SINGLETON_MPI.items() if name not in environ}
    environ.update(made)
    return made


_singleton_mpi(_os.environ)

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

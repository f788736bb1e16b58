"""dolfinx_corot: large-rotation structures and contact on DOLFINx 0.5.2.

The user's model is a :class:`Scene`; a driver (:class:`LoadControl`)
follows the load path; :func:`solve` returns a :class:`Result` with the
per-step history.
"""
import os as _os

# one thread per MPI rank: a threaded BLAS/OpenMP runtime spins idle threads that take the
# second core from the other rank (set before numpy loads BLAS; an explicit setting wins)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

try:  # VTK's C++ runtime before numba's: llvmlite's exported std::string symbols otherwise take
    import vtkmodules.vtkCommonCore  # noqa: F401,E402  (over VTK's and crash its std::regex: pictures)
except ImportError:  # no PyVista: no pictures
    pass

from .console import announce_compilation, show_compiler_output  # noqa: E402

show_compiler_output(_os.environ.get("DC_COMPILER_OUTPUT", "") not in ("", "0"))
announce_compilation()

from . import plot, rotations  # noqa: E402
from .amplitudes import Amplitude
from .contact.laws import AugmentedLagrangian, ContactError, Coulomb, Penalty
from .contact.pair import ContactPair
from .io.mesh import GroupNotFoundError, TaggedMesh, from_gmsh
from .materials import Elastic, NeoHookean, SaintVenantKirchhoff
from .parts import MeshError
from .result import History, Result
from .scene import Scene
from .sections import Circle, Pipe, Rectangle, Section
from .solvers import (ArcLength, CheckpointError, ConvergenceError, CriticalPoint, CriticalPointError, LoadControl,
                      NewtonOptions, SingularModelError, solve)

__version__ = "0.1.0"

__all__ = ["Amplitude", "ArcLength", "AugmentedLagrangian", "CheckpointError", "ContactError", "ContactPair",
           "Coulomb", "Penalty", "Circle", "ConvergenceError", "CriticalPoint", "CriticalPointError",
           "SingularModelError", "Elastic", "show_compiler_output", "GroupNotFoundError", "History", "LoadControl", "MeshError", "NeoHookean",
           "NewtonOptions", "Pipe", "Rectangle", "SaintVenantKirchhoff", "Result", "Scene", "Section", "TaggedMesh",
           "from_gmsh", "plot", "rotations", "solve"]

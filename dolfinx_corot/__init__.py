"""dolfinx_corot: large-rotation structures and contact on DOLFINx 0.5.2.

The user's model is a :class:`Scene`; a driver (:class:`LoadControl`)
follows the load path; :func:`solve` returns a :class:`Result` with the
per-step history.
"""
from . import rotations
from .amplitudes import Amplitude
from .io.mesh import GroupNotFoundError, TaggedMesh, from_gmsh
from .materials import Elastic, NeoHookean, SaintVenantKirchhoff
from .result import History, Result
from .scene import Scene
from .sections import Circle, Rectangle, Section
from .solvers import ArcLength, ConvergenceError, LoadControl, NewtonOptions, solve

__version__ = "0.1.0"

__all__ = ["Amplitude", "ArcLength", "Circle", "ConvergenceError", "Elastic", "GroupNotFoundError", "History", "LoadControl",
           "NeoHookean", "NewtonOptions", "Rectangle", "SaintVenantKirchhoff", "Result", "Scene", "Section", "TaggedMesh", "from_gmsh",
           "rotations", "solve"]

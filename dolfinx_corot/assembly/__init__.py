"""Assembly: the global numbering of parts on several meshes, the system as a sum of the parts'
forms and of contributions, and (in :mod:`.petsc`) every PETSc object of the package."""
from .contribution import Contribution
from .layout import DofLayout
from .system import CoupledSystem, System, Timings, make_system

__all__ = ["Contribution", "CoupledSystem", "DofLayout", "System", "Timings", "make_system"]

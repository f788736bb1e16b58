"""Newton's method (one loop with hooks for every driver), the drivers that follow a load path,
and runs with history, checkpoints and restart."""
from .control import ArcLength, LoadControl
from .newton import ConvergenceError, NewtonOptions, NewtonReport, Stepper, newton, solve_step
from .run import CheckpointError, solve
from .stability import CriticalPoint, CriticalPointError, SingularModelError

__all__ = ["ArcLength", "CheckpointError", "ConvergenceError", "CriticalPoint", "CriticalPointError",
           "SingularModelError", "LoadControl", "NewtonOptions", "NewtonReport",
           "Stepper", "newton", "solve", "solve_step"]

"""Newton's method and the drivers that follow a load path."""
from .drivers import ArcLength, LoadControl, solve
from .newton import ConvergenceError, NewtonOptions, NewtonReport, newton

__all__ = ["ArcLength", "ConvergenceError", "LoadControl", "NewtonOptions", "NewtonReport", "newton", "solve"]

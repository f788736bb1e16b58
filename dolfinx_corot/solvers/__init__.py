"""Newton's method and the drivers that follow a load path."""
from .drivers import LoadControl, solve
from .newton import ConvergenceError, NewtonOptions, NewtonReport, newton

__all__ = ["ConvergenceError", "LoadControl", "NewtonOptions", "NewtonReport", "newton", "solve"]

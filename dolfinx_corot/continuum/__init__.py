"""Large-deformation continua in UFL: kinematics and hyperelastic laws as plain functions."""
from .kinematics import deformation_gradient, green_lagrange
from .laws import first_piola, lame

__all__ = ["deformation_gradient", "first_piola", "green_lagrange", "lame"]

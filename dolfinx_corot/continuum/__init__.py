"""Large-deformation continua: kinematics and hyperelastic laws in UFL as plain functions
(:mod:`.kinematics`, :mod:`.laws`), and the laws' residual and tangent as C kernels
(:mod:`.compiled`, imported on first use)."""
from .kinematics import deformation_gradient, green_lagrange
from .laws import first_piola, lame

__all__ = ["deformation_gradient", "first_piola", "green_lagrange", "lame"]

"""Total-Lagrangian kinematics (UFL). In 2D the tensors are 2 × 2: plane strain (E_zz = 0, F_zz = 1)."""
from __future__ import annotations

import ufl


def deformation_gradient(u):
    """F = I + ∇u (reference configuration)."""
    d = len(u)
    return ufl.Identity(d) + ufl.grad(u)


def green_lagrange(F):
    """E = ½(FᵀF − I)."""
    return 0.5 * (F.T * F - ufl.Identity(F.ufl_shape[0]))

r"""Hyperelastic laws as first Piola–Kirchhoff stresses P(F) (UFL).

* St Venant–Kirchhoff: :math:`\mathbf S = \lambda\,\mathrm{tr}(\mathbf E)\mathbf I + 2\mu\mathbf E`,
  :math:`\mathbf P = \mathbf F\mathbf S`.
* compressible neo-Hookean: :math:`\psi = \tfrac\mu2(I_1 - 3 - 2\ln J) + \tfrac\lambda2(\ln J)^2`,
  :math:`\mathbf P = \mu(\mathbf F - \mathbf F^{-T}) + \lambda\ln J\,\mathbf F^{-T}`.

In 2D (plane strain) F is 2 × 2 with F_zz = 1: the 2 × 2 forms above are
exact for plane strain (I₁ − 3 = tr₂(C) + 1 − 3, J = det₂ F).
"""
from __future__ import annotations

import ufl

from ..materials import Elastic, NeoHookean, SaintVenantKirchhoff
from .kinematics import green_lagrange


def lame(E, nu):
    """(λ, μ) from Young's modulus and Poisson's ratio (numbers or UFL expressions)."""
    return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))


def first_piola(kind: type, F, lmbda, mu):
    """P(F) of the law ``kind`` (SaintVenantKirchhoff or NeoHookean) with Lamé constants λ, μ."""
    d = F.ufl_shape[0]
    if issubclass(kind, NeoHookean):
        J = ufl.det(F)
        Finv_T = ufl.inv(F).T
        return mu * (F - Finv_T) + lmbda * ufl.ln(J) * Finv_T
    if issubclass(kind, (SaintVenantKirchhoff, Elastic)):
        E = green_lagrange(F)
        S = lmbda * ufl.tr(E) * ufl.Identity(d) + 2.0 * mu * E
        return F * S
    raise TypeError(f"no continuum law for {kind.__name__}")

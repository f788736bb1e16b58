r"""Four-node membrane in its element frame (linear, plane stress).

The bilinear quadrilateral (Q4) on the projected initial local coordinates
(nodes counter-clockwise), :math:`\mathbf K = t\int\mathbf B^T\mathbf D\mathbf B\,dA` by 2 × 2
Gauss points; dofs (ū, v̄) per node. It passes the patch test on any convex
quadrilateral; like every Q4 it is stiff in in-plane bending, which
membranes (fabrics, sheets, cable-net infills) rarely carry.

``props = (E, nu, t)``, or ``(E, nu, t, A (3 × 3) row-major)`` with the section's membrane
stiffness A = Σ Q̄_k t_k (an orthotropic or laminated membrane, in the element's axes; E and ν a
reference).
"""
from __future__ import annotations

import numba
import numpy as np

NPROPS = 12
E_, NU, T = range(3)
A0 = 3

_G = 1.0 / np.sqrt(3.0)
_GAUSS = np.array([[-_G, -_G], [_G, -_G], [_G, _G], [-_G, _G]])
_NODES = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])


def check_props(E: float, nu: float, t: float, label: str) -> None:
    if not (np.isfinite(E) and E > 0.0):
        raise ValueError(f"{label}: Young's modulus E = {E} must be positive")
    if not (-1.0 < nu < 0.5):
        raise ValueError(f"{label}: Poisson's ratio nu = {nu} must lie in (-1, 0.5)")
    if not (np.isfinite(t) and t > 0.0):
        raise ValueError(f"{label}: thickness = {t} must be positive")


@numba.njit(cache=True)
def strain_B(xy, xi, eta, B):
    """Fill B (3, 8), the strain matrix ε = (ε_xx, ε_yy, γ_xy) = B d̄ of the Q4 at (ξ, η), for the
    local node coordinates xy (4, 2), counter-clockwise; returns det J."""
    dN = np.empty((2, 4))
    for a in range(4):
        dN[0, a] = 0.25 * _NODES[a, 0] * (1.0 + _NODES[a, 1] * eta)
        dN[1, a] = 0.25 * _NODES[a, 1] * (1.0 + _NODES[a, 0] * xi)
    J00 = J01 = J10 = J11 = 0.0
    for a in range(4):
        J00 += dN[0, a] * xy[a, 0]
        J01 += dN[0, a] * xy[a, 1]
        J10 += dN[1, a] * xy[a, 0]
        J11 += dN[1, a] * xy[a, 1]
    det = J00 * J11 - J01 * J10
    for a in range(4):
        nx = (J11 * dN[0, a] - J01 * dN[1, a]) / det
        ny = (-J10 * dN[0, a] + J00 * dN[1, a]) / det
        B[0, 2 * a] = nx
        B[1, 2 * a + 1] = ny
        B[2, 2 * a] = ny
        B[2, 2 * a + 1] = nx
    return det


@numba.njit(cache=True)
def plane_stress(props):
    """The plane-stress stiffness D (3, 3) of the membrane's material (A/t when A is given)."""
    t = props[T]
    if props.shape[0] > A0:
        return props[A0:A0 + 9].copy().reshape(3, 3) / t
    E, nu = props[E_], props[NU]
    c = E / (1.0 - nu * nu)
    return np.array([[c, c * nu, 0.0], [c * nu, c, 0.0], [0.0, 0.0, c * (1.0 - nu) / 2.0]])


@numba.njit(cache=True)
def local_stiffness(xy, props, K):
    """K (8, 8) for the local node coordinates xy (4, 2), counter-clockwise."""
    t = props[T]
    D = plane_stress(props)
    K[:, :] = 0.0
    B = np.zeros((3, 8))
    for q in range(4):
        w = t * strain_B(xy, _GAUSS[q, 0], _GAUSS[q, 1], B)
        for i in range(8):
            for j in range(8):
                acc = 0.0
                for r in range(3):
                    acc += B[r, i] * (D[r, 0] * B[0, j] + D[r, 1] * B[1, j] + D[r, 2] * B[2, j])
                K[i, j] += w * acc


@numba.njit(cache=True)
def centre_B(xy):
    """The strain matrix (3, 8) of the Q4 at its centre (ξ = η = 0) (see :func:`strain_B`)."""
    B = np.zeros((3, 8))
    strain_B(xy, 0.0, 0.0, B)
    return B

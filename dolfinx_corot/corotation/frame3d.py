r"""Co-rotational frame of a two-node element in space (Battini & Pacoste 2002).

Global element vector (node-major, as DOLFINx packs it)
:math:`\delta\mathbf d = (\delta\mathbf u_1, \delta\mathbf w_1, \delta\mathbf u_2, \delta\mathbf w_2)`,
with :math:`\delta\mathbf w_i` *spatial* spins: :math:`\mathbf R_i \leftarrow \exp(\delta\mathbf w_i)\mathbf R_i`.

Element frame :math:`\mathbf R_r = [\mathbf e_1\ \mathbf e_2\ \mathbf e_3]`:
:math:`\mathbf e_1` along the current chord; with
:math:`\mathbf p = \tfrac12(\mathbf R_1 + \mathbf R_2)\mathbf R_0\,\mathbf j` the mean of the
initial second axis carried by the nodal rotations,
:math:`\mathbf e_3 = \mathbf e_1\times\mathbf p/\|\mathbf e_1\times\mathbf p\|`, :math:`\mathbf e_2 = \mathbf e_3\times\mathbf e_1`.

Basic deformations :math:`\bar{\mathbf d} = (\bar u, \bar{\boldsymbol\theta}_1, \bar{\boldsymbol\theta}_2)`:
:math:`\bar u = l - l_0`, :math:`\bar{\boldsymbol\theta}_i = \log(\mathbf R_r^T\mathbf R_i\mathbf R_0)`.

Their variations (derived as in Battini & Pacoste 2002, eqs. 20–35):
:math:`\delta\bar u = \mathbf r\,\delta\mathbf d` and
:math:`\delta\bar{\boldsymbol\theta}_i = \mathbf T^{-1}(\bar{\boldsymbol\theta}_i)\,(\mathbf S_i - \mathbf G^T)\,\mathbf E^T\delta\mathbf d`,
where :math:`\mathbf E = \mathrm{diag}(\mathbf R_r, \mathbf R_r, \mathbf R_r, \mathbf R_r)`,
:math:`\mathbf S_i` picks :math:`\delta\mathbf w_i`, and :math:`\mathbf G^T\mathbf E^T\delta\mathbf d`
is the spin of the element frame in its own axes,

.. math::

    \mathbf G^T = \begin{bmatrix}
      0 & 0 & \eta/l & \eta_{12}/2 & -\eta_{11}/2 & 0 & 0 & 0 & -\eta/l & \eta_{22}/2 & -\eta_{21}/2 & 0\\
      0 & 0 & 1/l & 0 & 0 & 0 & 0 & 0 & -1/l & 0 & 0 & 0\\
      0 & -1/l & 0 & 0 & 0 & 0 & 0 & 1/l & 0 & 0 & 0 & 0 \end{bmatrix},

:math:`\eta = p_1/p_2`, :math:`\eta_{ij} = p_{ij}/p_2` (local components of
:math:`\mathbf p` and :math:`\mathbf p_i = \mathbf R_i\mathbf R_0\mathbf j`). Then
:math:`\mathbf f = \mathbf B^T\bar{\mathbf f}`.

The rotation algebra (exp, log, T⁻¹) is that of :mod:`dolfinx_corot.rotations`.
Every function here is complex-analytic in the configuration, so that the
consistent tangent :math:`\mathbf K = \partial\mathbf f/\partial\mathbf d` (material and
geometric parts, i.e. :math:`\mathbf B^T\bar{\mathbf K}\mathbf B + \partial\mathbf B^T/\partial\mathbf d:\bar{\mathbf f}`)
is obtained exactly to rounding by complex-step differentiation
(Squire & Trapp 1998) in :mod:`dolfinx_corot.kernels.beam3d`. Branches test
real parts only.
"""
from __future__ import annotations

import numba
import numpy as np

from ..rotations import cross, dot, log_so3, matmul3, matmul3_tn, tangent_inv_so3
from .transform import rotate_columns


@numba.njit(cache=True)
def initial_frame(X1, X2, v, R0):
    """R0 (3, 3): columns e1 along X2 − X1, e2 the part of v normal to e1, e3 = e1 × e2.

    Returns l0; raises nothing: a v parallel to the element is caught when the
    part is built (see ``check_orientation``).
    """
    d = X2 - X1
    l0 = np.sqrt(dot(d, d))
    e1 = d / l0
    e2 = v - dot(v, e1) * e1
    e2 = e2 / np.sqrt(dot(e2, e2))
    e3 = np.empty(3)
    cross(e1, e2, e3)
    for i in range(3):
        R0[i, 0] = e1[i]
        R0[i, 1] = e2[i]
        R0[i, 2] = e3[i]
    return l0


@numba.njit(cache=True)
def current_frame(X1, X2, u1, u2, R1, R2, R0, Rr, p1, p2):
    """The current element frame Rr (3, 3) (columns e1, e2, e3) and p1, p2 (3,) = R_i R0 j;
    returns the current length l."""
    dt = u1.dtype
    dx = np.empty(3, dtype=dt)
    for k in range(3):
        dx[k] = X2[k] + u2[k] - X1[k] - u1[k]
    l = np.sqrt(dot(dx, dx))
    e1 = dx / l
    for k in range(3):
        p1[k] = R1[k, 0] * R0[0, 1] + R1[k, 1] * R0[1, 1] + R1[k, 2] * R0[2, 1]
        p2[k] = R2[k, 0] * R0[0, 1] + R2[k, 1] * R0[1, 1] + R2[k, 2] * R0[2, 1]
    p = 0.5 * (p1 + p2)
    e3 = np.empty(3, dtype=dt)
    cross(e1, p, e3)
    e3 = e3 / np.sqrt(dot(e3, e3))
    e2 = np.empty(3, dtype=dt)
    cross(e3, e1, e2)
    for k in range(3):
        Rr[k, 0] = e1[k]
        Rr[k, 1] = e2[k]
        Rr[k, 2] = e3[k]
    return l


@numba.njit(cache=True)
def basic(X1, X2, u1, u2, R1, R2, R0, l0, th1, th2, B):
    """Basic deformations of the current configuration and B = ∂d̄/∂d (7, 12).

    X1, X2: initial nodal positions; u1, u2: displacements; R1, R2: nodal
    rotations; R0: initial element frame. Fills th1, th2 (3,) and B; returns ū.
    """
    dt = u1.dtype
    p1 = np.empty(3, dtype=dt)
    p2 = np.empty(3, dtype=dt)
    Rr = np.empty((3, 3), dtype=dt)
    l = current_frame(X1, X2, u1, u2, R1, R2, R0, Rr, p1, p2)
    p = 0.5 * (p1 + p2)
    e1 = Rr[:, 0].copy()
    e2 = Rr[:, 1].copy()
    T = np.empty((3, 3), dtype=dt)
    Rb = np.empty((3, 3), dtype=dt)
    R0c = np.empty((3, 3), dtype=dt)
    for i in range(3):
        for j in range(3):
            R0c[i, j] = R0[i, j]
    matmul3_tn(Rr, R1, T)
    matmul3(T, R0c, Rb)
    log_so3(Rb, th1)
    matmul3_tn(Rr, R2, T)
    matmul3(T, R0c, Rb)
    log_so3(Rb, th2)
    ubar = (l * l - l0 * l0) / (l + l0)
    # local components of p, p1, p2 (only the first two are needed)
    pl0 = dot(e1, p)
    pl1 = dot(e2, p)
    eta = pl0 / pl1
    GT = np.zeros((3, 12), dtype=dt)
    GT[0, 2] = eta / l
    GT[0, 3] = 0.5 * dot(e2, p1) / pl1
    GT[0, 4] = -0.5 * dot(e1, p1) / pl1
    GT[0, 8] = -eta / l
    GT[0, 9] = 0.5 * dot(e2, p2) / pl1
    GT[0, 10] = -0.5 * dot(e1, p2) / pl1
    GT[1, 2] = 1.0 / l
    GT[1, 8] = -1.0 / l
    GT[2, 1] = -1.0 / l
    GT[2, 7] = 1.0 / l
    # B in local components: row ū and rows T⁻¹(θ̄_i)(S_i − Gᵀ); then columns rotated by Rrᵀ
    Bl = np.zeros((7, 12), dtype=dt)
    Bl[0, 0] = -1.0
    Bl[0, 6] = 1.0
    Ti = np.empty((3, 3), dtype=dt)
    for i in range(2):
        tangent_inv_so3(th1 if i == 0 else th2, Ti)
        for r in range(3):
            for c in range(12):
                Bl[1 + 3 * i + r, c] = -(Ti[r, 0] * GT[0, c] + Ti[r, 1] * GT[1, c] + Ti[r, 2] * GT[2, c])
            for k in range(3):
                Bl[1 + 3 * i + r, 3 + 6 * i + k] += Ti[r, k]
    rotate_columns(Bl, Rr, B, 7, 12)
    return ubar

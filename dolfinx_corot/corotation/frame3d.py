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


@numba.njit(cache=True, inline="always")
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@numba.njit(cache=True, inline="always")
def cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@numba.njit(cache=True)
def rotation_from_quaternion(q, R):
    """R (3, 3) of the unit quaternion q (4,) = (w, x, y, z)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    R[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    R[0, 1] = 2.0 * (x * y - w * z)
    R[0, 2] = 2.0 * (x * z + w * y)
    R[1, 0] = 2.0 * (x * y + w * z)
    R[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    R[1, 2] = 2.0 * (y * z - w * x)
    R[2, 0] = 2.0 * (x * z - w * y)
    R[2, 1] = 2.0 * (y * z + w * x)
    R[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@numba.njit(cache=True)
def exp_spin(w, R):
    """R = exp(spin(w)) (Rodrigues), complex-analytic; series below |w|² = 1e-6."""
    t2 = dot(w, w)
    if abs(t2.real) < 1e-6:
        a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    else:
        t = np.sqrt(t2)
        a = np.sin(t) / t
        b = (1.0 - np.cos(t)) / t2
    W = np.zeros((3, 3), dtype=R.dtype)
    W[0, 1] = -w[2]
    W[0, 2] = w[1]
    W[1, 0] = w[2]
    W[1, 2] = -w[0]
    W[2, 0] = -w[1]
    W[2, 1] = w[0]
    R[:, :] = b * (W @ W) + a * W
    for i in range(3):
        R[i, i] += 1.0


@numba.njit(cache=True)
def log_rotation(R, th):
    """th (3,) = log(R) for a rotation below π (an element-frame rotation), complex-analytic."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    w = 0.5 * np.sqrt(1.0 + tr)
    f = 0.25 / w
    v0 = (R[2, 1] - R[1, 2]) * f
    v1 = (R[0, 2] - R[2, 0]) * f
    v2 = (R[1, 0] - R[0, 1]) * f
    s2 = v0 * v0 + v1 * v1 + v2 * v2
    if abs(s2.real) < 1e-16:
        c = (2.0 / w) * (1.0 - s2 / (3.0 * w * w))
    else:
        s = np.sqrt(s2)
        c = 2.0 * np.arctan(s / w) / s
    th[0] = c * v0
    th[1] = c * v1
    th[2] = c * v2


@numba.njit(cache=True)
def tangent_inverse(th, Ti):
    """Ti = T⁻¹(th) = I − ½Θ + (1 − (t/2)cot(t/2))/t² Θ² (spatial form), complex-analytic."""
    t2 = dot(th, th)
    if abs(t2.real) < 1e-6:
        c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    else:
        t = np.sqrt(t2)
        h = 0.5 * t
        c = (1.0 - h * np.cos(h) / np.sin(h)) / t2
    W = np.zeros((3, 3), dtype=Ti.dtype)
    W[0, 1] = -th[2]
    W[0, 2] = th[1]
    W[1, 0] = th[2]
    W[1, 2] = -th[0]
    W[2, 0] = -th[1]
    W[2, 1] = th[0]
    Ti[:, :] = c * (W @ W) - 0.5 * W
    for i in range(3):
        Ti[i, i] += 1.0


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
def basic(X1, X2, u1, u2, R1, R2, R0, l0, th1, th2, B):
    """Basic deformations of the current configuration and B = ∂d̄/∂d (7, 12).

    X1, X2: initial nodal positions; u1, u2: displacements; R1, R2: nodal
    rotations; R0: initial element frame. Fills th1, th2 (3,) and B; returns ū.
    """
    dt = u1.dtype
    dx = np.empty(3, dtype=dt)
    for k in range(3):
        dx[k] = X2[k] + u2[k] - X1[k] - u1[k]
    l = np.sqrt(dot(dx, dx))
    e1 = dx / l
    p1 = R1 @ R0[:, 1].astype(dt)
    p2 = R2 @ R0[:, 1].astype(dt)
    p = 0.5 * (p1 + p2)
    e3 = np.empty(3, dtype=dt)
    cross(e1, p, e3)
    e3 = e3 / np.sqrt(dot(e3, e3))
    e2 = np.empty(3, dtype=dt)
    cross(e3, e1, e2)
    Rr = np.empty((3, 3), dtype=dt)
    for k in range(3):
        Rr[k, 0] = e1[k]
        Rr[k, 1] = e2[k]
        Rr[k, 2] = e3[k]
    R0c = R0.astype(dt)
    log_rotation(Rr.T @ R1 @ R0c, th1)
    log_rotation(Rr.T @ R2 @ R0c, th2)
    ubar = (l * l - l0 * l0) / (l + l0)
    # local components of p, p1, p2
    pl = Rr.T @ p
    p1l = Rr.T @ p1
    p2l = Rr.T @ p2
    eta = pl[0] / pl[1]
    GT = np.zeros((3, 12), dtype=dt)
    GT[0, 2] = eta / l
    GT[0, 3] = 0.5 * p1l[1] / pl[1]
    GT[0, 4] = -0.5 * p1l[0] / pl[1]
    GT[0, 8] = -eta / l
    GT[0, 9] = 0.5 * p2l[1] / pl[1]
    GT[0, 10] = -0.5 * p2l[0] / pl[1]
    GT[1, 2] = 1.0 / l
    GT[1, 8] = -1.0 / l
    GT[2, 1] = -1.0 / l
    GT[2, 7] = 1.0 / l
    # rows in local components, then rotated to global: columns block k → block·Rrᵀ
    Bl = np.zeros((7, 12), dtype=dt)
    Bl[0, 0] = -1.0
    Bl[0, 6] = 1.0
    Ti = np.empty((3, 3), dtype=dt)
    for i, th in ((0, th1), (1, th2)):
        tangent_inverse(th, Ti)
        A = -GT.copy()
        for k in range(3):
            A[k, 3 + 6 * i + k] += 1.0
        Bl[1 + 3 * i:4 + 3 * i, :] = Ti @ A
    for blk in range(4):
        B[:, 3 * blk:3 * blk + 3] = Bl[:, 3 * blk:3 * blk + 3] @ Rr.T
    return ubar

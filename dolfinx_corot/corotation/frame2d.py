r"""Co-rotational frame of a two-node element in the plane.

Global element vector (node-major) :math:`\mathbf d = (u_1, v_1, \theta_1, u_2, v_2, \theta_2)`;
basic (element-frame) deformations :math:`\bar{\mathbf d} = (\bar u, \bar\theta_1, \bar\theta_2)`:

.. math::

    \bar u = l - l_0 = \frac{l^2 - l_0^2}{l + l_0},\qquad
    \bar\theta_i = \theta_i + \beta_0 - \beta \quad (\text{reduced to } (-\pi, \pi]),

with :math:`l, \beta` the current chord length and angle and
:math:`l_0, \beta_0` the initial ones. :math:`\bar\theta_i` is evaluated from
sines and cosines (Battini 2002, eq. 2.10), so the nodal angles may grow
without bound (beyond π, 2π, …) while the element-frame rotations stay small:
this is what lets a cantilever roll up into several turns.

Projector (Crisfield 1991, §7.3): with
:math:`\mathbf r = (-c, -s, 0, c, s, 0)`, :math:`\mathbf z = (s, -c, 0, -s, c, 0)`,

.. math::

    \mathbf P = \begin{bmatrix} \mathbf r^T \\ \mathbf e_3^T - \mathbf z^T/l \\ \mathbf e_6^T - \mathbf z^T/l\end{bmatrix},\quad
    \mathbf f = \mathbf P^T \bar{\mathbf f},\quad
    \mathbf K = \mathbf P^T \bar{\mathbf K} \mathbf P + \frac{\bar N}{l}\mathbf z\mathbf z^T
        + \frac{\bar M_1 + \bar M_2}{l^2}(\mathbf r\mathbf z^T + \mathbf z\mathbf r^T),

the last two terms being :math:`\partial(\mathbf P^T)/\partial\mathbf d : \bar{\mathbf f}`.
A bar (truss) uses the same frame with :math:`\bar M_1 = \bar M_2 = 0`.

The functions work on scalars and caller-provided arrays, so that the hot
loops allocate nothing.
"""
from __future__ import annotations

import numba
import numpy as np

from .transform import force


@numba.njit(cache=True, inline="always")
def initial(x1, y1, x2, y2):
    """Initial chord: (l0, c0, s0) with c0 = cos β0, s0 = sin β0."""
    dx = x2 - x1
    dy = y2 - y1
    l0 = np.sqrt(dx * dx + dy * dy)
    return l0, dx / l0, dy / l0


@numba.njit(cache=True, inline="always")
def update(x1, y1, x2, y2, d):
    """Current frame and basic deformations of one element.

    x1, y1, x2, y2: initial nodal coordinates; d: (6,) global displacements
    and total nodal angles. Returns (l0, l, c, s, ubar, theta1bar, theta2bar).
    """
    l0, c0, s0 = initial(x1, y1, x2, y2)
    dx = x2 + d[3] - x1 - d[0]
    dy = y2 + d[4] - y1 - d[1]
    l = np.sqrt(dx * dx + dy * dy)
    c = dx / l
    s = dy / l
    ubar = (l * l - l0 * l0) / (l + l0)
    # rotation from current chord back to the initial one: beta0 - beta
    cb = c0 * c + s0 * s
    sb = s0 * c - c0 * s
    ct1, st1 = np.cos(d[2]), np.sin(d[2])
    ct2, st2 = np.cos(d[5]), np.sin(d[5])
    t1 = np.arctan2(st1 * cb + ct1 * sb, ct1 * cb - st1 * sb)
    t2 = np.arctan2(st2 * cb + ct2 * sb, ct2 * cb - st2 * sb)
    return l0, l, c, s, ubar, t1, t2


@numba.njit(cache=True, inline="always")
def fill_projector(l, c, s, P):
    """P (3, 6) = ∂d̄/∂d at the current frame."""
    P[:, :] = 0.0
    P[0, 0] = -c
    P[0, 1] = -s
    P[0, 3] = c
    P[0, 4] = s
    for row in (1, 2):
        P[row, 0] = -s / l
        P[row, 1] = c / l
        P[row, 3] = s / l
        P[row, 4] = -c / l
    P[1, 2] = 1.0
    P[2, 5] = 1.0


@numba.njit(cache=True, inline="always")
def global_force(P, fbar, f):
    """f (6,) = Pᵀ f̄."""
    force(P, fbar, f, 3, 6)


@numba.njit(cache=True, inline="always")
def global_stiffness(l, c, s, P, kbar, fbar, K):
    """K (6, 6) = Pᵀ K̄ P + N̄/l z zᵀ + (M̄1 + M̄2)/l² (r zᵀ + z rᵀ)."""
    # material part
    for i in range(6):
        a0 = kbar[0, 0] * P[0, i] + kbar[1, 0] * P[1, i] + kbar[2, 0] * P[2, i]
        a1 = kbar[0, 1] * P[0, i] + kbar[1, 1] * P[1, i] + kbar[2, 1] * P[2, i]
        a2 = kbar[0, 2] * P[0, i] + kbar[1, 2] * P[1, i] + kbar[2, 2] * P[2, i]
        for j in range(6):
            K[i, j] = a0 * P[0, j] + a1 * P[1, j] + a2 * P[2, j]
    # geometric part
    gN = fbar[0] / l
    gM = (fbar[1] + fbar[2]) / (l * l)
    r0, r1 = -c, -s
    z0, z1 = s, -c
    # r and z are (r0, r1, 0, -r0, -r1, 0) and (z0, z1, 0, -z0, -z1, 0)
    idx = (0, 1, 3, 4)
    sgn = (1.0, 1.0, -1.0, -1.0)
    for a in range(4):
        i = idx[a]
        ri = sgn[a] * (r0 if i % 3 == 0 else r1)
        zi = sgn[a] * (z0 if i % 3 == 0 else z1)
        for b in range(4):
            j = idx[b]
            rj = sgn[b] * (r0 if j % 3 == 0 else r1)
            zj = sgn[b] * (z0 if j % 3 == 0 else z1)
            K[i, j] += gN * zi * zj + gM * (ri * zj + zi * rj)

r"""Co-rotational frame of a four-node membrane (element-independent co-rotational formulation).

Nodes 1–4 counter-clockwise, possibly warped. With the diagonals
:math:`\mathbf d_1 = \mathbf x_3 - \mathbf x_1`, :math:`\mathbf d_2 = \mathbf x_4 - \mathbf x_2`,
the element frame is

.. math::

    \mathbf e_3 = \frac{\mathbf n}{|\mathbf n|},\ \mathbf n = \mathbf d_1\times\mathbf d_2,\qquad
    \mathbf e_1 = \frac{\mathbf m}{|\mathbf m|},\ \mathbf m = \hat{\mathbf d}_1 - \hat{\mathbf d}_2,\qquad
    \mathbf e_2 = \mathbf e_3\times\mathbf e_1,

(e₁ bisects the diagonals, so the frame does not depend on which node is
called 1 beyond a quarter turn), origin at the centroid c. Deformational
displacements :math:`\bar{\mathbf u}_a = \mathbf R_r^T(\mathbf x_a - \mathbf c) - \bar{\mathbf x}_a^0`.
Their variation, with ω the spin of the frame in its own axes:

.. math::

    \delta\bar{\mathbf u}_a = \mathbf R_r^T(\delta\mathbf u_a - \delta\mathbf u_c) - \boldsymbol\omega\times\bar{\mathbf x}_a,\quad
    \omega_1 = -\frac{\mathbf e_2\cdot\delta\mathbf n}{|\mathbf n|},\quad
    \omega_2 = \frac{\mathbf e_1\cdot\delta\mathbf n}{|\mathbf n|},\quad
    \omega_3 = \frac{\mathbf e_2\cdot\delta\mathbf m}{|\mathbf m|}

(from :math:`\delta\mathbf e_3 = \boldsymbol\omega\times\mathbf e_3`, :math:`\delta\mathbf e_1 = \boldsymbol\omega\times\mathbf e_1`),
:math:`\delta\mathbf n = \delta\mathbf d_1\times\mathbf d_2 + \mathbf d_1\times\delta\mathbf d_2`,
:math:`\delta\hat{\mathbf d} = (\mathbf I - \hat{\mathbf d}\hat{\mathbf d}^T)\,\delta\mathbf d/|\mathbf d|`.
All functions are complex-analytic: the kernel's tangent is a complex-step
derivative of f = Bᵀ f̄.
"""
from __future__ import annotations

import numba
import numpy as np

from ..rotations import cross, dot
from .transform import frame_axes, local_coordinates, positions


@numba.njit(cache=True)
def frame(x, R):
    """Element frame R (3, 3) (columns e₁, e₂, e₃) of the four points x (4, 3)."""
    dt = x.dtype
    d1 = x[2] - x[0]
    d2 = x[3] - x[1]
    n = np.empty(3, dtype=dt)
    cross(d1, d2, n)
    e3 = n / np.sqrt(dot(n, n))
    m = d1 / np.sqrt(dot(d1, d1)) - d2 / np.sqrt(dot(d2, d2))
    e1 = m / np.sqrt(dot(m, m))
    frame_axes(e1, e3, R)


@numba.njit(cache=True)
def initial(X, R0, xbar0):
    """Initial frame R0 (3, 3) and local node coordinates xbar0 (4, 3) about the centroid."""
    frame(X, R0)
    local_coordinates(R0, X, xbar0)


@numba.njit(cache=True)
def basic(X, u, xbar0, dbar, B):
    """In-plane deformational displacements dbar (8,) = (ū_a, v̄_a) and B = ∂d̄/∂u (8, 12)."""
    dt = u.dtype
    x = positions(X, u)
    R = np.empty((3, 3), dtype=dt)
    frame(x, R)
    xbar = np.empty((4, 3), dtype=dt)
    local_coordinates(R, x, xbar)
    for a in range(4):
        dbar[2 * a] = xbar[a, 0] - xbar0[a, 0]
        dbar[2 * a + 1] = xbar[a, 1] - xbar0[a, 1]
    # frame spin ω (3, 12) in terms of the global δu
    d1 = x[2] - x[0]
    d2 = x[3] - x[1]
    n = np.empty(3, dtype=dt)
    cross(d1, d2, n)
    nn = np.sqrt(dot(n, n))
    l1 = np.sqrt(dot(d1, d1))
    l2 = np.sqrt(dot(d2, d2))
    h1 = d1 / l1
    h2 = d2 / l2
    m = h1 - h2
    mm = np.sqrt(dot(m, m))
    e1 = R[:, 0].copy()
    e2 = R[:, 1].copy()
    # e·δn = e·(δd1 × d2) + e·(d1 × δd2) = (d2 × e)·δd1 + (e × d1)·δd2
    p1 = np.empty(3, dtype=dt)
    p2 = np.empty(3, dtype=dt)
    q1 = np.empty(3, dtype=dt)
    q2 = np.empty(3, dtype=dt)
    cross(d2, e2, p1)
    cross(e2, d1, p2)
    cross(d2, e1, q1)
    cross(e1, d1, q2)
    # e2·δm = e2·(I − ĥ1ĥ1ᵀ)δd1/l1 − e2·(I − ĥ2ĥ2ᵀ)δd2/l2
    s1 = (e2 - dot(e2, h1) * h1) / l1
    s2 = -(e2 - dot(e2, h2) * h2) / l2
    Om = np.zeros((3, 12), dtype=dt)
    for k in range(3):
        # δd1 = δu3 − δu1, δd2 = δu4 − δu2
        Om[0, 6 + k] -= p1[k] / nn
        Om[0, k] += p1[k] / nn
        Om[0, 9 + k] -= p2[k] / nn
        Om[0, 3 + k] += p2[k] / nn
        Om[1, 6 + k] += q1[k] / nn
        Om[1, k] -= q1[k] / nn
        Om[1, 9 + k] += q2[k] / nn
        Om[1, 3 + k] -= q2[k] / nn
        Om[2, 6 + k] += s1[k] / mm
        Om[2, k] -= s1[k] / mm
        Om[2, 9 + k] += s2[k] / mm
        Om[2, 3 + k] -= s2[k] / mm
    for a in range(4):
        xa = xbar[a]
        for col in range(12):
            b, k = divmod(col, 3)
            coef = (1.0 if b == a else 0.0) - 0.25
            o0, o1, o2 = Om[0, col], Om[1, col], Om[2, col]
            # δū = Rᵀ(δu_a − δu_c) + x̄_a × ω, rows x and y
            B[2 * a, col] = coef * R[k, 0] + xa[1] * o2 - xa[2] * o1
            B[2 * a + 1, col] = coef * R[k, 1] + xa[2] * o0 - xa[0] * o2

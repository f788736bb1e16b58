r"""Co-rotational frame of a flat three-node shell element (element-independent co-rotational
formulation, Rankin & Nour-Omid 1988; Felippa & Haugen 2005).

Element frame :math:`\mathbf R_r = [\mathbf e_1\ \mathbf e_2\ \mathbf e_3]`: e₁ along side 1–2,
e₃ along :math:`(\mathbf x_2-\mathbf x_1)\times(\mathbf x_3-\mathbf x_1)`, e₂ = e₃ × e₁; origin at
the centroid c. Deformational displacements and rotations in that frame:

.. math::

    \bar{\mathbf u}_a = \mathbf R_r^T(\mathbf x_a - \mathbf c) - \mathbf R_0^T(\mathbf X_a - \mathbf C),\qquad
    \bar{\boldsymbol\theta}_a = \log(\mathbf R_r^T\mathbf R_a\mathbf R_0).

Their variations, with δw_a the spatial spins and ω the spin of the frame in
its own axes (a = x₂ − x₁ = (l, 0, 0), b = x₃ − x₁ = (b₁, b₂, 0) locally):

.. math::

    \delta\bar{\mathbf u}_a = \mathbf R_r^T(\delta\mathbf u_a - \delta\mathbf u_c) - \boldsymbol\omega\times\bar{\mathbf x}_a,\qquad
    \delta\bar{\boldsymbol\theta}_a = \mathbf T^{-1}(\bar{\boldsymbol\theta}_a)(\mathbf R_r^T\delta\mathbf w_a - \boldsymbol\omega),

    \omega_3 = \frac{\delta a_2}{l},\quad \omega_2 = -\frac{\delta a_3}{l},\quad
    \omega_1 = \frac{l\,\delta b_3 - b_1\,\delta a_3}{l\,b_2}

(local components of δa = δu₂ − δu₁, δb = δu₃ − δu₁; from δe₁ = ω × e₁ and
e₂·δe₃ = −ω₁). Then f = Bᵀ f̄. All functions are complex-analytic, so that the
consistent tangent is obtained by complex-step differentiation.
"""
from __future__ import annotations

import numba
import numpy as np

from .frame3d import _mat3, _mat3_tn, cross, dot, log_rotation, tangent_inverse


@numba.njit(cache=True)
def frame(x, R):
    """Element frame R (3, 3) of the three points x (3, 3) (rows are nodes); returns (l, b1, b2)."""
    dt = x.dtype
    a = x[1] - x[0]
    b = x[2] - x[0]
    l = np.sqrt(dot(a, a))
    e1 = a / l
    n = np.empty(3, dtype=dt)
    cross(a, b, n)
    nn = np.sqrt(dot(n, n))
    e3 = n / nn
    e2 = np.empty(3, dtype=dt)
    cross(e3, e1, e2)
    for k in range(3):
        R[k, 0] = e1[k]
        R[k, 1] = e2[k]
        R[k, 2] = e3[k]
    return l, dot(b, e1), nn / l


@numba.njit(cache=True)
def initial(X, R0, xbar0):
    """Initial frame R0 (3, 3) and local node coordinates xbar0 (3, 3) about the centroid."""
    frame(X, R0)
    c = (X[0] + X[1] + X[2]) / 3.0
    for a in range(3):
        for k in range(3):
            xbar0[a, k] = R0[0, k] * (X[a, 0] - c[0]) + R0[1, k] * (X[a, 1] - c[1]) + R0[2, k] * (X[a, 2] - c[2])


@numba.njit(cache=True)
def basic(X, u, R, R0, xbar0, dbar, B, rotations=True):
    """Deformational dofs dbar (18,) = (ū_a, θ̄_a) per node and B = ∂d̄/∂d (18, 18).

    X (3, 3) initial and u (3, 3) displacements of the nodes; R (3, 3, 3) nodal
    rotations; R0, xbar0 from :func:`initial`. rotations=False (membranes):
    θ̄ = 0 and its rows of B are zero; the nodal rotations are not used.
    """
    dt = u.dtype
    x = np.empty((3, 3), dtype=dt)
    for a in range(3):
        for k in range(3):
            x[a, k] = X[a, k] + u[a, k]
    Rr = np.empty((3, 3), dtype=dt)
    l, b1, b2 = frame(x, Rr)
    c = (x[0] + x[1] + x[2]) / 3.0
    xbar = np.empty((3, 3), dtype=dt)
    for a in range(3):
        for k in range(3):
            xbar[a, k] = Rr[0, k] * (x[a, 0] - c[0]) + Rr[1, k] * (x[a, 1] - c[1]) + Rr[2, k] * (x[a, 2] - c[2])
    R0c = np.empty((3, 3), dtype=dt)
    for i in range(3):
        for j in range(3):
            R0c[i, j] = R0[i, j]
    T = np.empty((3, 3), dtype=dt)
    Rb = np.empty((3, 3), dtype=dt)
    th = np.empty((3, 3), dtype=dt)
    Ra = np.empty((3, 3), dtype=dt)
    for a in range(3):
        if rotations:
            for i in range(3):
                for j in range(3):
                    Ra[i, j] = R[a, i, j]
            _mat3_tn(Rr, Ra, T)
            _mat3(T, R0c, Rb)
            log_rotation(Rb, th[a])
        else:
            th[a, :] = 0.0
        for k in range(3):
            dbar[6 * a + k] = xbar[a, k] - xbar0[a, k]
            dbar[6 * a + 3 + k] = th[a, k]
    # Ω (3, 18): local frame spin ω from the local components of δu
    # (dofs are first expressed in local components: d^l = blockdiag(Rrᵀ) d)
    Om = np.zeros((3, 18), dtype=dt)
    for k, sgn in ((1, 1.0),):
        Om[2, 6 * 1 + k] += sgn / l
        Om[2, 6 * 0 + k] -= sgn / l
    Om[1, 6 * 1 + 2] -= 1.0 / l
    Om[1, 6 * 0 + 2] += 1.0 / l
    # ω1 = (l δb3 − b1 δa3)/(l b2), δa = δu2 − δu1, δb = δu3 − δu1
    Om[0, 6 * 2 + 2] += 1.0 / b2
    Om[0, 6 * 0 + 2] -= 1.0 / b2
    Om[0, 6 * 1 + 2] -= b1 / (l * b2)
    Om[0, 6 * 0 + 2] += b1 / (l * b2)
    Bl = np.zeros((18, 18), dtype=dt)
    Ti = np.empty((3, 3), dtype=dt)
    for a in range(3):
        # δū_a = δu_a − δu_c − ω × x̄_a   (local components)
        for k in range(3):
            for b in range(3):
                Bl[6 * a + k, 6 * b + k] -= 1.0 / 3.0
            Bl[6 * a + k, 6 * a + k] += 1.0
        # −ω × x̄ = x̄ × ω = spin(x̄) ω
        xa = xbar[a]
        for col in range(18):
            o0, o1, o2 = Om[0, col], Om[1, col], Om[2, col]
            Bl[6 * a + 0, col] += xa[1] * o2 - xa[2] * o1
            Bl[6 * a + 1, col] += xa[2] * o0 - xa[0] * o2
            Bl[6 * a + 2, col] += xa[0] * o1 - xa[1] * o0
        # δθ̄_a = T⁻¹(θ̄_a)(δw_a − ω)
        if not rotations:
            continue
        tangent_inverse(th[a], Ti)
        for r in range(3):
            for col in range(18):
                Bl[6 * a + 3 + r, col] -= Ti[r, 0] * Om[0, col] + Ti[r, 1] * Om[1, col] + Ti[r, 2] * Om[2, col]
            for k in range(3):
                Bl[6 * a + 3 + r, 6 * a + 3 + k] += Ti[r, k]
    # columns back to global components: block·Rrᵀ
    for r in range(18):
        for blk in range(6):
            c0 = 3 * blk
            for j in range(3):
                B[r, c0 + j] = Bl[r, c0] * Rr[j, 0] + Bl[r, c0 + 1] * Rr[j, 1] + Bl[r, c0 + 2] * Rr[j, 2]

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
e₂·δe₃ = −ω₁). Then f = Bᵀ f̄.

Consistent tangent (:func:`force_and_tangent`), differentiating f = Λᵀ B_lᵀ f̄ with
f̄ = K̄ d̄: the frame turns (δΛᵀ g = Λᵀ(ω × g) blockwise), Ω changes with the
side length l and the coordinates (b₁, b₂) of node 3, x̄_a moves, and T⁻¹(θ̄_a)
changes with θ̄_a (its derivative contracted with the nodal moment, in closed
form: :func:`~dolfinx_corot.rotations.tangent_inv_so3_derivative`). :func:`basic` and :func:`parts` are
complex-analytic, so the closed form is checked against complex-step
differentiation of the internal force (tests).
"""
from __future__ import annotations

import numba
import numpy as np

from ..elements import shallow_shell
from ..rotations import cross, dot, log_so3, matmul3, matmul3_tn, tangent_inv_so3, tangent_inv_so3_derivative
from .transform import (add_omega_w, force, frame_axes, linear_force, local_coordinates, positions, rotate_columns,
                        stiffness, subtract_spin_g_omega, to_global)


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
    frame_axes(e1, n / nn, R)
    return l, dot(b, e1), nn / l


@numba.njit(cache=True)
def initial(X, R0, xbar0):
    """Initial frame R0 (3, 3) and local node coordinates xbar0 (3, 3) about the centroid."""
    frame(X, R0)
    local_coordinates(R0, X, xbar0)


@numba.njit(cache=True)
def parts(X, u, R, R0, xbar0, rotations=True):
    """The frame and its first variation in local components (d^l = Λd, Λ = blockdiag(R_rᵀ)).

    Returns (R_r, l, b₁, b₂, x̄ (3, 3), θ̄ (3, 3), T⁻¹(θ̄_a) (3, 3, 3), Ω (3, 18), B_l (18, 18),
    d̄ (18,)) with ω = Ω d^l and δd̄ = B_l δd^l. X (3, 3) initial and u (3, 3)
    displacements of the nodes; R (3, 3, 3) nodal rotations; R0, xbar0 from
    :func:`initial`. rotations=False (membranes): θ̄ = 0 and its rows of B_l are zero.
    Complex-analytic in u and R (the dtype of u is used throughout).
    """
    dt = u.dtype
    x = positions(X, u)
    Rr = np.empty((3, 3), dtype=dt)
    l, b1, b2 = frame(x, Rr)
    xbar = np.empty((3, 3), dtype=dt)
    local_coordinates(Rr, x, xbar)
    R0c = np.empty((3, 3), dtype=dt)
    for i in range(3):
        for j in range(3):
            R0c[i, j] = R0[i, j]
    T = np.empty((3, 3), dtype=dt)
    Rb = np.empty((3, 3), dtype=dt)
    Ra = np.empty((3, 3), dtype=dt)
    th = np.zeros((3, 3), dtype=dt)
    Ti = np.zeros((3, 3, 3), dtype=dt)
    dbar = np.empty(18, dtype=dt)
    for a in range(3):
        if rotations:
            for i in range(3):
                for j in range(3):
                    Ra[i, j] = R[a, i, j]
            matmul3_tn(Rr, Ra, T)
            matmul3(T, R0c, Rb)
            log_so3(Rb, th[a])
            tangent_inv_so3(th[a], Ti[a])
        for k in range(3):
            dbar[6 * a + k] = xbar[a, k] - xbar0[a, k]
            dbar[6 * a + 3 + k] = th[a, k]
    # Ω (3, 18): local frame spin ω from the local components of δu
    Om = np.zeros((3, 18), dtype=dt)
    Om[2, 7] += 1.0 / l
    Om[2, 1] -= 1.0 / l
    Om[1, 8] -= 1.0 / l
    Om[1, 2] += 1.0 / l
    # ω1 = (l δb3 − b1 δa3)/(l b2), δa = δu2 − δu1, δb = δu3 − δu1
    Om[0, 14] += 1.0 / b2
    Om[0, 2] -= 1.0 / b2
    Om[0, 8] -= b1 / (l * b2)
    Om[0, 2] += b1 / (l * b2)
    Bl = np.zeros((18, 18), dtype=dt)
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
        Tia = Ti[a]
        for r in range(3):
            for col in range(18):
                Bl[6 * a + 3 + r, col] -= Tia[r, 0] * Om[0, col] + Tia[r, 1] * Om[1, col] + Tia[r, 2] * Om[2, col]
            for k in range(3):
                Bl[6 * a + 3 + r, 6 * a + 3 + k] += Tia[r, k]
    return Rr, l, b1, b2, xbar, th, Ti, Om, Bl, dbar


@numba.njit(cache=True)
def basic(X, u, R, R0, xbar0, dbar, B, rotations=True):
    """Deformational dofs dbar (18,) = (ū_a, θ̄_a) per node and B = ∂d̄/∂d = B_l Λ (18, 18)
    (see :func:`parts`)."""
    Rr, l, b1, b2, xbar, th, Ti, Om, Bl, d = parts(X, u, R, R0, xbar0, rotations)
    for r in range(18):
        dbar[r] = d[r]
    rotate_columns(Bl, Rr, B, 18, 18)  # columns back to global components


@numba.njit(cache=True)
def internal_force(X, u, R, R0, xbar0, Kbar, sdata, f, rotations=True):
    """f (18,) = Λᵀ B_lᵀ f̄(d̄), without forming B = B_l Λ (real or complex); f̄ of the local law
    K̄ d̄ plus the shallow-shell term of sdata (:mod:`dolfinx_corot.elements.shallow_shell`)."""
    dt = u.dtype
    Rr, l, b1, b2, xbar, th, Ti, Om, Bl, dbar = parts(X, u, R, R0, xbar0, rotations)
    fbar = np.empty(18, dtype=dt)
    g = np.empty(18, dtype=dt)
    if shallow_shell.active(sdata):
        shallow_shell.force(dbar, Kbar, sdata, 3, fbar)
        force(Bl, fbar, g, 18, 18)
    else:
        linear_force(Bl, Kbar, dbar, fbar, g, 18, 18)
    for b in range(6):
        for k in range(3):
            f[3 * b + k] = Rr[k, 0] * g[3 * b] + Rr[k, 1] * g[3 * b + 1] + Rr[k, 2] * g[3 * b + 2]


@numba.njit(cache=True)
def force_and_tangent(X, u, R, R0, xbar0, Kbar, sdata, f, K, rotations=True):
    """f = Bᵀ f̄(d̄) (the local law of :func:`internal_force`) and its consistent tangent
    K = ∂f/∂d in closed form.

    In local components (d^l = Λd, Λ = blockdiag(R_rᵀ)), with g = B_lᵀ f̄, v = Σ_a(n_a × x̄_a − T_a⁻ᵀ m_a)
    (n_a, m_a the local nodal forces and moments), ω = Ω d^l the frame spin, K̄_t = ∂f̄/∂d̄:
    K^l = B_lᵀ K̄_t B_l − S(g) Ω + ∂(Ωᵀ v)/∂(l, b₁, b₂)·∂(l, b₁, b₂)/∂d^l
          + Ωᵀ Σ_a (spin(n_a) B_{u,a} − M_a B_{θ,a}) + Σ_a E_aᵀ M_a B_{θ,a},
    M_a = ∂(T⁻¹(θ̄_a)ᵀ m_a)/∂θ̄_a; then K = Λᵀ K^l Λ and f = Λᵀ g.
    """
    Rr, l, b1, b2, xbar, th, Ti, Om, Bl, dbar = parts(X, u, R, R0, xbar0, rotations)
    fbar = np.empty(18)
    g = np.empty(18)
    Kl = np.empty((18, 18))
    if shallow_shell.active(sdata):
        Kt = np.empty((18, 18))
        shallow_shell.force_and_tangent(dbar, Kbar, sdata, 3, fbar, Kt)
        force(Bl, fbar, g, 18, 18)
        stiffness(Bl, Kt, Kl, 18, 18)
    else:
        linear_force(Bl, Kbar, dbar, fbar, g, 18, 18)
        stiffness(Bl, Kbar, Kl, 18, 18)
    subtract_spin_g_omega(Kl, g, Om, 18)
    # v and M_a
    v = np.zeros(3)
    M = np.zeros((3, 3, 3))
    for a in range(3):
        n0, n1, n2 = fbar[6 * a], fbar[6 * a + 1], fbar[6 * a + 2]
        xa = xbar[a]
        v[0] += n1 * xa[2] - n2 * xa[1]
        v[1] += n2 * xa[0] - n0 * xa[2]
        v[2] += n0 * xa[1] - n1 * xa[0]
        if rotations:
            m = fbar[6 * a + 3:6 * a + 6].copy()
            for i in range(3):
                v[i] -= Ti[a, 0, i] * m[0] + Ti[a, 1, i] * m[1] + Ti[a, 2, i] * m[2]
            tangent_inv_so3_derivative(th[a], m, M[a])
    # ∂(Ωᵀ v)/∂(l, b1, b2) and the variations of l, b1, b2
    dc_l = np.zeros(18)
    dc_b1 = np.zeros(18)
    dc_b2 = np.zeros(18)
    l2 = l * l
    dc_l[7] = -v[2] / l2
    dc_l[1] = v[2] / l2
    dc_l[8] = v[1] / l2 + b1 * v[0] / (l2 * b2)
    dc_l[2] = -v[1] / l2 - b1 * v[0] / (l2 * b2)
    dc_b1[8] = -v[0] / (l * b2)
    dc_b1[2] = v[0] / (l * b2)
    dc_b2[8] = b1 * v[0] / (l * b2 * b2)
    dc_b2[2] = v[0] / (b2 * b2) - b1 * v[0] / (l * b2 * b2)
    dc_b2[14] = -v[0] / (b2 * b2)
    dl = np.zeros(18)
    dl[6] += 1.0
    dl[0] -= 1.0
    db1 = np.zeros(18)
    db2 = np.zeros(18)
    db1[12] += 1.0
    db1[0] -= 1.0
    db2[13] += 1.0
    db2[1] -= 1.0
    for j in range(18):
        db1[j] += b2 * Om[2, j]
        db2[j] -= b1 * Om[2, j]
    for i in range(18):
        if dc_l[i] != 0.0 or dc_b1[i] != 0.0 or dc_b2[i] != 0.0:
            for j in range(18):
                Kl[i, j] += dc_l[i] * dl[j] + dc_b1[i] * db1[j] + dc_b2[i] * db2[j]
    # Ωᵀ δv with δv = Σ_a (spin(n_a) B_{u,a} − M_a B_{θ,a}) δd^l, and back to global components
    add_omega_w(Kl, fbar, Bl, M, Om, 3, rotations)
    to_global(Kl, g, Rr, f, K, 18)

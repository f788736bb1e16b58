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
All functions are complex-analytic: the membrane kernel's tangent is a complex-step
derivative of f = Bᵀ f̄; the shell's is in closed form (:func:`shell_force_and_tangent`), and
complex steps are its tests' reference.
"""
from __future__ import annotations

import numba
import numpy as np

from ..elements import shallow_shell
from ..rotations import cross, dot, log_so3, matmul3, matmul3_tn, tangent_inv_so3, tangent_inv_so3_derivative
from .transform import (add_omega_w, force, frame_axes, linear_force, local_coordinates, positions, rotate_columns,
                        stiffness, subtract_spin_g_omega, to_global)

H = 1e-30  # complex step of the frame spin's variation


@numba.njit(cache=True)
def diagonals(x):
    """(d₁, d₂, n, |n|, l₁, l₂, ĥ₁, ĥ₂, m, |m|) of the four points x (4, 3): the diagonals
    d₁ = x₃ − x₁, d₂ = x₄ − x₂, their lengths and directions, n = d₁ × d₂ and the bisector
    m = ĥ₁ − ĥ₂ (real or complex, as x)."""
    d1 = x[2] - x[0]
    d2 = x[3] - x[1]
    n = np.empty(3, dtype=x.dtype)
    cross(d1, d2, n)
    l1 = np.sqrt(dot(d1, d1))
    l2 = np.sqrt(dot(d2, d2))
    h1 = d1 / l1
    h2 = d2 / l2
    m = h1 - h2
    return d1, d2, n, np.sqrt(dot(n, n)), l1, l2, h1, h2, m, np.sqrt(dot(m, m))


@numba.njit(cache=True)
def frame(x, R):
    """Element frame R (3, 3) (columns e₁, e₂, e₃) of the four points x (4, 3)."""
    _, _, n, nn, _, _, _, _, m, mm = diagonals(x)
    frame_axes(m / mm, n / nn, R)


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
    d1, d2, n, nn, l1, l2, h1, h2, m, mm = diagonals(x)
    R = np.empty((3, 3), dtype=dt)
    frame_axes(m / mm, n / nn, R)
    xbar = np.empty((4, 3), dtype=dt)
    local_coordinates(R, x, xbar)
    for a in range(4):
        dbar[2 * a] = xbar[a, 0] - xbar0[a, 0]
        dbar[2 * a + 1] = xbar[a, 1] - xbar0[a, 1]
    # frame spin ω (3, 12) in terms of the global δu
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


# -- four-node shells: nodal rotations as well -------------------------------------------------
#
# The same frame; the deformational rotations θ̄_a = log(R_rᵀ R_a R_0) and the variations in local
# components (d^l = Λd, Λ = blockdiag(R_rᵀ)), 6 dofs per node:
#     δū_a = δu_a − δu_c + x̄_a × ω,   δθ̄_a = T⁻¹(θ̄_a)(δw_a − ω),   ω = Ω(x̄) δu^l,
# as for the triangle (:mod:`.frame_triangle`). Ω depends on the element's shape alone, so its
# variation contracted with a vector, ∂(Ωᵀv)/∂x̄, is :func:`shape_spin_derivative` (closed form,
# tested against complex steps of :func:`shape_spin`) in :func:`shell_force_and_tangent`.


@numba.njit(cache=True, inline="always")
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True)
def shape_spin(y, Om):
    """Om (3, 24): the frame spin in the frame's own axes, ω = Ω δd^l, for nodes at y (4, 3) and
    variations δd^l (6 per node) in the frame's components. A function of the shape of y alone
    (invariant under rigid motions of y), complex-analytic; scalar arithmetic (no arrays made:
    its complex-step derivative is the reference of :func:`shape_spin_derivative`)."""
    d10, d11, d12 = y[2, 0] - y[0, 0], y[2, 1] - y[0, 1], y[2, 2] - y[0, 2]
    d20, d21, d22 = y[3, 0] - y[1, 0], y[3, 1] - y[1, 1], y[3, 2] - y[1, 2]
    n0, n1, n2 = _cross(d10, d11, d12, d20, d21, d22)
    nn = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    l1 = np.sqrt(d10 * d10 + d11 * d11 + d12 * d12)
    l2 = np.sqrt(d20 * d20 + d21 * d21 + d22 * d22)
    h10, h11, h12 = d10 / l1, d11 / l1, d12 / l1
    h20, h21, h22 = d20 / l2, d21 / l2, d22 / l2
    m0, m1, m2 = h10 - h20, h11 - h21, h12 - h22
    mm = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    a0, a1, a2 = m0 / mm, m1 / mm, m2 / mm           # e1
    c0, c1, c2 = n0 / nn, n1 / nn, n2 / nn           # e3
    b0, b1, b2 = _cross(c0, c1, c2, a0, a1, a2)      # e2 = e3 × e1
    # rows of ω against the global δd1 = δu3 − δu1 (s = 0) and δd2 = δu4 − δu2 (s = 1)
    p10, p11, p12 = _cross(d20, d21, d22, b0, b1, b2)
    p20, p21, p22 = _cross(b0, b1, b2, d10, d11, d12)
    q10, q11, q12 = _cross(d20, d21, d22, a0, a1, a2)
    q20, q21, q22 = _cross(a0, a1, a2, d10, d11, d12)
    t1 = b0 * h10 + b1 * h11 + b2 * h12
    t2 = b0 * h20 + b1 * h21 + b2 * h22
    s10, s11, s12 = (b0 - t1 * h10) / l1, (b1 - t1 * h11) / l1, (b2 - t1 * h12) / l1
    s20, s21, s22 = -(b0 - t2 * h20) / l2, -(b1 - t2 * h21) / l2, -(b2 - t2 * h22) / l2
    for i in range(3):
        for c in range(24):
            Om[i, c] = 0.0
    for k in range(3):  # local column k: the global row vectors projected on e_k
        if k == 0:
            e0, e1, e2 = a0, a1, a2
        elif k == 1:
            e0, e1, e2 = b0, b1, b2
        else:
            e0, e1, e2 = c0, c1, c2
        w = (-(p10 * e0 + p11 * e1 + p12 * e2) / nn, -(p20 * e0 + p21 * e1 + p22 * e2) / nn)
        Om[0, 12 + k] += w[0]
        Om[0, k] -= w[0]
        Om[0, 18 + k] += w[1]
        Om[0, 6 + k] -= w[1]
        w = ((q10 * e0 + q11 * e1 + q12 * e2) / nn, (q20 * e0 + q21 * e1 + q22 * e2) / nn)
        Om[1, 12 + k] += w[0]
        Om[1, k] -= w[0]
        Om[1, 18 + k] += w[1]
        Om[1, 6 + k] -= w[1]
        w = ((s10 * e0 + s11 * e1 + s12 * e2) / mm, (s20 * e0 + s21 * e1 + s22 * e2) / mm)
        Om[2, 12 + k] += w[0]
        Om[2, k] -= w[0]
        Om[2, 18 + k] += w[1]
        Om[2, 6 + k] -= w[1]


@numba.njit(cache=True, inline="always")
def _skew(a, S):
    """S (3, 3) = spin(a): S b = a × b."""
    S[0, 0] = 0.0
    S[0, 1] = -a[2]
    S[0, 2] = a[1]
    S[1, 0] = a[2]
    S[1, 1] = 0.0
    S[1, 2] = -a[0]
    S[2, 0] = -a[1]
    S[2, 1] = a[0]
    S[2, 2] = 0.0


@numba.njit(cache=True)
def shape_spin_derivative(y, v, J):
    r"""J (24, 12) = ∂(Ω(y)ᵀ v)/∂y for nodes at y (4, 3) and a fixed v (3,), in closed form.

    Ωᵀv δd = q·δn + r·δm with q = (v₂e₁ − v₁e₂)/|n|, r = v₃e₂/|m|, so that the translation rows
    of nodes 1 and 3 are ∓Eᵀg₁ and those of nodes 2 and 4 ∓Eᵀg₂ (the variations δd in the frame's
    components, E = [e₁ e₂ e₃]), g₁ = d₂ × q + P₁r/l₁, g₂ = q × d₁ − P₂r/l₂ (P_i = I − ĥ_iĥ_iᵀ).
    Their derivatives with respect to d₁ = y₃ − y₁ and d₂ = y₄ − y₂, Eᵀ∂g + (gᵀ∂e_k)_k, follow from
    δn = δd₁ × d₂ + d₁ × δd₂, δe₃ = (I − e₃e₃ᵀ)δn/|n|, δm = P₁δd₁/l₁ − P₂δd₂/l₂,
    δe₁ = (I − e₁e₁ᵀ)δm/|m|, δe₂ = δe₃ × e₁ + e₃ × δe₁. Tested against the complex-step derivative
    of :func:`shape_spin`."""
    d1, d2, n, nn, l1, l2, h1, h2, m, mm = diagonals(y)
    e1 = m / mm
    e3 = n / nn
    e2 = np.empty(3)
    cross(e3, e1, e2)
    q = (v[1] * e1 - v[0] * e2) / nn
    r = v[2] * e2 / mm
    P1 = np.empty((3, 3))
    P2 = np.empty((3, 3))
    Q1 = np.empty((3, 3))
    Q3 = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            dij = 1.0 if i == j else 0.0
            P1[i, j] = dij - h1[i] * h1[j]
            P2[i, j] = dij - h2[i] * h2[j]
            Q1[i, j] = (dij - e1[i] * e1[j]) / mm
            Q3[i, j] = (dij - e3[i] * e3[j]) / nn
    Sd1 = np.empty((3, 3))
    Sd2 = np.empty((3, 3))
    Se1 = np.empty((3, 3))
    Se3 = np.empty((3, 3))
    _skew(d1, Sd1)
    _skew(d2, Sd2)
    _skew(e1, Se1)
    _skew(e3, Se3)
    g = np.empty((2, 3))  # g₁, g₂
    cross(d2, q, g[0])
    cross(q, d1, g[1])
    hr1 = dot(h1, r)
    hr2 = dot(h2, r)
    for a in range(3):
        g[0, a] += (r[a] - h1[a] * hr1) / l1
        g[1, a] -= (r[a] - h2[a] * hr2) / l2
    dn = np.empty((3, 3))
    dm = np.empty((3, 3))
    de = np.empty((3, 3, 3))  # ∂e_c/∂d_k, c = 0, 1, 2
    tmp = np.empty((3, 3))
    dq = np.empty((3, 3))
    dr = np.empty((3, 3))
    D = np.empty((2, 2, 3, 3))  # ∂(Eᵀg_i)/∂d_k
    for k in range(2):
        for i in range(3):
            for j in range(3):
                dn[i, j] = -Sd2[i, j] if k == 0 else Sd1[i, j]             # ∂n/∂d_k
                dm[i, j] = P1[i, j] / l1 if k == 0 else -P2[i, j] / l2     # ∂m/∂d_k
        matmul3(Q3, dn, de[2])
        matmul3(Q1, dm, de[0])
        matmul3(Se1, de[2], tmp)
        matmul3(Se3, de[0], de[1])
        for i in range(3):
            for j in range(3):
                de[1, i, j] -= tmp[i, j]
        for j in range(3):
            e3dn = e3[0] * dn[0, j] + e3[1] * dn[1, j] + e3[2] * dn[2, j]
            e1dm = e1[0] * dm[0, j] + e1[1] * dm[1, j] + e1[2] * dm[2, j]
            for i in range(3):
                dq[i, j] = (v[1] * de[0, i, j] - v[0] * de[1, i, j] - q[i] * e3dn) / nn
                dr[i, j] = (v[2] * de[1, i, j] - r[i] * e1dm) / mm
        for gi in range(2):
            # ∂g_i/∂d_k, in tmp
            if gi == 0:
                matmul3(Sd2, dq, tmp)      # d₂ × ∂q
                for i in range(3):
                    for j in range(3):
                        tmp[i, j] += (P1[i, 0] * dr[0, j] + P1[i, 1] * dr[1, j] + P1[i, 2] * dr[2, j]) / l1
                if k == 1:                 # −q × δd₂
                    tmp[0, 1] += q[2]
                    tmp[0, 2] -= q[1]
                    tmp[1, 0] -= q[2]
                    tmp[1, 2] += q[0]
                    tmp[2, 0] += q[1]
                    tmp[2, 1] -= q[0]
                else:                      # P₁r/l₁ through ĥ₁ and l₁
                    for i in range(3):
                        Pr = r[i] - h1[i] * hr1
                        for j in range(3):
                            rP = r[0] * P1[0, j] + r[1] * P1[1, j] + r[2] * P1[2, j]
                            tmp[i, j] -= (hr1 * P1[i, j] + h1[i] * rP + Pr * h1[j]) / (l1 * l1)
            else:
                matmul3(Sd1, dq, tmp)      # −d₁ × ∂q
                for i in range(3):
                    for j in range(3):
                        tmp[i, j] = -tmp[i, j] - (P2[i, 0] * dr[0, j] + P2[i, 1] * dr[1, j] + P2[i, 2] * dr[2, j]) / l2
                if k == 0:                 # q × δd₁
                    tmp[0, 1] -= q[2]
                    tmp[0, 2] += q[1]
                    tmp[1, 0] += q[2]
                    tmp[1, 2] -= q[0]
                    tmp[2, 0] -= q[1]
                    tmp[2, 1] += q[0]
                else:                      # −P₂r/l₂ through ĥ₂ and l₂
                    for i in range(3):
                        Pr = r[i] - h2[i] * hr2
                        for j in range(3):
                            rP = r[0] * P2[0, j] + r[1] * P2[1, j] + r[2] * P2[2, j]
                            tmp[i, j] += (hr2 * P2[i, j] + h2[i] * rP + Pr * h2[j]) / (l2 * l2)
            # in the frame's components: Eᵀ ∂g_i/∂d_k + (g_iᵀ ∂e_c/∂d_k)_c
            for c in range(3):
                ec = e1 if c == 0 else (e2 if c == 1 else e3)
                for j in range(3):
                    D[gi, k, c, j] = (ec[0] * tmp[0, j] + ec[1] * tmp[1, j] + ec[2] * tmp[2, j]
                                      + g[gi, 0] * de[c, 0, j] + g[gi, 1] * de[c, 1, j] + g[gi, 2] * de[c, 2, j])
    J[:, :] = 0.0
    # rows: node 1 −g₁, node 3 +g₁, node 2 −g₂, node 4 +g₂; columns: y₁ −d₁, y₃ +d₁, y₂ −d₂, y₄ +d₂
    for i, (row_minus, row_plus) in enumerate(((0, 12), (6, 18))):
        for k, (col_minus, col_plus) in enumerate(((0, 6), (3, 9))):
            for a in range(3):
                for b in range(3):
                    x = D[i, k, a, b]
                    J[row_minus + a, col_minus + b] += x
                    J[row_minus + a, col_plus + b] -= x
                    J[row_plus + a, col_minus + b] -= x
                    J[row_plus + a, col_plus + b] += x


@numba.njit(cache=True)
def shape_spin_derivative_complex_step(y, v, J):
    """:func:`shape_spin_derivative` by complex steps of :func:`shape_spin` (its test's reference)."""
    yc = np.empty((4, 3), dtype=np.complex128)
    Omc = np.empty((3, 24), dtype=np.complex128)
    for j in range(12):
        for a in range(4):
            for k in range(3):
                yc[a, k] = y[a, k]
        yc[j // 3, j % 3] += 1j * H
        shape_spin(yc, Omc)
        for i in range(24):
            J[i, j] = (Omc[0, i] * v[0] + Omc[1, i] * v[1] + Omc[2, i] * v[2]).imag / H


@numba.njit(cache=True)
def shell_parts(X, u, R, R0, xbar0):
    """(R_r, x̄ (4, 3), θ̄ (4, 3), T⁻¹(θ̄_a) (4, 3, 3), Ω (3, 24), B_l (24, 24), d̄ (24,)) of a
    four-node shell: X (4, 3) initial nodes counter-clockwise, u (4, 3) displacements, R (4, 3, 3)
    nodal rotations, R0 and x̄0 from :func:`initial`; δd̄ = B_l δd^l. Complex-analytic."""
    dt = u.dtype
    x = positions(X, u)
    Rr = np.empty((3, 3), dtype=dt)
    frame(x, Rr)
    xbar = np.empty((4, 3), dtype=dt)
    local_coordinates(Rr, x, xbar)
    R0c = np.empty((3, 3), dtype=dt)
    for i in range(3):
        for j in range(3):
            R0c[i, j] = R0[i, j]
    T = np.empty((3, 3), dtype=dt)
    Rb = np.empty((3, 3), dtype=dt)
    Ra = np.empty((3, 3), dtype=dt)
    th = np.zeros((4, 3), dtype=dt)
    Ti = np.zeros((4, 3, 3), dtype=dt)
    dbar = np.empty(24, dtype=dt)
    for a in range(4):
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
    Om = np.empty((3, 24), dtype=dt)
    shape_spin(xbar, Om)
    Bl = np.zeros((24, 24), dtype=dt)
    for a in range(4):
        for k in range(3):
            for b in range(4):
                Bl[6 * a + k, 6 * b + k] -= 0.25
            Bl[6 * a + k, 6 * a + k] += 1.0
        xa = xbar[a]
        for col in range(24):
            o0, o1, o2 = Om[0, col], Om[1, col], Om[2, col]
            Bl[6 * a + 0, col] += xa[1] * o2 - xa[2] * o1
            Bl[6 * a + 1, col] += xa[2] * o0 - xa[0] * o2
            Bl[6 * a + 2, col] += xa[0] * o1 - xa[1] * o0
        Tia = Ti[a]
        for r in range(3):
            for col in range(24):
                Bl[6 * a + 3 + r, col] -= Tia[r, 0] * Om[0, col] + Tia[r, 1] * Om[1, col] + Tia[r, 2] * Om[2, col]
            for k in range(3):
                Bl[6 * a + 3 + r, 6 * a + 3 + k] += Tia[r, k]
    return Rr, xbar, th, Ti, Om, Bl, dbar


@numba.njit(cache=True)
def shell_basic(X, u, R, R0, xbar0, dbar, B):
    """d̄ (24,) and B = ∂d̄/∂d = B_l Λ (24, 24) of a four-node shell (see :func:`shell_parts`)."""
    Rr, xbar, th, Ti, Om, Bl, d = shell_parts(X, u, R, R0, xbar0)
    for r in range(24):
        dbar[r] = d[r]
    rotate_columns(Bl, Rr, B, 24, 24)


@numba.njit(cache=True)
def shell_force(X, u, R, R0, xbar0, Kbar, sdata, f):
    """f (24,) = Λᵀ B_lᵀ f̄(d̄) of a four-node shell (real or complex); f̄ of the local law K̄ d̄
    plus the shallow-shell term of sdata (:mod:`dolfinx_corot.elements.shallow_shell`)."""
    dt = u.dtype
    Rr, xbar, th, Ti, Om, Bl, dbar = shell_parts(X, u, R, R0, xbar0)
    fbar = np.empty(24, dtype=dt)
    g = np.empty(24, dtype=dt)
    if shallow_shell.active(sdata):
        shallow_shell.force(dbar, Kbar, sdata, 4, fbar)
        force(Bl, fbar, g, 24, 24)
    else:
        linear_force(Bl, Kbar, dbar, fbar, g, 24, 24)
    for b in range(8):
        for k in range(3):
            f[3 * b + k] = Rr[k, 0] * g[3 * b] + Rr[k, 1] * g[3 * b + 1] + Rr[k, 2] * g[3 * b + 2]


@numba.njit(cache=True)
def shell_force_and_tangent(X, u, R, R0, xbar0, Kbar, sdata, f, K):
    """f = Bᵀ f̄(d̄) (see :func:`shell_force`) and its consistent tangent K = ∂f/∂d of a
    four-node shell.

    In local components, with g = B_lᵀ f̄, v = Σ_a(n_a × x̄_a − T_a⁻ᵀ m_a) (n_a, m_a the
    local nodal forces and moments) and K̄_t = ∂f̄/∂d̄:
    K^l = B_lᵀ K̄_t B_l − S(g) Ω + Σ_a ∂(Ωᵀv)/∂x̄_a B_{u,a}
          + Ωᵀ Σ_a (spin(n_a) B_{u,a} − M_a B_{θ,a}) + Σ_a E_aᵀ M_a B_{θ,a},
    M_a = ∂(T⁻¹(θ̄_a)ᵀ m_a)/∂θ̄_a in closed form
    (:func:`~dolfinx_corot.rotations.tangent_inv_so3_derivative`), ∂(Ωᵀv)/∂x̄
    by :func:`shape_spin_derivative`; K = Λᵀ K^l Λ and f = Λᵀ g. The derivation is the
    triangle's (:func:`.frame_triangle.force_and_tangent`); only Ω differs."""
    Rr, xbar, th, Ti, Om, Bl, dbar = shell_parts(X, u, R, R0, xbar0)
    fbar = np.empty(24)
    g = np.empty(24)
    Kl = np.empty((24, 24))
    if shallow_shell.active(sdata):
        Kt = np.empty((24, 24))
        shallow_shell.force_and_tangent(dbar, Kbar, sdata, 4, fbar, Kt)
        force(Bl, fbar, g, 24, 24)
        stiffness(Bl, Kt, Kl, 24, 24)
    else:
        linear_force(Bl, Kbar, dbar, fbar, g, 24, 24)
        stiffness(Bl, Kbar, Kl, 24, 24)
    subtract_spin_g_omega(Kl, g, Om, 24)
    v = np.zeros(3)
    M = np.zeros((4, 3, 3))
    for a in range(4):
        n0, n1, n2 = fbar[6 * a], fbar[6 * a + 1], fbar[6 * a + 2]
        xa = xbar[a]
        v[0] += n1 * xa[2] - n2 * xa[1]
        v[1] += n2 * xa[0] - n0 * xa[2]
        v[2] += n0 * xa[1] - n1 * xa[0]
        m = fbar[6 * a + 3:6 * a + 6].copy()
        for i in range(3):
            v[i] -= Ti[a, 0, i] * m[0] + Ti[a, 1, i] * m[1] + Ti[a, 2, i] * m[2]
        tangent_inv_so3_derivative(th[a], m, M[a])
    # Σ_a ∂(Ωᵀv)/∂x̄_a B_{u,a}
    J = np.empty((24, 12))
    shape_spin_derivative(xbar, v, J)
    for i in range(24):
        for j in range(24):
            acc = 0.0
            for a in range(4):
                for k in range(3):
                    acc += J[i, 3 * a + k] * Bl[6 * a + k, j]
            Kl[i, j] += acc
    add_omega_w(Kl, fbar, Bl, M, Om, 4, True)
    to_global(Kl, g, Rr, f, K, 24)

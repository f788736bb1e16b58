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
The consistent tangent :math:`\mathbf K = \partial\mathbf f/\partial\mathbf d
= \mathbf B^T\bar{\mathbf K}\mathbf B + \partial\mathbf B^T/\partial\mathbf d:\bar{\mathbf f}`
is in closed form (:func:`add_geometric_stiffness`): the geometric part of Battini & Pacoste
(2002) with the variations of every entry of :math:`\mathbf G^T` kept, so that it equals the
complex-step derivative of the force (Squire & Trapp 1998) to rounding, which the tests check.
Every function is complex-analytic in the configuration (branches test real parts only), so
that the complex-step derivative stays available as that check.
"""
from __future__ import annotations

import numba
import numpy as np

from ..rotations import cross, dot, log_so3, matmul3, matmul3_tn, tangent_inv_so3, tangent_inv_so3_derivative
from .transform import rotate_columns, subtract_spin_g_omega


@numba.njit(cache=True)
def initial_frame(X1, X2, v, R0):
    """R0 (3, 3): columns e1 along X2 − X1, e2 the part of v normal to e1, e3 = e1 × e2.

    Returns l0; raises nothing: a v parallel to the element is caught when the
    part is built (see ``check_orientation``).
    """
    # (scalars: an element kernel allocates nothing here)
    d0, d1, d2 = X2[0] - X1[0], X2[1] - X1[1], X2[2] - X1[2]
    l0 = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    a0, a1, a2 = d0 / l0, d1 / l0, d2 / l0
    va = v[0] * a0 + v[1] * a1 + v[2] * a2
    b0, b1, b2 = v[0] - va * a0, v[1] - va * a1, v[2] - va * a2
    nb = np.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
    b0, b1, b2 = b0 / nb, b1 / nb, b2 / nb
    R0[0, 0], R0[1, 0], R0[2, 0] = a0, a1, a2
    R0[0, 1], R0[1, 1], R0[2, 1] = b0, b1, b2
    R0[0, 2] = a1 * b2 - a2 * b1
    R0[1, 2] = a2 * b0 - a0 * b2
    R0[2, 2] = a0 * b1 - a1 * b0
    return l0


@numba.njit(cache=True)
def current_frame(X1, X2, u1, u2, R1, R2, R0, Rr, p1, p2):
    """The current element frame Rr (3, 3) (columns e1, e2, e3) and p1, p2 (3,) = R_i R0 j;
    returns the current length l."""
    # (scalars: an element kernel allocates nothing here)
    x0 = X2[0] + u2[0] - X1[0] - u1[0]
    x1 = X2[1] + u2[1] - X1[1] - u1[1]
    x2 = X2[2] + u2[2] - X1[2] - u1[2]
    l = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    a0, a1, a2 = x0 / l, x1 / l, x2 / l
    for k in range(3):
        p1[k] = R1[k, 0] * R0[0, 1] + R1[k, 1] * R0[1, 1] + R1[k, 2] * R0[2, 1]
        p2[k] = R2[k, 0] * R0[0, 1] + R2[k, 1] * R0[1, 1] + R2[k, 2] * R0[2, 1]
    q0, q1, q2 = 0.5 * (p1[0] + p2[0]), 0.5 * (p1[1] + p2[1]), 0.5 * (p1[2] + p2[2])
    c0 = a1 * q2 - a2 * q1
    c1 = a2 * q0 - a0 * q2
    c2 = a0 * q1 - a1 * q0
    nc = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    c0, c1, c2 = c0 / nc, c1 / nc, c2 / nc
    Rr[0, 0], Rr[1, 0], Rr[2, 0] = a0, a1, a2
    Rr[0, 1] = c1 * a2 - c2 * a1
    Rr[1, 1] = c2 * a0 - c0 * a2
    Rr[2, 1] = c0 * a1 - c1 * a0
    Rr[0, 2], Rr[1, 2], Rr[2, 2] = c0, c1, c2
    return l


@numba.njit(cache=True)
def basic(X1, X2, u1, u2, R1, R2, R0, l0, th1, th2, B):
    """Basic deformations of the current configuration and B = ∂d̄/∂d (7, 12).

    X1, X2: initial nodal positions; u1, u2: displacements; R1, R2: nodal
    rotations; R0: initial element frame. Fills th1, th2 (3,) and B; returns ū.
    """
    dt = u1.dtype
    Rr = np.empty((3, 3), dtype=dt)
    p1 = np.empty(3, dtype=dt)
    p2 = np.empty(3, dtype=dt)
    GT = np.empty((3, 12), dtype=dt)
    Ti = np.empty((2, 3, 3), dtype=dt)
    ubar, _ = frame_and_basic(X1, X2, u1, u2, R1, R2, R0, l0, th1, th2, B, Rr, p1, p2, GT, Ti)
    return ubar


@numba.njit(cache=True)
def frame_and_basic(X1, X2, u1, u2, R1, R2, R0, l0, th1, th2, B, Rr, p1, p2, GT, Ti):
    """:func:`basic`, also filling what the tangent reuses: the frame Rr (3, 3), p1, p2 (3,),
    Gᵀ (3, 12) in local components and T⁻¹(θ̄_i) (2, 3, 3); returns (ū, l)."""
    dt = u1.dtype
    l = current_frame(X1, X2, u1, u2, R1, R2, R0, Rr, p1, p2)
    work = np.empty((3, 3, 3), dtype=dt)  # (one allocation: T, R_r^T R_i R_0, R_0 in the dtype)
    T = work[0]
    Rb = work[1]
    R0c = work[2]
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
    # local components of p, p1, p2 (only the first two are needed); e1, e2 the columns of Rr
    q0, q1, q2 = 0.5 * (p1[0] + p2[0]), 0.5 * (p1[1] + p2[1]), 0.5 * (p1[2] + p2[2])
    pl0 = Rr[0, 0] * q0 + Rr[1, 0] * q1 + Rr[2, 0] * q2
    pl1 = Rr[0, 1] * q0 + Rr[1, 1] * q1 + Rr[2, 1] * q2
    eta = pl0 / pl1
    GT[:, :] = 0.0
    GT[0, 2] = eta / l
    GT[0, 3] = 0.5 * (Rr[0, 1] * p1[0] + Rr[1, 1] * p1[1] + Rr[2, 1] * p1[2]) / pl1
    GT[0, 4] = -0.5 * (Rr[0, 0] * p1[0] + Rr[1, 0] * p1[1] + Rr[2, 0] * p1[2]) / pl1
    GT[0, 8] = -eta / l
    GT[0, 9] = 0.5 * (Rr[0, 1] * p2[0] + Rr[1, 1] * p2[1] + Rr[2, 1] * p2[2]) / pl1
    GT[0, 10] = -0.5 * (Rr[0, 0] * p2[0] + Rr[1, 0] * p2[1] + Rr[2, 0] * p2[2]) / pl1
    GT[1, 2] = 1.0 / l
    GT[1, 8] = -1.0 / l
    GT[2, 1] = -1.0 / l
    GT[2, 7] = 1.0 / l
    # B in local components: row ū and rows T⁻¹(θ̄_i)(S_i − Gᵀ); then columns rotated by Rrᵀ
    Bl = np.zeros((7, 12), dtype=dt)
    Bl[0, 0] = -1.0
    Bl[0, 6] = 1.0
    for i in range(2):
        tangent_inv_so3(th1 if i == 0 else th2, Ti[i])
        for r in range(3):
            for c in range(12):
                Bl[1 + 3 * i + r, c] = -(Ti[i, r, 0] * GT[0, c] + Ti[i, r, 1] * GT[1, c] + Ti[i, r, 2] * GT[2, c])
            for k in range(3):
                Bl[1 + 3 * i + r, 3 + 6 * i + k] += Ti[i, r, k]
    rotate_columns(Bl, Rr, B, 7, 12)
    return ubar, l


@numba.njit(cache=True, inline="always")
def _grad_dot(a, da, b, db, out):
    """out (12,) = ∇(a·b) = aᵀ∇b + bᵀ∇a for a, b (3,) with gradients da, db (3, 12)."""
    for j in range(12):
        out[j] = (a[0] * db[0, j] + a[1] * db[1, j] + a[2] * db[2, j]
                  + b[0] * da[0, j] + b[1] * da[1, j] + b[2] * da[2, j])


@numba.njit(cache=True)
def add_geometric_stiffness(l, Rr, p1, p2, GT, Ti, th1, th2, B, fbar, K):
    r"""K (12, 12) += ∂Bᵀ/∂d : f̄, the geometric part of the consistent tangent, in closed form.

    With m_i = T⁻ᵀ(θ̄_i) m̄_i and f_l = Σ_i (S_iᵀ − G) m_i the local rotational forces, the force is
    f = N r + E f_l, r = (−e₁, 0, e₁, 0); at fixed f̄ its variation has four parts:

    * N δr, δe₁ = ω × e₁;
    * E Σ_i (S_iᵀ − G) H_i δθ̄_i, H_i = ∂(T⁻ᵀ(θ) m̄_i)/∂θ at θ̄_i (Battini & Pacoste 2002's K_h;
      :func:`~dolfinx_corot.rotations.tangent_inv_so3_derivative`);
    * δE f_l = −E S(f_l) Ω δd, the frame's spin ω = R_r Ω δd, Ω = Gᵀ Eᵀ;
    * −E δG m, m = m₁ + m₂: the gradients of Gᵀ's entries η/l, p_i·e₂/(p·e₂), p_i·e₁/(p·e₂), 1/l
      through δe_k = ω × e_k, δp_i = δw_i × p_i and δl = r·δd.

    Arguments from :func:`frame_and_basic` and the basic forces f̄ (7,); every term is exact, so
    K equals the complex-step derivative of f = Bᵀ f̄ to rounding (tested)."""
    # (few allocations: an element kernel's time goes largely into them otherwise)
    v3 = np.empty((6, 3))
    w12 = np.zeros((6, 12))
    w312 = np.zeros((8, 3, 12))
    m = v3[0:2]
    for i in range(2):
        for r in range(3):
            m[i, r] = Ti[i, 0, r] * fbar[1 + 3 * i] + Ti[i, 1, r] * fbar[2 + 3 * i] + Ti[i, 2, r] * fbar[3 + 3 * i]
    ms = v3[2]
    for r in range(3):
        ms[r] = m[0, r] + m[1, r]
    fl = w12[0]
    for c in range(12):
        fl[c] = -(GT[0, c] * ms[0] + GT[1, c] * ms[1] + GT[2, c] * ms[2])
    for k in range(3):
        fl[3 + k] += m[0, k]
        fl[9 + k] += m[1, k]
    Om = w312[0]
    rotate_columns(GT, Rr, Om, 3, 12)
    Wg = w312[1]  # the frame's spin in global components per unit δd
    for k in range(3):
        for j in range(12):
            Wg[k, j] = Rr[k, 0] * Om[0, j] + Rr[k, 1] * Om[1, j] + Rr[k, 2] * Om[2, j]
    Z = np.zeros((12, 12))  # in local components, rotated to global rows at the end
    # K_h: (S_iᵀ − G) H_i B_θi
    HBs = w312[2]
    Hi = np.empty((3, 3))
    for i in range(2):
        tangent_inv_so3_derivative(th1 if i == 0 else th2, fbar[1 + 3 * i:4 + 3 * i], Hi)
        for r in range(3):
            for j in range(12):
                v = Hi[r, 0] * B[1 + 3 * i, j] + Hi[r, 1] * B[2 + 3 * i, j] + Hi[r, 2] * B[3 + 3 * i, j]
                Z[3 + 6 * i + r, j] += v
                HBs[r, j] += v
    for c in range(12):
        g0, g1, g2 = GT[0, c], GT[1, c], GT[2, c]
        if g0 != 0.0 or g1 != 0.0 or g2 != 0.0:
            for j in range(12):
                Z[c, j] -= g0 * HBs[0, j] + g1 * HBs[1, j] + g2 * HBs[2, j]
    # δE f_l
    subtract_spin_g_omega(Z, fl, Om, 12)
    # −δG m: gradients of e1, e2 (ω × e_k), p_i (δw_i × p_i), l
    e1 = v3[3]
    e2 = v3[4]
    for k in range(3):
        e1[k] = Rr[k, 0]
        e2[k] = Rr[k, 1]
    de1 = w312[3]
    de2 = w312[4]
    for j in range(12):
        for e, de in ((e1, de1), (e2, de2)):
            de[0, j] = Wg[1, j] * e[2] - Wg[2, j] * e[1]
            de[1, j] = Wg[2, j] * e[0] - Wg[0, j] * e[2]
            de[2, j] = Wg[0, j] * e[1] - Wg[1, j] * e[0]
    dp1 = w312[5]
    dp2 = w312[6]
    for pi, dpi, c0 in ((p1, dp1, 3), (p2, dp2, 9)):
        # δw × p_i: column c0 + k is e_k × p_i
        dpi[1, c0] = -pi[2]
        dpi[2, c0] = pi[1]
        dpi[0, c0 + 1] = pi[2]
        dpi[2, c0 + 1] = -pi[0]
        dpi[0, c0 + 2] = -pi[1]
        dpi[1, c0 + 2] = pi[0]
    p = v3[5]
    dp = w312[7]
    for k in range(3):
        p[k] = 0.5 * (p1[k] + p2[k])
        for j in range(12):
            dp[k, j] = 0.5 * (dp1[k, j] + dp2[k, j])
    P = dot(p, e2)
    Q = dot(p, e1)
    dP = w12[1]
    dQ = w12[2]
    _grad_dot(p, dp, e2, de2, dP)
    _grad_dot(p, dp, e1, de1, dQ)
    dinvl = w12[3]  # ∇(1/l) = −r/l²
    for k in range(3):
        dinvl[k] = e1[k] / (l * l)
        dinvl[6 + k] = -e1[k] / (l * l)
    ds = w12[4]
    dt_ = w12[5]
    for j in range(12):
        da0 = dQ[j] / (P * l) - Q / (P * P * l) * dP[j] + Q / P * dinvl[j]
        row2 = ms[0] * da0 + ms[1] * dinvl[j]
        Z[2, j] -= row2
        Z[8, j] += row2
        Z[1, j] += ms[2] * dinvl[j]
        Z[7, j] -= ms[2] * dinvl[j]
    for pi, dpi, c0 in ((p1, dp1, 3), (p2, dp2, 9)):
        s = dot(pi, e2)
        t = dot(pi, e1)
        _grad_dot(pi, dpi, e2, de2, ds)
        _grad_dot(pi, dpi, e1, de1, dt_)
        for j in range(12):
            Z[c0, j] -= ms[0] * (0.5 * ds[j] / P - 0.5 * s / (P * P) * dP[j])
            Z[c0 + 1, j] -= ms[0] * (-0.5 * dt_[j] / P + 0.5 * t / (P * P) * dP[j])
    # rows to global, then N δr
    for b in range(4):
        for k in range(3):
            for j in range(12):
                K[3 * b + k, j] += Rr[k, 0] * Z[3 * b, j] + Rr[k, 1] * Z[3 * b + 1, j] + Rr[k, 2] * Z[3 * b + 2, j]
    N = fbar[0]
    for k in range(3):
        for j in range(12):
            K[k, j] -= N * de1[k, j]
            K[6 + k, j] += N * de1[k, j]

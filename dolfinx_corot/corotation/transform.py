r"""Between the element frame and the global axes: the algebra every co-rotational frame shares.

With :math:`\mathbf B = \partial\bar{\mathbf d}/\partial\mathbf d` the frame's map from global to
basic (element-frame) variations (Rankin & Nour-Omid 1988; Crisfield 1991, §7.3):

.. math::

    \mathbf f = \mathbf B^T\bar{\mathbf f},\qquad
    \bar{\mathbf f} = \bar{\mathbf K}\bar{\mathbf d}\ \text{(linear local law)},\qquad
    \mathbf K_m = \mathbf B^T\bar{\mathbf K}\mathbf B\ \text{(material part of the tangent)}.

:func:`frame_axes` assembles the frame from its first and third axes. Frames that build B
in local components, :math:`\mathbf B = \mathbf B_l\boldsymbol\Lambda` with
:math:`\boldsymbol\Lambda = \mathrm{diag}(\mathbf R^T, \mathbf R^T, \dots)`, turn its columns with
:func:`rotate_columns`; node coordinates in the frame about the centroid come from
:func:`local_coordinates`. All functions work on caller-provided arrays, explicit loops (the
blocks are tiny), and are complex-analytic (complex-step tangents).
"""
from __future__ import annotations

import numba
import numpy as np


# The sizes m, n of B (B_l) are integer literals at every call (numba.literally): each size gets its
# own compiled loops with constant trip counts, which LLVM unrolls (at 18 × 18, Bᵀ K̄ B takes a
# third of the time it takes with the bounds read from the arrays). Sums run in index order.


@numba.njit(cache=True)
def force(B, fbar, f, m, n):
    """f (n,) = Bᵀ f̄ for B (m, n), f̄ (m,)."""
    numba.literally(m)
    numba.literally(n)
    for i in range(n):
        acc = B[0, i] * fbar[0]
        for r in range(1, m):
            acc += B[r, i] * fbar[r]
        f[i] = acc


@numba.njit(cache=True)
def linear_force(B, Kbar, dbar, fbar, f, m, n):
    """f̄ (m,) = K̄ d̄ and f (n,) = Bᵀ f̄ for B (m, n), K̄ (m, m), d̄ (m,)."""
    numba.literally(m)
    numba.literally(n)
    for i in range(m):
        acc = Kbar[i, 0] * dbar[0]
        for j in range(1, m):
            acc += Kbar[i, j] * dbar[j]
        fbar[i] = acc
    force(B, fbar, f, m, n)


@numba.njit(cache=True)
def stiffness(B, Kbar, K, m, n):
    """K (n, n) = Bᵀ (K̄ B) for B (m, n), K̄ (m, m)."""
    numba.literally(m)
    numba.literally(n)
    KB = np.empty((m, n), dtype=B.dtype)
    for r in range(m):
        for j in range(n):
            acc = Kbar[r, 0] * B[0, j]
            for s in range(1, m):
                acc += Kbar[r, s] * B[s, j]
            KB[r, j] = acc
    for i in range(n):
        for j in range(n):
            acc = B[0, i] * KB[0, j]
            for r in range(1, m):
                acc += B[r, i] * KB[r, j]
            K[i, j] = acc


@numba.njit(cache=True, inline="always")
def frame_axes(e1, e3, R):
    """R (3, 3) = [e₁ e₂ e₃] with e₂ = e₃ × e₁, for orthonormal e₁, e₃ (3,)."""
    R[0, 0] = e1[0]
    R[1, 0] = e1[1]
    R[2, 0] = e1[2]
    R[0, 1] = e3[1] * e1[2] - e3[2] * e1[1]
    R[1, 1] = e3[2] * e1[0] - e3[0] * e1[2]
    R[2, 1] = e3[0] * e1[1] - e3[1] * e1[0]
    R[0, 2] = e3[0]
    R[1, 2] = e3[1]
    R[2, 2] = e3[2]


@numba.njit(cache=True)
def rotate_columns(Bl, R, B, m, n):
    """B (m, n) = B_l Λ, Λ = diag(Rᵀ, …, Rᵀ): every 3-column block of B_l (m, n) times Rᵀ."""
    numba.literally(m)
    numba.literally(n)
    for r in range(m):
        for c0 in range(0, n, 3):
            for j in range(3):
                B[r, c0 + j] = Bl[r, c0] * R[j, 0] + Bl[r, c0 + 1] * R[j, 1] + Bl[r, c0 + 2] * R[j, 2]


@numba.njit(cache=True, inline="always")
def positions(X, u):
    """x (n, 3) = X + u, the current positions, of the dtype of u (real or complex)."""
    x = np.empty(u.shape, dtype=u.dtype)
    for a in range(u.shape[0]):
        for k in range(3):
            x[a, k] = X[a, k] + u[a, k]
    return x


@numba.njit(cache=True, inline="always")
def local_coordinates(R, x, xbar):
    """xbar (n, 3) = Rᵀ (x_a − c): the points x (n, 3) in the frame R (3, 3) about their centroid c."""
    n = x.shape[0]
    c = np.empty(3, dtype=x.dtype)
    for k in range(3):
        ck = x[0, k]
        for a in range(1, n):
            ck += x[a, k]
        c[k] = ck / n
    for a in range(n):
        for k in range(3):
            xbar[a, k] = R[0, k] * (x[a, 0] - c[0]) + R[1, k] * (x[a, 1] - c[1]) + R[2, k] * (x[a, 2] - c[2])


# -- the consistent tangent of a shell frame (triangles and quadrilaterals alike) ------------------
# With the local forces f̄ = K̄ d̄, g = B_lᵀ f̄, the frame spin ω = Ω d^l and v = Σ_a(n_a × x̄_a −
# T_a⁻ᵀ m_a) (:mod:`.frame_triangle`), the tangent in local components is
# K^l = B_lᵀ K̄ B_l − S(g) Ω + ∂(Ωᵀ v)/∂d^l + Ωᵀ Σ_a (spin(n_a) B_{u,a} − M_a B_{θ,a})
#       + Σ_a E_aᵀ M_a B_{θ,a};
# only ∂(Ωᵀ v)/∂d^l depends on the element's shape. These are the other terms, for ``nodes``
# nodes of 6 dofs (``rotations`` False: translations alone, the membranes' three-node frame).

@numba.njit(cache=True, inline="always")
def subtract_spin_g_omega(Kl, g, Om, n):
    """K^l (n, n) −= S(g) Ω: block b's rows 3b..3b+2 get −spin(g_b) Ω (g (n,), Ω (3, n))."""
    for b in range(n // 3):
        g0, g1, g2 = g[3 * b], g[3 * b + 1], g[3 * b + 2]
        for col in range(n):
            o0, o1, o2 = Om[0, col], Om[1, col], Om[2, col]
            Kl[3 * b + 0, col] -= g1 * o2 - g2 * o1
            Kl[3 * b + 1, col] -= g2 * o0 - g0 * o2
            Kl[3 * b + 2, col] -= g0 * o1 - g1 * o0


@numba.njit(cache=True, inline="always")
def add_omega_w(Kl, fbar, Bl, M, Om, nodes, rotations):
    """K^l += Ωᵀ W + Σ_a E_aᵀ M_a B_{θ,a} with W = Σ_a (spin(n_a) B_{u,a} − M_a B_{θ,a}): n_a, m_a
    the local nodal forces and moments in f̄ (6 per node), M_a = ∂(T⁻¹(θ̄_a)ᵀ m_a)/∂θ̄_a (nodes, 3, 3)."""
    n = 6 * nodes
    W = np.zeros((3, n))
    for a in range(nodes):
        n0, n1, n2 = fbar[6 * a], fbar[6 * a + 1], fbar[6 * a + 2]
        for j in range(n):
            t0, t1, t2 = Bl[6 * a, j], Bl[6 * a + 1, j], Bl[6 * a + 2, j]
            W[0, j] += n1 * t2 - n2 * t1
            W[1, j] += n2 * t0 - n0 * t2
            W[2, j] += n0 * t1 - n1 * t0
            if rotations:
                r0, r1, r2 = Bl[6 * a + 3, j], Bl[6 * a + 4, j], Bl[6 * a + 5, j]
                for i in range(3):
                    MB = M[a, i, 0] * r0 + M[a, i, 1] * r1 + M[a, i, 2] * r2
                    W[i, j] -= MB
                    Kl[6 * a + 3 + i, j] += MB
    for i in range(n):
        o0, o1, o2 = Om[0, i], Om[1, i], Om[2, i]
        if o0 != 0.0 or o1 != 0.0 or o2 != 0.0:
            for j in range(n):
                Kl[i, j] += o0 * W[0, j] + o1 * W[1, j] + o2 * W[2, j]


@numba.njit(cache=True, inline="always")
def to_global(Kl, g, Rr, f, K, n):
    """f = Λᵀ g and K = Λᵀ K^l Λ (Λ = diag(R_rᵀ, …)) in 3 × 3 blocks; K^l, K (n, n)."""
    for b in range(n // 3):
        for k in range(3):
            f[3 * b + k] = Rr[k, 0] * g[3 * b] + Rr[k, 1] * g[3 * b + 1] + Rr[k, 2] * g[3 * b + 2]
    tmp = np.empty((n, n))
    rotate_columns(Kl, Rr, tmp, n, n)  # K^l Λ
    for br in range(n // 3):
        for k in range(3):
            for j in range(n):
                K[3 * br + k, j] = (Rr[k, 0] * tmp[3 * br, j] + Rr[k, 1] * tmp[3 * br + 1, j]
                                    + Rr[k, 2] * tmp[3 * br + 2, j])

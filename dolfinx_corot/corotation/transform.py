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

"""Compiled helpers of :class:`~dolfinx_corot.assembly.petsc.DenseFactor` (small serial systems,
whose time goes into per-call overheads: one compiled call instead of a dozen NumPy ones).
Imported with the first dense factorization, so that a scene without one does not load numba."""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def unit_diagonal_scale(values, indptr, indices, s):
    """s (n,): s_i = 1/√|a_ii| of A's CSR arrays (1 where a_ii = 0), S = diag(s) scaling A to a
    unit diagonal."""
    for i in range(len(s)):
        s[i] = 1.0
        for k in range(indptr[i], indptr[i + 1]):
            if indices[k] == i and values[k] != 0.0:
                s[i] = 1.0 / np.sqrt(abs(values[k]))


@numba.njit(cache=True)
def scaled_dense(values, indptr, indices, K, s):
    """K (n, n) = S A S from A's CSR arrays, S of :func:`unit_diagonal_scale` (filled in s):
    the matrix scaled to a unit diagonal (entries (a_ij s_i) s_j)."""
    n = K.shape[0]
    for i in range(n):
        for j in range(n):
            K[i, j] = 0.0
    unit_diagonal_scale(values, indptr, indices, s)
    for i in range(n):
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            K[i, j] = values[k] * s[i] * s[j]


@numba.njit(cache=True)
def lu_summary(diagonal, piv, null_pivot):
    """(row swaps, pivots with |u_ii| ≤ ``null_pivot``, negative pivots) of LAPACK's LU from
    U's diagonal and the (0-based) pivots."""
    swaps = 0
    null = 0
    negative = 0
    for i in range(len(diagonal)):
        if piv[i] != i:
            swaps += 1
        u = diagonal[i]
        if abs(u) <= null_pivot:
            null += 1
        if u < 0.0:
            negative += 1
    return swaps, null, negative


@numba.njit(cache=True)
def bandwidths(indptr, indices):
    """(kl, ku): the largest i − j and j − i over the stored entries (i, j) of a CSR pattern."""
    kl = 0
    ku = 0
    for i in range(len(indptr) - 1):
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            if i - j > kl:
                kl = i - j
            if j - i > ku:
                ku = j - i
    return kl, ku


@numba.njit(cache=True)
def scaled_band(values, indptr, indices, kl, ku, ab, s):
    """:func:`scaled_dense` into LAPACK's band storage for LU (dgbtrf): ab (2 kl + ku + 1, n),
    ab[kl + ku + i − j, j] = (a_ij s_i) s_j, the first kl rows left for the fill."""
    n = ab.shape[1]
    for j in range(n):
        for r in range(ab.shape[0]):
            ab[r, j] = 0.0
    unit_diagonal_scale(values, indptr, indices, s)
    for i in range(n):
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            ab[kl + ku + i - j, j] = values[k] * s[i] * s[j]

"""Compiled helpers of :class:`~dolfinx_corot.assembly.petsc.DenseFactor` (small serial systems,
whose time goes into per-call overheads: one compiled call instead of a dozen NumPy ones).

The loops are C in the assembly's library (:func:`dolfinx_corot.assembly.cells.compiled`), so
that a small model factorized densely loads no numba. Matrices are in LAPACK's (column-major)
order; CSR arrays are those of ``PETSc.Mat.getValuesCSR``.
"""
from __future__ import annotations

import numpy as np

from .cells import compiled


def _csr(indptr, indices):
    return np.ascontiguousarray(indptr, dtype=np.int32), np.ascontiguousarray(indices, dtype=np.int32)


def _ptr(ffi, kind: str, a: np.ndarray):
    return ffi.cast(kind + "*", a.ctypes.data)


def scaled_dense(values, indptr, indices, K, s) -> None:
    """K (n, n), column-major, = S A S from A's CSR arrays, S = diag(s), s_i = 1/√|a_ii| (1 where
    a_ii = 0; filled in s): the matrix scaled to a unit diagonal (entries (a_ij s_i) s_j)."""
    n = K.shape[0]
    if K.shape != (n, n) or not K.flags.f_contiguous or K.dtype != np.float64 or s.shape != (n,):
        raise ValueError(f"scaled_dense: a column-major float64 ({n}, {n}) matrix and ({n},) scales are needed")
    indptr, indices = _csr(indptr, indices)
    values = np.ascontiguousarray(values, dtype=np.float64)
    module = compiled()
    ffi = module.ffi
    module.lib.scaled_dense(n, _ptr(ffi, "int32_t", indptr), _ptr(ffi, "int32_t", indices),
                            _ptr(ffi, "double", values), _ptr(ffi, "double", K), _ptr(ffi, "double", s))


def lu_summary(diagonal, piv, null_pivot: float) -> tuple[int, int, int]:
    """(row swaps, pivots with |u_ii| ≤ ``null_pivot``, negative pivots) of LAPACK's LU from
    U's diagonal and the (0-based) pivots."""
    diagonal = np.ascontiguousarray(diagonal, dtype=np.float64)
    piv = np.ascontiguousarray(piv, dtype=np.int32)
    out = np.zeros(3, dtype=np.int64)
    module = compiled()
    ffi = module.ffi
    module.lib.lu_summary(len(diagonal), _ptr(ffi, "double", diagonal), _ptr(ffi, "int32_t", piv), null_pivot,
                          _ptr(ffi, "int64_t", out))
    return int(out[0]), int(out[1]), int(out[2])


def bandwidths(indptr, indices) -> tuple[int, int]:
    """(kl, ku): the largest i − j and j − i over the stored entries (i, j) of a CSR pattern."""
    indptr, indices = _csr(indptr, indices)
    out = np.zeros(2, dtype=np.int64)
    module = compiled()
    ffi = module.ffi
    module.lib.bandwidths(len(indptr) - 1, _ptr(ffi, "int32_t", indptr), _ptr(ffi, "int32_t", indices),
                          _ptr(ffi, "int64_t", out))
    return int(out[0]), int(out[1])


def scaled_band(values, indptr, indices, kl: int, ku: int, ab, s) -> None:
    """:func:`scaled_dense` into LAPACK's band storage for LU (dgbtrf): ab (2 kl + ku + 1, n),
    column-major, ab[kl + ku + i − j, j] = (a_ij s_i) s_j, the first kl rows left for the fill."""
    n = ab.shape[1]
    if ab.shape[0] != 2 * kl + ku + 1 or not ab.flags.f_contiguous or ab.dtype != np.float64 or s.shape != (n,):
        raise ValueError(f"scaled_band: a column-major float64 ({2 * kl + ku + 1}, {n}) band and ({n},) scales "
                         "are needed")
    indptr, indices = _csr(indptr, indices)
    values = np.ascontiguousarray(values, dtype=np.float64)
    module = compiled()
    ffi = module.ffi
    module.lib.scaled_band(n, _ptr(ffi, "int32_t", indptr), _ptr(ffi, "int32_t", indices),
                           _ptr(ffi, "double", values), kl, ku, ab.shape[0], _ptr(ffi, "double", ab),
                           _ptr(ffi, "double", s))

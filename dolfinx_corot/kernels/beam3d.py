r"""Two-node beams and bars in space: gather ► frame ► law ► scatter.

Nodal state (7 per node): displacement (3) and unit quaternion (4) of the
nodal rotation; element vector (12): (u₁, w₁, u₂, w₂) with spatial spins w.

* :func:`corotational`: f = Bᵀ f̄ from :mod:`dolfinx_corot.corotation.frame3d`
  and :mod:`dolfinx_corot.elements.beam3d`; the consistent tangent
  K = ∂f/∂d (both Bᵀ K̄ B and ∂Bᵀ/∂d : f̄) by complex-step differentiation,
  K[:, j] = Im f(d + i h e_j)/h with h = 1e-30, exact to rounding (Squire &
  Trapp 1998; Martins, Sturdza & Alonso 2003): a spin column perturbs the
  nodal rotation multiplicatively, R ← exp(i h e_k) R, as Newton updates it.
  Only the six columns of node 1 are differentiated; those of node 2 follow
  exactly from translation and rotation invariance of f.
* :func:`linear`: K = B₀ᵀ K̄ B₀ in the initial frame, f = K d with the nodal
  rotation vectors log(R_i) (no co-rotational work).

DOLFINx kernels (:data:`vector_kernel`, :data:`matrix_kernel`): ``w`` =
[state node 1 (7), state node 2 (7), props (NPROPS)], ``c`` =
[large_rotations], ``coords`` (2, 3).
"""
from __future__ import annotations

import numba
import numpy as np

from ..corotation import frame3d
from ..elements import beam3d as law
from ..rotations import quat_to_matrix
from .ufcx import signature

NDOF = 12
NSTATE = 7
NCOEF = 2 * NSTATE + law.NPROPS
H = 1e-30  # complex step


@numba.njit(cache=True)
def _force(X1, X2, u1, u2, R1, R2, R0, l0, props, f):
    """f (12,) = Bᵀ f̄ at the given configuration (real or complex)."""
    dt = u1.dtype
    th1 = np.empty(3, dtype=dt)
    th2 = np.empty(3, dtype=dt)
    B = np.empty((7, 12), dtype=dt)
    ubar = frame3d.basic(X1, X2, u1, u2, R1, R2, R0, l0, th1, th2, B)
    fbar = np.empty(7, dtype=dt)
    law.basic_force(l0, ubar, th1, th2, props, True, fbar)
    for i in range(12):
        acc = B[0, i] * fbar[0]
        for r in range(1, 7):
            acc += B[r, i] * fbar[r]
        f[i] = acc


@numba.njit(cache=True)
def corotational(X1, X2, s1, s2, props, f, K):
    """Co-rotational element: s1, s2 nodal states (7,); fills f (12,) and K (12, 12)."""
    R0 = np.empty((3, 3))
    l0 = frame3d.initial_frame(X1, X2, props[law.VX:law.VZ + 1], R0)
    R1 = quat_to_matrix(s1[3:7])
    R2 = quat_to_matrix(s2[3:7])
    u1 = s1[:3].copy()
    u2 = s2[:3].copy()
    _force(X1, X2, u1, u2, R1, R2, R0, l0, props, f)
    # complex step, one column per dof
    u1c = u1.astype(np.complex128)
    u2c = u2.astype(np.complex128)
    R1c = R1.astype(np.complex128)
    R2c = R2.astype(np.complex128)
    fc = np.empty(12, dtype=np.complex128)
    E = np.empty((3, 3), dtype=np.complex128)
    w = np.zeros(3, dtype=np.complex128)
    for j in range(12):
        node = j // 6
        k = j % 3
        if j >= 6:
            break
        a1, a2, Q1, Q2 = u1c.copy(), u2c.copy(), R1c, R2c
        if j % 6 < 3:
            if node == 0:
                a1[k] += 1j * H
            else:
                a2[k] += 1j * H
        else:
            w[:] = 0.0
            w[k] = 1j * H
            frame3d.exp_spin(w, E)
            if node == 0:
                Q1 = np.empty((3, 3), dtype=np.complex128)
                frame3d._mat3(E, R1c, Q1)
            else:
                Q2 = np.empty((3, 3), dtype=np.complex128)
                frame3d._mat3(E, R2c, Q2)
        _force(X1, X2, a1, a2, Q1, Q2, R0, l0, props, fc)
        for i in range(12):
            K[i, j] = fc[i].imag / H
    # The remaining six columns follow from invariance, exactly:
    # translation — f depends on u2 − u1, so K[:, u2] = −K[:, u1];
    # rotation — a rigid rotation δu_i = e_k × x_i, δw_i = e_k turns every force and
    # moment block b of f into e_k × f_b, so
    # K[:, w2_k] = (e_k × f_b)_b − K[:, w1_k] − K[:, u1]·(e_k × (x1 − x2)).
    for i in range(12):
        for k in range(3):
            K[i, 6 + k] = -K[i, k]
    r = np.empty(3)
    for k in range(3):
        for m in range(3):
            r[m] = X1[m] + u1[m] - X2[m] - u2[m]
        ek_x_r = np.empty(3)
        ek_x_r[0] = (k == 1) * r[2] - (k == 2) * r[1]
        ek_x_r[1] = (k == 2) * r[0] - (k == 0) * r[2]
        ek_x_r[2] = (k == 0) * r[1] - (k == 1) * r[0]
        for b in range(4):
            fb0, fb1, fb2 = f[3 * b], f[3 * b + 1], f[3 * b + 2]
            g0 = (k == 1) * fb2 - (k == 2) * fb1
            g1 = (k == 2) * fb0 - (k == 0) * fb2
            g2 = (k == 0) * fb1 - (k == 1) * fb0
            for m, gm in ((0, g0), (1, g1), (2, g2)):
                i = 3 * b + m
                K[i, 9 + k] = gm - K[i, 3 + k] - (K[i, 0] * ek_x_r[0] + K[i, 1] * ek_x_r[1] + K[i, 2] * ek_x_r[2])


@numba.njit(cache=True)
def _rotation_vector(q, out):
    """Rotation vector of the unit quaternion q (angle below π)."""
    frame3d.log_rotation(quat_to_matrix(q), out)


@numba.njit(cache=True)
def linear(X1, X2, s1, s2, props, f, K):
    """Geometrically linear element in the initial frame: K = B₀ᵀ K̄ B₀, f = K d + B₀ᵀ f̄₀."""
    R0 = np.empty((3, 3))
    l0 = frame3d.initial_frame(X1, X2, props[law.VX:law.VZ + 1], R0)
    I3 = np.eye(3)
    th1 = np.empty(3)
    th2 = np.empty(3)
    B = np.empty((7, 12))
    frame3d.basic(X1, X2, np.zeros(3), np.zeros(3), I3, I3, R0, l0, th1, th2, B)
    kbar = np.empty((7, 7))
    law.basic_stiffness_linear(l0, props, kbar)
    K[:, :] = B.T @ kbar @ B
    d = np.empty(12)
    d[0:3] = s1[:3]
    d[6:9] = s2[:3]
    r = np.empty(3)
    _rotation_vector(s1[3:7], r)
    d[3:6] = r
    _rotation_vector(s2[3:7], r)
    d[9:12] = r
    f[:] = K @ d
    for i in range(12):
        f[i] += B[0, i] * props[law.N0]


@numba.njit(cache=True)
def evaluate(X1, X2, s1, s2, props, large_rotations, f, K):
    if large_rotations:
        corotational(X1, X2, s1, s2, props, f, K)
    else:
        linear(X1, X2, s1, s2, props, f, K)


@numba.njit(cache=True)
def evaluate_all(X, S, props, large_rotations, F, K):
    """All elements: X (n, 2, 3), S (n, 2, 7), props (n, NPROPS) → F (n, 12), K (n, 12, 12)."""
    for e in range(X.shape[0]):
        evaluate(X[e, 0], X[e, 1], S[e, 0], S[e, 1], props[e], large_rotations, F[e], K[e])


@numba.njit(cache=True, inline="always")
def _tabulate(w_, c_, coords_, f, K):
    w = numba.carray(w_, (NCOEF,))
    c = numba.carray(c_, (1,))
    X = numba.carray(coords_, (2, 3))
    evaluate(X[0].copy(), X[1].copy(), w[0:NSTATE].copy(), w[NSTATE:2 * NSTATE].copy(),
             w[2 * NSTATE:].copy(), c[0] != 0.0, f, K)


@numba.cfunc(signature, nopython=True, cache=True)
def vector_kernel(b_, w_, c_, coords_, entity_local_index, permutation):
    """Element internal-force vector (12,) for a DOLFINx linear form."""
    b = numba.carray(b_, (NDOF,))
    f = np.empty(NDOF)
    K = np.empty((NDOF, NDOF))
    w = numba.carray(w_, (NCOEF,))
    c = numba.carray(c_, (1,))
    X = numba.carray(coords_, (2, 3))
    R0 = np.empty((3, 3))
    props = w[2 * NSTATE:].copy()
    if c[0] != 0.0:
        # the residual needs the force only: no complex-step columns
        l0 = frame3d.initial_frame(X[0].copy(), X[1].copy(), props[law.VX:law.VZ + 1], R0)
        R1 = quat_to_matrix(w[3:7].copy())
        R2 = quat_to_matrix(w[NSTATE + 3:NSTATE + 7].copy())
        _force(X[0].copy(), X[1].copy(), w[0:3].copy(), w[NSTATE:NSTATE + 3].copy(), R1, R2, R0, l0, props, f)
    else:
        _tabulate(w_, c_, coords_, f, K)
    for i in range(NDOF):
        b[i] = f[i]


@numba.cfunc(signature, nopython=True, cache=True)
def matrix_kernel(A_, w_, c_, coords_, entity_local_index, permutation):
    """Element tangent (12, 12) for a DOLFINx bilinear form."""
    A = numba.carray(A_, (NDOF, NDOF))
    f = np.empty(NDOF)
    K = np.empty((NDOF, NDOF))
    _tabulate(w_, c_, coords_, f, K)
    A[:, :] = K

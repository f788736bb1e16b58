r"""Three-node flat shells in space: gather ► frame ► law ► scatter.

Nodal state (7 per node): displacement (3) and unit quaternion (4); element
vector (18): (u_a, w_a) per node with spatial spins w.

* :func:`corotational`: f = Bᵀ K̄ d̄ with the frame of
  :mod:`dolfinx_corot.corotation.frame_triangle` and the linear flat
  triangle of :mod:`dolfinx_corot.elements.shell_triangle` (element-independent
  co-rotational formulation); consistent tangent K = ∂f/∂d in closed form
  (:func:`frame_triangle.force_and_tangent`, 8 µs per element).
* :func:`corotational_complex_step`: the same f with K by complex-step
  differentiation (h = 1e-30), a spin column perturbing the nodal rotation
  multiplicatively; node 3's columns follow exactly from translation and
  rotation invariance of f (12 complex evaluations, 60 µs): the reference
  against which the closed form is tested.
* :func:`linear`: K = B₀ᵀ K̄ B₀ in the initial frame, f = K d with nodal
  rotation vectors (no co-rotational work).
"""
from __future__ import annotations

import numba
import numpy as np

from ..corotation import frame_triangle as frame
from ..corotation.frame3d import _mat3, exp_spin, log_rotation
from ..elements import shell_triangle as law
from ..rotations import quat_to_matrix
from .ufcx import signature

NDOF = 18
NSTATE = 7
NEDATA = 9 + 9 + 18 * 18  # per-cell constants: R0, x̄0, K̄ (computed once, see element_data)
NCOEF = 3 * NSTATE + law.NPROPS + NEDATA
H = 1e-30


@numba.njit(cache=True)
def _force(X, u, R, R0, xbar0, Kbar, f, rotations):
    dt = u.dtype
    dbar = np.empty(18, dtype=dt)
    B = np.empty((18, 18), dtype=dt)
    frame.basic(X, u, R, R0, xbar0, dbar, B, rotations)
    fbar = np.empty(18, dtype=dt)
    for i in range(18):
        acc = Kbar[i, 0] * dbar[0]
        for j in range(1, 18):
            acc += Kbar[i, j] * dbar[j]
        fbar[i] = acc
    for i in range(18):
        acc = B[0, i] * fbar[0]
        for r in range(1, 18):
            acc += B[r, i] * fbar[r]
        f[i] = acc


@numba.njit(cache=True)
def _setup(X, props):
    R0 = np.empty((3, 3))
    xbar0 = np.empty((3, 3))
    frame.initial(X, R0, xbar0)
    Kbar = np.empty((18, 18))
    law.local_stiffness(np.ascontiguousarray(xbar0[:, :2]), props, Kbar)
    return R0, xbar0, Kbar


@numba.njit(cache=True)
def element_data(X, props, out):
    """The constants of one element, out (NEDATA,) = (R0, x̄0, K̄) flattened (computed once per cell)."""
    R0, xbar0, Kbar = _setup(X, props)
    out[:9] = R0.ravel()
    out[9:18] = xbar0.ravel()
    out[18:] = Kbar.ravel()


@numba.njit(cache=True)
def element_data_all(X, props, active, out):
    """element_data for every cell c with active[c]: X (n, 3, 3), props (n, NPROPS), out (n, NEDATA)."""
    for c in range(X.shape[0]):
        if active[c]:
            element_data(X[c], props[c], out[c])


@numba.njit(cache=True)
def _unpack(edata):
    return (edata[:9].copy().reshape(3, 3), edata[9:18].copy().reshape(3, 3),
            edata[18:].copy().reshape(18, 18))


@numba.njit(cache=True)
def corotational(X, S, props, f, K):
    """X (3, 3) initial nodes, S (3, 7) nodal states → f (18,), K (18, 18) (closed-form tangent)."""
    edata = np.empty(NEDATA)
    element_data(X, props, edata)
    corotational_cached(X, S, props, edata, f, K)


@numba.njit(cache=True)
def corotational_cached(X, S, props, edata, f, K):
    """:func:`corotational` with the element constants given (see :func:`element_data`)."""
    R0, xbar0, Kbar = _unpack(edata)
    u = np.empty((3, 3))
    R = np.empty((3, 3, 3))
    for a in range(3):
        u[a] = S[a, :3]
        R[a] = quat_to_matrix(S[a, 3:7].copy())
    frame.force_and_tangent(X, u, R, R0, xbar0, Kbar, f, K, props[law.BENDING] != 0.0)


@numba.njit(cache=True)
def corotational_complex_step(X, S, props, f, K):
    """X (3, 3) initial nodes, S (3, 7) nodal states → f (18,), K (18, 18) (complex-step tangent)."""
    R0, xbar0, Kbar = _setup(X, props)
    u = np.empty((3, 3))
    R = np.empty((3, 3, 3))
    for a in range(3):
        u[a] = S[a, :3]
        R[a] = quat_to_matrix(S[a, 3:7].copy())
    rotations = props[law.BENDING] != 0.0
    _force(X, u, R, R0, xbar0, Kbar, f, rotations)
    uc = u.astype(np.complex128)
    Rc = R.astype(np.complex128)
    fc = np.empty(18, dtype=np.complex128)
    E = np.empty((3, 3), dtype=np.complex128)
    w = np.zeros(3, dtype=np.complex128)
    Q = np.empty((3, 3), dtype=np.complex128)
    for j in range(12):  # nodes 1 and 2; node 3 follows from invariance below
        a, c = divmod(j, 6)
        up = uc.copy()
        Rp = Rc.copy()
        if c < 3:
            up[a, c] += 1j * H
        else:
            w[:] = 0.0
            w[c - 3] = 1j * H
            exp_spin(w, E)
            _mat3(E, Rc[a], Q)
            Rp[a] = Q
        _force(X, up, Rp, R0, xbar0, Kbar, fc, rotations)
        for i in range(18):
            K[i, j] = fc[i].imag / H
    # translation invariance: Σ_a K[:, u_a] = 0
    for i in range(18):
        for k in range(3):
            K[i, 12 + k] = -K[i, k] - K[i, 6 + k]
    # rotation invariance: a rigid rotation δu_a = e_k × x_a, δw_a = e_k turns each block f_b into e_k × f_b
    x = np.empty((3, 3))
    for a in range(3):
        for m in range(3):
            x[a, m] = X[a, m] + u[a, m]
    ex = np.empty(3)
    for k in range(3):
        for i in range(18):
            acc = 0.0
            for a in range(3):
                # e_k × x_a
                ex[0] = (k == 1) * x[a, 2] - (k == 2) * x[a, 1]
                ex[1] = (k == 2) * x[a, 0] - (k == 0) * x[a, 2]
                ex[2] = (k == 0) * x[a, 1] - (k == 1) * x[a, 0]
                acc += K[i, 6 * a] * ex[0] + K[i, 6 * a + 1] * ex[1] + K[i, 6 * a + 2] * ex[2]
            b, m = divmod(i, 3)
            fb0, fb1, fb2 = f[3 * b], f[3 * b + 1], f[3 * b + 2]
            if m == 0:
                g = (k == 1) * fb2 - (k == 2) * fb1
            elif m == 1:
                g = (k == 2) * fb0 - (k == 0) * fb2
            else:
                g = (k == 0) * fb1 - (k == 1) * fb0
            K[i, 15 + k] = g - K[i, 3 + k] - K[i, 9 + k] - acc


@numba.njit(cache=True)
def linear(X, S, props, edata, f, K):
    """Geometrically linear flat shell in the initial frame: K = B₀ᵀ K̄ B₀, f = K d."""
    R0, xbar0, Kbar = _unpack(edata)
    u = np.zeros((3, 3))
    R = np.empty((3, 3, 3))
    for a in range(3):
        R[a] = np.eye(3)
    dbar = np.empty(18)
    B = np.empty((18, 18))
    frame.basic(X, u, R, R0, xbar0, dbar, B, props[law.BENDING] != 0.0)
    K[:, :] = B.T @ Kbar @ B
    d = np.empty(18)
    r = np.empty(3)
    for a in range(3):
        d[6 * a:6 * a + 3] = S[a, :3]
        log_rotation(quat_to_matrix(S[a, 3:7].copy()), r)
        d[6 * a + 3:6 * a + 6] = r
    f[:] = K @ d


@numba.njit(cache=True)
def evaluate_cached(X, S, props, edata, large_rotations, f, K):
    if large_rotations:
        corotational_cached(X, S, props, edata, f, K)
    else:
        linear(X, S, props, edata, f, K)


@numba.njit(cache=True)
def evaluate(X, S, props, large_rotations, f, K):
    """f and K of one element from its initial nodes X, states S and properties."""
    edata = np.empty(NEDATA)
    element_data(X, props, edata)
    evaluate_cached(X, S, props, edata, large_rotations, f, K)


_P0 = 3 * NSTATE
_E0 = 3 * NSTATE + law.NPROPS


@numba.njit(cache=True, inline="always")
def _tabulate(w_, c_, coords_, f, K):
    w = numba.carray(w_, (NCOEF,))
    c = numba.carray(c_, (1,))
    X = numba.carray(coords_, (3, 3)).copy()
    S = w[:_P0].copy().reshape(3, NSTATE)
    evaluate_cached(X, S, w[_P0:_E0].copy(), w[_E0:].copy(), c[0] != 0.0, f, K)


@numba.cfunc(signature, nopython=True, cache=True)
def vector_kernel(b_, w_, c_, coords_, entity_local_index, permutation):
    """Element internal-force vector (18,) for a DOLFINx linear form."""
    b = numba.carray(b_, (NDOF,))
    w = numba.carray(w_, (NCOEF,))
    c = numba.carray(c_, (1,))
    f = np.empty(NDOF)
    if c[0] != 0.0:
        X = numba.carray(coords_, (3, 3)).copy()
        R0, xbar0, Kbar = _unpack(w[_E0:].copy())
        u = np.empty((3, 3))
        R = np.empty((3, 3, 3))
        for a in range(3):
            u[a] = w[NSTATE * a:NSTATE * a + 3]
            R[a] = quat_to_matrix(w[NSTATE * a + 3:NSTATE * a + 7].copy())
        _force(X, u, R, R0, xbar0, Kbar, f, w[_P0 + law.BENDING] != 0.0)
    else:
        K = np.empty((NDOF, NDOF))
        _tabulate(w_, c_, coords_, f, K)
    for i in range(NDOF):
        b[i] = f[i]


@numba.cfunc(signature, nopython=True, cache=True)
def matrix_kernel(A_, w_, c_, coords_, entity_local_index, permutation):
    """Element tangent (18, 18) for a DOLFINx bilinear form."""
    A = numba.carray(A_, (NDOF, NDOF))
    f = np.empty(NDOF)
    K = np.empty((NDOF, NDOF))
    _tabulate(w_, c_, coords_, f, K)
    A[:, :] = K

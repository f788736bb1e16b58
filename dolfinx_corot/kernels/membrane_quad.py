"""Four-node co-rotational membranes in space: gather ► frame ► law ► scatter.

Nodal state (7 per node, as for shells: displacement and a quaternion that
membranes leave untouched); element vector (24,) with 6 dofs per node, the
rotational ones zero (membrane-only nodes have their rotations fixed).

f = Bᵀ K̄ d̄ with the frame of :mod:`dolfinx_corot.corotation.frame_quad`
and the linear Q4 of :mod:`dolfinx_corot.elements.membrane_quad`; tangent
K = ∂f/∂u by complex-step differentiation (h = 1e-30) of the translations of
nodes 1–3, node 4's columns from translation invariance (9 complex
evaluations). DOLFINx orders a quadrilateral's vertices (0, 0), (1, 0),
(0, 1), (1, 1); the kernels work counter-clockwise (0, 1, 3, 2).
"""
from __future__ import annotations

import numba
import numpy as np

from ..corotation import frame_quad as frame
from ..corotation.transform import linear_force, positions, stiffness
from ..elements import membrane_quad as law
from . import CCW
from .spatial import H, SYMMETRIZED, pack_constants, symmetrize, unpack_constants
from .ufcx import lazy_kernels, tabulate_tensor_kernels

NNODE = 4
NDOF = 6 * NNODE
NSTATE = 7
NEDATA = 9 + 12 + 64           # R0, x̄0, K̄ (computed once per cell)
NCOEF = NNODE * NSTATE + law.NPROPS + NEDATA
_P0 = NNODE * NSTATE
_E0 = _P0 + law.NPROPS


@numba.njit(cache=True)
def element_data(X, props, out):
    """out (NEDATA,) = (R0, x̄0, K̄) of the element with counter-clockwise nodes X (4, 3)."""
    R0 = np.empty((3, 3))
    xbar0 = np.empty((4, 3))
    frame.initial(X, R0, xbar0)
    K = np.empty((8, 8))
    law.local_stiffness(np.ascontiguousarray(xbar0[:, :2]), props, K)
    pack_constants(R0, xbar0, K, out)


@numba.njit(cache=True)
def element_data_all(X, props, linear, active, out):
    """element_data for every active cell; X (n, 4, 3) in DOLFINx vertex order (linear: unused,
    the triangles' signature: every edge of a quadrilateral is linear)."""
    for c in range(X.shape[0]):
        if active[c]:
            Xc = np.empty((4, 3))
            for a in range(4):
                Xc[a] = X[c, CCW[a]]
            element_data(Xc, props[c], out[c])


@numba.njit(cache=True)
def _force(X, u, xbar0, Kbar, f):
    """f (12,) = Bᵀ K̄ d̄ on the translations of the counter-clockwise nodes."""
    dt = u.dtype
    dbar = np.empty(8, dtype=dt)
    B = np.empty((8, 12), dtype=dt)
    frame.basic(X, u, xbar0, dbar, B)
    fbar = np.empty(8, dtype=dt)
    linear_force(B, Kbar, dbar, fbar, f, 8, 12)


@numba.njit(cache=True)
def corotational(X, u, xbar0, Kbar, f, K):
    """X (4, 3), u (4, 3) counter-clockwise → f (12,), K (12, 12) = ∂f/∂u (complex step)."""
    _force(X, u, xbar0, Kbar, f)
    uc = u.astype(np.complex128)
    fc = np.empty(12, dtype=np.complex128)
    for j in range(9):
        a, k = divmod(j, 3)
        up = uc.copy()
        up[a, k] += 1j * H
        _force(X, up, xbar0, Kbar, fc)
        for i in range(12):
            K[i, j] = fc[i].imag / H
    for i in range(12):
        for k in range(3):
            K[i, 9 + k] = -K[i, k] - K[i, 3 + k] - K[i, 6 + k]


@numba.njit(cache=True)
def linear(X, u, R0, xbar0, Kbar, f, K):
    """Geometrically linear membrane in its initial frame: K = B₀ᵀ K̄ B₀, f = K u."""
    z = np.zeros((4, 3))
    dbar = np.empty(8)
    B = np.empty((8, 12))
    frame.basic(X, z, xbar0, dbar, B)
    stiffness(B, Kbar, K, 8, 12)
    f[:] = K @ u.ravel()


@numba.njit(cache=True)
def _counter_clockwise(X, S):
    """(positions (4, 3), displacements (4, 3)) of the nodes counter-clockwise, from DOLFINx's
    vertex order."""
    Xc = np.empty((4, 3))
    u = np.empty((4, 3))
    for a in range(4):
        Xc[a] = X[CCW[a]]
        u[a] = S[CCW[a], :3]
    return Xc, u


@numba.njit(cache=True)
def evaluate(X, S, props, large_rotations, f24, K24):
    """Element vector f24 (24,) and matrix K24 (24, 24) in DOLFINx vertex order and dof layout."""
    Xc, u = _counter_clockwise(X, S)
    edata = np.empty(NEDATA)
    element_data(Xc, props, edata)
    _evaluate_ccw(Xc, u, edata, large_rotations, True, f24, K24)


@numba.njit(cache=True)
def _evaluate_ccw(Xc, u, edata, large_rotations, tangent, f24, K24):
    R0, xbar0, Kbar = unpack_constants(edata, 4, 8)
    f = np.empty(12)
    K = np.empty((12, 12))
    if large_rotations and not tangent:
        _force(Xc, u, xbar0, Kbar, f)
        K[:, :] = 0.0
    elif large_rotations:
        corotational(Xc, u, xbar0, Kbar, f, K)
    else:
        linear(Xc, u, R0, xbar0, Kbar, f, K)
    f24[:] = 0.0
    K24[:, :] = 0.0
    for a in range(4):
        A = CCW[a]
        for k in range(3):
            f24[6 * A + k] = f[3 * a + k]
            for b in range(4):
                Bn = CCW[b]
                for m in range(3):
                    K24[6 * A + k, 6 * Bn + m] = K[3 * a + k, 3 * b + m]


@numba.njit(cache=True)
def resultants(X, S, props, large_rotations, out, axes):
    """out (16,): the components of :data:`dolfinx_corot.kernels.shell3d.RESULTANTS` of one
    membrane (X (4, 3), S (4, 7) in DOLFINx vertex order) at its centre, in its current frame (the
    initial one for a geometrically linear analysis): membrane forces N = t D ε̄(0, 0), the
    stress N/t on both faces and its von Mises value; no moments or shears. axes (3, 3): rows
    e1, e2, e3."""
    Xc, u = _counter_clockwise(X, S)
    edata = np.empty(NEDATA)
    element_data(Xc, props, edata)
    R0, xbar0, _ = unpack_constants(edata, 4, 8)
    dbar = np.empty(8)
    B = np.empty((8, 12))
    if large_rotations:
        frame.basic(Xc, u, xbar0, dbar, B)
        R = np.empty((3, 3))
        frame.frame(positions(Xc, u), R)
    else:
        frame.basic(Xc, np.zeros((4, 3)), xbar0, np.empty(8), B)
        dbar[:] = B @ u.ravel()
        R = R0
    t = props[law.T]
    eps = law.centre_B(np.ascontiguousarray(xbar0[:, :2])) @ dbar
    N = (law.plane_stress(props) * t) @ eps
    out[:] = 0.0
    out[0:3] = N
    s = N / t
    mises = np.sqrt(max(s[0] * s[0] - s[0] * s[1] + s[1] * s[1] + 3.0 * s[2] * s[2], 0.0))
    for side in range(2):
        out[8 + 3 * side:11 + 3 * side] = s
        out[14 + side] = mises
    axes[:, :] = R.T


@numba.njit(cache=True)
def resultants_all(X, S, props, large_rotations, out, axes):
    """:func:`resultants` of every element: X (n, 4, 3), S (n, 4, 7) → out (n, 16), axes (n, 3, 3)."""
    for e in range(X.shape[0]):
        resultants(X[e], S[e], props[e], large_rotations, out[e], axes[e])


@numba.njit(cache=True, inline="always")
def _tabulate(w, c, X, f, K, tangent):
    """The element function of the DOLFINx kernels (see :mod:`.ufcx`)."""
    Xc = np.empty((4, 3))
    u = np.empty((4, 3))
    for a in range(4):
        for k in range(3):
            Xc[a, k] = X[CCW[a], k]
            u[a, k] = w[NSTATE * CCW[a] + k]
    _evaluate_ccw(Xc, u, w[_E0:], c[0] != 0.0, tangent, f, K)
    if tangent and c[0] == SYMMETRIZED:
        symmetrize(K)


vector_kernel, matrix_kernel = tabulate_tensor_kernels(_tabulate, NDOF, NCOEF, NNODE)


@numba.njit(cache=True, inline="always")
def _tabulate_staged(w, c, X, f, K, tangent):
    """An element added undeformed when its nodes' states were A = w[NCOEF:] (staged construction,
    approach II): reference X + u_A (its constants computed there), displacements u − u_A (the
    rotations, which membranes do not use, are left out)."""
    Xc = np.empty((4, 3))
    u = np.empty((4, 3))
    for a in range(4):
        A = NCOEF + NSTATE * CCW[a]
        for k in range(3):
            Xc[a, k] = X[CCW[a], k] + w[A + k]
            u[a, k] = w[NSTATE * CCW[a] + k] - w[A + k]
    _evaluate_ccw(Xc, u, w[_E0:NCOEF], c[0] != 0.0, tangent, f, K)
    if tangent and c[0] == SYMMETRIZED:
        symmetrize(K)


# (vector_kernel, matrix_kernel) of staged elements, compiled on first use
staged_kernels = lazy_kernels(_tabulate_staged, NDOF, NCOEF + NNODE * NSTATE, NNODE)

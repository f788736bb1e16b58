r"""Four-node co-rotational shells in space: gather ► frame ► law ► scatter.

Nodal state (7 per node): displacement (3) and unit quaternion (4); element vector (24,):
(u_a, w_a) per node with spatial spins w, in DOLFINx's vertex order (0, 0), (1, 0), (0, 1),
(1, 1); the kernels work counter-clockwise (0, 1, 3, 2).

* :func:`corotational`: f = Bᵀ K̄ d̄ with the frame of :mod:`dolfinx_corot.corotation.frame_quad`
  (e₁ between the diagonals, e₃ their normal: independent of which node is numbered first) and
  the linear flat element of :mod:`dolfinx_corot.elements.shell_quad` (incompatible-mode
  membrane with drilling rotations, MITC4 bending and shear, rigid links for warping);
  consistent tangent in closed form (:func:`frame_quad.shell_force_and_tangent`).
* :func:`corotational_complex_step`: the same f, K by complex-step differentiation of f,
  node 4's columns from invariance: the reference the closed form is tested against.
* :func:`linear`: K = B₀ᵀ K̄ B₀ in the initial frame, f = K d with nodal rotation vectors.

DOLFINx kernels: ``w`` = [states (4 × 7), props (NPROPS), element constants (NEDATA)],
``c`` = [mode: 0 linear, 1 co-rotational, 2 co-rotational with the symmetric part of the
tangent], ``coords`` (4, 3).
"""
from __future__ import annotations

import numba
import numpy as np

from ..corotation import frame_quad as frame
from ..corotation.transform import stiffness
from ..elements import shallow_shell
from ..elements import shell_quad as law
from . import CCW
from .spatial import (H, SYMMETRIZED, last_node_columns, nodal_states, pack_constants, perturb,
                      rotation_vector_dofs, shallow_constants, since_activation, symmetrize, unpack_constants)
from .ufcx import lazy_kernels, tabulate_tensor_kernels

NNODE = 4
NDOF = 24
NSTATE = 7
NEDATA = 9 + 12 + 24 * 24 + shallow_shell.size(4)  # R0, x̄0, K̄, shallow-shell data (once per cell)
NCOEF = NNODE * NSTATE + law.NPROPS + NEDATA
_P0 = NNODE * NSTATE
_E0 = _P0 + law.NPROPS


@numba.njit(cache=True)
def element_data(X, props, out):
    """out (NEDATA,) = (R0, x̄0, K̄) of the element with counter-clockwise nodes X (4, 3)."""
    R0 = np.empty((3, 3))
    xbar0 = np.empty((4, 3))
    frame.initial(X, R0, xbar0)
    K = np.empty((24, 24))
    law.local_stiffness(xbar0, props, K)
    pack_constants(R0, xbar0, K, out)
    law.shallow_data(xbar0, props, out[9 + 12 + 24 * 24:])


@numba.njit(cache=True)
def element_data_all(X, props, linear, active, out):
    """element_data for every active cell; X (n, 4, 3) in DOLFINx vertex order (linear: unused,
    the triangles' signature: every edge of a quadrilateral is linear)."""
    Xc = np.empty((4, 3))
    for c in range(X.shape[0]):
        if active[c]:
            for a in range(4):
                Xc[a] = X[c, CCW[a]]
            element_data(Xc, props[c], out[c])


@numba.njit(cache=True)
def _counter_clockwise(X, S):
    """(X (4, 3), S (4, 7)) counter-clockwise from DOLFINx's vertex order."""
    Xc = np.empty((4, 3))
    Sc = np.empty((4, NSTATE))
    for a in range(4):
        Xc[a] = X[CCW[a]]
        Sc[a] = S[CCW[a]]
    return Xc, Sc


@numba.njit(cache=True)
def corotational_ccw(Xc, Sc, edata, f, K, tangent=True):
    """f (24,) and, with tangent, K (24, 24) of the counter-clockwise element (closed form)."""
    R0, xbar0, Kbar = unpack_constants(edata, 4, 24)
    u = np.empty((4, 3))
    R = np.empty((4, 3, 3))
    nodal_states(Sc, u, R)
    sdata = shallow_constants(edata, 4, 24)
    if tangent:
        frame.shell_force_and_tangent(Xc, u, R, R0, xbar0, Kbar, sdata, f, K)
    else:
        frame.shell_force(Xc, u, R, R0, xbar0, Kbar, sdata, f)


@numba.njit(cache=True)
def complex_step_ccw(Xc, Sc, edata, f, K):
    """:func:`corotational_ccw` with K by complex-step differentiation of f (18 evaluations;
    node 4's columns from translation and rotation invariance)."""
    R0, xbar0, Kbar = unpack_constants(edata, 4, 24)
    u = np.empty((4, 3))
    R = np.empty((4, 3, 3))
    nodal_states(Sc, u, R)
    sdata = shallow_constants(edata, 4, 24)
    frame.shell_force(Xc, u, R, R0, xbar0, Kbar, sdata, f)
    uc = u.astype(np.complex128)
    Rc = R.astype(np.complex128)
    up = np.empty_like(uc)
    Rp = np.empty_like(Rc)
    fc = np.empty(24, dtype=np.complex128)
    for j in range(18):
        perturb(uc, Rc, j, up, Rp)
        frame.shell_force(Xc, up, Rp, R0, xbar0, Kbar, sdata, fc)
        for i in range(24):
            K[i, j] = fc[i].imag / H
    last_node_columns(f, Xc, u, K)


@numba.njit(cache=True)
def linear_ccw(Xc, Sc, edata, f, K):
    """Geometrically linear shell in the initial frame: K = B₀ᵀ K̄ B₀, f = K d."""
    R0, xbar0, Kbar = unpack_constants(edata, 4, 24)
    R = np.empty((4, 3, 3))
    for a in range(4):
        R[a] = np.eye(3)
    dbar = np.empty(24)
    B = np.empty((24, 24))
    frame.shell_basic(Xc, np.zeros((4, 3)), R, R0, xbar0, dbar, B)
    stiffness(B, Kbar, K, 24, 24)
    d = np.empty(24)
    rotation_vector_dofs(Sc, d)
    f[:] = K @ d


@numba.njit(cache=True)
def _to_dolfinx(fc, Kc, f, K, tangent):
    """f, K in DOLFINx's vertex order from the counter-clockwise fc, Kc."""
    for a in range(4):
        A = CCW[a]
        for k in range(6):
            f[6 * A + k] = fc[6 * a + k]
            if tangent:
                for b in range(4):
                    Bn = CCW[b]
                    for m in range(6):
                        K[6 * A + k, 6 * Bn + m] = Kc[6 * a + k, 6 * b + m]


@numba.njit(cache=True)
def evaluate_ccw(Xc, Sc, props, edata, mode, tangent, f, K):
    """f, K (DOLFINx order) of the element with counter-clockwise X, S; mode as c[0]."""
    fc = np.empty(24)
    Kc = np.empty((24, 24))
    if mode == 0.0:
        linear_ccw(Xc, Sc, edata, fc, Kc)
    else:
        corotational_ccw(Xc, Sc, edata, fc, Kc, tangent)
        if tangent and mode == SYMMETRIZED:
            symmetrize(Kc)
    _to_dolfinx(fc, Kc, f, K, tangent)


@numba.njit(cache=True)
def evaluate(X, S, props, large_rotations, f, K):
    """f (24,), K (24, 24) of one element from its nodes X (4, 3) and states S (4, 7) in
    DOLFINx's vertex order."""
    Xc, Sc = _counter_clockwise(X, S)
    edata = np.empty(NEDATA)
    element_data(Xc, props, edata)
    evaluate_ccw(Xc, Sc, props, edata, 1.0 if large_rotations else 0.0, True, f, K)


@numba.njit(cache=True)
def evaluate_complex_step(X, S, props, f, K):
    """:func:`evaluate` (co-rotational) with the complex-step tangent."""
    Xc, Sc = _counter_clockwise(X, S)
    edata = np.empty(NEDATA)
    element_data(Xc, props, edata)
    fc = np.empty(24)
    Kc = np.empty((24, 24))
    complex_step_ccw(Xc, Sc, edata, fc, Kc)
    _to_dolfinx(fc, Kc, f, K, True)


@numba.njit(cache=True)
def _mises_plane(sxx, syy, sxy):
    return np.sqrt(max(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy, 0.0))


@numba.njit(cache=True)
def resultants(X, S, props, large_rotations, out, axes):
    """out (16,) = :data:`dolfinx_corot.kernels.RESULTANTS` of one element (X (4, 3), S (4, 7) in
    DOLFINx's vertex order) at its centre, per unit length, in its current frame (e₁ between the
    diagonals, e₃ the normal; the initial frame in a geometrically linear analysis): N, M = ∫σz dz
    and the MITC4 shear Q (see :func:`dolfinx_corot.elements.shell_quad.centre_resultants`), the
    face stresses σ = N/t ± 6M/t² and their von Mises values. axes (3, 3): rows e1, e2, e3."""
    Xc, Sc = _counter_clockwise(X, S)
    edata = np.empty(NEDATA)
    element_data(Xc, props, edata)
    R0, xbar0, _ = unpack_constants(edata, 4, 24)
    u = np.empty((4, 3))
    R = np.empty((4, 3, 3))
    nodal_states(Sc, u, R)
    dbar = np.empty(24)
    B = np.empty((24, 24))
    if large_rotations:
        Rr, _, _, _, _, _, d = frame.shell_parts(Xc, u, R, R0, xbar0)
        dbar[:] = d
        axes[:, :] = Rr.T
    else:
        for a in range(4):
            R[a] = np.eye(3)
        frame.shell_basic(Xc, np.zeros((4, 3)), R, R0, xbar0, np.empty(24), B)
        d = np.empty(24)
        rotation_vector_dofs(Sc, d)
        dbar[:] = B @ d
        axes[:, :] = R0.T
    out[:] = 0.0
    law.centre_resultants(xbar0, props, dbar, out)
    if large_rotations:  # the shallow-shell strain: N += A η̄, M += B η̄
        eta = shallow_shell.mean_strain(dbar, shallow_constants(edata, 4, 24), 4)
        out[0:3] += props[law.A0:law.A0 + 9].copy().reshape(3, 3) @ eta
        out[3:6] += props[law.B0:law.B0 + 9].copy().reshape(3, 3) @ eta
    t = props[law.T]
    for side in range(2):
        z = 1.0 if side == 0 else -1.0
        sig = out[0:3] / t + z * 6.0 * out[3:6] / (t * t)
        out[8 + 3 * side:11 + 3 * side] = sig
        out[14 + side] = _mises_plane(sig[0], sig[1], sig[2])


@numba.njit(cache=True)
def resultants_all(X, S, props, large_rotations, out, axes):
    """:func:`resultants` of every element: X (n, 4, 3), S (n, 4, 7) → out (n, 16), axes (n, 3, 3)."""
    for e in range(X.shape[0]):
        resultants(X[e], S[e], props[e], large_rotations, out[e], axes[e])


@numba.njit(cache=True, inline="always")
def _tabulate(w, c, X, f, K, tangent):
    """The element function of the DOLFINx kernels (see :mod:`.ufcx`)."""
    Xc = np.empty((4, 3))
    Sc = np.empty((4, NSTATE))
    for a in range(4):
        for k in range(3):
            Xc[a, k] = X[CCW[a], k]
        for k in range(NSTATE):
            Sc[a, k] = w[NSTATE * CCW[a] + k]
    evaluate_ccw(Xc, Sc, w[_P0:_E0], w[_E0:], c[0], tangent, f, K)


vector_kernel, matrix_kernel = tabulate_tensor_kernels(_tabulate, NDOF, NCOEF, NNODE)


@numba.njit(cache=True, inline="always")
def _tabulate_staged(w, c, X, f, K, tangent):
    """An element added undeformed when its nodes' states were A = w[NCOEF:] (staged construction,
    approach II): reference X + u_A (its constants computed there), states since then
    (u − u_A, R R_Aᵀ)."""
    Xa, Sa = since_activation(X, w[:_P0].reshape(NNODE, NSTATE), w[NCOEF:NCOEF + _P0].reshape(NNODE, NSTATE))
    Xc, Sc = _counter_clockwise(Xa, Sa)
    evaluate_ccw(Xc, Sc, w[_P0:_E0], w[_E0:NCOEF], c[0], tangent, f, K)


# (vector_kernel, matrix_kernel) of staged elements, compiled on first use
staged_kernels = lazy_kernels(_tabulate_staged, NDOF, NCOEF + NNODE * NSTATE, NNODE)

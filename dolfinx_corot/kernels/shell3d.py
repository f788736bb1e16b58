r"""Three-node flat shells in space: gather ► frame ► law ► scatter.

Nodal state (7 per node): displacement (3) and unit quaternion (4); element
vector (18): (u_a, w_a) per node with spatial spins w.

* :func:`corotational`: f = Bᵀ K̄ d̄ with the frame of
  :mod:`dolfinx_corot.corotation.frame_triangle` and the linear flat
  triangle of :mod:`dolfinx_corot.elements.shell_triangle` (element-independent
  co-rotational formulation); consistent tangent K = ∂f/∂d in closed form
  (:func:`frame_triangle.force_and_tangent`, 8 µs per element).
* :func:`corotational_complex_step`: the same f with K by complex-step
  differentiation (:func:`dolfinx_corot.kernels.spatial.perturb`); node 3's
  columns follow exactly from translation and rotation invariance of f (12
  complex evaluations, 60 µs): the reference against which the closed form
  is tested.
* :func:`linear`: K = B₀ᵀ K̄ B₀ in the initial frame, f = K d with nodal
  rotation vectors (no co-rotational work).

DOLFINx kernels (:data:`vector_kernel`, :data:`matrix_kernel`, from
:func:`dolfinx_corot.kernels.ufcx.tabulate_tensor_kernels`): ``w`` = [states
(3 × 7), props (NPROPS), element constants (NEDATA, see :func:`element_data`)],
``c`` = [mode: 0 linear, 1 co-rotational, 2 co-rotational with the symmetric part of the
tangent], ``coords`` (3, 3). The residual of a co-rotational
analysis is f = Bᵀ K̄ d̄ alone.
"""
from __future__ import annotations

import numba
import numpy as np

from ..corotation import frame_triangle as frame
from ..corotation.transform import stiffness
from ..elements import shallow_shell
from ..elements import shell_triangle as law
from .spatial import (H, SYMMETRIZED, last_node_columns, nodal_states, pack_constants, perturb,
                      rotation_vector_dofs, shallow_constants, since_activation, symmetrize, unpack_constants)
from . import RESULTANTS  # the names of resultants()' components
from .ufcx import lazy_kernels, tabulate_tensor_kernels

NDOF = 18
NSTATE = 7
NSHALLOW = shallow_shell.size(3)
NEDATA = 9 + 9 + 18 * 18 + NSHALLOW  # per-cell constants: R0, x̄0, K̄, shallow-shell data (once per cell)
NCOEF = 3 * NSTATE + law.NPROPS + NEDATA
_P0 = 3 * NSTATE
_E0 = 3 * NSTATE + law.NPROPS


@numba.njit(cache=True)
def _force(X, u, R, R0, xbar0, Kbar, sdata, f, rotations):
    """f (18,) = Bᵀ f̄(d̄) at the given configuration (real or complex)."""
    frame.internal_force(X, u, R, R0, xbar0, Kbar, sdata, f, rotations)


@numba.njit(cache=True)
def _setup(X, props, linear):
    R0 = np.empty((3, 3))
    xbar0 = np.empty((3, 3))
    frame.initial(X, R0, xbar0)
    Kbar = np.empty((18, 18))
    xy = np.ascontiguousarray(xbar0[:, :2])
    law.local_stiffness_edges(xy, props, Kbar, linear)
    sdata = np.empty(NSHALLOW)
    law.shallow_data(xy, props, sdata)
    return R0, xbar0, Kbar, sdata


@numba.njit(cache=True)
def element_data(X, props, out):
    """The constants of one element, out (NEDATA,) = (R0, x̄0, K̄, shallow-shell data) flattened
    (computed once per cell)."""
    element_data_edges(X, props, np.zeros(3), out)


@numba.njit(cache=True)
def element_data_edges(X, props, linear, out):
    """:func:`element_data` with the OPT's edges (1–2, 2–3, 3–1) where ``linear`` is nonzero
    kept linear (:func:`dolfinx_corot.elements.shell_triangle.opt_membrane_edges`)."""
    R0, xbar0, Kbar, sdata = _setup(X, props, linear)
    pack_constants(R0, xbar0, Kbar, out)
    out[9 + 9 + 18 * 18:] = sdata


@numba.njit(cache=True)
def element_data_all(X, props, linear, active, out):
    """element_data for every cell c with active[c]: X (n, 3, 3), props (n, NPROPS), linear
    (n, 3) the edges kept linear (:func:`element_data_edges`), out (n, NEDATA)."""
    for c in range(X.shape[0]):
        if active[c]:
            element_data_edges(X[c], props[c], linear[c], out[c])


@numba.njit(cache=True)
def corotational(X, S, props, f, K):
    """X (3, 3) initial nodes, S (3, 7) nodal states → f (18,), K (18, 18) (closed-form tangent)."""
    edata = np.empty(NEDATA)
    element_data(X, props, edata)
    corotational_cached(X, S, props, edata, f, K)


@numba.njit(cache=True)
def corotational_cached(X, S, props, edata, f, K, tangent=True):
    """:func:`corotational` with the element constants given (see :func:`element_data`);
    with tangent False, f alone (f = Bᵀ K̄ d̄, K untouched)."""
    R0, xbar0, Kbar = unpack_constants(edata, 3, 18)
    sdata = shallow_constants(edata, 3, 18)
    u = np.empty((3, 3))
    R = np.empty((3, 3, 3))
    nodal_states(S, u, R)
    rotations = props[law.BENDING] != 0.0
    if tangent:
        frame.force_and_tangent(X, u, R, R0, xbar0, Kbar, sdata, f, K, rotations)
    else:
        _force(X, u, R, R0, xbar0, Kbar, sdata, f, rotations)


@numba.njit(cache=True)
def corotational_complex_step(X, S, props, f, K):
    """X (3, 3) initial nodes, S (3, 7) nodal states → f (18,), K (18, 18) (complex-step tangent)."""
    R0, xbar0, Kbar, sdata = _setup(X, props, np.zeros(3))
    u = np.empty((3, 3))
    R = np.empty((3, 3, 3))
    nodal_states(S, u, R)
    rotations = props[law.BENDING] != 0.0
    _force(X, u, R, R0, xbar0, Kbar, sdata, f, rotations)
    uc = u.astype(np.complex128)
    Rc = R.astype(np.complex128)
    up = np.empty_like(uc)
    Rp = np.empty_like(Rc)
    fc = np.empty(18, dtype=np.complex128)
    for j in range(12):  # nodes 1 and 2; node 3 follows from invariance
        perturb(uc, Rc, j, up, Rp)
        _force(X, up, Rp, R0, xbar0, Kbar, sdata, fc, rotations)
        for i in range(18):
            K[i, j] = fc[i].imag / H
    last_node_columns(f, X, u, K)


@numba.njit(cache=True)
def linear(X, S, props, edata, f, K):
    """Geometrically linear flat shell in the initial frame: K = B₀ᵀ K̄ B₀, f = K d."""
    R0, xbar0, Kbar = unpack_constants(edata, 3, 18)
    u = np.zeros((3, 3))
    R = np.empty((3, 3, 3))
    for a in range(3):
        R[a] = np.eye(3)
    dbar = np.empty(18)
    B = np.empty((18, 18))
    frame.basic(X, u, R, R0, xbar0, dbar, B, props[law.BENDING] != 0.0)
    stiffness(B, Kbar, K, 18, 18)
    d = np.empty(18)
    rotation_vector_dofs(S, d)
    f[:] = K @ d


@numba.njit(cache=True)
def evaluate_cached(X, S, props, edata, large_rotations, f, K):
    """f and K of one element whose constants edata are given (see :func:`element_data`)."""
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


@numba.njit(cache=True)
def _mises_plane(sxx, syy, sxy):
    return np.sqrt(max(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy, 0.0))


@numba.njit(cache=True)
def resultants(X, S, props, edata, large_rotations, out, axes):
    """out (16,) = :data:`RESULTANTS` of one element in its current frame (e1 along side 1–2, e3
    its normal; the initial frame for a geometrically linear analysis), per unit length:

    * membrane forces N = t D ε̄ with ε̄ the mean (constant-strain) membrane strain of the
      deformational displacements;
    * moments M = ∫ σ z dz = −D_b κ at the centroid (κ = (w,xx, w,yy, 2w,xy) of the DKT);
    * transverse shears from equilibrium, Qx = Mxx,x + Mxy,y, Qy = Mxy,x + Myy,y (the DKT
      moments vary linearly over the element);
    * stresses on the top (z = +t/2, the e3 side) and bottom faces, σ = N/t ± 6M/t², and
      their von Mises values (plane stress).

    axes (3, 3): rows e1, e2, e3 of that frame.
    """
    R0, xbar0, Kbar = unpack_constants(edata, 3, 18)
    bending = props[law.BENDING] != 0.0
    u = np.empty((3, 3))
    R = np.empty((3, 3, 3))
    nodal_states(S, u, R)
    dbar = np.empty(18)
    if large_rotations:
        Rr, _, _, _, _, _, _, _, _, d = frame.parts(X, u, R, R0, xbar0, bending)
        dbar[:] = d
        axes[:, :] = Rr.T
    else:  # d̄ = B₀ d in the initial frame
        B = np.empty((18, 18))
        for a in range(3):
            R[a] = np.eye(3)
        frame.basic(X, np.zeros((3, 3)), R, R0, xbar0, np.empty(18), B, bending)
        d = np.empty(18)
        rotation_vector_dofs(S, d)
        dbar[:] = B @ d
        axes[:, :] = R0.T
    xy = np.ascontiguousarray(xbar0[:, :2])
    t = props[law.T]
    Am = props[law.A0:law.A0 + 9].copy().reshape(3, 3)
    Bc = props[law.B0:law.B0 + 9].copy().reshape(3, 3)
    Db = props[law.D0:law.D0 + 9].copy().reshape(3, 3)
    Bm, _ = law.membrane_B(xy)
    uv = np.array([dbar[0], dbar[1], dbar[6], dbar[7], dbar[12], dbar[13]])
    eps = Bm @ uv
    if large_rotations:  # the shallow-shell strain (membrane forces A ε, moments B ε)
        eps = eps + shallow_shell.mean_strain(dbar, shallow_constants(edata, 3, 18), 3)
    N = Am @ eps
    out[:] = 0.0
    M = np.zeros(3)
    if bending:  # κ = −(the DKT's curvature of the slopes)
        wt = np.array([dbar[2], dbar[3], dbar[4], dbar[8], dbar[9], dbar[10], dbar[14], dbar[15], dbar[16]])
        kap = -(law.bending_B(xy, 1.0 / 3.0, 1.0 / 3.0) @ wt)
        N = N + Bc @ kap
        M = Bc @ eps + Db @ kap
        M0 = -(Db @ (law.bending_B(xy, 0.0, 0.0) @ wt))
        dxi = -(Db @ (law.bending_B(xy, 1.0, 0.0) @ wt)) - M0
        deta = -(Db @ (law.bending_B(xy, 0.0, 1.0) @ wt)) - M0
        # ∂/∂x, ∂/∂y = J⁻¹ (∂/∂ξ, ∂/∂η), J = [[x2 − x1, y2 − y1], [x3 − x1, y3 − y1]]
        j00, j01 = xy[1, 0] - xy[0, 0], xy[1, 1] - xy[0, 1]
        j10, j11 = xy[2, 0] - xy[0, 0], xy[2, 1] - xy[0, 1]
        det = j00 * j11 - j01 * j10
        dx = (j11 * dxi - j01 * deta) / det
        dy = (-j10 * dxi + j00 * deta) / det
        out[3:6] = M
        out[6] = dx[0] + dy[2]
        out[7] = dx[2] + dy[1]
    out[0:3] = N
    for side in range(2):
        z = 1.0 if side == 0 else -1.0
        sig = N / t + z * 6.0 * M / (t * t)
        out[8 + 3 * side:11 + 3 * side] = sig
        out[14 + side] = _mises_plane(sig[0], sig[1], sig[2])


@numba.njit(cache=True)
def resultants_all(X, S, props, large_rotations, out, axes):
    """:func:`resultants` of every element: X (n, 3, 3), S (n, 3, 7) → out (n, 16), axes (n, 3, 3)."""
    edata = np.empty(NEDATA)
    for e in range(X.shape[0]):
        element_data(X[e], props[e], edata)
        resultants(X[e], S[e], props[e], edata, large_rotations, out[e], axes[e])


@numba.njit(cache=True, inline="always")
def _tabulate(w, c, X, f, K, tangent):
    """The element function of the DOLFINx kernels (see :mod:`.ufcx`)."""
    S = w[:_P0].reshape(3, NSTATE)
    props = w[_P0:_E0]
    edata = w[_E0:]
    if c[0] == 0.0:
        linear(X, S, props, edata, f, K)
    else:
        corotational_cached(X, S, props, edata, f, K, tangent)
        if tangent and c[0] == SYMMETRIZED:
            symmetrize(K)


vector_kernel, matrix_kernel = tabulate_tensor_kernels(_tabulate, NDOF, NCOEF, 3)


@numba.njit(cache=True, inline="always")
def _tabulate_staged(w, c, X, f, K, tangent):
    """An element added undeformed when its nodes' states were A = w[NCOEF:] (staged construction,
    approach II): reference X + u_A (its constants computed there), states since then
    (u − u_A, R R_Aᵀ)."""
    Xa, Sa = since_activation(X, w[:_P0].reshape(3, NSTATE), w[NCOEF:NCOEF + 3 * NSTATE].reshape(3, NSTATE))
    props = w[_P0:_E0]
    edata = w[_E0:NCOEF]
    if c[0] == 0.0:
        linear(Xa, Sa, props, edata, f, K)
    else:
        corotational_cached(Xa, Sa, props, edata, f, K, tangent)
        if tangent and c[0] == SYMMETRIZED:
            symmetrize(K)


# (vector_kernel, matrix_kernel) of staged elements, compiled on first use
staged_kernels = lazy_kernels(_tabulate_staged, NDOF, NCOEF + 3 * NSTATE, 3)

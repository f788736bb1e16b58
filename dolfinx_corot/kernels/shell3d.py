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
``c`` = [large_rotations], ``coords`` (3, 3). The residual of a co-rotational
analysis is f = Bᵀ K̄ d̄ alone.
"""
from __future__ import annotations

import numba
import numpy as np

from ..corotation import frame_triangle as frame
from ..corotation.transform import linear_force, stiffness
from ..elements import shell_triangle as law
from .spatial import (H, last_node_columns, nodal_states, pack_constants, perturb, rotation_vector_dofs,
                      since_activation, unpack_constants)
from .ufcx import lazy_kernels, tabulate_tensor_kernels

NDOF = 18
NSTATE = 7
NEDATA = 9 + 9 + 18 * 18  # per-cell constants: R0, x̄0, K̄ (computed once, see element_data)
NCOEF = 3 * NSTATE + law.NPROPS + NEDATA
_P0 = 3 * NSTATE
_E0 = 3 * NSTATE + law.NPROPS


@numba.njit(cache=True)
def _force(X, u, R, R0, xbar0, Kbar, f, rotations):
    """f (18,) = Bᵀ K̄ d̄ at the given configuration (real or complex)."""
    dt = u.dtype
    dbar = np.empty(18, dtype=dt)
    B = np.empty((18, 18), dtype=dt)
    frame.basic(X, u, R, R0, xbar0, dbar, B, rotations)
    fbar = np.empty(18, dtype=dt)
    linear_force(B, Kbar, dbar, fbar, f, 18, 18)


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
    pack_constants(R0, xbar0, Kbar, out)


@numba.njit(cache=True)
def element_data_all(X, props, active, out):
    """element_data for every cell c with active[c]: X (n, 3, 3), props (n, NPROPS), out (n, NEDATA)."""
    for c in range(X.shape[0]):
        if active[c]:
            element_data(X[c], props[c], out[c])


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
    u = np.empty((3, 3))
    R = np.empty((3, 3, 3))
    nodal_states(S, u, R)
    rotations = props[law.BENDING] != 0.0
    if tangent:
        frame.force_and_tangent(X, u, R, R0, xbar0, Kbar, f, K, rotations)
    else:
        _force(X, u, R, R0, xbar0, Kbar, f, rotations)


@numba.njit(cache=True)
def corotational_complex_step(X, S, props, f, K):
    """X (3, 3) initial nodes, S (3, 7) nodal states → f (18,), K (18, 18) (complex-step tangent)."""
    R0, xbar0, Kbar = _setup(X, props)
    u = np.empty((3, 3))
    R = np.empty((3, 3, 3))
    nodal_states(S, u, R)
    rotations = props[law.BENDING] != 0.0
    _force(X, u, R, R0, xbar0, Kbar, f, rotations)
    uc = u.astype(np.complex128)
    Rc = R.astype(np.complex128)
    up = np.empty_like(uc)
    Rp = np.empty_like(Rc)
    fc = np.empty(18, dtype=np.complex128)
    for j in range(12):  # nodes 1 and 2; node 3 follows from invariance
        perturb(uc, Rc, j, up, Rp)
        _force(X, up, Rp, R0, xbar0, Kbar, fc, rotations)
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


# (vector_kernel, matrix_kernel) of staged elements, compiled on first use
staged_kernels = lazy_kernels(_tabulate_staged, NDOF, NCOEF + 3 * NSTATE, 3)

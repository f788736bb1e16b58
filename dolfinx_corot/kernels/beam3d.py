r"""Two-node beams and bars in space: gather ► frame ► law ► scatter.

Nodal state (7 per node): displacement (3) and unit quaternion (4) of the
nodal rotation; element vector (12): (u₁, w₁, u₂, w₂) with spatial spins w.

* :func:`corotational`: f = Bᵀ f̄ from :mod:`dolfinx_corot.corotation.frame3d`
  and :mod:`dolfinx_corot.elements.beam3d`; the consistent tangent
  K = ∂f/∂d = Bᵀ K̄ B + ∂Bᵀ/∂d : f̄ in closed form
  (:func:`~dolfinx_corot.corotation.frame3d.add_geometric_stiffness`), 5 µs an element
  against 20 µs for its complex-step derivative, :func:`corotational_complex_step`
  (:func:`dolfinx_corot.kernels.spatial.perturb`; the six columns of node 1 differentiated,
  those of node 2 from translation and rotation invariance of f), which the tests compare it to.
* :func:`linear`: K = B₀ᵀ K̄ B₀ in the initial frame, f = K d with the nodal
  rotation vectors log(R_i) (no co-rotational work).

DOLFINx kernels (:data:`vector_kernel`, :data:`matrix_kernel`, from
:func:`dolfinx_corot.kernels.ufcx.tabulate_tensor_kernels`): ``w`` =
[state node 1 (7), state node 2 (7), props (NPROPS)], ``c`` =
[mode: 0 linear, 1 co-rotational, 2 co-rotational with the symmetric part of the
tangent], ``coords`` (2, 3). The residual of a co-rotational
analysis needs the force only.
"""
from __future__ import annotations

import numba
import numpy as np

from ..corotation import frame3d
from ..corotation.transform import force, stiffness
from ..elements import beam3d as law
from .spatial import (H, SYMMETRIZED, last_node_columns, nodal_states, perturb, rotation_vector_dofs,
                      since_activation, symmetrize)
from .ufcx import lazy_kernels, tabulate_tensor_kernels

NDOF = 12
NSTATE = 7
NCOEF = 2 * NSTATE + law.NPROPS


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
    force(B, fbar, f, 7, 12)


@numba.njit(cache=True)
def _corotational(X, S, props, f, K, tangent):
    """:func:`corotational` on the element's X (2, 3) and S (2, 7); K only if tangent: the closed
    form Bᵀ K̄ B + ∂Bᵀ/∂d : f̄ (:func:`~dolfinx_corot.corotation.frame3d.add_geometric_stiffness`)."""
    # (few allocations: an element kernel's time goes largely into them otherwise)
    frames = np.empty((4, 3, 3))  # R0, Rr, the nodal rotations
    vectors = np.empty((6, 3))    # θ̄1, θ̄2, p1, p2, u1, u2
    rows = np.empty((10, 12))     # B, Gᵀ
    R0, Rr, R = frames[0], frames[1], frames[2:]
    th1, th2, p1, p2, u = vectors[0], vectors[1], vectors[2], vectors[3], vectors[4:]
    B, GT = rows[:7], rows[7:]
    l0 = frame3d.initial_frame(X[0], X[1], props[law.VX:law.VZ + 1], R0)
    nodal_states(S, u, R)
    Ti = np.empty((2, 3, 3))
    ubar, l = frame3d.frame_and_basic(X[0], X[1], u[0], u[1], R[0], R[1], R0, l0, th1, th2, B, Rr, p1, p2, GT, Ti)
    fbar = np.empty(7)
    law.basic_force(l0, ubar, th1, th2, props, True, fbar)
    force(B, fbar, f, 7, 12)
    if not tangent:
        return
    kbar = np.empty((7, 7))
    law.basic_stiffness(l0, ubar, th1, th2, props, True, kbar)
    stiffness(B, kbar, K, 7, 12)
    frame3d.add_geometric_stiffness(l, Rr, p1, p2, GT, Ti, th1, th2, B, fbar, K)


@numba.njit(cache=True)
def corotational_complex_step(X1, X2, s1, s2, props, f, K):
    """:func:`corotational` with K by complex-step differentiation of f (the closed form's check):
    the six columns of node 1 by complex steps, those of node 2 from invariance."""
    X, S = _element(X1, X2, s1, s2)
    R0 = np.empty((3, 3))
    l0 = frame3d.initial_frame(X[0], X[1], props[law.VX:law.VZ + 1], R0)
    u = np.empty((2, 3))
    R = np.empty((2, 3, 3))
    nodal_states(S, u, R)
    _force(X[0], X[1], u[0], u[1], R[0], R[1], R0, l0, props, f)
    uc = u.astype(np.complex128)
    Rc = R.astype(np.complex128)
    up = np.empty_like(uc)
    Rp = np.empty_like(Rc)
    fc = np.empty(12, dtype=np.complex128)
    for j in range(6):  # node 1; node 2 follows from invariance
        perturb(uc, Rc, j, up, Rp)
        _force(X[0], X[1], up[0], up[1], Rp[0], Rp[1], R0, l0, props, fc)
        for i in range(12):
            K[i, j] = fc[i].imag / H
    last_node_columns(f, X, u, K)


@numba.njit(cache=True)
def _linear(X, S, props, f, K):
    """:func:`linear` on the element's X (2, 3) and S (2, 7)."""
    R0 = np.empty((3, 3))
    l0 = frame3d.initial_frame(X[0], X[1], props[law.VX:law.VZ + 1], R0)
    I3 = np.eye(3)
    th1 = np.empty(3)
    th2 = np.empty(3)
    B = np.empty((7, 12))
    frame3d.basic(X[0], X[1], np.zeros(3), np.zeros(3), I3, I3, R0, l0, th1, th2, B)
    kbar = np.empty((7, 7))
    law.basic_stiffness_linear(l0, props, kbar)
    stiffness(B, kbar, K, 7, 12)
    d = np.empty(12)
    rotation_vector_dofs(S, d)
    f[:] = K @ d
    for i in range(12):
        f[i] += B[0, i] * props[law.N0]


@numba.njit(cache=True)
def _evaluate(X, S, props, large_rotations, tangent, f, K):
    if large_rotations:
        _corotational(X, S, props, f, K, tangent)
    else:
        _linear(X, S, props, f, K)


@numba.njit(cache=True)
def _element(X1, X2, s1, s2):
    """X (2, 3) and S (2, 7) of one element from its nodes."""
    X = np.empty((2, 3))
    X[0] = X1
    X[1] = X2
    S = np.empty((2, NSTATE))
    S[0] = s1
    S[1] = s2
    return X, S


@numba.njit(cache=True)
def corotational(X1, X2, s1, s2, props, f, K):
    """Co-rotational element: s1, s2 nodal states (7,); fills f (12,) and K (12, 12)."""
    X, S = _element(X1, X2, s1, s2)
    _corotational(X, S, props, f, K, True)


@numba.njit(cache=True)
def linear(X1, X2, s1, s2, props, f, K):
    """Geometrically linear element in the initial frame: K = B₀ᵀ K̄ B₀, f = K d + B₀ᵀ f̄₀."""
    X, S = _element(X1, X2, s1, s2)
    _linear(X, S, props, f, K)


@numba.njit(cache=True)
def evaluate(X1, X2, s1, s2, props, large_rotations, f, K):
    """f (12,) and K (12, 12) of one element: co-rotational or geometrically linear."""
    X, S = _element(X1, X2, s1, s2)
    _evaluate(X, S, props, large_rotations, True, f, K)


@numba.njit(cache=True)
def evaluate_all(X, S, props, large_rotations, F, K):
    """All elements: X (n, 2, 3), S (n, 2, 7), props (n, NPROPS) → F (n, 12), K (n, 12, 12)."""
    for e in range(X.shape[0]):
        _evaluate(X[e], S[e], props[e], large_rotations, True, F[e], K[e])


@numba.njit(cache=True)
def section_forces(X, S, props, large_rotations, out, axes):
    """out (2, 6): the section forces (N, Vy, Vz, T, My, Mz) at ends 1 and 2 of one element, in its
    current axes (the initial ones for a geometrically linear analysis): the resultants on the
    cross-section's face whose outward normal is +e1, i.e. −Rᵀf₁ at end 1 and +Rᵀf₂ at end 2 of the
    nodal forces f the element exerts (N > 0 in tension); axes (3, 3): rows e1, e2, e3."""
    f = np.empty(12)
    K = np.empty((12, 12))
    _evaluate(X, S, props, large_rotations, False, f, K)
    R0 = np.empty((3, 3))
    frame3d.initial_frame(X[0], X[1], props[law.VX:law.VZ + 1], R0)
    Rr = R0
    if large_rotations:
        u = np.empty((2, 3))
        R = np.empty((2, 3, 3))
        nodal_states(S, u, R)
        Rr = np.empty((3, 3))
        frame3d.current_frame(X[0], X[1], u[0], u[1], R[0], R[1], R0, Rr, np.empty(3), np.empty(3))
    for a in range(2):
        sign = -1.0 if a == 0 else 1.0
        for i in range(3):
            F = 0.0
            M = 0.0
            for k in range(3):
                F += Rr[k, i] * f[6 * a + k]
                M += Rr[k, i] * f[6 * a + 3 + k]
            out[a, i] = sign * F
            out[a, 3 + i] = sign * M
    axes[:, :] = Rr.T


@numba.njit(cache=True)
def section_forces_all(X, S, props, large_rotations, out, axes):
    """:func:`section_forces` of every element: X (n, 2, 3), S (n, 2, 7) → out (n, 2, 6), axes (n, 3, 3)."""
    for e in range(X.shape[0]):
        section_forces(X[e], S[e], props[e], large_rotations, out[e], axes[e])


@numba.njit(cache=True)
def _follower_force(X, u, R, R0, q, bending, f):
    """f (12,) the nodal loads of a uniform load q (3,) per current length given in the element's
    current axes (e1 along the chord, e2, e3 of the nodal rotations, as the element's frame) on
    the element X (2, 3) at u (2, 3), R (2, 3, 3): half of q l at each node, and for a beam the
    end moments ±(l²/12) e1 × q of a uniform span load. Real or complex (complex step)."""
    dt = u.dtype
    Rr = np.empty((3, 3), dtype=dt)
    l = frame3d.current_frame(X[0], X[1], u[0], u[1], R[0], R[1], R0, Rr,
                              np.empty(3, dtype=dt), np.empty(3, dtype=dt))
    g = Rr @ q.astype(dt)  # the load per length in global axes
    e1 = Rr[:, 0]
    m = np.empty(3, dtype=dt)
    m[0] = e1[1] * g[2] - e1[2] * g[1]
    m[1] = e1[2] * g[0] - e1[0] * g[2]
    m[2] = e1[0] * g[1] - e1[1] * g[0]
    for k in range(3):
        f[k] = f[6 + k] = 0.5 * l * g[k]
        f[3 + k] = l * l / 12.0 * bending * m[k]
        f[9 + k] = -f[3 + k]


@numba.njit(cache=True)
def follower_loads(X, S, props, q, bending, f, K):
    """:func:`_follower_force` of one element (X (2, 3), S (2, 7), props: its orientation vector)
    into f (12,), and K (12, 12) = ∂f/∂d over the translations and the rotation increments
    (R ← exp(δθ) R), by complex-step differentiation."""
    R0 = np.empty((3, 3))
    frame3d.initial_frame(X[0], X[1], props[law.VX:law.VZ + 1], R0)
    u = np.empty((2, 3))
    R = np.empty((2, 3, 3))
    nodal_states(S, u, R)
    fc = np.empty(12, dtype=np.complex128)
    _follower_force(X, u.astype(np.complex128), R.astype(np.complex128), R0, q, bending, fc)
    f[:] = fc.real
    up = np.empty((2, 3), dtype=np.complex128)
    Rp = np.empty((2, 3, 3), dtype=np.complex128)
    for j in range(12):
        perturb(u.astype(np.complex128), R.astype(np.complex128), j, up, Rp)
        _follower_force(X, up, Rp, R0, q, bending, fc)
        K[:, j] = fc.imag / H


@numba.njit(cache=True)
def follower_loads_all(X, S, props, q, bending, f, K):
    """:func:`follower_loads` of every element: X (n, 2, 3), S (n, 2, 7), q (n, 3), bending (n,) →
    f (n, 12), K (n, 12, 12)."""
    for e in range(X.shape[0]):
        follower_loads(X[e], S[e], props[e], q[e], bending[e], f[e], K[e])


@numba.njit(cache=True, inline="always")
def _tabulate(w, c, X, f, K, tangent):
    """The element function of the DOLFINx kernels (see :mod:`.ufcx`)."""
    _evaluate(X, w[:2 * NSTATE].reshape(2, NSTATE), w[2 * NSTATE:], c[0] != 0.0, tangent, f, K)
    if tangent and c[0] == SYMMETRIZED:
        symmetrize(K)


vector_kernel, matrix_kernel = tabulate_tensor_kernels(_tabulate, NDOF, NCOEF, 2)


@numba.njit(cache=True, inline="always")
def _tabulate_staged(w, c, X, f, K, tangent):
    """An element added undeformed when its nodes' states were A = w[NCOEF:] (staged construction,
    approach II): reference X + u_A, states since then (u − u_A, R R_Aᵀ)."""
    Xa, Sa = since_activation(X, w[:2 * NSTATE].reshape(2, NSTATE),
                              w[NCOEF:NCOEF + 2 * NSTATE].reshape(2, NSTATE))
    _evaluate(Xa, Sa, w[2 * NSTATE:NCOEF], c[0] != 0.0, tangent, f, K)
    if tangent and c[0] == SYMMETRIZED:
        symmetrize(K)


# (vector_kernel, matrix_kernel) of staged elements, compiled on first use
staged_kernels = lazy_kernels(_tabulate_staged, NDOF, NCOEF + 2 * NSTATE, 2)

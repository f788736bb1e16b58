r"""What the kernels of elements in space (beams, shells, membranes) share.

Nodal state (7 per node): displacement u (3) and unit quaternion (4) of the
nodal rotation R; element vector: (u_a, w_a) per node, 6 dofs, with spatial
spins w (R_a ← exp(w_a) R_a).

* :func:`pack_constants`, :func:`unpack_constants`: the per-cell constants
  (R0, x̄0, K̄) of a flat element, computed once and packed into the kernels'
  coefficients;

* :func:`nodal_states`: u (n, 3) and R (n, 3, 3) from the states S (n, 7);
* :func:`rotation_vector_dofs`: the element vector (u_a, log R_a) of a
  geometrically linear analysis;
* :func:`perturb`: a state moved by i·h along one dof, for the complex-step
  tangent K[:, j] = Im f(d + i h e_j)/h with h = 1e-30, exact to rounding
  (Squire & Trapp 1998; Martins, Sturdza & Alonso 2003): a spin column turns
  the nodal rotation multiplicatively, R_a ← exp(i h e_k) R_a, as Newton
  updates it;
* :func:`last_node_columns`: the six columns of the last node, exactly, from
  the others and f (translation and rotation invariance of f);
* :func:`symmetrize`: K ← ½(K + Kᵀ), the tangent a kernel hands over when its part asks for
  the symmetric part (``c[0]`` = :data:`dolfinx_corot.kernels.SYMMETRIZED`; see
  :meth:`dolfinx_corot.assembly.System.symmetrize`);
* :func:`since_activation`: an element added undeformed when its nodes' states were A
  (staged construction, approach II) sees the nodes at X + u_A and their states since then,
  (u − u_A, R R_Aᵀ); the spins are unchanged (exp(w) R R_Aᵀ), so is the tangent;
* :func:`secant_quaternions`: the secant predictor of nodal states on the rotation group.
"""
from __future__ import annotations

import numba
import numpy as np

from . import SYMMETRIZED  # noqa: F401 (the kernels' c[0] asking for symmetrize)
from ..rotations import (exp_so3, log_so3, matmul3, quat_from_rotvec, quat_mul, quat_to_matrix, quat_to_matrix_into,
                         rotvec_from_quat)

H = 1e-30  # complex step


@numba.njit(cache=True)
def pack_constants(R0, xbar0, Kbar, out):
    """out[:9 + 3n + m²] = (R0 (3, 3), x̄0 (n, 3), K̄ (m, m)) flattened (a shell's shallow-shell
    data follows, see :func:`shallow_constants`)."""
    e = 9 + xbar0.size
    out[:9] = R0.ravel()
    out[9:e] = xbar0.ravel()
    out[e:e + Kbar.size] = Kbar.ravel()


@numba.njit(cache=True)
def unpack_constants(edata, nnode, nbar):
    """(R0 (3, 3), x̄0 (nnode, 3), K̄ (nbar, nbar)) from the packed per-cell constants edata."""
    e = 9 + 3 * nnode
    return (edata[:9].copy().reshape(3, 3), edata[9:e].copy().reshape(nnode, 3),
            edata[e:e + nbar * nbar].copy().reshape(nbar, nbar))


@numba.njit(cache=True)
def shallow_constants(edata, nnode, nbar):
    """The shallow-shell data (:mod:`dolfinx_corot.elements.shallow_shell`) packed after K̄."""
    return edata[9 + 3 * nnode + nbar * nbar:]


@numba.njit(cache=True)
def nodal_states(S, u, R):
    """u (n, 3) displacements and R (n, 3, 3) rotation tensors of the nodal states S (n, 7)."""
    for a in range(S.shape[0]):
        for k in range(3):
            u[a, k] = S[a, k]
        quat_to_matrix_into(S[a, 3:7], R[a])


@numba.njit(cache=True)
def rotation_vector_dofs(S, d):
    """d (6n,) = (u_a, log R_a) per node of the states S (n, 7) (rotations below π)."""
    for a in range(S.shape[0]):
        d[6 * a:6 * a + 3] = S[a, :3]
        log_so3(quat_to_matrix(S[a, 3:7].copy()), d[6 * a + 3:6 * a + 6])


@numba.njit(cache=True)
def perturb(u, R, j, up, Rp):
    """up, Rp = the complex state u (n, 3), R (n, 3, 3) moved by i·H along dof j = 6a + c:
    u_a[c] += iH for c < 3, R_a ← exp(iH e_{c−3}) R_a otherwise."""
    up[:, :] = u
    Rp[:, :, :] = R
    a, c = divmod(j, 6)
    if c < 3:
        up[a, c] += 1j * H
    else:
        w = np.zeros(3, dtype=np.complex128)
        w[c - 3] = 1j * H
        E = np.empty((3, 3), dtype=np.complex128)
        exp_so3(w, E)
        matmul3(E, R[a], Rp[a])


@numba.njit(cache=True, inline="always")
def _cross_e(k, v0, v1, v2):
    """e_k × v."""
    return (k == 1) * v2 - (k == 2) * v1, (k == 2) * v0 - (k == 0) * v2, (k == 0) * v1 - (k == 1) * v0


@numba.njit(cache=True)
def last_node_columns(f, X, u, K):
    """Fill the six columns of the last of the n nodes of K (6n, 6n) from the others and f (6n,).

    X, u (n, 3): initial positions and displacements. Translation: f depends on
    the differences of the positions, so K[:, u_n] = −Σ_{a<n} K[:, u_a].
    Rotation: a rigid rotation δu_a = e_k × x_a, δw_a = e_k turns every force and
    moment block f_b into e_k × f_b, so
    K[:, w_n,k] = (e_k × f_b)_b − Σ_{a<n} (K[:, w_a,k] + K[:, u_a]·(e_k × (x_a − x_n))).
    """
    n = X.shape[0]
    last = 6 * (n - 1)
    for i in range(K.shape[0]):
        for k in range(3):
            acc = -K[i, k]
            for a in range(1, n - 1):
                acc -= K[i, 6 * a + k]
            K[i, last + k] = acc
    r = np.empty((n - 1, 3))
    for a in range(n - 1):
        for m in range(3):
            r[a, m] = X[a, m] + u[a, m] - X[n - 1, m] - u[n - 1, m]
    for k in range(3):
        for i in range(K.shape[0]):
            b, m = divmod(i, 3)
            acc = _cross_e(k, f[3 * b], f[3 * b + 1], f[3 * b + 2])[m]
            for a in range(n - 1):
                acc -= K[i, 6 * a + 3 + k]
            for a in range(n - 1):
                e0, e1, e2 = _cross_e(k, r[a, 0], r[a, 1], r[a, 2])
                acc -= K[i, 6 * a] * e0 + K[i, 6 * a + 1] * e1 + K[i, 6 * a + 2] * e2
            K[i, last + 3 + k] = acc


@numba.njit(cache=True, inline="always")
def symmetrize(K):
    """K (n, n) ← ½(K + Kᵀ) in place."""
    n = K.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            s = 0.5 * (K[i, j] + K[j, i])
            K[i, j] = s
            K[j, i] = s


@numba.njit(cache=True)
def since_activation(X, S, A):
    """(X + u_A, S since A) for nodes X (n, 3), states S (n, 7) and states at activation A (n, 7):
    displacements u − u_A, quaternions q∘q_A⁻¹ (R R_Aᵀ)."""
    Xa = np.empty((X.shape[0], 3))
    Sa = np.empty((S.shape[0], 7))
    qi = np.empty(4)
    for a in range(S.shape[0]):
        for k in range(3):
            Xa[a, k] = X[a, k] + A[a, k]
            Sa[a, k] = S[a, k] - A[a, k]
        qi[0] = A[a, 3]
        for k in range(1, 4):
            qi[k] = -A[a, 3 + k]
        Sa[a, 3:7] = quat_mul(S[a, 3:7].copy(), qi)
    return Xa, Sa


@numba.njit(cache=True)
def since_activation_all(X, S, A, Xa, Sa):
    """(X + u_A, S since A) of every element (see :func:`since_activation`): X (n, m, 3),
    S and A (n, m, 7) → Xa, Sa."""
    for e in range(X.shape[0]):
        Xa[e], Sa[e] = since_activation(X[e], S[e], A[e])


@numba.njit(cache=True)
def secant_quaternions(state, older, newer, f):
    """state (n, 7) ← (u₁ + f (u₁ − u₀), exp(f log(q₁∘q₀⁻¹))∘q₁) for every node (ghosts alike:
    their states equal their owners'): the secant predictor on the rotation group."""
    for i in range(state.shape[0]):
        for k in range(3):
            state[i, k] = newer[i, k] + f * (newer[i, k] - older[i, k])
        q0 = older[i, 3:7].copy()
        q0[1:] = -q0[1:]  # the inverse of a unit quaternion
        w = rotvec_from_quat(quat_mul(newer[i, 3:7].copy(), q0))
        q = quat_mul(quat_from_rotvec(f * w), newer[i, 3:7].copy())
        state[i, 3:7] = q / np.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2 + q[3] ** 2)

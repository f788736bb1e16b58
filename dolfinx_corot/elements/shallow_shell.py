r"""The shallow-shell part of the flat shells' local law: the membrane strain of the bent facet.

The flat shells' local law (:mod:`.shell_triangle`, :mod:`.shell_quad`) is linear in the
element frame: K̄ d̄. Like the beams' shallow-arch strain (Crisfield 1991, §7.2.1;
:mod:`.beam3d`), the co-rotational shells add the membrane strain that the element's own
bending makes, von Kármán's ½ w,ᵢ w,ⱼ with the slopes β = (w,x, w,y) of the element's bending
field (the DKT's or the DKQ's quadratic slopes, whose edges deflect as cubics: on a beam this
is exactly the shallow-arch term):

.. math::

    \bar{\boldsymbol\eta} = \frac1A\int_A\bigl(\tfrac12\beta_x^2,\ \tfrac12\beta_y^2,\
        \beta_x\beta_y\bigr)\,dA = \tfrac12\bigl(\mathbf q^T\mathbf G_k\mathbf q\bigr)_{k=1..3},

    U = \tfrac12\bar{\mathbf d}^T\bar{\mathbf K}\bar{\mathbf d}
        + A\bigl(\bar{\boldsymbol\eta}^T\mathbf N_0
        + \tfrac12\bar{\boldsymbol\eta}^T\mathbf A_m\bar{\boldsymbol\eta}\bigr),\qquad
    \mathbf N_0 = \mathbf C_N\bar{\mathbf d},

q the element's plate dofs (w, θx, θy per node), N₀ the element's mean membrane force of the
linear law (A ε̄ + B κ̄: the constant-strain part of the membrane, the mean curvature), A_m the
section's membrane stiffness and A the area. Then

.. math::

    \bar{\mathbf f} = \bar{\mathbf K}\bar{\mathbf d} + A(\mathbf H^T\mathbf N + \mathbf C_N^T\bar{\boldsymbol\eta}),
    \qquad \mathbf N = \mathbf N_0 + \mathbf A_m\bar{\boldsymbol\eta},\quad
    \mathbf H = \partial\bar{\boldsymbol\eta}/\partial\bar{\mathbf d}\ (\text{rows } \mathbf G_k\mathbf q),

    \bar{\mathbf K}_t = \bar{\mathbf K} + A\Bigl(\sum_k N_k\mathbf G_k + \mathbf H^T\mathbf C_N
        + \mathbf C_N^T\mathbf H + \mathbf H^T\mathbf A_m\mathbf H\Bigr),

the Hessian of U (symmetric). The first term of the bracket is the initial-stress stiffness
the linear law lacks: a membrane force acting on the element's own bending. A geometrically
linear analysis uses K̄ alone.

Packed per cell (:func:`pack`, after K̄ in the kernels' element constants): G (3, n_q, n_q),
C_N (3, n), A_m (3, 3), A. A = 0 switches the term off (membranes). The functions of the state
are complex-analytic (complex-step tangents).
"""
from __future__ import annotations

import numba
import numpy as np


def size(nnode: int) -> int:
    """Length of the packed data of an element of nnode nodes (6 dofs each, 3 plate dofs)."""
    nq = 3 * nnode
    return 3 * nq * nq + 3 * 6 * nnode + 9 + 1


@numba.njit(cache=True)
def pack(G, CN, Am, area, out):
    """out = (G (3, nq, nq), C_N (3, n), A_m (3, 3), A) flattened."""
    g = G.size
    c = CN.size
    out[:g] = G.ravel()
    out[g:g + c] = CN.ravel()
    out[g + c:g + c + 9] = Am.ravel()
    out[g + c + 9] = area


@numba.njit(cache=True, inline="always")
def active(sdata):
    """Whether the term is switched on (the packed area, the last entry, is not 0)."""
    return sdata[sdata.shape[0] - 1] != 0.0


@numba.njit(cache=True)
def _plate_dof(i):
    """Index in the element vector (6 per node) of plate dof i (3 per node: w, θx, θy)."""
    return 6 * (i // 3) + 2 + i % 3


@numba.njit(cache=True)
def _eta(dbar, sdata, nnode):
    """(η̄ (3,), H (3, nq) = ∂η̄/∂q, area) of the deformational dofs dbar (real or complex)."""
    nq = 3 * nnode
    dt = dbar.dtype
    eta = np.zeros(3, dtype=dt)
    H = np.zeros((3, nq), dtype=dt)
    q = np.empty(nq, dtype=dt)
    for i in range(nq):
        q[i] = dbar[_plate_dof(i)]
    for k in range(3):
        o = k * nq * nq
        acc = 0.0 * q[0]
        for i in range(nq):
            h = 0.0 * q[0]
            for j in range(nq):
                h += sdata[o + i * nq + j] * q[j]
            H[k, i] = h
            acc += h * q[i]
        eta[k] = 0.5 * acc
    return eta, H


@numba.njit(cache=True)
def _force(dbar, Kbar, sdata, nnode, fbar):
    """Fill f̄ (n,) = ∂U/∂d̄ (real or complex); returns (active, η̄ (3,), H (3, nq), N (3,)) for
    the tangent (H and N meaningless when not active)."""
    n = 6 * nnode
    nq = 3 * nnode
    for i in range(n):
        acc = Kbar[i, 0] * dbar[0]
        for j in range(1, n):
            acc += Kbar[i, j] * dbar[j]
        fbar[i] = acc
    g = 3 * nq * nq
    c = g + 3 * n
    area = sdata[c + 9]
    N = np.zeros(3, dtype=dbar.dtype)
    if area == 0.0:
        return False, N, np.zeros((3, nq), dtype=dbar.dtype), N
    eta, H = _eta(dbar, sdata, nnode)
    for k in range(3):  # N = C_N d̄ + A_m η̄
        acc = 0.0 * dbar[0]
        for j in range(n):
            acc += sdata[g + k * n + j] * dbar[j]
        for m in range(3):
            acc += sdata[c + 3 * k + m] * eta[m]
        N[k] = acc
    for j in range(n):
        fbar[j] += area * (sdata[g + j] * eta[0] + sdata[g + n + j] * eta[1] + sdata[g + 2 * n + j] * eta[2])
    for i in range(nq):
        fbar[_plate_dof(i)] += area * (H[0, i] * N[0] + H[1, i] * N[1] + H[2, i] * N[2])
    return True, eta, H, N


@numba.njit(cache=True)
def force(dbar, Kbar, sdata, nnode, fbar):
    """f̄ (n,) = ∂U/∂d̄ (the module's docstring), n = 6 nnode (real or complex)."""
    _force(dbar, Kbar, sdata, nnode, fbar)


@numba.njit(cache=True)
def force_and_tangent(dbar, Kbar, sdata, nnode, fbar, Kt):
    """f̄ (n,) and K̄_t = ∂f̄/∂d̄ (n, n) (real)."""
    n = 6 * nnode
    nq = 3 * nnode
    active, eta, Hq, N = _force(dbar, Kbar, sdata, nnode, fbar)
    for i in range(n):
        for j in range(n):
            Kt[i, j] = Kbar[i, j]
    if not active:
        return
    g = 3 * nq * nq
    c = g + 3 * n
    area = sdata[c + 9]
    H = np.zeros((3, n))  # H on all dofs
    for k in range(3):
        for i in range(nq):
            H[k, _plate_dof(i)] = Hq[k, i]
    CA = np.empty((3, n))  # C_N + A_m H
    for k in range(3):
        for j in range(n):
            acc = sdata[g + k * n + j]
            for m in range(3):
                acc += sdata[c + 3 * k + m] * H[m, j]
            CA[k, j] = acc
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(3):
                acc += H[k, i] * CA[k, j] + sdata[g + k * n + i] * H[k, j]
            Kt[i, j] += area * acc
    for i in range(nq):
        pi = _plate_dof(i)
        for j in range(nq):
            pj = _plate_dof(j)
            o = i * nq + j
            Kt[pi, pj] += area * (N[0] * sdata[o] + N[1] * sdata[nq * nq + o] + N[2] * sdata[2 * nq * nq + o])


@numba.njit(cache=True)
def mean_strain(dbar, sdata, nnode):
    """η̄ (3,), the shallow part of the element's mean membrane strain (zeros when switched off);
    it adds A η̄ to the membrane forces and B η̄ to the moments."""
    nq = 3 * nnode
    c = 3 * nq * nq + 3 * 6 * nnode
    if sdata[c + 9] == 0.0:
        return np.zeros(3)
    eta, _ = _eta(dbar, sdata, nnode)
    return eta


@numba.njit(cache=True)
def interpolate_slopes(N, S):
    """(2, nq): the slopes Σ_n N_n (βx, βy)_n at a point, from the shape functions N (m,) and the
    slopes at the m interpolation nodes S (2m, nq) (rows βx, βy per node)."""
    out = np.zeros((2, S.shape[1]))
    for n in range(N.shape[0]):
        for col in range(S.shape[1]):
            out[0, col] += N[n] * S[2 * n, col]
            out[1, col] += N[n] * S[2 * n + 1, col]
    return out


@numba.njit(cache=True)
def add_slope_products(S, w, G):
    """G (3, nq, nq) += w (SxᵀSx, SyᵀSy, SxᵀSy + SyᵀSx) for the slopes S (2, nq) at a point."""
    nq = S.shape[1]
    for i in range(nq):
        for j in range(nq):
            G[0, i, j] += w * S[0, i] * S[0, j]
            G[1, i, j] += w * S[1, i] * S[1, j]
            G[2, i, j] += w * (S[0, i] * S[1, j] + S[1, i] * S[0, j])

r"""Two-node line elements in the plane (beam and bar): gather ► frame ► law ► scatter.

:func:`corotational` evaluates the co-rotational element (frame from
:mod:`dolfinx_corot.corotation.frame2d`, law from
:mod:`dolfinx_corot.elements.line2d`); :func:`linear` the geometrically linear
element in the initial frame (no co-rotational work at all).

For DOLFINx the two are wrapped in numba ``cfunc`` tabulate-tensor kernels
(:data:`vector_kernel`, :data:`matrix_kernel`, from
:func:`dolfinx_corot.kernels.ufcx.tabulate_tensor_kernels`) with the ufcx signature
``(A, w, c, coords, entity_local_index, permutation)``:

* ``w`` = [state of node 1 (u, v, θ), state of node 2, props (NPROPS)],
  where θ is the total nodal angle (node-major, as DOLFINx packs a
  blocked space);
* ``c`` = [large_rotations (1.0 or 0.0)];
* staged elements (:func:`staged_kernels`) read after the props the state of their nodes when
  they appeared, a (6,): element added undeformed in the configuration of that moment
  (seed §3.1.2, approach II) — reference X + a, deformation d − a;
* ``coords`` = (2, 3) initial nodal coordinates (padded to 3).
"""
from __future__ import annotations

import numba
import numpy as np

from ..corotation import frame2d
from ..corotation.transform import stiffness
from ..elements import line2d as law
from .ufcx import lazy_kernels, tabulate_tensor_kernels

NDOF = 6
NCOEF = NDOF + law.NPROPS


@numba.njit(cache=True)
def corotational(x1, y1, x2, y2, d, props, f, K, P, fbar, kbar):
    """Co-rotational element: f (6,) internal force, K (6, 6) consistent tangent.

    P (3, 6), fbar (3,), kbar (3, 3) are work arrays.
    """
    l0, l, c, s, ub, t1, t2 = frame2d.update(x1, y1, x2, y2, d)
    law.basic_response(l0, ub, t1, t2, props, fbar, kbar, True)
    frame2d.fill_projector(l, c, s, P)
    frame2d.global_force(P, fbar, f)
    frame2d.global_stiffness(l, c, s, P, kbar, fbar, K)


@numba.njit(cache=True)
def linear(x1, y1, x2, y2, d, props, f, K, P, fbar, kbar):
    """Geometrically linear element in the initial frame: K = P₀ᵀ K̄ P₀, f = K d + P₀ᵀ f̄₀."""
    l0, c0, s0 = frame2d.initial(x1, y1, x2, y2)
    frame2d.fill_projector(l0, c0, s0, P)
    ub = 0.0
    t1 = 0.0
    t2 = 0.0
    for j in range(6):
        ub += P[0, j] * d[j]
        t1 += P[1, j] * d[j]
        t2 += P[2, j] * d[j]
    law.basic_response(l0, ub, t1, t2, props, fbar, kbar, False)
    frame2d.global_force(P, fbar, f)
    stiffness(P, kbar, K, 3, 6)


@numba.njit(cache=True)
def evaluate(x1, y1, x2, y2, d, props, large_rotations, f, K):
    """Dispatch to :func:`corotational` or :func:`linear`."""
    P = np.empty((3, 6))
    fbar = np.empty(3)
    kbar = np.empty((3, 3))
    if large_rotations:
        corotational(x1, y1, x2, y2, d, props, f, K, P, fbar, kbar)
    else:
        linear(x1, y1, x2, y2, d, props, f, K, P, fbar, kbar)


@numba.njit(cache=True)
def evaluate_all(X, D, props, large_rotations, F, K):
    """All elements at once: X (n, 2, 2), D (n, 6), props (n, NPROPS) → F (n, 6), K (n, 6, 6)."""
    P = np.empty((3, 6))
    fbar = np.empty(3)
    kbar = np.empty((3, 3))
    for e in range(X.shape[0]):
        if large_rotations:
            corotational(X[e, 0, 0], X[e, 0, 1], X[e, 1, 0], X[e, 1, 1], D[e], props[e],
                         F[e], K[e], P, fbar, kbar)
        else:
            linear(X[e, 0, 0], X[e, 0, 1], X[e, 1, 0], X[e, 1, 1], D[e], props[e],
                   F[e], K[e], P, fbar, kbar)


@numba.njit(cache=True, inline="always")
def _tabulate(w, c, X, f, K, tangent):
    """The element function of the DOLFINx kernels (see :mod:`.ufcx`); K is cheap, always filled."""
    evaluate(X[0, 0], X[0, 1], X[1, 0], X[1, 1], w[:NDOF], w[NDOF:], c[0] != 0.0, f, K)


vector_kernel, matrix_kernel = tabulate_tensor_kernels(_tabulate, NDOF, NCOEF, 2)


@numba.njit(cache=True, inline="always")
def _tabulate_staged(w, c, X, f, K, tangent):
    """An element that appeared undeformed when its nodes' state was a = w[NCOEF:]: its reference
    is the nodes' position then (X + a), its deformation d − a (angles in the plane add)."""
    a = w[NCOEF:NCOEF + NDOF]
    d = np.empty(NDOF)
    for j in range(NDOF):
        d[j] = w[j] - a[j]
    evaluate(X[0, 0] + a[0], X[0, 1] + a[1], X[1, 0] + a[3], X[1, 1] + a[4], d, w[NDOF:NCOEF],
             c[0] != 0.0, f, K)


# (vector_kernel, matrix_kernel) of staged elements, compiled on first use
staged_kernels = lazy_kernels(_tabulate_staged, NDOF, NCOEF + NDOF, 2)

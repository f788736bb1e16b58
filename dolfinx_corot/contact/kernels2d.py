r"""Frictionless node-to-segment contact in 2D: gap, force and consistent tangent.

A slave node :math:`\mathbf x_s` meets the straight master segment
:math:`\mathbf x_1\mathbf x_2` (the master body on the left of
:math:`\mathbf x_1\to\mathbf x_2`, so that :math:`\mathbf n` points out of
it). With :math:`\mathbf d = \mathbf x_2-\mathbf x_1`, :math:`l=|\mathbf d|`,
:math:`\mathbf t=\mathbf d/l`, :math:`\mathbf n=(t_y,-t_x)`
(Wriggers 2006, *Computational Contact Mechanics*, §4.3 and §9.1):

.. math::
   \xi = \frac{(\mathbf x_s-\mathbf x_1)\cdot\mathbf d}{l^2},\qquad
   g = (\mathbf x_s-\mathbf x_1)\cdot\mathbf n,\qquad
   \frac{\partial g}{\partial(\mathbf x_s,\mathbf x_1,\mathbf x_2)}
   = \mathbf N = \bigl(\mathbf n,\;-(1-\xi)\mathbf n,\;-\xi\,\mathbf n\bigr).

The contact pressure of the augmented Lagrangian (penalty when λ = 0) is
:math:`p=\langle\lambda-\varepsilon g\rangle` (Simo & Laursen 1992), with the
potential :math:`\Phi = \frac{A}{2\varepsilon}\langle\lambda-\varepsilon g\rangle^2`
over the slave's tributary length A. Its gradient and Hessian are the
contact force and the consistent tangent,

.. math::
   \mathbf f = -A\,p\,\mathbf N,\qquad
   \mathbf K = A\bigl(\varepsilon\,\mathbf N\mathbf N^T - p\,\partial^2 g\bigr),

where :math:`\partial^2 g` (the rotation of the normal and the sliding of
the projection point) is the complex-step derivative of the closed-form
:math:`\mathbf N(\mathbf x)` — exact to round-off, six evaluations of a
few flops. The segment is fixed within an evaluation; the search decides
which segment a slave meets.
"""
from __future__ import annotations

import numba
import numpy as np

_H = 1e-30  # complex step


@numba.njit(cache=True)
def _gap_gradient(x, out):
    """N = ∂g/∂x for x = (x_s, x_1, x_2) flattened (6,), real or complex; returns (g, ξ)."""
    dx = x[4] - x[2]
    dy = x[5] - x[3]
    l2 = dx * dx + dy * dy
    l = np.sqrt(l2)
    tx = dx / l
    ty = dy / l
    nx = ty
    ny = -tx
    ax = x[0] - x[2]
    ay = x[1] - x[3]
    xi = (ax * dx + ay * dy) / l2
    g = ax * nx + ay * ny
    out[0] = nx
    out[1] = ny
    out[2] = -(1.0 - xi) * nx
    out[3] = -(1.0 - xi) * ny
    out[4] = -xi * nx
    out[5] = -xi * ny
    return g, xi


@numba.njit(cache=True)
def gap(xs, x1, x2):
    """Gap g and projection coordinate ξ of slave points on segments.

    xs, x1, x2: (k, 2) current positions; returns g, ξ: (k,)."""
    k = xs.shape[0]
    g = np.empty(k)
    xi = np.empty(k)
    x = np.empty(6)
    n = np.empty(6)
    for i in range(k):
        x[0:2] = xs[i]
        x[2:4] = x1[i]
        x[4:6] = x2[i]
        g[i], xi[i] = _gap_gradient(x, n)
    return g, xi


@numba.njit(cache=True)
def node_to_segment(xs, x1, x2, multiplier, penalty, area, with_tangent, touch=0.0):
    """Contact force and tangent of k slave–segment pairs.

    xs, x1, x2: (k, 2) current positions; multiplier λ ≥ 0, penalty ε > 0 and
    tributary length A: (k,); touch: a pair whose λ − ε g ≥ −ε·touch is closed
    (it has the penalty stiffness even at zero pressure: a body resting on a
    point at the start). Returns g, ξ, p: (k,); f: (k, 6) on (x_s, x_1, x_2);
    K: (k, 6, 6) (zeros unless ``with_tangent`` or open); energy Φ: (k,)."""
    k = xs.shape[0]
    g = np.empty(k)
    xi = np.empty(k)
    p = np.zeros(k)
    energy = np.zeros(k)
    f = np.zeros((k, 6))
    K = np.zeros((k, 6, 6))
    x = np.empty(6)
    N = np.empty(6)
    xc = np.empty(6, dtype=np.complex128)
    Nc = np.empty(6, dtype=np.complex128)
    for i in range(k):
        x[0:2] = xs[i]
        x[2:4] = x1[i]
        x[4:6] = x2[i]
        g[i], xi[i] = _gap_gradient(x, N)
        eps = penalty[i]
        pi = multiplier[i] - eps * g[i]
        if pi < -eps * touch:
            continue  # open; a touching pair keeps its stiffness
        pi = max(pi, 0.0)
        p[i] = pi
        a = area[i]
        energy[i] = 0.5 * a * pi * pi / eps
        for r in range(6):
            f[i, r] = -a * pi * N[r]
        if not with_tangent:
            continue
        for r in range(6):
            for c in range(6):
                K[i, r, c] = a * eps * N[r] * N[c]
        for c in range(6):
            for j in range(6):
                xc[j] = x[j]
            xc[c] += 1j * _H
            _gap_gradient(xc, Nc)
            for r in range(6):
                K[i, r, c] -= a * pi * Nc[r].imag / _H
        # ∂²g is symmetric; remove the round-off asymmetry
        for r in range(6):
            for c in range(r + 1, 6):
                s = 0.5 * (K[i, r, c] + K[i, c, r])
                K[i, r, c] = s
                K[i, c, r] = s
    return g, xi, p, f, K, energy


@numba.njit(cache=True)
def node_to_vertex(xs, xv, normal, multiplier, penalty, area, with_tangent, touch=0.0):
    r"""Contact of slaves with master vertices (the closest point of the master surface is a
    vertex shared by two segments).

    The gap is the distance to the vertex, signed by the side of the vertex's averaged
    normal: :math:`g = s\,|\mathbf x_s-\mathbf x_v|`, :math:`s = \mathrm{sign}((\mathbf x_s-\mathbf x_v)\cdot\bar{\mathbf n})`;
    :math:`\partial g/\partial(\mathbf x_s, \mathbf x_v) = (\boldsymbol\nu, -\boldsymbol\nu)` with
    :math:`\boldsymbol\nu = s\,\mathbf d/|\mathbf d|`, and
    :math:`\partial^2 g = \frac{s}{|\mathbf d|}(\mathbf I-\hat{\mathbf d}\hat{\mathbf d}^T)\begin{pmatrix}1&-1\\-1&1\end{pmatrix}`.
    At the edge of a segment's region (ξ = 0 or 1) this gap and its gradient equal the
    segment's, so a slave passes from segment to vertex to segment without a jump.

    xs, xv: (k, 2); normal: (k, 2) averaged unit normals at the vertices; multiplier,
    penalty, area: (k,). Returns g, p: (k,); f: (k, 4) on (x_s, x_v); K: (k, 4, 4)."""
    k = xs.shape[0]
    g = np.empty(k)
    p = np.zeros(k)
    f = np.zeros((k, 4))
    K = np.zeros((k, 4, 4))
    for i in range(k):
        dx = xs[i, 0] - xv[i, 0]
        dy = xs[i, 1] - xv[i, 1]
        dist = np.sqrt(dx * dx + dy * dy)
        s = 1.0 if dx * normal[i, 0] + dy * normal[i, 1] >= 0.0 else -1.0
        g[i] = s * dist
        eps = penalty[i]
        pi = multiplier[i] - eps * g[i]
        if pi < -eps * touch or dist == 0.0:
            continue
        pi = max(pi, 0.0)
        p[i] = pi
        a = area[i]
        nux = s * dx / dist
        nuy = s * dy / dist
        N = (nux, nuy, -nux, -nuy)
        for r in range(4):
            f[i, r] = -a * pi * N[r]
        if not with_tangent:
            continue
        ux = dx / dist
        uy = dy / dist
        P = ((1.0 - ux * ux, -ux * uy), (-ux * uy, 1.0 - uy * uy))
        c = s / dist
        for r in range(4):
            for q in range(4):
                K[i, r, q] = a * eps * N[r] * N[q]
        for r in range(2):
            for q in range(2):
                h = a * pi * c * P[r][q]
                K[i, r, q] -= h
                K[i, r + 2, q + 2] -= h
                K[i, r, q + 2] += h
                K[i, r + 2, q] += h
    return g, p, f, K

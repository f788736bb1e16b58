r"""Node-to-segment contact in 2D: gap, force and consistent tangent, frictionless and with
Coulomb friction (:func:`node_to_smooth_segment_friction`).

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

from ..kernels.spatial import symmetrize

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
def _pair_law(N, g, multiplier, eps, a, touch, with_tangent, f_row, K_row):
    """Pressure ⟨λ − εg⟩ of one pair with gap g and gradient N: f_row = −A p N and, with the
    tangent, K_row = A ε N Nᵀ (the curvature part is the caller's). Returns (p, energy, acting):
    acting is False for an open pair (a touching one acts, with zero force)."""
    pi = multiplier - eps * g
    if pi < -eps * touch:
        return 0.0, 0.0, False
    pi = max(pi, 0.0)
    n = N.shape[0]
    for r in range(n):
        f_row[r] = -a * pi * N[r]
    if with_tangent:
        for r in range(n):
            for c in range(n):
                K_row[r, c] = a * eps * N[r] * N[c]
    return pi, 0.5 * a * pi * pi / eps, True


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
        p[i], energy[i], acting = _pair_law(N, g[i], multiplier[i], penalty[i], area[i], touch, with_tangent,
                                            f[i], K[i])
        if not (acting and with_tangent):
            continue  # open (a touching pair keeps its stiffness)
        a, pi = area[i], p[i]
        for c in range(6):
            for j in range(6):
                xc[j] = x[j]
            xc[c] += 1j * _H
            _gap_gradient(xc, Nc)
            for r in range(6):
                K[i, r, c] -= a * pi * Nc[r].imag / _H
        symmetrize(K[i])  # ∂²g is symmetric: the complex-step columns' round-off asymmetry removed
    return g, xi, p, f, K, energy


@numba.njit(cache=True)
def node_to_vertex(xs, xv, normal, offset, multiplier, penalty, area, with_tangent, touch=0.0):
    r"""Contact of slaves with master vertices (the closest point of the master surface is a
    vertex shared by two segments).

    The gap is the distance to the vertex, signed by the side of the vertex's averaged
    normal: :math:`g = s\,|\mathbf x_s-\mathbf x_v|`, :math:`s = \mathrm{sign}((\mathbf x_s-\mathbf x_v)\cdot\bar{\mathbf n})`;
    :math:`\partial g/\partial(\mathbf x_s, \mathbf x_v) = (\boldsymbol\nu, -\boldsymbol\nu)` with
    :math:`\boldsymbol\nu = s\,\mathbf d/|\mathbf d|`, and
    :math:`\partial^2 g = \frac{s}{|\mathbf d|}(\mathbf I-\hat{\mathbf d}\hat{\mathbf d}^T)\begin{pmatrix}1&-1\\-1&1\end{pmatrix}`.
    At the edge of a segment's region (ξ = 0 or 1) this gap and its gradient equal the
    segment's, so a slave passes from segment to vertex to segment without a jump.

    xs, xv: (k, 2); normal: (k, 2) averaged unit normals at the vertices; offset (k,) subtracted
    from the gap (half the depth of a beam whose node is the slave); multiplier, penalty, area:
    (k,). Returns g, p: (k,); f: (k, 4) on (x_s, x_v); K: (k, 4, 4)."""
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
        g[i] = s * dist - offset[i]
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


# -- smooth (C¹) master surface ---------------------------------------------------------------
@numba.njit(cache=True, error_model="numpy")
def _hermite(x, xi):
    """Point, first and second derivatives of the Hermite curve of the segment a → b at ξ, the
    weights φ of (p, a, b, q) and their derivatives dφ/dξ; x = (x_s, x_p, x_a, x_b, x_q)
    flattened (10,).

    Nodal tangents: Catmull–Rom, (x_b − x_p)/2 at a and (x_q − x_a)/2 at b; at an end without a
    neighbour (p = a or q = b: a free end or a sharp corner) the natural end condition x'' = 0,
    which keeps an evenly divided straight surface exactly straight and linearly parametrized."""
    free_a = x[2].real == x[4].real and x[3].real == x[5].real
    free_b = x[8].real == x[6].real and x[9].real == x[7].real
    # tangents as combinations of (p, a, b, q)
    if free_a and free_b:
        ca = (0.0, -1.0, 1.0, 0.0)
        cb = (0.0, -1.0, 1.0, 0.0)
    elif free_a:
        ca = (0.0, -1.25, 1.5, -0.25)
        cb = (0.0, -0.5, 0.0, 0.5)
    elif free_b:
        ca = (-0.5, 0.0, 0.5, 0.0)
        cb = (0.25, -1.5, 1.25, 0.0)
    else:
        ca = (-0.5, 0.0, 0.5, 0.0)
        cb = (0.0, -0.5, 0.0, 0.5)
    x2 = xi * xi
    x3 = x2 * xi
    h00, h10, h01, h11 = 2 * x3 - 3 * x2 + 1, x3 - 2 * x2 + xi, -2 * x3 + 3 * x2, x3 - x2
    d00, d10, d01, d11 = 6 * x2 - 6 * xi, 3 * x2 - 4 * xi + 1, -6 * x2 + 6 * xi, 3 * x2 - 2 * xi
    s00, s10, s01, s11 = 12 * xi - 6, 6 * xi - 4, -12 * xi + 6, 6 * xi - 2
    w = (h10 * ca[0] + h11 * cb[0], h00 + h10 * ca[1] + h11 * cb[1],
         h01 + h10 * ca[2] + h11 * cb[2], h10 * ca[3] + h11 * cb[3])
    dw = (d10 * ca[0] + d11 * cb[0], d00 + d10 * ca[1] + d11 * cb[1],
          d01 + d10 * ca[2] + d11 * cb[2], d10 * ca[3] + d11 * cb[3])
    sw = (s10 * ca[0] + s11 * cb[0], s00 + s10 * ca[1] + s11 * cb[1],
          s01 + s10 * ca[2] + s11 * cb[2], s10 * ca[3] + s11 * cb[3])
    px = w[0] * x[2] + w[1] * x[4] + w[2] * x[6] + w[3] * x[8]
    py = w[0] * x[3] + w[1] * x[5] + w[2] * x[7] + w[3] * x[9]
    tx = dw[0] * x[2] + dw[1] * x[4] + dw[2] * x[6] + dw[3] * x[8]
    ty = dw[0] * x[3] + dw[1] * x[5] + dw[2] * x[7] + dw[3] * x[9]
    cx = sw[0] * x[2] + sw[1] * x[4] + sw[2] * x[6] + sw[3] * x[8]
    cy = sw[0] * x[3] + sw[1] * x[5] + sw[2] * x[7] + sw[3] * x[9]
    return px, py, tx, ty, cx, cy, w, dw


@numba.njit(cache=True, error_model="numpy")
def _closest_on_curve(x, xi, iterations):
    """Newton on (x_s − x(ξ))·x'(ξ) = 0 from ξ; returns (ξ, converged to a distance minimum).
    Quadratic convergence: one more iteration after a correction below 1e-9 reaches round-off."""
    if not abs(xi.real) < 3.0:
        return xi, False
    last = False
    for _ in range(iterations):
        px, py, tx, ty, cx, cy, w, _ = _hermite(x, xi)
        rx = x[0] - px
        ry = x[1] - py
        f = rx * tx + ry * ty
        df = -(tx * tx + ty * ty) + rx * cx + ry * cy
        if not df.real < 0.0:
            return xi, False  # not a distance minimum (a slave beyond the curvature centre)
        step = f / df
        xi = xi - step
        if last:
            # beyond its ends a segment's cubic may turn back: its points there are not used
            return xi, -0.25 < xi.real < 1.25
        last = abs(step.real) < 1e-9
        if not abs(xi.real) < 3.0:
            return xi, False  # far beyond the segment: another segment's point
    return xi, False


@numba.njit(cache=True, error_model="numpy")
def _smooth_gap_gradient(x, out, xi):
    r"""Gap to the C¹ master curve through x = (x_s, x_p, x_a, x_b, x_q) flattened (10,), real or
    complex, from the projection coordinate ξ solved to round-off (the real part); returns (g, ξ)
    and N = ∂g/∂x in ``out``: (n, −φ_p n, −φ_a n, −φ_b n, −φ_q n) — at the closest point the
    variations of ξ and of the normal drop out (r ∥ n ⊥ x')."""
    px, py, tx, ty, cx, cy, w, _ = _hermite(x, xi)
    lt = np.sqrt(tx * tx + ty * ty)
    nx = ty / lt
    ny = -tx / lt
    g = (x[0] - px) * nx + (x[1] - py) * ny
    out[0] = nx
    out[1] = ny
    for k in range(4):
        out[2 + 2 * k] = -w[k] * nx
        out[3 + 2 * k] = -w[k] * ny
    return g


@numba.njit(cache=True, error_model="numpy")
def _straight_xi(x):
    dx = x[6] - x[4]
    dy = x[7] - x[5]
    return ((x[0] - x[4]) * dx + (x[1] - x[5]) * dy) / (dx * dx + dy * dy)


@numba.njit(cache=True, error_model="numpy")
def smooth_gap(x):
    """Gap, projection coordinate and validity (a distance minimum was found) of k slave–segment
    pairs on the C¹ master curve; x: (k, 10) positions of (slave, p, a, b, q)
    (see :func:`node_to_smooth_segment`)."""
    k = x.shape[0]
    g = np.empty(k)
    xi = np.empty(k)
    ok = np.empty(k, dtype=np.bool_)
    N = np.empty(10)
    for i in range(k):
        xii, oki = _closest_on_curve(x[i], _straight_xi(x[i]), 30)
        g[i] = _smooth_gap_gradient(x[i], N, xii) if oki else np.inf
        xi[i] = xii
        ok[i] = oki
    return g, xi, ok


@numba.njit(cache=True, error_model="numpy")
def node_to_smooth_segment(x, side, offset, multiplier, penalty, area, with_tangent, touch=0.0):
    r"""Contact force and tangent of k slaves on the segments of a C¹ master curve.

    Each master segment a → b is replaced by the cubic Hermite curve through x_a and x_b with the
    nodal tangents (x_b − x_p)/2 and (x_q − x_a)/2 (Catmull–Rom; p and q the neighbouring nodes on
    the surface; p = a or q = b at a sharp corner or a free end, where the curve ends with zero
    curvature): neighbouring segments share the tangent at their common node, so the surface, its
    normal and the gap are continuous with their first derivatives when a slave passes from one
    segment to the next (the straight segments turn their normal abruptly there; Wriggers 2006,
    §9.4; Padmanabhan & Laursen 2001). A straight, evenly divided surface stays the straight
    segments. The closest point x(ξ) solves (x_s − x(ξ))·x'(ξ) = 0 (Newton), and the gap is
    g = s (x_s − x(ξ))·n − c with n ⊥ x': s = ±1 the side of the curve the contact is on (−1: a
    slave on the body's side of a beam's axis) and c ≥ 0 an offset (half the thicknesses of beams,
    whose axes are the curves).

    x: (k, 10) current positions (x_s, x_p, x_a, x_b, x_q); side, offset, multiplier, penalty,
    area: (k,).
    Returns g, ξ, p: (k,); f: (k, 10); K: (k, 10, 10); energy (k,); N = ∂g/∂x (k, 10) of every
    pair with a closest point (open ones included). Pressure law, force and
    tangent as :func:`node_to_segment` (f = −A p N, K = A(ε N Nᵀ − p ∂²g), ∂²g by complex step
    of N, the projection re-solved in complex arithmetic)."""
    k = x.shape[0]
    g = np.empty(k)
    xi = np.empty(k)
    p = np.zeros(k)
    energy = np.zeros(k)
    f = np.zeros((k, 10))
    K = np.zeros((k, 10, 10))
    N = np.empty(10)
    normal = np.zeros((k, 10))
    xc = np.empty(10, dtype=np.complex128)
    Nc = np.empty(10, dtype=np.complex128)
    for i in range(k):
        xii, ok = _closest_on_curve(x[i], _straight_xi(x[i]), 30)
        xi[i] = xii
        if not ok:
            g[i] = np.inf
            continue
        gi = side[i] * _smooth_gap_gradient(x[i], N, xii) - offset[i]
        for r in range(10):
            N[r] *= side[i]
            normal[i, r] = N[r]
        g[i] = gi
        p[i], energy[i], acting = _pair_law(N, gi, multiplier[i], penalty[i], area[i], touch, with_tangent,
                                            f[i], K[i])
        if not (acting and with_tangent):
            continue
        a, pi = area[i], p[i]
        for c in range(10):
            for j in range(10):
                xc[j] = x[i, j]
            xc[c] += 1j * _H
            xic, _ = _closest_on_curve(xc, xii + 0j, 3)
            _smooth_gap_gradient(xc, Nc, xic)
            for r in range(10):
                K[i, r, c] -= a * pi * side[i] * Nc[r].imag / _H
        symmetrize(K[i])  # ∂²g is symmetric: the complex-step columns' round-off asymmetry removed
    return g, xi, p, f, K, energy, normal


# -- Coulomb friction on the C¹ master curve ---------------------------------------------------
@numba.njit(cache=True, error_model="numpy")
def slip(x, xi, xi0, out):
    r"""Elastic slip s = (x_s − X₀)·τ(ξ) of the slave x[0:2] from the stick point X₀ of parameter
    ξ₀ on the segment's curve, the slave's closest point being at ξ, and its gradient ∂s/∂x (10,)
    into ``out``; real or complex x (ξ then the complex solution). In closed form, with
    a = x'(ξ), c₂ = x''(ξ), r = x_s − x(ξ) (normal to a), ν the unit normal, r₀ = x_s − X₀:
    δξ = [(δx_s − Σ φ_k δx_k)·a + r·Σ φ'_k δx_k] / (a·a − r·c₂) (the closest point's variation) and
    δs = (δx_s − Σ φ_k(ξ₀) δx_k)·τ + (r₀·ν/|a|) ν·(Σ φ'_k δx_k + c₂ δξ)."""
    px, py, tx, ty, cx, cy, w, dw = _hermite(x, xi)
    w0 = _hermite(x, xi0 + 0.0 * xi)[6]
    X0x = w0[0] * x[2] + w0[1] * x[4] + w0[2] * x[6] + w0[3] * x[8]
    X0y = w0[0] * x[3] + w0[1] * x[5] + w0[2] * x[7] + w0[3] * x[9]
    la = np.sqrt(tx * tx + ty * ty)
    taux = tx / la
    tauy = ty / la
    nux = tauy
    nuy = -taux
    r0x = x[0] - X0x
    r0y = x[1] - X0y
    rx = x[0] - px
    ry = x[1] - py
    den = tx * tx + ty * ty - (rx * cx + ry * cy)
    q = (r0x * nux + r0y * nuy) / la
    nc = nux * cx + nuy * cy
    out[0] = taux + q * nc * tx / den
    out[1] = tauy + q * nc * ty / den
    for k in range(4):
        cxk = (-w[k] * tx + dw[k] * rx) / den  # ∂ξ/∂x_k
        cyk = (-w[k] * ty + dw[k] * ry) / den
        out[2 + 2 * k] = -w0[k] * taux + q * (dw[k] * nux + nc * cxk)
        out[3 + 2 * k] = -w0[k] * tauy + q * (dw[k] * nuy + nc * cyk)
    return r0x * taux + r0y * tauy


@numba.njit(cache=True)
def _friction_arrays(k):
    """The outputs of k frictional pairs — g, p, t, s (k,), slipping (k,), f (k, 10), K (k, 10, 10)
    — and the complex-step work arrays x, f (10,)."""
    return (np.empty(k), np.zeros(k), np.zeros(k), np.zeros(k), np.zeros(k, dtype=np.bool_), np.zeros((k, 10)),
            np.zeros((k, 10, 10)), np.empty(10, dtype=np.complex128), np.empty(10, dtype=np.complex128))


@numba.njit(cache=True, error_model="numpy")
def _return_map(lam_t, eps_t, s, cohesion, mu, p):
    """Coulomb's traction along the tangent: the predictor λ_T + ε_T s returned onto the slip
    surface |t| ≤ c + μ p (decided on the real parts); returns (t, slipping)."""
    t = lam_t + eps_t * s
    cap = cohesion + mu * p
    slipping = abs(t.real) > cap.real
    if slipping:
        t = cap if t.real > 0.0 else -cap
    return t, slipping


@numba.njit(cache=True, error_model="numpy")
def _friction_force(x, xi, side, offset, lam, eps, area, eps_t, mu, cohesion, xi0, lam_t, f):
    """Gap, pressure, traction, slip and force f (10,) of one pair at the closest point ξ (the
    module's law); returns (g, p, t, s, slipping)."""
    N = np.empty(10, dtype=x.dtype)
    S = np.empty(10, dtype=x.dtype)
    g = side * _smooth_gap_gradient(x, N, xi) - offset
    p = lam - eps * g
    if p.real <= 0.0:
        for r in range(10):
            f[r] = 0.0
        return g, 0.0 * p, 0.0 * p, 0.0 * p, False
    s = slip(x, xi, xi0, S)
    t, slipping = _return_map(lam_t, eps_t, s, cohesion, mu, p)
    for r in range(10):
        f[r] = -area * p * side * N[r] + area * t * S[r]
    return g, p, t, s, slipping


@numba.njit(cache=True, error_model="numpy")
def node_to_smooth_segment_friction(x, side, offset, multiplier, penalty, area, eps_t, mu, cohesion, xi0, lam_t,
                                    with_tangent):
    r"""Frictional contact of k slaves on the segments of the C¹ master curve: Coulomb's law with
    cohesion.

    Normally as :func:`node_to_smooth_segment` (closest point x(ξ), gap g, p = ⟨λ − εg⟩).
    Tangentially the slave is attached to a point of the master, its stick point
    X₀ = Σ φ_k(ξ₀) x_k: the master's material point of parameter ξ₀, which moves with the master's
    nodes. The elastic slip is the distance from X₀ to the slave along the unit tangent
    τ = x'/|x'| at the contact point, s = (x_s − X₀)·τ(ξ) (:func:`slip`): a function of relative
    positions only, so rigid motions of the pair change neither s nor the traction (frame
    indifference). The tangential traction (force per tributary length A, along τ) is the
    predictor λ_T + ε_T s (λ_T the augmented Lagrangian's tangential multiplier, held within a
    Newton solve; zero: the penalty law) returned onto Coulomb's slip surface |t| ≤ c + μ p (c the
    cohesion, μ = tan φ): t = λ_T + ε_T s in stick (|λ_T + ε_T s| ≤ c + μ p), t = (c + μ p) sign(λ_T +
    ε_T s) in slip. The pair's internal force is f = −A p ∂g/∂x + A t ∂s/∂x: in stick the gradient
    of the energy A⟨λ − εg⟩²/2ε + A (λ_T s + ε_T s²/2) (a symmetric tangent); in slip the
    traction follows the pressure and the tangent is not symmetric. Both parts are gradients of
    rotation-invariant scalars weighted by scalars, so the pair conserves linear and angular
    momentum. At convergence a slipping slave is attached right under itself
    (:func:`slipped_stick_point`), its traction kept in λ_T. K = ∂f/∂x is the complex-step
    derivative of f, the projection re-solved in complex arithmetic, stick or slip decided on
    the real parts. (Wriggers, Computational Contact Mechanics, 2nd ed., Springer 2006:
    tangential slip in the master's convected coordinates and Coulomb's law by a return map;
    Laursen, Computational Contact and Impact Mechanics, Springer 2002: frame-indifferent
    tangential kinematics.)

    x: (k, 10) current positions (x_s, x_p, x_a, x_b, x_q); side, offset, multiplier λ, penalty ε,
    area A, tangential penalty ε_T, friction coefficient μ, cohesion c, stick points ξ₀ (on each
    pair's segment curve) and tangential multipliers λ_T: (k,). Returns g, ξ, p, t, s: (k,) (g inf
    where no closest point was found; p, t zero for open pairs), slipping (k,) bool, f (k, 10),
    K (k, 10, 10)."""
    k = x.shape[0]
    xi = np.empty(k)
    g, p, t, s, slipping, f, K, xc, fc = _friction_arrays(k)
    for i in range(k):
        xii, ok = _closest_on_curve(x[i], _straight_xi(x[i]), 30)
        xi[i] = xii
        if not ok:
            g[i] = np.inf
            continue
        g[i], p[i], t[i], s[i], slipping[i] = _friction_force(x[i], xii, side[i], offset[i], multiplier[i],
                                                              penalty[i], area[i], eps_t[i], mu[i], cohesion[i],
                                                              xi0[i], lam_t[i], f[i])
        if not with_tangent or p[i] <= 0.0:
            continue
        for c in range(10):
            for j in range(10):
                xc[j] = x[i, j]
            xc[c] += 1j * _H
            xic, _ = _closest_on_curve(xc, xii + 0j, 3)
            _friction_force(xc, xic, side[i], offset[i], multiplier[i] + 0j, penalty[i], area[i], eps_t[i],
                            mu[i], cohesion[i], xi0[i], lam_t[i] + 0j, fc)
            for r in range(10):
                K[i, r, c] = fc[r].imag / _H
    return g, xi, p, t, s, slipping, f, K


@numba.njit(cache=True, error_model="numpy")
def slipped_stick_point(x, xi, xi0, t, eps_t):
    """The return map's new stick point after a slip: the parameter ξ₁ of the point of the
    segment's curve at the elastic distance t/ε_T behind the slave along the curve (s = t/ε_T
    from it), by Newton on s(ξ₁) from ξ₀; x (10,) the converged positions, ξ the slave's closest
    point. Returns ξ₁ (unchanged if t is ε_T s: a sticking slave keeps its point)."""
    S = np.empty(10)
    target = t / eps_t
    xi1 = xi0
    for _ in range(30):
        s = slip(x, xi, xi1, S)
        px, py, tx, ty, cx, cy, w, dw = _hermite(x, xi1)
        la = np.sqrt(tx * tx + ty * ty)
        # ∂s/∂ξ₁ = −x'(ξ₁)·τ(ξ): about −|x'|
        _, _, ax, ay, _, _, _, _ = _hermite(x, xi)
        lt = np.sqrt(ax * ax + ay * ay)
        ds = -(tx * ax + ty * ay) / lt
        step = (s - target) / ds
        xi1 = xi1 - step
        if abs(step) * la < 1e-14 * (1.0 + abs(target)):
            break
    return xi1


@numba.njit(cache=True, error_model="numpy")
def _vertex_tangent(x, which):
    """The unit tangent (τ_x, τ_y), the speed |x'| and the weights dφ/dξ of the segment's curve
    at its vertex ``which`` (1: a, ξ = 0; 2: b, ξ = 1)."""
    _, _, tx, ty, _, _, _, dw = _hermite(x, 0.0 * x[0] + (which - 1.0))
    la = np.sqrt(tx * tx + ty * ty)
    return tx / la, ty / la, la, dw


@numba.njit(cache=True, error_model="numpy")
def _vertex_friction_force(x, which, nbx, nby, offset, lam, eps, area, eps_t, mu, cohesion, xi0, lam_t, f):
    """Gap, pressure, traction, slip and force f (10,) of one slave at the vertex ``which`` (1: a,
    2: b) of its segment (:func:`node_to_vertex_friction`); returns (g, p, t, s, slipping)."""
    v = 2 + 2 * which
    dx = x[0] - x[v]
    dy = x[1] - x[v + 1]
    dist = np.sqrt(dx * dx + dy * dy)
    sg = 1.0 if (dx * nbx + dy * nby).real >= 0.0 else -1.0
    g = sg * dist - offset
    p = lam - eps * g
    if p.real <= 0.0 or dist.real == 0.0:
        for r in range(10):
            f[r] = 0.0
        return g, 0.0 * p, 0.0 * p, 0.0 * p, False
    taux, tauy, la, dw = _vertex_tangent(x, which)
    w0 = _hermite(x, xi0 + 0.0 * dist)[6]
    r0x = x[0] - (w0[0] * x[2] + w0[1] * x[4] + w0[2] * x[6] + w0[3] * x[8])
    r0y = x[1] - (w0[0] * x[3] + w0[1] * x[5] + w0[2] * x[7] + w0[3] * x[9])
    s = r0x * taux + r0y * tauy
    # δs = (δx_s − Σ φ_k(ξ₀) δx_k)·τ + (r₀·ν/|x'|) ν·Σ dφ_k δx_k, ν = (τ_y, −τ_x): τ turns
    # with the nodes
    q = (r0x * tauy - r0y * taux) / la
    S = np.empty(10, dtype=x.dtype)
    S[0] = taux
    S[1] = tauy
    for k in range(4):
        S[2 + 2 * k] = -w0[k] * taux + q * dw[k] * tauy
        S[3 + 2 * k] = -w0[k] * tauy - q * dw[k] * taux
    t, slipping = _return_map(lam_t, eps_t, s, cohesion, mu, p)
    for r in range(10):
        f[r] = area * t * S[r]
    f[0] -= area * p * sg * dx / dist
    f[1] -= area * p * sg * dy / dist
    f[v] += area * p * sg * dx / dist
    f[v + 1] += area * p * sg * dy / dist
    return g, p, t, s, slipping


@numba.njit(cache=True, error_model="numpy")
def node_to_vertex_friction(x, which, normal, offset, multiplier, penalty, area, eps_t, mu, cohesion, xi0, lam_t,
                            with_tangent):
    r"""Frictional contact of k slaves with master vertices (a sharp corner of the master surface:
    its closest point is the vertex ``which`` (1: a, 2: b) of the slave's segment).

    Normally as :func:`node_to_vertex` (g = ±|x_s − x_v|, the contact normal along
    d = x_s − x_v). Tangentially the slave is attached to the stick point X₀ = Σ φ_k(ξ₀) x_k of its
    segment's curve, as in :func:`node_to_smooth_segment_friction`, and its elastic slip is
    s = (x_s − X₀)·τ_v along the unit tangent τ_v of the segment's curve at the vertex. A tangent
    that turned with d instead would take the slave's motion around the vertex out of the slip
    (at a sharp corner the contact point stays at the vertex) and, with a stick point some way
    back along the segment, turn its slip into a force that grows as |d| shrinks; τ_v is bounded
    and, at the edge of the vertex's region, the segment's own tangent there (the curve ends with
    x'' = 0 at a sharp corner), so that slip, traction and the slave's force carry over. The same
    Coulomb return map, force f = −A p ∂g/∂x + A t ∂s/∂x (gradients of rotation-invariant scalars:
    frame-indifferent, momentum-conserving) and complex-step tangent K.

    x: (k, 10) positions (x_s, x_p, x_a, x_b, x_q) of the segment's stencil; which (k,) int;
    normal (k, 2) the vertices' averaged normals (the side of the gap's sign); offset, multiplier,
    penalty, area, eps_t, mu, cohesion, xi0, lam_t: (k,). Returns g, p, t, s (k,), slipping (k,)
    bool, f (k, 10), K (k, 10, 10)."""
    k = x.shape[0]
    g, p, t, s, slipping, f, K, xc, fc = _friction_arrays(k)
    for i in range(k):
        g[i], p[i], t[i], s[i], slipping[i] = _vertex_friction_force(
            x[i], which[i], normal[i, 0], normal[i, 1], offset[i], multiplier[i], penalty[i], area[i], eps_t[i],
            mu[i], cohesion[i], xi0[i], lam_t[i], f[i])
        if not with_tangent or p[i] <= 0.0:
            continue
        for c in range(10):
            for j in range(10):
                xc[j] = x[i, j]
            xc[c] += 1j * _H
            _vertex_friction_force(xc, which[i], normal[i, 0], normal[i, 1], offset[i], multiplier[i] + 0j,
                                   penalty[i], area[i], eps_t[i], mu[i], cohesion[i], xi0[i], lam_t[i] + 0j, fc)
            for r in range(10):
                K[i, r, c] = fc[r].imag / _H
    return g, p, t, s, slipping, f, K


@numba.njit(cache=True, error_model="numpy")
def vertex_stick_point(x, which, xi0):
    """The parameter ξ₁ of the point of the segment's curve right under a slave at a vertex (its
    slip (x_s − X(ξ₁))·τ_v zero, :func:`node_to_vertex_friction`), by Newton from ξ₀; x (10,)
    the converged positions."""
    taux, tauy, _, _ = _vertex_tangent(x, which)
    xi1 = xi0
    for _ in range(30):
        px, py, tx, ty, _, _, _, _ = _hermite(x, xi1)
        ds = -(tx * taux + ty * tauy)
        if ds == 0.0:
            break
        step = ((x[0] - px) * taux + (x[1] - py) * tauy) / ds
        xi1 = xi1 - step
        if abs(step) < 1e-14:
            break
    return xi1


@numba.njit(cache=True, error_model="numpy")
def curve_points(x, xi):
    """Points (k, 2) of the segments' curves at the parameters ξ (k,); x (k, 10) as in
    :func:`node_to_smooth_segment` (the slave's entries unused)."""
    k = x.shape[0]
    out = np.empty((k, 2))
    for i in range(k):
        px, py, _, _, _, _, _, _ = _hermite(x[i], xi[i])
        out[i, 0] = px
        out[i, 1] = py
    return out

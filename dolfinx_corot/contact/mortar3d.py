r"""Mortar (segment-to-segment) contact kernels in 3D: a slave face against a master face.

A pair is a slave face (k_s = 3 or 4 nodes, counter-clockwise seen from outside the slave body:
its normal points out of it, towards the master) and a master face (k_m = 3 or 4 nodes), stored as
x (k_s + k_m, 3); its dofs are the slave face's translations, then the master face's. The pair's
contribution is an integral over the overlap of the two faces (Puso & Laursen 2004, §3; Popp et
al. 2010 for the clipping and integration):

1. the slave face's plane: its centre c, its unit normal n (of a triangle; of a quadrilateral, the
   cross product of its diagonals) and an orthonormal basis e₁, e₂ in it;
2. both faces projected onto the plane along n; the projected master polygon clips the slave
   polygon (Sutherland–Hodgman; both convex), and the overlap polygon is split into triangles
   from its vertices' mean;
3. on each triangle a 6-point rule of degree 4 (Dunavant 1985); at each point y of the plane the
   slave's and the master's parameters (inverses of the projected maps; Newton for bilinear faces),
   the points x_s = Σ N_A x_A and x_m = Σ N_B x_B, the gap g = (x_m − x_s)·n − Σ N_A c_A (c_A: the
   slave nodes' offsets, initial gaps of staged construction) and the pressure
   p = ⟨Σ N_A λ_A − ε g⟩ (penalty ε; λ_A the augmented-Lagrangian multipliers at the slave nodes);
4. the internal forces f_A = ∫ p N_A n dA on the slave nodes and f_B = −∫ p N_B n dA on the
   master's: equal and opposite along n at each point (linear and angular momentum are conserved),
   and for a uniform pressure the consistent nodal forces of both faces whatever the meshes — the
   patch test on non-matching faces. The weighted gaps ∫ N_A g dA, the slaves' shares of the
   overlap ∫ N_A dA and of the force ∫ N_A p dA are summed per slave node for the Uzawa update
   λ_A ← ⟨λ_A − ε ∫N_A g dA / ∫N_A dA⟩, whose fixed point makes every active node's weighted gap
   vanish (the mortar constraint).

The tangent K = ∂f/∂x is computed by complex-step differentiation of f (Squire & Trapp 1998), the
clipping's branches taken on the real parts: consistent by construction (the overlap's change,
the normal's rotation and the parameters' motion included), not symmetric. A point open by less
than ``touch`` (p's argument in [−ε touch, 0]) adds no force but keeps the penalty's linearization
in K (the value's real part is dropped, its derivative kept): bodies that touch without load are
held in the first iterations, as with node-to-face contact.

References: M. A. Puso and T. A. Laursen, A mortar segment-to-segment contact method for large
deformation solid mechanics, CMAME 193 (2004) 601–629; A. Popp, M. Gee and W. A. Wall, A finite
deformation mortar contact formulation using a primal–dual active set strategy, IJNME 79 (2009)
1354–1391; D. A. Dunavant, High degree efficient symmetrical Gaussian quadrature rules for the
triangle, IJNME 21 (1985) 1129–1148; W. Squire and G. Trapp, SIAM Review 40 (1998) 110–112.
"""
from __future__ import annotations

import numba
import numpy as np

from .kernels3d import QUAD_ETA, QUAD_XI

H = 1e-30  # complex step
NMAX = 4
PAIR_DOFS = 6 * NMAX  # a slave face's nodes, then a master face's, three translations each
# Dunavant's degree-4 rule: barycentric points (a, a, 1 − 2a) and permutations, weights summing to 1
_A1, _W1 = 0.445948490915965, 0.223381589678011
_A2, _W2 = 0.091576213509771, 0.109951743655322
RULE = np.array([[_A1, _A1, _W1], [1.0 - 2.0 * _A1, _A1, _W1], [_A1, 1.0 - 2.0 * _A1, _W1],
                 [_A2, _A2, _W2], [1.0 - 2.0 * _A2, _A2, _W2], [_A2, 1.0 - 2.0 * _A2, _W2]])
_MAXV = 16  # vertices of a clipped polygon at most
CLIP_TOLERANCE = 1e-11  # a vertex this far (× the edge's length) outside a clipping edge counts as on it


@numba.njit(cache=True)
def _shape(k, xi, eta, N):
    if k == 3:
        N[0] = 1.0 - xi - eta
        N[1] = xi
        N[2] = eta
    else:
        for a in range(4):
            N[a] = 0.25 * (1.0 + QUAD_XI[a] * xi) * (1.0 + QUAD_ETA[a] * eta)


@numba.njit(cache=True)
def _parameters(P, k, y0, y1):
    """(ξ, η) of the plane point (y0, y1) in the projected face P (k, 2): barycentric for a
    triangle, Newton on the bilinear map for a quadrilateral (from its centre; two more
    iterations once converged, for the complex step's imaginary part)."""
    if k == 3:
        a0 = P[1, 0] - P[0, 0]
        a1 = P[1, 1] - P[0, 1]
        b0 = P[2, 0] - P[0, 0]
        b1 = P[2, 1] - P[0, 1]
        r0 = y0 - P[0, 0]
        r1 = y1 - P[0, 1]
        det = a0 * b1 - a1 * b0
        return (r0 * b1 - r1 * b0) / det, (a0 * r1 - a1 * r0) / det
    xi = y0 * 0.0
    eta = y0 * 0.0
    done = 0
    for _ in range(30):
        x0 = xi * 0.0
        x1 = xi * 0.0
        j00 = xi * 0.0
        j01 = xi * 0.0
        j10 = xi * 0.0
        j11 = xi * 0.0
        for a in range(4):
            N = 0.25 * (1.0 + QUAD_XI[a] * xi) * (1.0 + QUAD_ETA[a] * eta)
            dx = 0.25 * QUAD_XI[a] * (1.0 + QUAD_ETA[a] * eta)
            de = 0.25 * QUAD_ETA[a] * (1.0 + QUAD_XI[a] * xi)
            x0 += N * P[a, 0]
            x1 += N * P[a, 1]
            j00 += dx * P[a, 0]
            j01 += de * P[a, 0]
            j10 += dx * P[a, 1]
            j11 += de * P[a, 1]
        r0 = y0 - x0
        r1 = y1 - x1
        det = j00 * j11 - j01 * j10
        dxi = (j11 * r0 - j01 * r1) / det
        deta = (j00 * r1 - j10 * r0) / det
        xi += dxi
        eta += deta
        if abs(dxi.real) + abs(deta.real) < 1e-14:
            done += 1
            if done >= 2:
                break
    return xi, eta


@numba.njit(cache=True)
def _normal(x, first, k, n):
    """Unit normal n (3,) of the face of nodes x[first:first + k]: a triangle's, or the cross
    product of a quadrilateral's diagonals; returns |·| before normalizing (real part)."""
    if k == 3:
        a = x[first + 1] - x[first]
        b = x[first + 2] - x[first]
    else:
        a = x[first + 2] - x[first]
        b = x[first + 3] - x[first + 1]
    n[0] = a[1] * b[2] - a[2] * b[1]
    n[1] = a[2] * b[0] - a[0] * b[2]
    n[2] = a[0] * b[1] - a[1] * b[0]
    norm = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
    for d in range(3):
        n[d] /= norm
    return norm.real


@numba.njit(cache=True)
def _clip(S, ns, M, nm, out):
    """The polygon S (ns, 2) clipped by the convex polygon M (nm, 2), both counter-clockwise, into
    out (≤ _MAXV, 2); returns its number of vertices (Sutherland–Hodgman, branches on real parts)."""
    dt = S.dtype
    cur = np.empty((_MAXV, 2), dtype=dt)
    nxt = np.empty((_MAXV, 2), dtype=dt)
    nc = ns
    for i in range(ns):
        cur[i, 0] = S[i, 0]
        cur[i, 1] = S[i, 1]
    for e in range(nm):
        a0, a1 = M[e, 0], M[e, 1]
        b0, b1 = M[(e + 1) % nm, 0], M[(e + 1) % nm, 1]
        t0, t1 = b0 - a0, b1 - a1
        # the clipping line moved out by 1e-11 of the edge: a vertex on the edge (a common border of
        # both surfaces) is inside, not at the mercy of round-off, and no intersection is taken
        # between two points on the line (its derivative would be ill-conditioned)
        tol = CLIP_TOLERANCE * (t0.real * t0.real + t1.real * t1.real)
        nn = 0
        for i in range(nc):
            j = (i + 1) % nc
            di = t0 * (cur[i, 1] - a1) - t1 * (cur[i, 0] - a0) + tol  # > 0: on the inner (left) side
            dj = t0 * (cur[j, 1] - a1) - t1 * (cur[j, 0] - a0) + tol
            if di.real >= 0.0:
                if nn < _MAXV:
                    nxt[nn, 0] = cur[i, 0]
                    nxt[nn, 1] = cur[i, 1]
                    nn += 1
            if (di.real >= 0.0) != (dj.real >= 0.0) and di.real != dj.real:
                s = di / (di - dj)
                if nn < _MAXV:
                    nxt[nn, 0] = cur[i, 0] + s * (cur[j, 0] - cur[i, 0])
                    nxt[nn, 1] = cur[i, 1] + s * (cur[j, 1] - cur[i, 1])
                    nn += 1
        nc = nn
        for i in range(nc):
            cur[i, 0] = nxt[i, 0]
            cur[i, 1] = nxt[i, 1]
        if nc < 3:
            return 0
    for i in range(nc):
        out[i, 0] = cur[i, 0]
        out[i, 1] = cur[i, 1]
    return nc


@numba.njit(cache=True)
def _segment(x, ks, km, lam, off, eps, touch, band, f, nodal):
    """Internal forces f (3 (ks + km),) of one slave–master face pair x (ks + km, 3) (see the
    module's docstring) in the dtype of x; ``nodal`` (ks, 3) += the real parts of ∫N_A g dA,
    ∫N_A dA and ∫N_A p dA. ``band``: whether points open by less than ``touch`` keep the penalty's
    linearization. Returns the numbers of points in contact (p > 0) and in the band."""
    dt = x.dtype
    zero = x[0, 0] * 0.0
    for i in range(f.shape[0]):
        f[i] = zero
    n = np.empty(3, dtype=dt)
    nmst = np.empty(3, dtype=dt)
    if _normal(x, 0, ks, n) <= 0.0 or _normal(x, ks, km, nmst) <= 0.0:
        return 0, 0
    if (n[0] * nmst[0] + n[1] * nmst[1] + n[2] * nmst[2]).real >= 0.0:  # not facing each other
        return 0, 0
    c = np.zeros(3, dtype=dt)
    for a in range(ks):
        for d in range(3):
            c[d] += x[a, d] / ks
    e1 = x[1] - x[0]
    along = e1[0] * n[0] + e1[1] * n[1] + e1[2] * n[2]
    for d in range(3):
        e1[d] -= along * n[d]
    norm = np.sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2])
    for d in range(3):
        e1[d] /= norm
    e2 = np.empty(3, dtype=dt)
    e2[0] = n[1] * e1[2] - n[2] * e1[1]
    e2[1] = n[2] * e1[0] - n[0] * e1[2]
    e2[2] = n[0] * e1[1] - n[1] * e1[0]
    S = np.empty((ks, 2), dtype=dt)
    M = np.empty((km, 2), dtype=dt)
    for a in range(ks):
        S[a, 0] = (x[a, 0] - c[0]) * e1[0] + (x[a, 1] - c[1]) * e1[1] + (x[a, 2] - c[2]) * e1[2]
        S[a, 1] = (x[a, 0] - c[0]) * e2[0] + (x[a, 1] - c[1]) * e2[1] + (x[a, 2] - c[2]) * e2[2]
    for b in range(km):  # the master runs clockwise seen along n: reversed, counter-clockwise
        y = x[ks + km - 1 - b]
        M[b, 0] = (y[0] - c[0]) * e1[0] + (y[1] - c[1]) * e1[1] + (y[2] - c[2]) * e1[2]
        M[b, 1] = (y[0] - c[0]) * e2[0] + (y[1] - c[1]) * e2[1] + (y[2] - c[2]) * e2[2]
    Mf = np.empty((km, 2), dtype=dt)  # in the master's own node order, for its parameters
    for b in range(km):
        Mf[b, 0] = M[km - 1 - b, 0]
        Mf[b, 1] = M[km - 1 - b, 1]
    poly = np.empty((_MAXV, 2), dtype=dt)
    nv = _clip(S, ks, M, km, poly)
    if nv < 3:
        return 0, 0
    q0 = zero
    q1 = zero
    for i in range(nv):
        q0 += poly[i, 0] / nv
        q1 += poly[i, 1] / nv
    Ns = np.empty(ks, dtype=dt)
    Nm = np.empty(km, dtype=dt)
    closed = 0
    touching = 0
    for i in range(nv):
        j = (i + 1) % nv
        u0, u1 = poly[i, 0] - q0, poly[i, 1] - q1
        v0, v1 = poly[j, 0] - q0, poly[j, 1] - q1
        area = 0.5 * (u0 * v1 - u1 * v0)  # signed: the fan sums to the polygon's area even where
        if area.real == 0.0:               # round-off makes a sliver of it turn back
            continue
        for r in range(RULE.shape[0]):
            la, lb, w = RULE[r, 0], RULE[r, 1], RULE[r, 2]
            y0 = q0 + la * u0 + lb * v0
            y1 = q1 + la * u1 + lb * v1
            xi, eta = _parameters(S, ks, y0, y1)
            _shape(ks, xi, eta, Ns)
            xi, eta = _parameters(Mf, km, y0, y1)
            _shape(km, xi, eta, Nm)
            g = zero
            lam_h = zero
            for d in range(3):
                xs = zero
                xm = zero
                for a in range(ks):
                    xs += Ns[a] * x[a, d]
                for b in range(km):
                    xm += Nm[b] * x[ks + b, d]
                g += (xm - xs) * n[d]
            for a in range(ks):
                g -= Ns[a] * off[a]
                lam_h += Ns[a] * lam[a]
            p = lam_h - eps * g
            if p.real > 0.0:
                closed += 1
            elif band and p.real >= -eps * touch:
                p = p - p.real  # no force; the penalty's linearization kept
                touching += 1
            else:
                p = zero
            dA = w * area
            for a in range(ks):
                nodal[a, 0] += (Ns[a] * g * dA).real
                nodal[a, 1] += (Ns[a] * dA).real
                nodal[a, 2] += (Ns[a] * p * dA).real
                for d in range(3):
                    f[3 * a + d] += p * Ns[a] * n[d] * dA
            for b in range(km):
                for d in range(3):
                    f[3 * (ks + b) + d] -= p * Nm[b] * n[d] * dA
    return closed, touching


@numba.njit(cache=True)
def segment_to_segment(x, ks, km, lam, off, eps, touch, band, tangent, f, K, nodal):
    """Force f (3 (ks + km),), (``tangent``) K = ∂f/∂x and the slave nodes' integrals ``nodal``
    (ks, 3, added to) of one pair x (ks + km, 3); returns its number of points in contact. A pair
    without points in contact or in the band has K = 0 (no complex evaluations)."""
    closed, touching = _segment(x, ks, km, lam, off, eps, touch, band, f, nodal)
    if tangent:
        K[:, :] = 0.0
    if tangent and closed + touching > 0:
        m = 3 * (ks + km)
        xc = x.astype(np.complex128)
        fc = np.empty(m, dtype=np.complex128)
        scratch = np.zeros((ks, 3))
        for j in range(m):
            node, d = divmod(j, 3)
            xc[node, d] += 1j * H
            _segment(xc, ks, km, lam, off, eps, touch, band, fc, scratch)
            xc[node, d] = x[node, d]
            for i in range(m):
                K[i, j] = fc[i].imag / H
    return closed


@numba.njit(cache=True)
def faces_to_faces(xs, xm, sfaces, snodes, mfaces, mnodes, sf, mf, lam, off, eps, touch, band, tangent, f, K,
                   nodal, closed):
    """segment_to_segment for pairs (slave face sf[i], master face mf[i]) of slave nodes xs (ns, 3)
    and master nodes xm (nm, 3), faces padded to four nodes (``snodes``, ``mnodes``: their real
    numbers); lam, off (ns,) per slave node. Into f (p, 24), K (p, 24, 24) (zero beyond a pair's
    dofs: a triangle's fourth node), nodal (ns, 3) (added to) and closed (p,)."""
    for i in range(len(sf)):
        ks = snodes[sf[i]]
        km = mnodes[mf[i]]
        x = np.empty((ks + km, 3))
        la = np.empty(ks)
        oa = np.empty(ks)
        for a in range(ks):
            x[a] = xs[sfaces[sf[i], a]]
            la[a] = lam[sfaces[sf[i], a]]
            oa[a] = off[sfaces[sf[i], a]]
        for b in range(km):
            x[ks + b] = xm[mfaces[mf[i], b]]
        m = 3 * (ks + km)
        fi = np.zeros(m)
        Ki = np.zeros((m, m))
        part = np.zeros((ks, 3))
        closed[i] = segment_to_segment(x, ks, km, la, oa, eps, touch, band, tangent, fi, Ki, part)
        for a in range(ks):
            for c in range(3):
                nodal[sfaces[sf[i], a], c] += part[a, c]
        f[i, :] = 0.0
        K[i, :, :] = 0.0
        # the slave's nodes at 0 … 3 ks − 1 → 0 …, the master's at 3 ks … → 12 …
        for r in range(m):
            rr = r if r < 3 * ks else 12 + r - 3 * ks
            f[i, rr] = fi[r]
            for s in range(m):
                ss = s if s < 3 * ks else 12 + s - 3 * ks
                K[i, rr, ss] = Ki[r, s]

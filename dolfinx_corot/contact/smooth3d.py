r"""Node-to-face contact against a smoothed master surface in 3D: averaged nodal normals, the
Nagata patches through them and the normal field they interpolate.

Each master node a of a face carries the unit normal n_a = s_a/|s_a|, s_a = Σ_f c_f the sum of
the area vectors of the faces around it (c_f = (x_2 − x_1) × (x_3 − x_1) for a triangle, the
cross product of the diagonals (x_3 − x_1) × (x_4 − x_2) for a quadrilateral; twice the area
times the unit normal), taken over the faces whose normal in the reference configuration lies
within the smoothing angle of the face's own: across a sharp feature (a block's corner edge)
each side keeps its own normals. The face is the Nagata patch x(ξ) = Σ N_a x_a − Σ_e c_e B_e
through its nodes and their normals (:func:`surface`; Nagata 2005, Neto et al. 2014). The normal
field over it is n̄(ξ) = Σ N_a(ξ) n_a, and the slave's contact point is found along it, not
along the shortest distance (the "normal field projection"; Puso & Laursen 2004 and Popp et al.
2009 project along averaged nodal normals in their mortar methods; Wriggers 2006, §9.1.2):

    x_s = x(ξ) + t n̄(ξ),   three equations for (ξ, η, t),

solved by Newton from the flat closest point. The gap is g = t |n̄| − offset (the distance along
the unit normal ν = n̄/|n̄|), the pressure p = ⟨λ − ε g⟩ and the forces act along ν:

    f_s = −A p ν,   f_a = A p w_a ν   (a = the face's nodes),

with w the shape functions where the line x(ξ) + s ν meets the flat face (:func:`_weights`).
The forces sum to zero and their moment vanishes (x_s − Σ w_a x_a is parallel to ν), so the
pair conserves linear and angular momentum. On a shared edge the patch, the normal field and
so g and ν depend only on the edge's two nodes and their normals: a slave crossing from face to
face sees its gap, normal and force pass continuously — no jump of the force direction at the
edges of a faceted curved master, whose normal turns by the angle between the faces (the
master nodes' shares w differ between the two faces by the distance, along ν, of the curved
edge from the flat faces' planes: 1e-5 of the force in the tests). On a flat surface all
normals are the face's, every c_e vanishes and the kernel is the flat one's (the patch test
holds).

The force is not the gradient of an energy (the gap's derivatives with respect to ξ do not drop
out along a normal field other than the face's), so its exact derivative K = ∂f/∂x is not
symmetric; it is computed by complex-step differentiation (Squire & Trapp 1998) over all the
dofs the force depends on: the slave, the face's nodes and the nodes of the faces around them
(the pair's stencil, through the nodal normals). The direct solver factors an unsymmetric
matrix while such a pair is engaged.

Stencil data per master face (:func:`stencils`): ``ext`` (nf, W) its nodes then the other nodes
of the faces around them (−1 padded), ``star`` (nf, 4, S, 5) for each of its nodes the faces
around it ([nodes, rows of their nodes in the pair's coordinates x (1 + W, 3), row 0 the
slave]) and ``nstar`` (nf, 4) their number.
"""
from __future__ import annotations

import numba
import numpy as np

from .kernels3d import H, convected, coulomb_traction, project, shape, tangent_step

_NEWTON_ITERATIONS = 30


@numba.njit(cache=True)
def _triple(a, b, c):
    """a · (b × c)."""
    return (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
            a[2] * (b[0] * c[1] - b[1] * c[0]))


@numba.njit(cache=True)
def _normal_field(k, N, nn, out):
    """n̄ = Σ N_a n_a into out (3,); returns |n̄|."""
    for d in range(3):
        out[d] = 0.0
        for a in range(k):
            out[d] += N[a] * nn[a, d]
    return np.sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2])


@numba.njit(cache=True)
def _area_vector(x, star, a, j, out):
    """c_f of face j around face node a (rows of x in star[a, j, 1:])."""
    r0, r1, r2, r3 = star[a, j, 1], star[a, j, 2], star[a, j, 3], star[a, j, 4]
    if star[a, j, 0] == 3:
        u0, u1, u2 = x[r1, 0] - x[r0, 0], x[r1, 1] - x[r0, 1], x[r1, 2] - x[r0, 2]
        v0, v1, v2 = x[r2, 0] - x[r0, 0], x[r2, 1] - x[r0, 1], x[r2, 2] - x[r0, 2]
    else:
        u0, u1, u2 = x[r2, 0] - x[r0, 0], x[r2, 1] - x[r0, 1], x[r2, 2] - x[r0, 2]
        v0, v1, v2 = x[r3, 0] - x[r1, 0], x[r3, 1] - x[r1, 1], x[r3, 2] - x[r1, 2]
    out[0] = u1 * v2 - u2 * v1
    out[1] = u2 * v0 - u0 * v2
    out[2] = u0 * v1 - u1 * v0


@numba.njit(cache=True)
def nodal_normals(x, k, star, nstar, nn):
    """The unit normals nn (k, 3) at the face's nodes (rows 1 … k of x): the normalized sums of
    the area vectors of the faces around each (``star``, ``nstar`` of this face)."""
    c = np.empty(3, dtype=x.dtype)
    for a in range(k):
        for d in range(3):
            nn[a, d] = 0.0
        for j in range(nstar[a]):
            _area_vector(x, star, a, j, c)
            for d in range(3):
                nn[a, d] += c[d]
        norm = np.sqrt(nn[a, 0] * nn[a, 0] + nn[a, 1] * nn[a, 1] + nn[a, 2] * nn[a, 2])
        for d in range(3):
            nn[a, d] /= norm


@numba.njit(cache=True)
def _edge_curvature(x, nn, a, b, c):
    """The curvature coefficient c (3,) of the edge from face node a to b, whose curve is the
    quadratic x(s) = (1 − s) x_a + s x_b − c s (1 − s): c = (d·Δ/|v|²) v with d = x_b − x_a,
    v = (n_a + n_b)/2, Δ = (n_a − n_b)/2, the part along the mean normal of Nagata's coefficient
    (Nagata 2005: c = (d·Δ/|v|²) v + (d·v/|Δ|²) Δ). Nagata's second, in-plane part makes the end
    tangents exactly normal to both nodal normals; it vanishes on circular arcs, cylinders and
    spheres (there the chord is normal to the mean normal) and is singular as the normals turn
    parallel (1/|Δ|²): on a nearly flat, slightly rough surface it reached 25 times the edge's
    length, folding the patch and making the point along the normal field jump. It is left out."""
    dd = x[0, 0] * 0.0
    vv = dd
    for d in range(3):
        v = 0.5 * (nn[a, d] + nn[b, d])
        dd += (x[1 + b, d] - x[1 + a, d]) * 0.5 * (nn[a, d] - nn[b, d])
        vv += v * v
    for d in range(3):
        c[d] = dd / vv * 0.5 * (nn[a, d] + nn[b, d])


@numba.njit(cache=True)
def surface(x, k, nn, xi, eta, xc, t1, t2):
    """The point xc (3,) and tangents t1 = ∂xc/∂ξ, t2 = ∂xc/∂η of the face's Nagata patch at (ξ, η):
    xc = Σ N_a x_a − Σ_e c_e B_e, B_e = N_a N_b on a triangle's edge (a, b) and the bilinear
    quadrilateral's s(1 − s) along the edge times the linear decay across it: each edge curve
    depends only on its two nodes and their normals."""
    dt = x.dtype
    N = np.empty(k, dtype=dt)
    dN = np.empty((k, 2), dtype=dt)
    shape(k, xi, eta, N, dN)
    c = np.empty(3, dtype=dt)
    for d in range(3):
        xc[d] = 0.0
        t1[d] = 0.0
        t2[d] = 0.0
        for a in range(k):
            xc[d] += N[a] * x[1 + a, d]
            t1[d] += dN[a, 0] * x[1 + a, d]
            t2[d] += dN[a, 1] * x[1 + a, d]
    for a in range(k):
        b = (a + 1) % k
        _edge_curvature(x, nn, a, b, c)
        if k == 3:
            B = N[a] * N[b]
            B1 = dN[a, 0] * N[b] + N[a] * dN[b, 0]
            B2 = dN[a, 1] * N[b] + N[a] * dN[b, 1]
        elif a % 2 == 0:  # edges 0 (η = −1) and 2 (η = 1): along ξ
            s = 1.0 if a == 2 else -1.0
            B = 0.125 * (1.0 - xi * xi) * (1.0 + s * eta)
            B1 = -0.25 * xi * (1.0 + s * eta)
            B2 = 0.125 * s * (1.0 - xi * xi)
        else:  # edges 1 (ξ = 1) and 3 (ξ = −1): along η
            s = 1.0 if a == 1 else -1.0
            B = 0.125 * (1.0 - eta * eta) * (1.0 + s * xi)
            B1 = 0.125 * s * (1.0 - eta * eta)
            B2 = -0.25 * eta * (1.0 + s * xi)
        for d in range(3):
            xc[d] -= c[d] * B
            t1[d] -= c[d] * B1
            t2[d] -= c[d] * B2


@numba.njit(cache=True)
def normal_point(x, k, nn, xi, eta, t):
    """(ξ, η, t, converged) with x_s = x(ξ) + t Σ N_a n_a (the slave x[0], x(ξ) the point of the
    Nagata patch of the face's nodes x[1 … k] and their normals nn, :func:`surface`), by Newton
    from (ξ, η, t) (steps at most the face's size); in the dtype of x (complex for the complex
    step: two more iterations for the imaginary part)."""
    dt = x.dtype
    N = np.empty(k, dtype=dt)
    dN = np.empty((k, 2), dtype=dt)
    F = np.empty(3, dtype=dt)
    a1 = np.empty(3, dtype=dt)
    a2 = np.empty(3, dtype=dt)
    a3 = np.empty(3, dtype=dt)
    done = 0
    for it in range(_NEWTON_ITERATIONS):
        shape(k, xi, eta, N, dN)
        surface(x, k, nn, xi, eta, F, a1, a2)
        for d in range(3):
            F[d] -= x[0, d]
            a3[d] = 0.0
            for a in range(k):
                F[d] += N[a] * t * nn[a, d]
                a1[d] += dN[a, 0] * t * nn[a, d]
                a2[d] += dN[a, 1] * t * nn[a, d]
                a3[d] += N[a] * nn[a, d]
        # Cramer's rule for J (dξ, dη, dt) = −F, J = [a1 a2 a3]
        det = _triple(a1, a2, a3)
        if det.real == 0.0:
            return xi, eta, t, False
        dxi = -_triple(F, a2, a3) / det
        deta = -_triple(a1, F, a3) / det
        dtt = -_triple(a1, a2, F) / det
        step = abs(dxi.real) + abs(deta.real)
        if step > 1.0:
            dxi /= step
            deta /= step
            dtt /= step
        xi += dxi
        eta += deta
        t += dtt
        if step < 1e-13:
            done += 1
            if done >= 2:
                return xi, eta, t, True
    return xi, eta, t, False


@numba.njit(cache=True)
def start_point(x, k, nn):
    """A start for :func:`normal_point`: the flat closest point, and t the slave's distance
    along the normal field there."""
    xi, eta, _ = project(x[: 1 + k], k)
    N = np.empty(k, dtype=x.dtype)
    dN = np.empty((k, 2), dtype=x.dtype)
    shape(k, xi, eta, N, dN)
    xc = np.empty(3, dtype=x.dtype)
    t1 = np.empty(3, dtype=x.dtype)
    t2 = np.empty(3, dtype=x.dtype)
    surface(x, k, nn, xi, eta, xc, t1, t2)
    nb = np.empty(3, dtype=x.dtype)
    norm = _normal_field(k, N, nn, nb)
    num = x[0, 0] * 0.0
    for d in range(3):
        num += (x[0, d] - xc[d]) * nb[d]
    return xi, eta, num / (norm * norm)


@numba.njit(cache=True)
def _weights(x, k, xc, nu, xi, eta, N):
    """The weights N (k,) of the face's nodes for a force along ν at the contact point xc: the shape
    functions where the line xc + s ν meets the flat (bilinear) face, by Newton from (ξ, η). With
    them the face nodes' forces have the moment of the slave's (the curved patch's point lies off
    the flat face)."""
    dt = x.dtype
    dN = np.empty((k, 2), dtype=dt)
    r = np.empty(3, dtype=dt)
    a1 = np.empty(3, dtype=dt)
    a2 = np.empty(3, dtype=dt)
    done = 0
    for it in range(_NEWTON_ITERATIONS):
        shape(k, xi, eta, N, dN)
        for d in range(3):  # r = Σ N_a x_a − xc (− s ν, s eliminated by the cross products below)
            r[d] = -xc[d]
            a1[d] = 0.0
            a2[d] = 0.0
            for a in range(k):
                r[d] += N[a] * x[1 + a, d]
                a1[d] += dN[a, 0] * x[1 + a, d]
                a2[d] += dN[a, 1] * x[1 + a, d]
        # J (dξ, dη, ds) = −r with J = [a1 a2 −ν]: Cramer's rule for dξ, dη
        det = -_triple(a1, a2, nu)
        dxi = _triple(r, a2, nu) / det
        deta = _triple(a1, r, nu) / det
        xi += dxi
        eta += deta
        if abs(dxi.real) + abs(deta.real) < 1e-13:
            done += 1
            if done >= 2:
                break
    shape(k, xi, eta, N, dN)


@numba.njit(cache=True)
def _normal_force(x, k, star, nstar, side, offset, lam, eps, area, xi0, eta0, t0, f, nn, nu, N):
    """Gap, pressure and force f (3 (1 + W),) of one pair along the normal field (module docstring),
    the point sought from (ξ0, η0, t0); f zero beyond the face's nodes; into nn (k, 3) the nodal
    normals, nu (3,) the unit normal ν, N (k,) the face nodes' weights. Returns (g, p, ξ, η)."""
    dt = x.dtype
    nodal_normals(x, k, star, nstar, nn)
    xi, eta, t, _ = normal_point(x, k, nn, xi0 + 0.0 * x[0, 0], eta0 + 0.0 * x[0, 0], t0 + 0.0 * x[0, 0])
    dN = np.empty((k, 2), dtype=dt)
    shape(k, xi, eta, N, dN)
    norm = _normal_field(k, N, nn, nu)
    sign = -1.0 if side < 0.0 else 1.0
    for d in range(3):
        nu[d] = sign * nu[d] / norm
    g = sign * t * norm - offset
    xc = np.empty(3, dtype=dt)
    t1 = np.empty(3, dtype=dt)
    t2 = np.empty(3, dtype=dt)
    surface(x, k, nn, xi, eta, xc, t1, t2)
    _weights(x, k, xc, nu, xi, eta, N)
    p = lam - eps * g
    if p.real <= 0.0:
        p = 0.0 * p
    for j in range(len(f)):
        f[j] = 0.0
    for d in range(3):
        f[d] = -area * p * nu[d]
        for a in range(k):
            f[3 + 3 * a + d] = area * p * N[a] * nu[d]
    return g, p, xi, eta


@numba.njit(cache=True)
def _force(x, k, star, nstar, side, offset, lam, eps, area, xi0, eta0, t0, f):
    """Gap and force f (3 (1 + W),) of one pair along the normal field (:func:`_normal_force`)."""
    dt = x.dtype
    nn = np.empty((k, 3), dtype=dt)
    nu = np.empty(3, dtype=dt)
    N = np.empty(k, dtype=dt)
    return _normal_force(x, k, star, nstar, side, offset, lam, eps, area, xi0, eta0, t0, f, nn, nu, N)[0]


@numba.njit(cache=True)
def node_to_smooth_face(x, k, rows, star, nstar, side, offset, lam, eps, area, tangent, f, K, touch=0.0):
    """Gap g (inf if the point along the normal field is not found), force f (3 (1 + W),) and
    (``tangent``) K = ∂f/∂x of a slave x[0] against a face (nodes x[1 … k]) whose stencil has
    ``rows`` rows of x besides the slave (the rest padding); ``side``, ``offset``, ``touch`` as in
    :func:`~dolfinx_corot.contact.kernels3d.node_to_face`. Returns (g, ξ, η)."""
    nn = np.empty((k, 3))
    nodal_normals(x, k, star, nstar, nn)
    xi, eta, t = start_point(x, k, nn)
    xi, eta, t, ok = normal_point(x, k, nn, xi, eta, t)
    f[:] = 0.0
    K[:, :] = 0.0
    if not ok:
        return np.inf, xi, eta
    g = _force(x, k, star, nstar, side, offset, lam, eps, area, xi, eta, t, f)
    if not tangent:
        return g, xi, eta
    m = 3 * (1 + rows)
    if lam - eps * g <= 0.0:
        if lam - eps * g >= -eps * touch:  # the touch band: A ε w wᵀ, w the force's direction per unit p
            w = np.zeros(m)
            fw = np.zeros(len(f))
            _force(x, k, star, nstar, side, offset, 1.0 + eps * g, eps, 1.0, xi, eta, t, fw)
            w[:] = -fw[:m]
            for i in range(m):
                for j in range(m):
                    K[i, j] = area * eps * w[i] * w[j]
        return g, xi, eta
    xc = x.astype(np.complex128)
    fc = np.empty(len(f), dtype=np.complex128)
    for j in range(m):
        node, d = divmod(j, 3)
        xc[node, d] += 1j * H
        _force(xc, k, star, nstar, side, offset, lam, eps, area, xi, eta, t, fc)
        xc[node, d] = x[node, d]
        for i in range(m):
            K[i, j] = fc[i].imag / H
    return g, xi, eta


@numba.njit(cache=True)
def _gather(xs, xm, ext, slave, face, x):
    """The pair's coordinates x (1 + W, 3): the slave, then the stencil's nodes (padding: the
    slave again, never read by a face's normals); returns the stencil's size."""
    x[0] = xs[slave]
    rows = 0
    for j in range(ext.shape[1]):
        v = ext[face, j]
        if v >= 0:
            x[1 + j] = xm[v]
            rows = j + 1
        else:
            x[1 + j] = xs[slave]
    return rows


@numba.njit(cache=True)
def pairs_to_smooth_faces(xs, xm, ext, nodes, star, nstar, s, m, side, offset, lam, eps, area, tangent, g, f, K,
                          touch=0.0):
    """node_to_smooth_face for pairs (slave s[i], face m[i]): g (p,), f (p, 3 (1 + W)),
    K (p, 3 (1 + W), 3 (1 + W))."""
    W = ext.shape[1]
    x = np.empty((1 + W, 3))
    for i in range(len(s)):
        rows = _gather(xs, xm, ext, s[i], m[i], x)
        g[i], _, _ = node_to_smooth_face(x, nodes[m[i]], rows, star[m[i]], nstar[m[i]], side[i], offset[i], lam[i],
                                         eps[i], area[i], tangent, f[i], K[i], touch)


@numba.njit(cache=True)
def smooth_on_faces(xs, xm, ext, nodes, star, nstar, s, m, out_xi, out_eta, out_dist, out_ok):
    """For each candidate pair (s[i], m[i]): the point (ξ, η) along the face's normal field, the
    slave's signed distance t |n̄| along it and whether it was found."""
    W = ext.shape[1]
    x = np.empty((1 + W, 3))
    for i in range(len(s)):
        _gather(xs, xm, ext, s[i], m[i], x)
        k = nodes[m[i]]
        nn = np.empty((k, 3))
        nodal_normals(x, k, star[m[i]], nstar[m[i]], nn)
        xi, eta, t = start_point(x, k, nn)
        xi, eta, t, ok = normal_point(x, k, nn, xi, eta, t)
        N = np.empty(k)
        dN = np.empty((k, 2))
        shape(k, xi, eta, N, dN)
        out_xi[i] = xi
        out_eta[i] = eta
        out_dist[i] = t * _normal_field(k, N, nn, np.empty(3))
        out_ok[i] = ok


@numba.njit(cache=True)
def stencils(faces, nodes, normal, cos_sharp, node_ptr, node_faces, W, S):
    """The stencil of each face (module docstring) of faces (nf, 4) with ``nodes`` (nf,) nodes,
    reference unit normals ``normal`` (nf, 3), the faces around each node (CSR ``node_ptr``,
    ``node_faces``): a face around node a joins a's normal if its normal is within the smoothing
    angle (cos ``cos_sharp``) of the face's own. ``W`` and ``S`` bound the stencil's width and
    the faces per node; returns (ext, star, nstar, width used, faces per node used)."""
    nf = len(faces)
    ext = np.full((nf, W), -1, dtype=np.int64)
    star = np.zeros((nf, 4, S, 5), dtype=np.int64)
    nstar = np.zeros((nf, 4), dtype=np.int64)
    wmax = 0
    smax = 0
    for m in range(nf):
        k = nodes[m]
        cnt = 0
        for a in range(k):
            ext[m, a] = faces[m, a]
        cnt = k
        for a in range(k):
            v = faces[m, a]
            for q in range(node_ptr[v], node_ptr[v + 1]):
                fq = node_faces[q]
                dot = normal[fq, 0] * normal[m, 0] + normal[fq, 1] * normal[m, 1] + normal[fq, 2] * normal[m, 2]
                if dot < cos_sharp:
                    continue
                j = nstar[m, a]
                nstar[m, a] += 1
                smax = max(smax, j + 1)
                if j >= S:
                    continue
                star[m, a, j, 0] = nodes[fq]
                for b in range(4):
                    w = faces[fq, b] if b < nodes[fq] else faces[fq, 0]
                    r = -1
                    for c in range(min(cnt, W)):
                        if ext[m, c] == w:
                            r = c
                            break
                    if r < 0:
                        if cnt < W:
                            ext[m, cnt] = w
                        r = cnt
                        cnt += 1
                    star[m, a, j, 1 + b] = 1 + r
        wmax = max(wmax, cnt)
    return ext, star, nstar, wmax, smax


def build_stencils(X: np.ndarray, facets: np.ndarray, sharp: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ext, star, nstar) of the faces ``facets`` (nf, 3 or 4) of nodes X (the reference
    configuration): a face around a node joins the node's normal for a face if their normals
    differ by less than ``sharp`` radians (see :func:`stencils`)."""
    nf, k = facets.shape
    faces = np.hstack([facets, np.repeat(facets[:, :1], 4 - k, axis=1)]).astype(np.int64)
    nodes = np.full(nf, k, dtype=np.int64)
    x = X[faces]
    c = (np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]) if k == 3 else
         np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]))
    normal = c / np.linalg.norm(c, axis=1)[:, None]
    owner = np.repeat(np.arange(nf), k)[np.argsort(facets.ravel(), kind="stable")].astype(np.int64)
    ptr = np.zeros(len(X) + 1, dtype=np.int64)
    ptr[1:] = np.cumsum(np.bincount(facets.ravel(), minlength=len(X)))
    W, S = 16, 8
    while True:
        ext, star, nstar, w, n = stencils(faces, nodes, normal, np.cos(sharp), ptr, owner, W, S)
        if w <= W and n <= S:
            return ext[:, :w], star[:, :, :n], nstar
        W, S = max(W, w), max(S, n)


# -- Coulomb friction on the smoothed master ---------------------------------------------------
@numba.njit(cache=True)
def _friction_force(x, k, star, nstar, side, offset, lam, eps, area, eps_t, mu, cohesion, xs0, es0, lam_t, xi, eta,
                    tt, f, t, n):
    """Gap, pressure and slip state of one frictional pair along the normal field, with its force
    f (3 (1 + W),), traction t (3,) and normal n = ν (3,), the stick point at (ξ₀, η₀) = (xs0, es0)
    on the face's patch, the tangential multiplier's components lam_t (3,) on the patch's
    convected basis there, the contact point sought from (ξ, η, tt); returns (g, p, slipping)."""
    dt = x.dtype
    nn = np.empty((k, 3), dtype=dt)
    N = np.empty(k, dtype=dt)
    g, p, _, _ = _normal_force(x, k, star, nstar, side, offset, lam, eps, area, xi, eta, tt, f, nn, n, N)
    for d in range(3):
        t[d] = 0.0
    if p.real <= 0.0:
        return g, p, False
    X0 = np.empty(3, dtype=dt)
    t1 = np.empty(3, dtype=dt)
    t2 = np.empty(3, dtype=dt)
    zero = x[0, 0] * 0.0
    surface(x, k, nn, xs0 + zero, es0 + zero, X0, t1, t2)
    lt = np.empty(3, dtype=dt)
    convected(t1, t2, lam_t, lt)
    slipping = coulomb_traction(x[0], X0, n, p, eps_t, mu, cohesion, lt, t)
    for d in range(3):
        f[d] += area * t[d]
        for a in range(k):
            f[3 + 3 * a + d] -= area * N[a] * t[d]
    return g, p, slipping


@numba.njit(cache=True)
def _attach_patch(x, k, nn, y, n, xi, eta):
    """(ξ, η) of the point x(ξ) of the face's Nagata patch (extended beyond the face) on the line
    through y along n, by Gauss–Newton from (ξ, η); real."""
    X = np.empty(3)
    a1 = np.empty(3)
    a2 = np.empty(3)
    e = np.empty(3)
    for it in range(_NEWTON_ITERATIONS):
        surface(x, k, nn, xi, eta, X, a1, a2)
        for d in range(3):
            e[d] = y[d] - X[d]
        xi, eta, step = tangent_step(a1, a2, e, n, xi, eta)
        if step < 1e-14:
            break
    return xi, eta


@numba.njit(cache=True)
def node_to_smooth_face_friction(x, k, rows, star, nstar, side, offset, lam, eps, area, eps_t, mu, cohesion, attach,
                                 y, xi0, lam_t, tangent, f, K, t, n, touch=0.0):
    """Frictional contact of a slave x[0] with a smoothed face: the normal part as
    :func:`node_to_smooth_face`, the tangential one as
    :func:`~dolfinx_corot.contact.kernels3d.node_to_face_friction` with the stick point on the
    face's Nagata patch, X₀ = x(ξ₀), the slip s = (I − ν νᵀ)(x_s − X₀) in the tangent plane of
    the normal field's ν, and the traction's reaction on the face nodes with the normal force's
    weights. ``attach``, y, xi0 (2,), lam_t (3,) as there (the stick point where the line through
    y along ν meets the patch; the multiplier's components on the patch's convected basis at the
    stick point). Returns (g, p, slipping)."""
    nn = np.empty((k, 3))
    nodal_normals(x, k, star, nstar, nn)
    xi, eta, tt = start_point(x, k, nn)
    xi, eta, tt, ok = normal_point(x, k, nn, xi, eta, tt)
    f[:] = 0.0
    K[:, :] = 0.0
    t[:] = 0.0
    if not ok:
        return np.inf, 0.0, False
    g, p, slipping = _friction_force(x, k, star, nstar, side, offset, lam, eps, area, eps_t, mu, cohesion, xi0[0],
                                     xi0[1], lam_t, xi, eta, tt, f, t, n)
    if p <= 0.0:
        g, _, _ = node_to_smooth_face(x, k, rows, star, nstar, side, offset, lam, eps, area, tangent, f, K, touch)
        return g, 0.0, False
    if attach:
        xi0[0], xi0[1] = _attach_patch(x, k, nn, y, n, xi, eta)
        g, p, slipping = _friction_force(x, k, star, nstar, side, offset, lam, eps, area, eps_t, mu, cohesion,
                                         xi0[0], xi0[1], lam_t, xi, eta, tt, f, t, n)
    if tangent:
        m = 3 * (1 + rows)
        xc = x.astype(np.complex128)
        fc = np.empty(len(f), dtype=np.complex128)
        tc = np.empty(3, dtype=np.complex128)
        nc = np.empty(3, dtype=np.complex128)
        for j in range(m):
            node, d = divmod(j, 3)
            xc[node, d] += 1j * H
            _friction_force(xc, k, star, nstar, side, offset, lam + 0j, eps, area, eps_t, mu, cohesion, xi0[0],
                            xi0[1], lam_t, xi, eta, tt, fc, tc, nc)
            xc[node, d] = x[node, d]
            for i in range(m):
                K[i, j] = fc[i].imag / H
    return g, p, slipping


@numba.njit(cache=True)
def pairs_to_smooth_faces_friction(xs, xm, ext, nodes, star, nstar, s, m, side, offset, lam, eps, area, eps_t, mu,
                                   cohesion, attach, y, xi0, lam_t, tangent, g, p, slipping, t, n, f, K, touch=0.0):
    """node_to_smooth_face_friction for pairs (slave s[i], face m[i]) as :func:`pairs_to_smooth_faces`;
    attach, y (p, 3), xi0 (p, 2) (in and out), lam_t (p, 3), p, slipping, t (p, 3), n (p, 3) per pair."""
    W = ext.shape[1]
    x = np.empty((1 + W, 3))
    for i in range(len(s)):
        rows = _gather(xs, xm, ext, s[i], m[i], x)
        g[i], p[i], slipping[i] = node_to_smooth_face_friction(
            x, nodes[m[i]], rows, star[m[i]], nstar[m[i]], side[i], offset[i], lam[i], eps[i], area[i], eps_t, mu,
            cohesion, attach[i], y[i], xi0[i], lam_t[i], tangent, f[i], K[i], t[i], n[i], touch)


@numba.njit(cache=True)
def _patch(point, xm, ext, nodes, star, nstar, face, x):
    """Gathers into x (1 + W, 3) the point (row 0) and the stencil of face ``face``; returns the
    face's nodes k and their nodal normals (k, 3)."""
    x[0] = point
    for j in range(ext.shape[1]):
        x[1 + j] = xm[ext[face, j]] if ext[face, j] >= 0 else point
    k = nodes[face]
    nn = np.empty((k, 3))
    nodal_normals(x, k, star[face], nstar[face], nn)
    return k, nn


@numba.njit(cache=True)
def attach_on_patches(xm, ext, nodes, star, nstar, m, y, n, xi0):
    """The stick points (ξ₀, η₀) in xi0 (p, 2) (start in, result out) on the patches of faces m
    where the lines through y (p, 3) along n (p, 3) meet them."""
    x = np.empty((1 + ext.shape[1], 3))
    for i in range(len(m)):
        k, nn = _patch(y[i], xm, ext, nodes, star, nstar, m[i], x)
        xi0[i, 0], xi0[i, 1] = _attach_patch(x, k, nn, y[i], n[i], xi0[i, 0], xi0[i, 1])


@numba.njit(cache=True)
def patch_frames(xm, ext, nodes, star, nstar, m, xi0, out, a1, a2):
    """The points x(ξ₀) (p, 3) of the patches of faces m (p,) at the parameters xi0 (p, 2) and
    their bases a_α = ∂x/∂ξ^α (p, 3) each."""
    x = np.empty((1 + ext.shape[1], 3))
    for i in range(len(m)):
        k, nn = _patch(xm[ext[m[i], 0]], xm, ext, nodes, star, nstar, m[i], x)
        surface(x, k, nn, xi0[i, 0], xi0[i, 1], out[i], a1[i], a2[i])


@numba.njit(cache=True)
def patch_points(xm, ext, nodes, star, nstar, m, xi0, out):
    """The points of :func:`patch_frames` alone."""
    patch_frames(xm, ext, nodes, star, nstar, m, xi0, out, np.empty_like(out), np.empty_like(out))

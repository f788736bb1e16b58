r"""Node-to-face contact kernels in 3D: a slave node against a triangle or a bilinear quadrilateral.

A pair is the slave x_s and the face's nodes x_1 … x_k (k = 3 or 4, counter-clockwise seen from
outside the master body, so that the face normal points out of it), stored as x (1 + k, 3); the
pair's dofs are the slave's translations then the face nodes'. The contact point x_c is the
closest point to the slave

* on the face (``mode`` 0): x_c = Σ N_a(ξ) x_a with ξ = (ξ, η) solving (x_s − x_c)·∂x_c/∂ξ_i = 0
  (one Newton step for triangles, a few for the bilinear quadrilateral), n the unit normal
  x_{,ξ} × x_{,η} / |·| there;
* on the edge e from local node e to e + 1 (``mode`` 1, where the slave is beyond a convex edge):
  x_c = (1 − t) x_a + t x_b, n = ±(x_s − x_c)/|x_s − x_c|;
* at the vertex v (``mode`` 2): x_c = x_v, n = ±(x_s − x_v)/|x_s − x_v|,

the sign making n point out of the master (the side of the face normal at the face's centre).
A two-sided master (a shell's mid-surface, whose contact faces lie at ±t/2 on either side) is
met on the slave's ``side`` (±1): on the face n = side × the face normal, at an edge or a vertex
n = (x_s − x_c)/|x_s − x_c| (the free edge of a shell is met as a rounded edge); ``side`` 0 is
the one-sided master of a solid. Beyond the border of a solid's surface (``side`` BORDER) the
body's side faces are not known: a slave beyond a border edge or vertex counts as inside only
below the 45° line from it (deeper below the face's plane than it is beyond the border), so that
a slave beside the body, at or a hair below the face's plane, is outside (grazing), and one that
sinks below a shared border (two blocks flush, pressed) is still held.
Gap g = (x_s − x_c)·n − offset (offset: a shell's half thickness, a beam's half depth); pressure
p = ⟨λ − ε g⟩ (penalty ε; λ the augmented-Lagrangian multiplier, 0 for pure penalty); with the
slave's tributary area A the pair's energy is W = A ⟨λ − ε g⟩²/(2ε) and its internal force
f = ∂W/∂x = −A p ∂g/∂x, with ∂g/∂x_s = n and ∂g/∂x_a = −N_a n (the closest point's parametric
derivatives drop out at the projection). The tangent K = ∂f/∂x is computed by complex-step
differentiation of f (Squire & Trapp 1998; h = 1e-30: exact to round-off), each column one
complex evaluation of the projection and the force — consistent by construction, symmetric
(the Hessian of W).

References: P. Wriggers, *Computational Contact Mechanics*, 2nd ed., Springer 2006, §4.1 and
§9.1 (3D node-to-surface contact, closest-point projection, edge and vertex contact);
T. A. Laursen, *Computational Contact and Impact Mechanics*, Springer 2002, ch. 5; W. Squire and
G. Trapp, SIAM Review 40 (1998) 110–112.
"""
from __future__ import annotations

import numba
import numpy as np

H = 1e-30  # complex step
NMAX = 4   # nodes of a face at most
PAIR_DOFS = 3 * (1 + NMAX)
QUAD_XI = np.array([-1.0, 1.0, 1.0, -1.0])
QUAD_ETA = np.array([-1.0, -1.0, 1.0, 1.0])
_NEWTON_ITERATIONS = 30


@numba.njit(cache=True)
def shape(k, xi, eta, N, dN):
    """Shape functions N (k,) and their derivatives dN (k, 2) at (ξ, η): the linear triangle on
    the unit triangle (k = 3), the bilinear quadrilateral on [−1, 1]² (k = 4)."""
    if k == 3:
        N[0] = 1.0 - xi - eta
        N[1] = xi
        N[2] = eta
        dN[0, 0] = -1.0
        dN[0, 1] = -1.0
        dN[1, 0] = 1.0
        dN[1, 1] = 0.0
        dN[2, 0] = 0.0
        dN[2, 1] = 1.0
    else:
        for a in range(4):
            N[a] = 0.25 * (1.0 + QUAD_XI[a] * xi) * (1.0 + QUAD_ETA[a] * eta)
            dN[a, 0] = 0.25 * QUAD_XI[a] * (1.0 + QUAD_ETA[a] * eta)
            dN[a, 1] = 0.25 * QUAD_ETA[a] * (1.0 + QUAD_XI[a] * xi)


@numba.njit(cache=True)
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@numba.njit(cache=True)
def project(x, k):
    """(ξ, η) of the closest point of the (unbounded) face surface to the slave: Newton on
    (x_s − x_c)·x_{c,ξi} = 0 from the face's centre (Gauss–Newton where the Hessian of the
    distance is not positive, far from a warped face; steps at most the face's size); works in
    the dtype of x (complex for the complex step). Returns (ξ, η, converged)."""
    dt = x.dtype
    zero = x[0, 0] * 0.0
    # coordinates from the face's first node: round-off at the scale of the face, not of the model
    y = np.empty((1 + k, 3), dtype=dt)
    for a in range(1 + k):
        for d in range(3):
            y[a, d] = x[a, d] - x[1, d]
    x = y
    xi = (zero + 1.0 / 3.0) if k == 3 else zero
    eta = xi
    N = np.empty(k, dtype=dt)
    dN = np.empty((k, 2), dtype=dt)
    xc = np.empty(3, dtype=dt)
    t1 = np.empty(3, dtype=dt)
    t2 = np.empty(3, dtype=dt)
    t12 = np.empty(3, dtype=dt)
    done = 0
    for it in range(_NEWTON_ITERATIONS):
        shape(k, xi, eta, N, dN)
        for d in range(3):
            xc[d] = 0.0
            t1[d] = 0.0
            t2[d] = 0.0
            t12[d] = 0.0
        for a in range(k):
            for d in range(3):
                xc[d] += N[a] * x[1 + a, d]
                t1[d] += dN[a, 0] * x[1 + a, d]
                t2[d] += dN[a, 1] * x[1 + a, d]
                if k == 4:
                    t12[d] += 0.25 * QUAD_XI[a] * QUAD_ETA[a] * x[1 + a, d]
        r1 = zero
        r2 = zero
        a11 = zero
        a12 = zero
        a22 = zero
        e12 = zero  # the curvature term of the Hessian (bilinear faces)
        for d in range(3):
            e = x[0, d] - xc[d]
            r1 += e * t1[d]
            r2 += e * t2[d]
            a11 += t1[d] * t1[d]
            a22 += t2[d] * t2[d]
            a12 += t1[d] * t2[d] - e * t12[d]
            e12 += e * t12[d]
        det = a11 * a22 - a12 * a12
        if not (det.real > 1e-14 * (a11.real * a22.real)):  # far from a warped face: Gauss–Newton
            a12 = a12 + e12
            det = a11 * a22 - a12 * a12
            if not det.real > 0.0:
                return xi, eta, False
        dxi = (a22 * r1 - a12 * r2) / det
        deta = (a11 * r2 - a12 * r1) / det
        step = abs(dxi.real) + abs(deta.real)
        if step > 1.0:  # no more than the face's size per iteration
            dxi /= step
            deta /= step
        xi += dxi
        eta += deta
        if abs(dxi.real) + abs(deta.real) < 1e-13:
            done += 1
            if done >= 2 or k == 3:  # two more for the complex step's imaginary part
                return xi, eta, True
    return xi, eta, False


@numba.njit(cache=True)
def inside(k, xi, eta, tol):
    """Whether (ξ, η) lies on the face, within ``tol`` (in its parameter) beyond its edges."""
    if k == 3:
        return xi >= -tol and eta >= -tol and xi + eta <= 1.0 + tol
    return abs(xi) <= 1.0 + tol and abs(eta) <= 1.0 + tol


BORDER = 2.0  # ``side`` of a pair at an edge or vertex of the border of a one-sided master


@numba.njit(cache=True)
def _contact_point(x, k, mode, which, side, N, n):
    """The contact point's weights N (k,) on the face nodes and the unit normal n (3,) out of the
    master, for ``mode`` 0 (face), 1 (edge ``which``) or 2 (vertex ``which``), on ``side`` (0:
    one-sided; ±1: that side of a two-sided master); returns the distance (x_s − x_c)·n."""
    dt = x.dtype
    zero = x[0, 0] * 0.0
    dN = np.empty((k, 2), dtype=dt)
    t1 = np.zeros(3, dtype=dt)
    t2 = np.zeros(3, dtype=dt)
    # the face normal at its centre: the master's outside
    shape(k, (zero + 1.0 / 3.0) if k == 3 else zero, (zero + 1.0 / 3.0) if k == 3 else zero, N, dN)
    for a in range(k):
        for d in range(3):
            t1[d] += dN[a, 0] * x[1 + a, d]
            t2[d] += dN[a, 1] * x[1 + a, d]
    nc = np.empty(3, dtype=dt)
    _cross(t1, t2, nc)
    for a in range(k):
        N[a] = 0.0
    if mode == 0:
        xi, eta, _ = project(x, k)
        shape(k, xi, eta, N, dN)
        for d in range(3):
            t1[d] = 0.0
            t2[d] = 0.0
        for a in range(k):
            for d in range(3):
                t1[d] += dN[a, 0] * x[1 + a, d]
                t2[d] += dN[a, 1] * x[1 + a, d]
        _cross(t1, t2, n)
        norm = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        if side < 0.0:
            norm = -norm
        for d in range(3):
            n[d] /= norm
    else:
        if mode == 1:
            a = which
            b = (which + 1) % k
            num = zero
            den = zero
            for d in range(3):
                e = x[1 + b, d] - x[1 + a, d]
                num += (x[0, d] - x[1 + a, d]) * e
                den += e * e
            t = num / den
            N[a] = 1.0 - t
            N[b] = t
        else:
            N[which] = 1.0
        norm2 = zero
        along = 0.0
        nc2 = 0.0
        for d in range(3):
            xc = zero
            for a in range(k):
                xc += N[a] * x[1 + a, d]
            n[d] = x[0, d] - xc
            norm2 += n[d] * n[d]
            along += (n[d] * nc[d]).real
            nc2 += (nc[d] * nc[d]).real
        norm = np.sqrt(norm2)
        if side == BORDER:  # inside only below the 45° line: deeper than beyond the border
            sign = -1.0 if (along < 0.0 and along * along > 0.5 * norm2.real * nc2) else 1.0
        else:
            sign = 1.0 if (along >= 0.0 or side != 0.0) else -1.0
        for d in range(3):
            n[d] = sign * n[d] / norm
    dist = zero
    for d in range(3):
        xc = zero
        for a in range(k):
            xc += N[a] * x[1 + a, d]
        dist += (x[0, d] - xc) * n[d]
    return dist


@numba.njit(cache=True)
def _force(x, k, mode, which, side, offset, lam, eps, area, f):
    """Gap and internal force f (3 (1 + k),) of one pair (see the module's docstring)."""
    dt = x.dtype
    zero = x[0, 0] * 0.0
    N = np.empty(k, dtype=dt)
    n = np.empty(3, dtype=dt)
    g = _contact_point(x, k, mode, which, side, N, n) - offset
    p = lam - eps * g
    if p.real <= 0.0:
        p = zero
    for d in range(3):
        f[d] = -area * p * n[d]
        for a in range(k):
            f[3 + 3 * a + d] = area * p * N[a] * n[d]
    return g


@numba.njit(cache=True)
def node_to_face(x, k, mode, which, side, offset, lam, eps, area, tangent, f, K, touch=0.0):
    """Gap g, force f (3 (1 + k),) and (``tangent``) K = ∂f/∂x (3 (1 + k), 3 (1 + k)) of one pair
    x (1 + k, 3) in ``mode`` 0 (face), 1 (edge ``which``), 2 (vertex ``which``), on ``side`` (0:
    a one-sided master; ±1: that side of a two-sided one). A pair open by
    less than ``touch`` (λ − ε g ≥ −ε touch, no force) keeps the penalty stiffness A ε ∇g ∇gᵀ in
    its tangent: bodies touching without load are held in the linearization."""
    g = _force(x, k, mode, which, side, offset, lam, eps, area, f)
    if tangent and lam - eps * g <= 0.0:
        K[:, :] = 0.0
        if lam - eps * g >= -eps * touch:
            N = np.empty(k)
            n = np.empty(3)
            _contact_point(x, k, mode, which, side, N, n)
            grad = np.zeros(3 * (1 + k))
            for d in range(3):
                grad[d] = n[d]
                for a in range(k):
                    grad[3 + 3 * a + d] = -N[a] * n[d]
            for i in range(3 * (1 + k)):
                for j in range(3 * (1 + k)):
                    K[i, j] = area * eps * grad[i] * grad[j]
        return g
    if tangent:
        m = 3 * (1 + k)
        xc = x.astype(np.complex128)
        fc = np.empty(m, dtype=np.complex128)
        for j in range(m):
            node, d = divmod(j, 3)
            xc[node, d] += 1j * H
            _force(xc, k, mode, which, side, offset, lam, eps, area, fc)
            xc[node, d] = x[node, d]
            for i in range(m):
                K[i, j] = fc[i].imag / H
    return g


@numba.njit(cache=True)
def _face_pair(point, xm, faces, nodes, face):
    """A pair's coordinates x (1 + k, 3): the point (a slave), then the nodes of face ``face``."""
    k = nodes[face]
    x = np.empty((1 + k, 3))
    x[0] = point
    for a in range(k):
        x[1 + a] = xm[faces[face, a]]
    return x


@numba.njit(cache=True)
def pairs_to_faces(xs, xm, faces, nodes, s, m, mode, which, side, offset, lam, eps, area, tangent, g, f, K,
                   touch=0.0):
    """node_to_face for pairs (slave s[i], face m[i]) on side[i] of slaves xs (ns, 3) against faces (nf, 4)
    of master nodes xm (nm, 3) with ``nodes`` (nf,) nodes each (3: the fourth entry unused):
    g (p,), f (p, 15), K (p, 15, 15), zero beyond a triangle's 12 dofs; ``touch`` as in
    :func:`node_to_face`."""
    for i in range(len(s)):
        k = nodes[m[i]]
        x = _face_pair(xs[s[i]], xm, faces, nodes, m[i])
        fi = np.zeros(3 * (1 + k))
        Ki = np.zeros((3 * (1 + k), 3 * (1 + k)))
        g[i] = node_to_face(x, k, mode[i], which[i], side[i], offset[i], lam[i], eps[i], area[i], tangent, fi, Ki,
                            touch)
        f[i, :] = 0.0
        K[i, :, :] = 0.0
        f[i, : 3 * (1 + k)] = fi
        K[i, : 3 * (1 + k), : 3 * (1 + k)] = Ki


@numba.njit(cache=True)
def _closest_real(xs, xm, face, k, tol):
    """Allocation-free closest point of slave xs (3,) on face ``face`` (node indices into xm):
    (ξ, η, signed distance along the face normal there, on the face within ``tol``)."""
    ox, oy, oz = xm[face[0], 0], xm[face[0], 1], xm[face[0], 2]
    px, py, pz = xs[0] - ox, xs[1] - oy, xs[2] - oz
    if k == 3:
        ax, ay, az = xm[face[1], 0] - ox, xm[face[1], 1] - oy, xm[face[1], 2] - oz
        bx, by, bz = xm[face[2], 0] - ox, xm[face[2], 1] - oy, xm[face[2], 2] - oz
        a11 = ax * ax + ay * ay + az * az
        a12 = ax * bx + ay * by + az * bz
        a22 = bx * bx + by * by + bz * bz
        r1 = px * ax + py * ay + pz * az
        r2 = px * bx + py * by + pz * bz
        det = a11 * a22 - a12 * a12
        xi = (a22 * r1 - a12 * r2) / det
        eta = (a11 * r2 - a12 * r1) / det
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        cx, cy, cz = xi * ax + eta * bx, xi * ay + eta * by, xi * az + eta * bz
        on = xi >= -tol and eta >= -tol and xi + eta <= 1.0 + tol
    else:
        # x(ξ, η) = c0 + ξ c1 + η c2 + ξη c3 (corners counter-clockwise at (∓1, ∓1)), from node 0
        x1 = xm[face[1]]
        x2 = xm[face[2]]
        x3 = xm[face[3]]
        q1x, q1y, q1z = x1[0] - ox, x1[1] - oy, x1[2] - oz
        q2x, q2y, q2z = x2[0] - ox, x2[1] - oy, x2[2] - oz
        q3x, q3y, q3z = x3[0] - ox, x3[1] - oy, x3[2] - oz
        c0x, c0y, c0z = 0.25 * (q1x + q2x + q3x), 0.25 * (q1y + q2y + q3y), 0.25 * (q1z + q2z + q3z)
        c1x, c1y, c1z = 0.25 * (q1x + q2x - q3x), 0.25 * (q1y + q2y - q3y), 0.25 * (q1z + q2z - q3z)
        c2x, c2y, c2z = 0.25 * (q2x + q3x - q1x), 0.25 * (q2y + q3y - q1y), 0.25 * (q2z + q3z - q1z)
        c3x, c3y, c3z = 0.25 * (q2x - q1x - q3x), 0.25 * (q2y - q1y - q3y), 0.25 * (q2z - q1z - q3z)
        # start: the projection on the face's mean plane (the parallelogram c0 + ξ c1 + η c2)
        ex, ey, ez = px - c0x, py - c0y, pz - c0z
        a11 = c1x * c1x + c1y * c1y + c1z * c1z
        a22 = c2x * c2x + c2y * c2y + c2z * c2z
        a12 = c1x * c2x + c1y * c2y + c1z * c2z
        r1 = ex * c1x + ey * c1y + ez * c1z
        r2 = ex * c2x + ey * c2y + ez * c2z
        det = a11 * a22 - a12 * a12
        xi = (a22 * r1 - a12 * r2) / det if det > 0.0 else 0.0
        eta = (a11 * r2 - a12 * r1) / det if det > 0.0 else 0.0
        step = abs(xi) + abs(eta)
        if step > 2.0:  # far outside: from the centre
            xi = 0.0
            eta = 0.0
        ok = False
        for it in range(_NEWTON_ITERATIONS):
            t1x, t1y, t1z = c1x + eta * c3x, c1y + eta * c3y, c1z + eta * c3z
            t2x, t2y, t2z = c2x + xi * c3x, c2y + xi * c3y, c2z + xi * c3z
            ex = px - (c0x + xi * c1x + eta * c2x + xi * eta * c3x)
            ey = py - (c0y + xi * c1y + eta * c2y + xi * eta * c3y)
            ez = pz - (c0z + xi * c1z + eta * c2z + xi * eta * c3z)
            r1 = ex * t1x + ey * t1y + ez * t1z
            r2 = ex * t2x + ey * t2y + ez * t2z
            a11 = t1x * t1x + t1y * t1y + t1z * t1z
            a22 = t2x * t2x + t2y * t2y + t2z * t2z
            e12 = ex * c3x + ey * c3y + ez * c3z
            a12 = t1x * t2x + t1y * t2y + t1z * t2z - e12
            det = a11 * a22 - a12 * a12
            if not det > 1e-14 * a11 * a22:
                a12 += e12
                det = a11 * a22 - a12 * a12
                if not det > 0.0:
                    break
            dxi = (a22 * r1 - a12 * r2) / det
            deta = (a11 * r2 - a12 * r1) / det
            step = abs(dxi) + abs(deta)
            if step > 1.0:
                dxi /= step
                deta /= step
            xi += dxi
            eta += deta
            if step < 1e-13:
                ok = True
                break
        t1x, t1y, t1z = c1x + eta * c3x, c1y + eta * c3y, c1z + eta * c3z
        t2x, t2y, t2z = c2x + xi * c3x, c2y + xi * c3y, c2z + xi * c3z
        nx, ny, nz = t1y * t2z - t1z * t2y, t1z * t2x - t1x * t2z, t1x * t2y - t1y * t2x
        cx = c0x + xi * c1x + eta * c2x + xi * eta * c3x
        cy = c0y + xi * c1y + eta * c2y + xi * eta * c3y
        cz = c0z + xi * c1z + eta * c2z + xi * eta * c3z
        on = ok and abs(xi) <= 1.0 + tol and abs(eta) <= 1.0 + tol
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    dist = ((px - cx) * nx + (py - cy) * ny + (pz - cz) * nz) / norm
    return xi, eta, dist, on


@numba.njit(cache=True)
def closest_on_faces(xs, xm, faces, nodes, s, m, tol, out_xi, out_eta, out_dist, out_inside):
    """For each candidate pair (s[i], m[i]): the projection (ξ, η) on the face's surface, the signed
    distance along its normal and whether the projection lies on the face (within ``tol``)."""
    for i in range(len(s)):
        xi, eta, dist, on = _closest_real(xs[s[i]], xm, faces[m[i]], nodes[m[i]], tol)
        out_xi[i] = xi
        out_eta[i] = eta
        out_dist[i] = dist
        out_inside[i] = on


# -- Coulomb friction -----------------------------------------------------------------------
@numba.njit(cache=True)
def _attach(x, k, y, n, xi, eta):
    """(ξ, η) of the point X(ξ) = Σ N_a(ξ) x_a of the face (nodes x[1 … k], the bilinear surface
    extended beyond the face) on the line through y along n: (I − n nᵀ)(y − X(ξ)) = 0, by
    Gauss–Newton from (ξ, η); real."""
    N = np.empty(k)
    dN = np.empty((k, 2))
    e = np.empty(3)
    a1 = np.empty(3)
    a2 = np.empty(3)
    for it in range(_NEWTON_ITERATIONS):
        shape(k, xi, eta, N, dN)
        for d in range(3):
            e[d] = y[d]
            a1[d] = 0.0
            a2[d] = 0.0
            for a in range(k):
                e[d] -= N[a] * x[1 + a, d]
                a1[d] += dN[a, 0] * x[1 + a, d]
                a2[d] += dN[a, 1] * x[1 + a, d]
        xi, eta, step = tangent_step(a1, a2, e, n, xi, eta)
        if step < 1e-14:
            break
    return xi, eta


@numba.njit(cache=True)
def tangent_step(a1, a2, e, n, xi, eta):
    """One Gauss–Newton step for P (a1 dξ + a2 dη) = P e, P = I − n nᵀ (least squares in the
    tangent plane of n; along a1, a2 alone where P a1, P a2 are parallel): (ξ + dξ, η + dη, |d|)."""
    en = e[0] * n[0] + e[1] * n[1] + e[2] * n[2]
    b1n = a1[0] * n[0] + a1[1] * n[1] + a1[2] * n[2]
    b2n = a2[0] * n[0] + a2[1] * n[1] + a2[2] * n[2]
    m11 = m12 = m22 = r1 = r2 = 0.0
    for d in range(3):
        b1 = a1[d] - b1n * n[d]
        b2 = a2[d] - b2n * n[d]
        pe = e[d] - en * n[d]
        m11 += b1 * b1
        m12 += b1 * b2
        m22 += b2 * b2
        r1 += b1 * pe
        r2 += b2 * pe
    det = m11 * m22 - m12 * m12
    if det > 1e-12 * m11 * m22:
        dxi = (m22 * r1 - m12 * r2) / det
        deta = (m11 * r2 - m12 * r1) / det
    elif m11 >= m22 and m11 > 0.0:  # the face seen edge-on along n: along its longer tangent
        dxi, deta = r1 / m11, 0.0
    elif m22 > 0.0:
        dxi, deta = 0.0, r2 / m22
    else:
        return xi, eta, 0.0
    return xi + dxi, eta + deta, abs(dxi) + abs(deta)


@numba.njit(cache=True)
def convected(a1, a2, c, out):
    """The vector out = c₁ a₁ + c₂ a₂ + c₃ a₁ × a₂ (3,) of components c (3,) on the convected basis
    (a₁, a₂, a₁ × a₂) of a face (a_α = ∂X/∂ξ^α): a vector that turns and stretches with the face
    (the normal's share: at an edge or vertex the contact normal is not the face's); real or
    complex."""
    for d in range(3):
        e, f = (d + 1) % 3, (d + 2) % 3
        out[d] = c[0] * a1[d] + c[1] * a2[d] + c[2] * (a1[e] * a2[f] - a1[f] * a2[e])


@numba.njit(cache=True)
def coulomb_traction(xs, X0, n, p, eps_t, mu, cohesion, lt, t):
    """Coulomb's traction t (3,) of a slave at xs attached to the stick point X0, contact normal n,
    pressure p, tangential multiplier lt (3,): the predictor (I − n nᵀ)(lt + ε_T (xs − X0)) (the
    multiplier and the elastic slip in the tangent plane) returned radially onto the cone
    |t| ≤ c + μ p. Real or complex (decided on the real parts); returns whether the slave
    slips."""
    s = np.empty(3, dtype=t.dtype)
    rn = xs[0] * 0.0
    for d in range(3):
        s[d] = lt[d] + eps_t * (xs[d] - X0[d])
        rn += s[d] * n[d]
    ss = rn * 0.0
    for d in range(3):
        s[d] -= rn * n[d]
        ss += s[d] * s[d]
    norm = np.sqrt(ss)
    cap = cohesion + mu * p
    slipping = norm.real > cap.real
    for d in range(3):
        t[d] = cap * s[d] / norm if slipping else s[d]
    return slipping


@numba.njit(cache=True)
def _friction_force(x, k, mode, which, side, offset, lam, eps, area, eps_t, mu, cohesion, xi0, eta0, lam_t, f, t, n):
    """Gap, pressure and slip state of one frictional pair with its force f (3 (1 + k),), traction
    t (3,) and contact normal n (3,) (the module's friction law; lam_t (3,) the tangential
    multiplier's components on the face's basis at the stick point); returns (g, p, slipping)."""
    dt = x.dtype
    zero = x[0, 0] * 0.0
    N = np.empty(k, dtype=dt)
    g = _contact_point(x, k, mode, which, side, N, n) - offset
    p = lam - eps * g
    for j in range(len(f)):
        f[j] = 0.0
    for d in range(3):
        t[d] = 0.0
    if p.real <= 0.0:
        return g, zero, False
    N0 = np.empty(k)
    dN0 = np.empty((k, 2))
    shape(k, xi0, eta0, N0, dN0)
    X0 = np.zeros(3, dtype=dt)
    a1 = np.zeros(3, dtype=dt)
    a2 = np.zeros(3, dtype=dt)
    for d in range(3):
        for a in range(k):
            X0[d] += N0[a] * x[1 + a, d]
            a1[d] += dN0[a, 0] * x[1 + a, d]
            a2[d] += dN0[a, 1] * x[1 + a, d]
    lt = np.empty(3, dtype=dt)
    convected(a1, a2, lam_t, lt)
    slipping = coulomb_traction(x[0], X0, n, p, eps_t, mu, cohesion, lt, t)
    for d in range(3):
        f[d] = -area * p * n[d] + area * t[d]
        for a in range(k):
            f[3 + 3 * a + d] = area * N[a] * (p * n[d] - t[d])
    return g, p, slipping


@numba.njit(cache=True)
def node_to_face_friction(x, k, mode, which, side, offset, lam, eps, area, eps_t, mu, cohesion, attach, y, xi0,
                          lam_t, tangent, f, K, t, n, touch=0.0):
    r"""Frictional contact of one slave x[0] with a face (nodes x[1 … k]) in ``mode`` at ``which``
    on ``side`` (as :func:`node_to_face`): Coulomb's law with cohesion.

    Normally as :func:`node_to_face`: contact point x_c = Σ N_a x_a, unit normal n, gap g,
    pressure p = ⟨λ − εg⟩. Tangentially the slave is attached to a material point of the face,
    its stick point X₀ = Σ N_a(ξ₀) x_a (ξ₀ = (ξ₀, η₀) in the face's parameters, the face's
    surface extended beyond its edges), which moves with the face's nodes. The elastic slip is
    the part of x_s − X₀ in the tangent plane at the contact point, s = (I − n nᵀ)(x_s − X₀) =
    (I − n nᵀ)(x_c − X₀): the chord from the stick point to the contact point, in the plane of
    the face (exactly that chord on a flat face). It depends on relative positions only: rigid
    motions rotate it with the pair (frame indifference). The traction (force per tributary
    area A) is the predictor t* = (I − n nᵀ)(λ_T + ε_T (x_s − X₀)) returned onto Coulomb's cone
    |t| ≤ c + μ p: t = t* in stick, t = (c + μ p) t*/|t*| in slip (radial return).
    λ_T is the augmented Lagrangian's tangential multiplier (zero: the penalty law), held within
    a Newton solve as its components ``lam_t`` (3,) on the face's convected basis at the stick
    point (:func:`convected`), so that it turns with the face (frame indifference), its
    variation in the tangent. It acts on the slave and, opposite,
    at the contact point of the face: f_s = A(−p n + t), f_a = A N_a (p n − t) (linear momentum
    conserved; the couple A (x_s − x_c) × t, of the order of the penetration times the traction,
    is that of the usual node-to-surface friction which leaves out the gap's share of the slip's
    variation). K = ∂f/∂x by complex-step differentiation, stick or slip decided on the real
    parts: consistent and, in slip, unsymmetric. (Wriggers, Computational Contact Mechanics,
    2nd ed., Springer 2006, §5.2 and §9.1: the return map of Coulomb's law and node-to-surface
    frictional contact; Laursen, Computational Contact and Impact Mechanics, Springer 2002,
    §5.3: frame-indifferent tangential kinematics.)

    ``attach`` 1: the stick point is first put (from the real configuration, then held fixed for
    the tangent) where the line through y (3,) along the contact normal meets the face's surface
    (y the slave: a slave that has just closed starts without slip; y a stick point on another
    face: a slave that has passed to this face keeps its point); 0: ξ₀ is given. ``xi0`` (2,) in
    and out. Returns (g, p, slipping); t (3,) the traction, n (3,) the normal. An open pair: as
    :func:`node_to_face` (with its touch band), t zero."""
    g, p, slipping = _friction_force(x, k, mode, which, side, offset, lam, eps, area, eps_t, mu, cohesion,
                                     xi0[0], xi0[1], lam_t, f, t, n)
    if p <= 0.0:
        g = node_to_face(x, k, mode, which, side, offset, lam, eps, area, tangent, f, K, touch)
        return g, 0.0, False
    if attach:  # from the face's centre
        xi0[0], xi0[1] = _attach(x, k, y, n, 1.0 / 3.0 if k == 3 else 0.0, 1.0 / 3.0 if k == 3 else 0.0)
        g, p, slipping = _friction_force(x, k, mode, which, side, offset, lam, eps, area, eps_t, mu, cohesion,
                                         xi0[0], xi0[1], lam_t, f, t, n)
    if tangent:
        m = 3 * (1 + k)
        xc = x.astype(np.complex128)
        fc = np.empty(m, dtype=np.complex128)
        tc = np.empty(3, dtype=np.complex128)
        nc = np.empty(3, dtype=np.complex128)
        for j in range(m):
            node, d = divmod(j, 3)
            xc[node, d] += 1j * H
            _friction_force(xc, k, mode, which, side, offset, lam + 0j, eps, area, eps_t, mu, cohesion,
                            xi0[0], xi0[1], lam_t, fc, tc, nc)
            xc[node, d] = x[node, d]
            for i in range(m):
                K[i, j] = fc[i].imag / H
    return g, p, slipping


@numba.njit(cache=True)
def pairs_to_faces_friction(xs, xm, faces, nodes, s, m, mode, which, side, offset, lam, eps, area, eps_t, mu,
                            cohesion, attach, y, xi0, lam_t, tangent, g, p, slipping, t, n, f, K, touch=0.0):
    """node_to_face_friction for pairs (slave s[i], face m[i]) as :func:`pairs_to_faces`; attach,
    y (p, 3), xi0 (p, 2) (in and out), lam_t (p, 3), p, slipping, t (p, 3), n (p, 3) per pair."""
    for i in range(len(s)):
        k = nodes[m[i]]
        x = _face_pair(xs[s[i]], xm, faces, nodes, m[i])
        fi = np.zeros(3 * (1 + k))
        Ki = np.zeros((3 * (1 + k), 3 * (1 + k)))
        g[i], p[i], slipping[i] = node_to_face_friction(x, k, mode[i], which[i], side[i], offset[i], lam[i], eps[i],
                                                        area[i], eps_t, mu, cohesion, attach[i], y[i], xi0[i],
                                                        lam_t[i], tangent, fi, Ki, t[i], n[i], touch)
        f[i, :] = 0.0
        K[i, :, :] = 0.0
        f[i, : 3 * (1 + k)] = fi
        K[i, : 3 * (1 + k), : 3 * (1 + k)] = Ki


@numba.njit(cache=True)
def attach_on_faces(xm, faces, nodes, m, y, n, xi0):
    """The stick points (ξ₀, η₀) in xi0 (p, 2) (start in, result out) on faces m (p,) where the
    lines through y (p, 3) along n (p, 3) meet them (the return map's new stick point after a
    slip, y = x_s − t/ε_T)."""
    for i in range(len(m)):
        x = _face_pair(y[i], xm, faces, nodes, m[i])
        xi0[i, 0], xi0[i, 1] = _attach(x, nodes[m[i]], y[i], n[i], xi0[i, 0], xi0[i, 1])


@numba.njit(cache=True)
def face_frames(xm, faces, nodes, m, xi0, out, a1, a2):
    """The points Σ N_a(ξ₀) x_a (p, 3) of faces m (p,) at the parameters xi0 (p, 2) and their
    convected bases a_α = ∂X/∂ξ^α (p, 3) each."""
    for i in range(len(m)):
        k = nodes[m[i]]
        N = np.empty(k)
        dN = np.empty((k, 2))
        shape(k, xi0[i, 0], xi0[i, 1], N, dN)
        for d in range(3):
            out[i, d] = a1[i, d] = a2[i, d] = 0.0
            for a in range(k):
                xa = xm[faces[m[i], a], d]
                out[i, d] += N[a] * xa
                a1[i, d] += dN[a, 0] * xa
                a2[i, d] += dN[a, 1] * xa


@numba.njit(cache=True)
def face_points(xm, faces, nodes, m, xi0, out):
    """The points of :func:`face_frames` alone."""
    face_frames(xm, faces, nodes, m, xi0, out, np.empty_like(out), np.empty_like(out))

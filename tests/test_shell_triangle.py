"""Flat shell triangle (CST + drilling + DKT) in its local frame: rigid modes and patch tests."""
import numpy as np
import pytest
from scipy.spatial import Delaunay

from dolfinx_corot.elements import shell_triangle as st

PROPS = np.array([2.1e5, 0.3, 0.1, 1e-2, 1.0])


def _K(xy, props=PROPS):
    K = np.empty((18, 18))
    st.local_stiffness(np.ascontiguousarray(xy, dtype=float), props, K)
    return K


def test_rigid_body_modes_cost_nothing():
    """Six zero-energy modes: three translations, three rotations (the drilling dof follows ω)."""
    xy = np.array([[0.1, 0.2], [1.3, -0.1], [0.4, 0.9]])
    K = _K(xy)
    modes = []
    for k in range(3):  # translations
        m = np.zeros(18)
        m[k::6] = 1.0
        modes.append(m)
    for axis in range(3):  # rotations about x, y, z through the origin
        m = np.zeros(18)
        om = np.zeros(3)
        om[axis] = 1.0
        for a in range(3):
            x = np.array([xy[a, 0], xy[a, 1], 0.0])
            m[6 * a:6 * a + 3] = np.cross(om, x)
            m[6 * a + 3:6 * a + 6] = om
        modes.append(m)
    for m in modes:
        assert np.abs(K @ m).max() < 1e-9 * np.abs(K).max()
    assert np.sum(np.linalg.eigvalsh(K) < 1e-9 * np.abs(K).max()) == 6


def _patch():
    rng = np.random.default_rng(0)
    edge = np.linspace(0.0, 2.0, 4)
    bnd = np.array([(x, 0.0) for x in edge[:-1]] + [(2.0, y) for y in edge[:-1]] +
                   [(x, 2.0) for x in edge[:0:-1]] + [(0.0, y) for y in edge[:0:-1]])
    interior = np.array([[0.7, 0.6], [1.3, 0.8], [0.9, 1.4], [1.4, 1.3]]) + rng.uniform(-0.1, 0.1, (4, 2))
    pts = np.vstack([bnd, interior])
    tri = Delaunay(pts).simplices
    # counter-clockwise
    for t in tri:
        a, b, c = pts[t]
        if (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]) < 0:
            t[[1, 2]] = t[[2, 1]]
    return pts, tri, len(bnd)


def _solve_patch(field):
    pts, tri, nb = _patch()
    n = len(pts)
    K = np.zeros((6 * n, 6 * n))
    for t in tri:
        Ke = _K(pts[t])
        dofs = (6 * t[:, None] + np.arange(6)).ravel()
        K[np.ix_(dofs, dofs)] += Ke
    exact = np.concatenate([field(*p) for p in pts])
    fixed = np.arange(6 * nb)
    free = np.arange(6 * nb, 6 * n)
    u = exact.copy()
    u[free] = np.linalg.solve(K[np.ix_(free, free)], -K[np.ix_(free, fixed)] @ exact[fixed])
    return u, exact


def test_membrane_patch_test():
    """A linear in-plane field (constant strain, rigid rotation included) is reproduced exactly."""
    a, b, c, d = 1e-3, -2e-3, 0.5e-3, 1.5e-3

    def field(x, y):
        u, v = a * x + b * y, c * x + d * y
        return np.array([u, v, 0.0, 0.0, 0.0, 0.5 * (c - b)])

    u, exact = _solve_patch(field)
    np.testing.assert_allclose(u, exact, atol=1e-12)


@pytest.mark.parametrize("kappa", [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.3, -0.7, 0.4)])
def test_bending_patch_test(kappa):
    """A constant-curvature field w = ½(kx x² + ky y²) + kxy x y is reproduced exactly (DKT passes)."""
    kx, ky, kxy = kappa

    def field(x, y):
        w = 0.5 * (kx * x * x + ky * y * y) + kxy * x * y
        wx, wy = kx * x + kxy * y, ky * y + kxy * x
        return np.array([0.0, 0.0, w, wy, -wx, 0.0])  # θx = w,y, θy = −w,x

    u, exact = _solve_patch(field)
    np.testing.assert_allclose(u, exact, atol=1e-10)


def test_cantilever_strip_tip_deflection():
    """A strip of triangles as a cantilever under a tip moment: w = ML²/(2D) with D per width (ν = 0)."""
    L, b, nx = 4.0, 1.0, 8
    x = np.linspace(0, L, nx + 1)
    pts = np.array([(xi, yi) for xi in x for yi in (0.0, b)])
    tri = []
    for i in range(nx):
        a0, a1, b0, b1 = 2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3
        tri += [(a0, b0, b1), (a0, b1, a1)]
    props = np.array([1e4, 0.0, 0.1, 1e-2, 1.0])
    n = len(pts)
    K = np.zeros((6 * n, 6 * n))
    for t in np.array(tri):
        dofs = (6 * t[:, None] + np.arange(6)).ravel()
        Ke = np.empty((18, 18))
        st.local_stiffness(pts[t].copy(), props, Ke)
        K[np.ix_(dofs, dofs)] += Ke
    M = 1e-3
    f = np.zeros(6 * n)
    f[6 * (n - 2) + 4] = f[6 * (n - 1) + 4] = -M / 2  # moment about y at the tip edge
    fixed = np.concatenate([np.arange(12)] + [6 * np.arange(n) + k for k in (0, 1, 5)])
    free = np.setdiff1d(np.arange(6 * n), fixed)
    u = np.zeros(6 * n)
    u[free] = np.linalg.solve(K[np.ix_(free, free)], f[free])
    D = 1e4 * 0.1**3 / 12 * b
    np.testing.assert_allclose(u[6 * (n - 1) + 2], M * L**2 / (2 * D), rtol=1e-10)

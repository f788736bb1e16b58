"""Flat shell triangle (OPT or CST membrane + DKT) in its local frame: rigid modes, patch tests,
and the OPT membrane's exact energy in in-plane bending (Felippa 2003)."""
import numpy as np
import pytest
from scipy.spatial import Delaunay

from dolfinx_corot.elements import shell_triangle as st

PROPS = st.isotropic_props(2.1e5, 0.3, 0.1, 1e-2, True, True)  # OPT membrane
PROPS_CST = st.isotropic_props(2.1e5, 0.3, 0.1, 1e-2, True, False)  # CST + drilling penalty
MEMBRANES = {"opt": PROPS, "cst": PROPS_CST}


def _K(xy, props=PROPS):
    K = np.empty((18, 18))
    st.local_stiffness(np.ascontiguousarray(xy, dtype=float), props, K)
    return K


@pytest.mark.parametrize("membrane", MEMBRANES)
def test_rigid_body_modes_cost_nothing(membrane):
    """Six zero-energy modes: three translations, three rotations (the drilling dof follows ω)."""
    xy = np.array([[0.1, 0.2], [1.3, -0.1], [0.4, 0.9]])
    K = _K(xy, MEMBRANES[membrane])
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


def _solve_patch(field, props=PROPS):
    pts, tri, nb = _patch()
    n = len(pts)
    K = np.zeros((6 * n, 6 * n))
    for t in tri:
        Ke = _K(pts[t], props)
        dofs = (6 * t[:, None] + np.arange(6)).ravel()
        K[np.ix_(dofs, dofs)] += Ke
    exact = np.concatenate([field(*p) for p in pts])
    fixed = np.arange(6 * nb)
    free = np.arange(6 * nb, 6 * n)
    u = exact.copy()
    u[free] = np.linalg.solve(K[np.ix_(free, free)], -K[np.ix_(free, fixed)] @ exact[fixed])
    return u, exact


@pytest.mark.parametrize("membrane", MEMBRANES)
def test_membrane_patch_test(membrane):
    """A linear in-plane field (constant strain, rigid rotation included) is reproduced exactly."""
    a, b, c, d = 1e-3, -2e-3, 0.5e-3, 1.5e-3

    def field(x, y):
        u, v = a * x + b * y, c * x + d * y
        return np.array([u, v, 0.0, 0.0, 0.0, 0.5 * (c - b)])

    u, exact = _solve_patch(field, MEMBRANES[membrane])
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
    props = st.isotropic_props(1e4, 0.0, 0.1, 1e-2, True, True)
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


def _rectangle_unit(a, b, nu, props_kind="opt"):
    """Stiffness (12, 12) on (u, v, θz) of a rectangle a × b cut into two triangles."""
    X = np.array([[0.0, -b / 2], [a, -b / 2], [a, b / 2], [0.0, b / 2]])
    K = np.zeros((12, 12))
    for t in ((0, 1, 2), (0, 2, 3)):
        if props_kind == "opt":
            Ke = st.opt_membrane(np.ascontiguousarray(X[list(t)]), st.plane_stress(1.0, nu), nu, 1.0)
        else:
            Kf = _K(X[list(t)], st.isotropic_props(1.0, nu, 1.0, 1e-2, True, False))
            sel = np.array([0, 1, 5, 6, 7, 11, 12, 13, 17])
            Ke = Kf[np.ix_(sel, sel)]
        dofs = np.array([[3 * v, 3 * v + 1, 3 * v + 2] for v in t]).ravel()
        K[np.ix_(dofs, dofs)] += Ke
    return X, K


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
def test_opt_membrane_is_exact_in_pure_bending_of_rectangles(nu):
    """Felippa's optimality: the energy of in-plane pure bending (u = −κxy, v = κ(x² + νy²)/2,
    θ = κx) of a rectangular unit of two OPT triangles equals the exact ½EIκ²a for every
    aspect ratio; the CST with a drilling penalty locks (its ratio grows with a/b)."""
    for ratio in (0.25, 1.0, 4.0, 16.0):
        X, K = _rectangle_unit(ratio, 1.0, nu)
        d = np.array([[-x * y, (x * x + nu * y * y) / 2, x] for x, y in X]).ravel()
        exact = 0.5 * (1.0 / 12.0) * ratio
        assert abs(0.5 * d @ K @ d / exact - 1.0) < 1e-10
        if ratio >= 4.0:
            X, K = _rectangle_unit(ratio, 1.0, nu, "cst")
            assert 0.5 * d @ K @ d / exact > 1.5


def test_opt_membrane_has_exactly_three_rigid_modes():
    xy = np.array([[0.1, 0.2], [1.3, -0.1], [0.4, 0.9]])
    K = st.opt_membrane(xy, st.plane_stress(2.1e5, 0.3), 0.3, 0.1)
    ev = np.linalg.eigvalsh(K)
    assert np.sum(ev < 1e-10 * ev.max()) == 3 and ev.min() > -1e-10 * ev.max()
    # rigid in-plane rotation with θz = 1 at every node
    m = np.array([[-y, x, 1.0] for x, y in xy]).ravel()
    assert np.abs(K @ m).max() < 1e-10 * np.abs(K).max()


def test_opt_with_linear_edges_keeps_its_rigid_modes_and_no_more():
    """The OPT with one, two or all of its edges kept linear (beside quadrilaterals or CST
    triangles): positive semi-definite with exactly the three in-plane rigid modes (a rigid turn
    with θz equal to it costs nothing), and unchanged when no edge is flagged (1e-12)."""
    xy = np.array([[0.0, 0.0], [1.2, 0.1], [0.3, 0.9]])
    D = st.plane_stress(1.0, 0.3)
    base = st.opt_membrane(xy, D, 0.3, 1.0)
    np.testing.assert_allclose(st.opt_membrane_edges(xy, D, 0.3, 1.0, np.zeros(3)), base, atol=1e-14)
    turn = np.array([[-y, x, 1.0] for x, y in xy]).ravel()
    for flags in ([1, 0, 0], [0, 1, 1], [1, 1, 1]):
        K = st.opt_membrane_edges(xy, D, 0.3, 1.0, np.array(flags, float))
        w = np.linalg.eigvalsh(0.5 * (K + K.T))
        assert w.min() > -1e-12 * w.max() and np.sum(w < 1e-10 * w.max()) == 3
        assert np.abs(K @ turn).max() < 1e-12 * w.max()
        assert np.abs(K - base).max() > 1e-3 * w.max()

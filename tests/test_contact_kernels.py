"""2D node-to-segment contact kernel: gap geometry, finite-difference force and tangent."""
import numpy as np
import pytest

from dolfinx_corot.contact.kernels2d import gap, node_to_segment


def _pair(rng, penetration):
    """A segment of random orientation and a slave at depth ``penetration`` below it."""
    a = rng.uniform(-1, 1, 2)
    phi = rng.uniform(0, 2 * np.pi)
    length = rng.uniform(0.5, 2.0)
    t = np.array([np.cos(phi), np.sin(phi)])
    n = np.array([t[1], -t[0]])
    xi = rng.uniform(0.1, 0.9)
    xs = a + xi * length * t - penetration * n
    return xs, a, a + length * t, xi


def test_gap_and_projection_are_exact():
    rng = np.random.default_rng(1)
    for depth in (0.3, -0.2, 0.0):
        xs, x1, x2, xi = _pair(rng, depth)
        g, x = gap(xs[None], x1[None], x2[None])
        assert abs(g[0] + depth) < 1e-14 and abs(x[0] - xi) < 1e-14
    # the master body lies on the left of x1 -> x2: a slave on the right is outside (g > 0)
    g, _ = gap(np.array([[0.5, -1.0]]), np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]))
    assert g[0] == 1.0


@pytest.mark.parametrize("multiplier", [0.0, 3.0])
def test_force_and_tangent_match_finite_differences(multiplier):
    """f = ∂Φ/∂x and K = ∂f/∂x by central differences at random active pairs (penalty and
    augmented Lagrangian), rotation of the normal and sliding of ξ included."""
    rng = np.random.default_rng(7)
    for trial in range(6):
        xs, x1, x2, _ = _pair(rng, rng.uniform(0.01, 0.1))
        x0 = np.concatenate([xs, x1, x2])
        eps, area = np.array([rng.uniform(10, 1000)]), np.array([rng.uniform(0.1, 1.0)])
        lam = np.array([multiplier])

        def ev(x, tangent=False):
            return node_to_segment(x[None, 0:2], x[None, 2:4], x[None, 4:6], lam, eps, area, tangent)

        g, xi, p, f, K, W = ev(x0, True)
        assert p[0] > 0 and abs(p[0] - (multiplier - eps[0] * g[0])) < 1e-12 * p[0]
        h = 1e-6
        fd_f = np.zeros(6)
        fd_K = np.zeros((6, 6))
        for j in range(6):
            e = np.zeros(6)
            e[j] = h
            Wp, Wm = ev(x0 + e)[5][0], ev(x0 - e)[5][0]
            fd_f[j] = (Wp - Wm) / (2 * h)
            fd_K[:, j] = (ev(x0 + e)[3][0] - ev(x0 - e)[3][0]) / (2 * h)
        assert np.abs(f[0] - fd_f).max() < 1e-6 * np.abs(f[0]).max()
        assert np.abs(K[0] - fd_K).max() < 1e-6 * np.abs(K[0]).max()
        assert np.abs(K[0] - K[0].T).max() < 1e-12 * np.abs(K[0]).max()
        # the geometric part −A p ∂²g is present: the normal rotates with the segment
        N = -f[0] / (area[0] * p[0])
        geometric = K[0] - area[0] * eps[0] * np.outer(N, N)
        assert np.abs(geometric).max() > 1e-3 * np.abs(K[0]).max()


def test_force_balances_and_moments_vanish():
    """Contact forces on (slave, master ends) sum to zero and have no resultant moment
    (Newton's third law on the pair)."""
    rng = np.random.default_rng(3)
    xs, x1, x2, _ = _pair(rng, 0.05)
    g, xi, p, f, K, W = node_to_segment(xs[None], x1[None], x2[None], np.zeros(1), np.array([100.0]),
                                        np.array([1.0]), False)
    F = f[0].reshape(3, 2)
    assert np.abs(F.sum(axis=0)).max() < 1e-12 * np.abs(F).max()
    # moment about the slave: the master forces act at x1, x2 with the lever of the projection point
    moment = sum(np.cross(x - xs, Fi) for x, Fi in zip((xs, x1, x2), F))
    assert abs(moment) < 1e-12 * np.abs(F).max()


def test_separated_pair_is_inactive():
    xs, x1, x2 = np.array([[0.5, -0.1]]), np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]])
    g, xi, p, f, K, W = node_to_segment(xs, x1, x2, np.zeros(1), np.array([1e3]), np.array([1.0]), True)
    assert g[0] == pytest.approx(0.1) and p[0] == 0 and not f.any() and not K.any() and W[0] == 0


@pytest.mark.parametrize("multiplier", [0.0, 2.0])
def test_node_to_vertex_force_and_tangent_match_finite_differences(multiplier):
    from dolfinx_corot.contact.kernels2d import node_to_vertex

    rng = np.random.default_rng(11)
    for trial in range(6):
        xv = rng.uniform(-1, 1, 2)
        nbar = rng.normal(size=2)
        nbar /= np.linalg.norm(nbar)
        d = -rng.uniform(0.01, 0.1) * (nbar + 0.3 * rng.normal(size=2))  # inside: g < 0
        x0 = np.concatenate([xv + d, xv])
        eps, area, lam = np.array([rng.uniform(10, 1000)]), np.array([0.7]), np.array([multiplier])

        def ev(x, tangent=False):
            return node_to_vertex(x[None, 0:2], x[None, 2:4], nbar[None], lam, eps, area, tangent)

        g, p, f, K = ev(x0, True)
        assert g[0] < 0 and p[0] > 0
        h = 1e-7
        fd_K = np.zeros((4, 4))
        fd_f = np.zeros(4)
        for j in range(4):
            e = np.zeros(4)
            e[j] = h
            fd_K[:, j] = (ev(x0 + e)[2][0] - ev(x0 - e)[2][0]) / (2 * h)
            # f = ∂Φ/∂x with Φ = A/(2ε) p²
            Wp = area[0] / (2 * eps[0]) * ev(x0 + e)[1][0] ** 2
            Wm = area[0] / (2 * eps[0]) * ev(x0 - e)[1][0] ** 2
            fd_f[j] = (Wp - Wm) / (2 * h)
        assert np.abs(f[0] - fd_f).max() < 1e-6 * np.abs(f[0]).max()
        assert np.abs(K[0] - fd_K).max() < 1e-6 * np.abs(K[0]).max()


def test_node_to_vertex_continues_node_to_segment_at_the_segment_end():
    """At ξ = 1 the vertex gap, force and normal stiffness equal the segment's."""
    from dolfinx_corot.contact.kernels2d import node_to_vertex

    x1, x2 = np.array([0.0, 0.0]), np.array([1.0, 0.0])
    xs = np.array([1.0, 0.02])       # below the segment's end (the body is above: n = (0, -1))
    lam, eps, area = np.array([1.0]), np.array([100.0]), np.array([0.5])
    g, xi, p, f, K, W = node_to_segment(xs[None], x1[None], x2[None], lam, eps, area, True)
    assert abs(xi[0] - 1.0) < 1e-15
    gv, pv, fv, Kv = node_to_vertex(xs[None], x2[None], np.array([[0.0, -1.0]]), lam, eps, area, True)
    assert abs(gv[0] - g[0]) < 1e-15 and abs(pv[0] - p[0]) < 1e-12
    assert np.abs(fv[0] - f[0][[0, 1, 4, 5]]).max() < 1e-12

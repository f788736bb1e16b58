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


def _check_vertex_pair_by_fd(ev, x0, f, K, area, eps):
    """f = ∂Φ/∂x (Φ = A/(2ε) p², the penalty potential) and K = ∂f/∂x of a node-to-vertex pair
    ``ev(x) -> (g, p, f, K)`` against central differences at x0."""
    h = 1e-7
    fd_K = np.zeros((4, 4))
    fd_f = np.zeros(4)
    for j in range(4):
        e = np.zeros(4)
        e[j] = h
        fd_K[:, j] = (ev(x0 + e)[2][0] - ev(x0 - e)[2][0]) / (2 * h)
        fd_f[j] = area / (2 * eps) * (ev(x0 + e)[1][0] ** 2 - ev(x0 - e)[1][0] ** 2) / (2 * h)
    assert np.abs(f - fd_f).max() < 1e-6 * np.abs(f).max()
    assert np.abs(K - fd_K).max() < 1e-6 * np.abs(K).max()


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
            return node_to_vertex(x[None, 0:2], x[None, 2:4], nbar[None], np.zeros(1), lam, eps, area, tangent)

        g, p, f, K = ev(x0, True)
        assert g[0] < 0 and p[0] > 0
        _check_vertex_pair_by_fd(ev, x0, f[0], K[0], area[0], eps[0])


@pytest.mark.parametrize("multiplier", [0.0, 2.0])
def test_node_to_vertex_around_a_beam_kink_matches_finite_differences(multiplier):
    """A beam's kink (two-sided master): the face is the circle of radius r (the offsets: half the
    beam's depth plus the slave's) around the vertex, on the slave's side — the interface passes
    the direction vertex → slave as the normal and r as the offset: g = |x_s − x_v| − r."""
    from dolfinx_corot.contact.kernels2d import node_to_vertex

    rng = np.random.default_rng(5)
    for trial in range(6):
        xv = rng.uniform(-1, 1, 2)
        r = rng.uniform(0.05, 0.2)
        d = rng.normal(size=2)
        d *= rng.uniform(0.5, 0.95) * r / np.linalg.norm(d)  # within the rounded face: g < 0
        x0 = np.concatenate([xv + d, xv])
        eps, area, lam = np.array([rng.uniform(10, 1000)]), np.array([0.7]), np.array([multiplier])

        def ev(x, tangent=False):
            return node_to_vertex(x[None, 0:2], x[None, 2:4], (x[0:2] - x[2:4])[None], np.array([r]), lam, eps,
                                  area, tangent)

        g, p, f, K = ev(x0, True)
        assert abs(g[0] - (np.linalg.norm(d) - r)) < 1e-14 and p[0] > 0
        _check_vertex_pair_by_fd(ev, x0, f[0], K[0], area[0], eps[0])


def test_node_to_vertex_continues_node_to_segment_at_the_segment_end():
    """At ξ = 1 the vertex gap, force and normal stiffness equal the segment's."""
    from dolfinx_corot.contact.kernels2d import node_to_vertex

    x1, x2 = np.array([0.0, 0.0]), np.array([1.0, 0.0])
    xs = np.array([1.0, 0.02])       # below the segment's end (the body is above: n = (0, -1))
    lam, eps, area = np.array([1.0]), np.array([100.0]), np.array([0.5])
    g, xi, p, f, K, W = node_to_segment(xs[None], x1[None], x2[None], lam, eps, area, True)
    assert abs(xi[0] - 1.0) < 1e-15
    gv, pv, fv, Kv = node_to_vertex(xs[None], x2[None], np.array([[0.0, -1.0]]), np.zeros(1), lam, eps, area, True)
    assert abs(gv[0] - g[0]) < 1e-15 and abs(pv[0] - p[0]) < 1e-12
    assert np.abs(fv[0] - f[0][[0, 1, 4, 5]]).max() < 1e-12


# -- smooth (C¹ Hermite) master curve ---------------------------------------------------------
def _arc_nodes(rng, n=6, radius=2.0, spacing=0.35):
    """Nodes of a convex arc (body below, traversed in −x so that it lies on the left), jittered."""
    th = (np.arange(n) - (n - 1) / 2) * spacing / radius * rng.uniform(0.8, 1.2, n)
    pts = np.column_stack([radius * np.sin(th), radius * np.cos(th) - radius])[::-1]
    return pts + rng.normal(0.0, 0.01, pts.shape)


def _pair_x(nodes, j, xs, free_a=False, free_b=False):
    """(x_s, x_p, x_a, x_b, x_q) of segment j → j+1 of a chain of nodes."""
    p = j if free_a else j - 1
    q = j + 1 if free_b else j + 2
    return np.concatenate([xs, nodes[p], nodes[j], nodes[j + 1], nodes[q]])


@pytest.mark.parametrize("side", [1, -1], ids=["surface", "beam-underside"])
@pytest.mark.parametrize("ends", ["inside", "free a", "free b", "free both"])
def test_smooth_kernel_force_and_tangent_match_finite_differences(ends, side):
    """f = ∂Φ/∂x and K = ∂f/∂x of the smooth-curve kernel by central differences at random
    penetrating slaves on a jittered arc (penalty and augmented Lagrangian), on the outer side of
    a body's surface or (side −1, offset) on the far side of a beam's axis. At a free end p = a
    (or q = b) is one node: the derivatives are those of the node's summed columns."""
    from dolfinx_corot.contact.kernels2d import node_to_smooth_segment, smooth_gap

    rng = np.random.default_rng(11)
    free_a, free_b = ends in ("free a", "free both"), ends in ("free b", "free both")
    for trial in range(8):
        nodes = _arc_nodes(rng)
        a, b = nodes[2], nodes[3]
        t = (b - a) / np.linalg.norm(b - a)
        depth = rng.uniform(0.01, 0.05)
        offset = np.array([0.0 if side == 1 else depth + 0.03])
        xs = a + rng.uniform(0.1, 0.9) * (b - a) + depth * np.array([-t[1], t[0]])
        x0 = _pair_x(nodes, 2, xs, free_a, free_b)
        # independent coordinates: slave, (p), a, b, (q); P maps them to the 10 entries
        slots = [0, 2 if free_a else 1, 2, 3, 3 if free_b else 4]
        uniq = sorted(set(slots))
        P = np.zeros((10, 2 * len(uniq)))
        for k, node in enumerate(slots):
            P[2 * k:2 * k + 2, 2 * uniq.index(node):2 * uniq.index(node) + 2] = np.eye(2)
        y0 = np.concatenate([x0[2 * node:2 * node + 2] for node in uniq])
        lam = np.array([rng.choice([0.0, 0.5])])
        eps, area = np.array([rng.uniform(10, 100)]), np.array([0.3])

        def ev(y, tangent=False):
            return node_to_smooth_segment((P @ y)[None], np.array([float(side)]), offset, lam, eps, area, tangent)

        g, xi, p, f, K, W, _ = ev(y0, True)
        assert p[0] > 0 and 0.0 <= xi[0] <= 1.0
        assert abs(side * smooth_gap((P @ y0)[None])[0][0] - offset[0] - g[0]) < 1e-15
        fc, Kc = P.T @ f[0], P.T @ K[0] @ P
        h = 1e-6
        m = len(y0)
        fd_f, fd_K = np.zeros(m), np.zeros((m, m))
        for j in range(m):
            e = np.zeros(m)
            e[j] = h
            fd_f[j] = (ev(y0 + e)[5][0] - ev(y0 - e)[5][0]) / (2 * h)
            fd_K[:, j] = P.T @ (ev(y0 + e)[3][0] - ev(y0 - e)[3][0]) / (2 * h)
        assert np.abs(fc - fd_f).max() < 1e-7 * np.abs(fc).max()
        assert np.abs(Kc - fd_K).max() < 1e-6 * np.abs(Kc).max()


def test_smooth_curve_is_c1_across_vertices():
    """A slave at a master vertex, seen from either segment: the same gap, the same normal and
    the same nodal forces (the straight segments' normals differ there by the vertex angle)."""
    from dolfinx_corot.contact.kernels2d import node_to_smooth_segment

    rng = np.random.default_rng(2)
    nodes = _arc_nodes(rng, n=7)
    v = nodes[3]
    inward = np.array([-(nodes[4] - nodes[2])[1], (nodes[4] - nodes[2])[0]])
    inward /= np.linalg.norm(inward)  # ⊥ to the curve's (Catmull–Rom) tangent at the vertex
    xs = v + 0.02 * inward  # 0.02 inside the master body, on the vertex's normal
    one = dict(side=np.ones(1), offset=np.zeros(1), multiplier=np.zeros(1), penalty=np.array([50.0]),
               area=np.array([0.3]), with_tangent=True)
    left = node_to_smooth_segment(_pair_x(nodes, 2, xs)[None], *one.values())   # segment 2→3, ξ = 1
    right = node_to_smooth_segment(_pair_x(nodes, 3, xs)[None], *one.values())  # segment 3→4, ξ = 0
    assert abs(left[1][0] - 1.0) < 1e-12 and abs(right[1][0]) < 1e-12
    assert abs(left[0][0] - right[0][0]) < 1e-14 and abs(left[0][0] + 0.02) < 1e-12
    assert np.allclose(right[3][0][0:2], left[3][0][0:2], atol=1e-13)  # slave force: same normal
    # on the vertex, both segments hand the whole reaction to the vertex node
    assert np.allclose(left[3][0][6:8], -left[3][0][0:2], atol=1e-12)
    assert np.allclose(right[3][0][4:6], -right[3][0][0:2], atol=1e-12)


def test_smooth_curve_keeps_an_even_straight_surface_straight():
    """On evenly divided collinear nodes (and at free ends) the Hermite curve is the segment
    itself, linearly parametrized: gap and ξ are those of the straight kernel."""
    from dolfinx_corot.contact.kernels2d import smooth_gap

    nodes = np.column_stack([np.linspace(3.0, 0.0, 7), np.zeros(7)])
    rng = np.random.default_rng(4)
    for j in range(6):
        xs = np.array([rng.uniform(nodes[j + 1, 0], nodes[j, 0]), rng.uniform(-0.1, 0.1)])
        x = _pair_x(nodes, j, xs, free_a=(j == 0), free_b=(j == 5))
        g, xi, ok = smooth_gap(x[None])
        g0, xi0 = gap(xs[None], nodes[j][None], nodes[j + 1][None])
        assert ok[0] and abs(g[0] - g0[0]) < 1e-14 and abs(xi[0] - xi0[0]) < 1e-12

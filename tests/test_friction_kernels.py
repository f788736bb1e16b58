"""Coulomb friction of 2D node-to-segment contact on the C¹ master curve and at its sharp corners
(issue 16, the kernels).
References: the slip's gradient and the tangent against central differences; in stick the force
is the gradient of the energy A⟨λ − εg⟩²/2ε + A ε_T s²/2; in slip the tangential traction is
c + μ p (Coulomb with cohesion) against the slip; frame indifference and momentum (invariance of
the gap and the slip under rigid motions)."""
import numpy as np
import pytest

from dolfinx_corot.contact.kernels2d import (node_to_smooth_segment, node_to_smooth_segment_friction,
                                             node_to_vertex, node_to_vertex_friction, slip, slipped_stick_point,
                                             vertex_stick_point)

EPS, EPS_T, AREA = 100.0, 60.0, 0.7


def _stencil(seed: int = 0, R: float = 3.0):
    """(p, a, b, q) on a circle of radius R (centre below: the body inside), shaken by 1 %, and
    the flattened pair coordinates for a slave 0.02 inside the curve above ξ ≈ 0.4."""
    rng = np.random.default_rng(seed)
    angles = np.radians([110.0, 100.0, 90.0, 80.0])  # counter-clockwise order reversed: body on the left
    nodes = np.column_stack([R * np.cos(angles), R * np.sin(angles) - R]) + rng.normal(0.0, 0.005, (4, 2))
    a, b = nodes[1], nodes[2]
    mid = a + 0.4 * (b - a)
    n = np.array([(b - a)[1], -(b - a)[0]]) / np.linalg.norm(b - a)
    return np.concatenate([mid - 0.02 * n, nodes.ravel()])


def _evaluate(x, xi0, lam=0.0, mu=0.3, cohesion=0.0, side=1.0, tangent=False, lam_t=0.0):
    one = np.ones(1)
    return node_to_smooth_segment_friction(x[None], side * one, 0.0 * one, lam * one, EPS * one, AREA * one,
                                           EPS_T * one, mu * one, cohesion * one, xi0 * one, lam_t * one, tangent)


def _fd(fun, x, h=1e-7):
    cols = []
    for j in range(len(x)):
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        cols.append((np.asarray(fun(xp)) - np.asarray(fun(xm))) / (2 * h))
    return np.array(cols).T


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("dxi0", [0.0, 0.03, -0.2])
def test_the_slip_gradient_is_the_derivative_of_the_slip(seed, dxi0):
    """∂s/∂x in closed form (the closest point's variation included) against central differences of
    s, the closest point re-solved: 1e-8; the stick point moves with the master's nodes."""
    x = _stencil(seed)
    xi = _evaluate(x, 0.0)[1][0]

    def s_of(y):
        xi_y = _evaluate(y, 0.0)[1][0]
        return slip(y, xi_y, xi + dxi0, np.zeros(10))

    grad = np.zeros(10)
    slip(x, xi, xi + dxi0, grad)
    assert np.abs(grad - _fd(s_of, x)).max() < 1e-8 * np.abs(grad).max()


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("lam, lam_t", [(0.0, 0.0), (2.0, 0.0), (2.0, -0.3)])
def test_in_stick_the_force_is_the_energy_gradient_and_the_tangent_its_symmetric_derivative(seed, lam, lam_t):
    """A slave 0.004 (in ξ) from its stick point, μ large enough to stick: f = ∂W/∂x with
    W = A⟨λ − εg⟩²/2ε + A (λ_T s + ε_T s²/2) (1e-8), K = ∂f/∂x (1e-7 of its largest entry) and
    symmetric; with and without a tangential multiplier λ_T."""
    x = _stencil(seed)
    xi = _evaluate(x, 0.0)[1][0]
    xi0 = xi - 0.004

    def energy(y):
        g, _, p, t, s, _, _, _ = _evaluate(y, xi0, lam, mu=5.0, lam_t=lam_t)
        return AREA * p[0] ** 2 / (2 * EPS) + AREA * (lam_t * s[0] + EPS_T * s[0] ** 2 / 2)

    g, _, p, t, s, slipping, f, K = _evaluate(x, xi0, lam, mu=5.0, tangent=True, lam_t=lam_t)
    assert p[0] > 0.0 and not slipping[0] and t[0] == pytest.approx(lam_t + EPS_T * s[0], rel=1e-14)
    assert np.abs(f[0] - _fd(energy, x)).max() < 1e-8 * np.abs(f[0]).max()
    Kfd = _fd(lambda y: _evaluate(y, xi0, lam, mu=5.0, lam_t=lam_t)[6][0], x)
    assert np.abs(K[0] - Kfd).max() < 1e-7 * np.abs(K[0]).max()
    assert np.abs(K[0] - K[0].T).max() < 1e-10 * np.abs(K[0]).max()


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("cohesion", [0.0, 0.05])
@pytest.mark.parametrize("direction", [1.0, -1.0])
@pytest.mark.parametrize("lam_t", [0.0, 0.4])
def test_in_slip_the_traction_is_coulombs_and_the_tangent_its_unsymmetric_derivative(seed, cohesion, direction,
                                                                                     lam_t):
    """A slave 0.05 (in ξ) from its stick point, μ = 0.3: it slips, the traction is c + μ p against
    the slip (1e-14), K = ∂f/∂x (1e-7) and not symmetric (the traction follows the pressure). A
    tangential multiplier λ_T (smaller than the slip's ε_T s) does not change the direction."""
    x = _stencil(seed)
    xi = _evaluate(x, 0.0)[1][0]
    xi0 = xi - direction * 0.05
    lam_t = -direction * lam_t  # against the slip: the return map still slips, along the slip
    g, _, p, t, s, slipping, f, K = _evaluate(x, xi0, 1.0, 0.3, cohesion, tangent=True, lam_t=lam_t)
    assert slipping[0] and np.sign(s[0]) == direction and abs(EPS_T * s[0]) > 2 * abs(lam_t)
    assert t[0] == pytest.approx(direction * (cohesion + 0.3 * p[0]), rel=1e-14)
    Kfd = _fd(lambda y: _evaluate(y, xi0, 1.0, 0.3, cohesion, lam_t=lam_t)[6][0], x)
    assert np.abs(K[0] - Kfd).max() < 1e-7 * np.abs(K[0]).max()
    assert np.abs(K[0] - K[0].T).max() > 1e-3 * np.abs(K[0]).max()


def test_without_slip_or_friction_the_kernel_is_the_frictionless_one():
    """At its stick point (s = 0) a sticking slave carries no tangential force: the force is the
    frictionless kernel's (1e-13) and the tangent adds the stick stiffness A ε_T ∂s/∂x ∂s/∂xᵀ
    (1e-11); with μ = c = 0 a slipping slave has the frictionless force and tangent."""
    x = _stencil(1)
    one = np.ones(1)
    _, xi, _, f0, K0 = node_to_smooth_segment(x[None], one, 0.0 * one, 0.5 * one, EPS * one, AREA * one, True)[:5]
    S = np.zeros(10)
    slip(x, xi[0], xi[0], S)
    for xi0, mu, stick in ((xi[0], 0.3, AREA * EPS_T * np.outer(S, S)), (xi[0] - 0.1, 0.0, 0.0)):
        _, _, _, t, _, _, f, K = _evaluate(x, xi0, 0.5, mu, tangent=True)
        assert abs(t[0]) < 1e-13
        assert np.abs(f - f0).max() < 1e-13 * np.abs(f0).max()
        assert np.abs(K[0] - K0[0] - stick).max() < 1e-11 * np.abs(K0).max()


@pytest.mark.parametrize("slipping", [False, True])
def test_frame_indifference_and_momentum(slipping):
    """The pair turned by 2.3 rad and moved by 8: gap, slip, pressure and traction unchanged (1e-10:
    the coordinates, 7, against the gap, 0.02, cost three digits), the forces turned with it (1e-12);
    the forces sum to zero and their moment vanishes (1e-13)."""
    x = _stencil(2)
    xi = _evaluate(x, 0.0)[1][0]
    xi0 = xi - (0.05 if slipping else 0.002)
    out = _evaluate(x, xi0, 0.5, 0.3)
    Q, y = _turned(x)
    moved = _evaluate(y, xi0, 0.5, 0.3)
    assert out[5][0] == slipping and moved[5][0] == slipping
    _assert_objective([out[j][0] for j in (0, 2, 3, 4)], [moved[j][0] for j in (0, 2, 3, 4)], out[6][0],
                      moved[6][0], Q, x)  # g, p, t, s; f


def _turned(x):
    """The rotation Q by 2.3 rad and the pair x turned by it and moved by (4, −7)."""
    c, sn = np.cos(2.3), np.sin(2.3)
    Q = np.array([[c, -sn], [sn, c]])
    return Q, (x.reshape(5, 2) @ Q.T + [4.0, -7.0]).ravel()


def _assert_objective(scalars, moved_scalars, f, moved_f, Q, x):
    """The pair's scalars (gap, pressure, traction, slip) unchanged by a rigid motion Q (1e-10: the
    coordinates, 7, against gaps of 0.02, cost three digits), its forces f (10,) turned with it
    (1e-12); they sum to zero and their moment about the origin vanishes (1e-13)."""
    for a, b in zip(moved_scalars, scalars):
        assert a == pytest.approx(b, rel=1e-10, abs=1e-14)
    f = f.reshape(5, 2)
    assert np.abs(moved_f.reshape(5, 2) - f @ Q.T).max() < 1e-12 * np.abs(f).max()
    assert np.abs(f.sum(axis=0)).max() < 1e-13 * np.abs(f).max()
    X = x.reshape(5, 2)
    assert abs(np.sum(X[:, 0] * f[:, 1] - X[:, 1] * f[:, 0])) < 1e-13 * np.abs(f).max() * 10


def test_the_return_map_puts_the_stick_point_at_the_elastic_distance():
    """After a slip the new stick point lies where the slave's slip from it is t/ε_T (1e-13):
    evaluated from it, the slave carries the traction it slipped with (1e-12)."""
    x = _stencil(3)
    xi = _evaluate(x, 0.0)[1][0]
    xi0 = xi - 0.05
    _, _, p, t, s, slipping, _, _ = _evaluate(x, xi0, 1.0, 0.3)
    assert slipping[0]
    xi1 = slipped_stick_point(x, xi, xi0, t[0], EPS_T)
    assert slip(x, xi, xi1, np.zeros(10)) == pytest.approx(t[0] / EPS_T, rel=1e-13)
    t1 = _evaluate(x, xi1, 1.0, 0.3)[3]  # on the slip surface: stick or slip, the same traction
    assert t1[0] == pytest.approx(t[0], rel=1e-12)


# -- at a sharp corner: the slave's closest point is the vertex b of its segment -----------------
def _corner(seed: int = 0, turn: float = 0.6):
    """A segment a → b of a curve ending at the sharp corner b (q = b), shaken by 1 %, and a slave
    0.01 outside the corner, its direction from b turned by ``turn`` of the angle between the
    curve's end normal and the next face's (a right-angled corner): in the vertex's region."""
    rng = np.random.default_rng(seed)
    p, a, b = np.array([-2.0, 0.1]), np.array([-1.0, 0.02]), np.array([0.0, 0.0]) + rng.normal(0.0, 0.01, 2)
    tau = 0.25 * p - 1.5 * a + 1.25 * b  # the curve's tangent at b (its end without a neighbour: x'' = 0)
    tau /= np.linalg.norm(tau)
    nu = np.array([tau[1], -tau[0]])
    angle = turn * np.pi / 2  # from the segment's normal towards its tangent
    slave = b + 0.01 * (np.cos(angle) * nu + np.sin(angle) * tau)
    normal = (nu + tau) / np.linalg.norm(nu + tau)  # the vertex's averaged normal
    return np.concatenate([slave, p, a, b, b]), normal


# the corner node b is also the stencil's q: derivatives are taken with them moving together
_TIE = np.vstack([np.eye(8), np.eye(8)[6:8]])  # (10, 8): (x_s, x_p, x_a, x_b) → (x_s, x_p, x_a, x_b, x_b)


def _tied(fun):
    """fun of the 10 stencil coordinates as a function of the 8 independent ones."""
    return lambda y: fun(_TIE @ y)


def _at_vertex(x, normal, xi0, lam=2.0, mu=0.3, cohesion=0.0, tangent=False, lam_t=0.0):
    one = np.ones(1)
    return node_to_vertex_friction(x[None], np.array([2]), normal[None], 0.0 * one, lam * one, EPS * one,
                                   AREA * one, EPS_T * one, mu * one, cohesion * one, xi0 * one, lam_t * one, tangent)


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("lam_t", [0.0, -0.3])
@pytest.mark.parametrize("turn", [0.3, 0.9])
def test_at_a_corner_in_stick_the_force_is_the_energy_gradient_and_the_tangent_its_derivative(seed, lam_t, turn):
    """A slave at a sharp corner, its stick point on the segment 0.004 (in ξ) from the vertex, μ
    large enough to stick: f = ∂W/∂x with W = A⟨λ − εg⟩²/2ε + A (λ_T s + ε_T s²/2) (1e-8), the
    stick point and the vertex's tangent moving with the segment's nodes; K = ∂f/∂x (1e-7) and
    symmetric; near either edge of the vertex's region."""
    x, normal = _corner(seed, turn)
    xi0 = 0.996

    def energy(y):
        _, p, _, s, _, _, _ = _at_vertex(y, normal, xi0, mu=5.0, lam_t=lam_t)
        return AREA * p[0] ** 2 / (2 * EPS) + AREA * (lam_t * s[0] + EPS_T * s[0] ** 2 / 2)

    g, p, t, s, slipping, f, K = _at_vertex(x, normal, xi0, mu=5.0, tangent=True, lam_t=lam_t)
    assert p[0] > 0.0 and not slipping[0] and abs(s[0]) > 1e-5 and t[0] == pytest.approx(lam_t + EPS_T * s[0])
    f, K = _TIE.T @ f[0], _TIE.T @ K[0] @ _TIE
    assert np.abs(f - _fd(_tied(energy), x[:8])).max() < 1e-8 * np.abs(f).max()
    Kfd = _fd(_tied(lambda y: _TIE.T @ _at_vertex(y, normal, xi0, mu=5.0, lam_t=lam_t)[5][0]), x[:8])
    assert np.abs(K - Kfd).max() < 1e-7 * np.abs(K).max()
    assert np.abs(K - K.T).max() < 1e-10 * np.abs(K).max()


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("cohesion", [0.0, 0.05])
@pytest.mark.parametrize("xi0", [0.9, 1.1])
def test_at_a_corner_in_slip_the_traction_is_coulombs_and_the_tangent_its_derivative(seed, cohesion, xi0):
    """A slave at a corner 0.1 (in ξ) from its stick point, on either side of it, μ = 0.3: it
    slips, the traction is c + μ p along the slip (1e-14), K = ∂f/∂x (1e-7), not symmetric."""
    x, normal = _corner(seed)
    g, p, t, s, slipping, f, K = _at_vertex(x, normal, xi0, 2.0, 0.3, cohesion, tangent=True)
    assert slipping[0] and t[0] == pytest.approx(np.sign(s[0]) * (cohesion + 0.3 * p[0]), rel=1e-14)
    K = _TIE.T @ K[0] @ _TIE
    Kfd = _fd(_tied(lambda y: _TIE.T @ _at_vertex(y, normal, xi0, 2.0, 0.3, cohesion)[5][0]), x[:8])
    assert np.abs(K - Kfd).max() < 1e-7 * np.abs(K).max()
    assert np.abs(K - K.T).max() > 1e-3 * np.abs(K).max()


def test_at_the_edge_of_a_corners_region_the_vertex_and_the_segment_agree():
    """A slave on the curve's end normal (the edge between the segment's and the vertex's regions):
    gap, pressure, slip, traction, stick or slip and the slave's force of the corner kernel are
    the segment's (1e-9), so that a slave passes from one to the other without a jump; deep in
    the vertex's region its friction force stays c + μ p along the vertex's tangent (bounded,
    however close to the vertex). Without friction the corner kernel is :func:`node_to_vertex`
    (1e-14)."""
    x, normal = _corner(1, turn=0.0)
    one = np.ones(1)
    for xi0, mu in ((0.999, 5.0), (0.9, 0.3)):
        seg = node_to_smooth_segment_friction(x[None], one, 0.0 * one, 2.0 * one, EPS * one, AREA * one,
                                              EPS_T * one, mu * one, 0.0 * one, xi0 * one, 0.1 * one, False)
        assert seg[1][0] == pytest.approx(1.0, abs=1e-9)
        g, p, t, s, slipping, f, _ = _at_vertex(x, normal, xi0, mu=mu, lam_t=0.1)
        for a, b in ((seg[0], g), (seg[2], p), (seg[4], s), (seg[3], t)):
            assert a[0] == pytest.approx(b[0], rel=1e-9, abs=1e-12)
        assert seg[5][0] == slipping[0]
        assert np.abs(seg[6][0][:2] - f[0][:2]).max() < 1e-9 * np.abs(f[0]).max()
    for turn in (0.5, 0.95):
        x, normal = _corner(1, turn)
        x[:2] = x[6:8] + 1e-4 * (x[:2] - x[6:8])  # 1e-6 from the vertex
        _, p, t, _, slipping, f, _ = _at_vertex(x, normal, 0.5, lam=2.0, mu=0.3)
        assert slipping[0] and np.linalg.norm(f[0][:2]) < AREA * np.hypot(p[0], t[0]) * (1 + 1e-12)
    x, normal = _corner(2)
    g, p, t, s, slipping, f, _ = _at_vertex(x, normal, 0.7, mu=0.0)
    gv, pv, fv, _ = node_to_vertex(x[None, :2], x[None, 6:8], normal[None], np.zeros(1), 2.0 * one, EPS * one,
                                   AREA * one, False)
    assert g[0] == pytest.approx(gv[0], rel=1e-14) and p[0] == pytest.approx(pv[0], rel=1e-14)
    assert np.abs(f[0][[0, 1, 6, 7]] - fv[0]).max() < 1e-14 * np.abs(fv).max()
    assert np.abs(f[0][2:6]).max() == 0.0 and np.abs(f[0][8:]).max() == 0.0


@pytest.mark.parametrize("slipping", [False, True])
def test_at_a_corner_frame_indifference_and_momentum(slipping):
    """The pair at a corner turned by 2.3 rad and moved: g, p, s, t unchanged (1e-10), the forces
    turned with it (1e-12), their sum and moment zero (1e-13)."""
    x, normal = _corner(2)
    xi0 = vertex_stick_point(x, 2, 0.9) - (0.1 if slipping else 0.002)  # (from right under the slave)
    out = _at_vertex(x, normal, xi0, 2.0, 0.3)
    Q, y = _turned(x)
    moved = _at_vertex(y, Q @ normal, xi0, 2.0, 0.3)
    assert out[4][0] == slipping and moved[4][0] == slipping
    _assert_objective([v[0] for v in out[:4]], [v[0] for v in moved[:4]], out[5][0], moved[5][0], Q, x)


def test_a_slave_slipping_at_a_corner_is_attached_right_under_itself():
    """The commit of a slave slipping at a corner: the new stick point ξ₁ on the segment has zero
    slip (1e-13), so the slave carries its traction in λ_T alone."""
    x, normal = _corner(3)
    _, p, t, s, slipping, _, _ = _at_vertex(x, normal, 0.9, 2.0, 0.3)
    assert slipping[0]
    xi1 = vertex_stick_point(x, 2, 0.9)
    assert abs(_at_vertex(x, normal, xi1, 2.0, 0.3)[3][0]) < 1e-13
    t1 = _at_vertex(x, normal, xi1, 2.0, 0.3, lam_t=t[0])[2]
    assert t1[0] == pytest.approx(t[0], rel=1e-12)

"""3D node-to-face contact: the kernels (closest point on triangles and bilinear quadrilaterals, on
their edges and vertices; gap, force, complex-step tangent) and the 3D broad phase.
References: the force is the gradient of the pair's energy W = A⟨λ − εg⟩²/2ε (Wriggers,
Computational Contact Mechanics, §4.1), checked by central differences of W; the tangent by
central differences of the force; the search against the brute-force box test."""
import numpy as np
import pytest

from dolfinx_corot.contact import kernels3d as k3
from dolfinx_corot.contact.search3d import broad_phase_boxes, face_boxes

EPS, AREA = 100.0, 0.7


def _face(k: int, rng) -> np.ndarray:
    face = (np.array([[0, 0, 0], [1, 0, 0.1], [0.1, 1, -0.1]], float) if k == 3 else
            np.array([[0, 0, 0], [1, 0, 0.1], [1.1, 1, 0.0], [0, 0.9, -0.1]], float))  # warped quad
    return face + rng.normal(0.0, 0.02, face.shape)


def _evaluate(x, k, mode, which, offset, lam, tangent=False, side=0.0):
    m = 3 * (1 + k)
    f, K = np.zeros(m), np.zeros((m, m))
    g = k3.node_to_face(x, k, mode, which, side, offset, lam, EPS, AREA, tangent, f, K)
    return g, f, K


# slaves: inside the face (penetrating), beyond an edge, beyond a vertex
CASES = [(0, 0, [0.3, 0.35, -0.02]), (1, 0, [0.5, -0.2, -0.03]), (1, 1, [0.9, 0.6, -0.05]),
         (2, 1, [1.3, -0.2, -0.05]), (2, 0, [-0.2, -0.2, -0.01])]


def _check_derivatives(x, k, mode, which, offset, lam, side=0.0):
    """f = ∂W/∂x and K = ∂f/∂x by central differences (h = 1e-6: 1e-8 of the largest entry), K
    symmetric (the Hessian of W: 1e-12), the pair's forces in balance (1e-13)."""
    g, f, K = _evaluate(x, k, mode, which, offset, lam, tangent=True, side=side)
    assert lam - EPS * g > 0.0  # in contact
    m = 3 * (1 + k)
    h = 1e-6
    fd_f, fd_K = np.zeros(m), np.zeros((m, m))
    energy = (lambda gap: AREA * max(0.0, lam - EPS * gap) ** 2 / (2 * EPS))  # noqa: E731
    for j in range(m):
        xp, xm = x.copy(), x.copy()
        xp.flat[j] += h
        xm.flat[j] -= h
        (gp, fp, _) = _evaluate(xp, k, mode, which, offset, lam, side=side)
        (gm, fm, _) = _evaluate(xm, k, mode, which, offset, lam, side=side)
        fd_f[j] = (energy(gp) - energy(gm)) / (2 * h)
        fd_K[:, j] = (fp - fm) / (2 * h)
    assert np.abs(f - fd_f).max() < 1e-8 * np.abs(f).max()
    assert np.abs(K - fd_K).max() < 1e-8 * np.abs(K).max()
    assert np.abs(K - K.T).max() < 1e-12 * np.abs(K).max()
    # the slave's force balances the face nodes' (no net force along any axis)
    assert np.abs(f.reshape(-1, 3).sum(axis=0)).max() < 1e-13 * np.abs(f).max()
    return g, f


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("mode, which, slave", CASES)
@pytest.mark.parametrize("offset, lam", [(0.0, 0.0), (0.05, 0.0), (0.0, 3.0)])
def test_force_is_the_energy_gradient_and_the_tangent_its_derivative(k, mode, which, slave, offset, lam):
    """Face interior, edge and vertex contact of a slave against a triangle and a warped bilinear
    quadrilateral, with an offset (a beam slave's radius) and an augmented-Lagrangian
    multiplier."""
    rng = np.random.default_rng(11)
    _check_derivatives(np.vstack([slave, _face(k, rng)]), k, mode, which, offset, lam)


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("mode, which, slave", CASES)
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_two_sided_master_with_a_shell_offset(k, mode, which, slave, side):
    """A shell's mid-surface as a two-sided master, its contact faces at ±t/2 (offset 0.4): a
    slave 0.03 from the mid-surface on either side, over the face, beyond an edge and beyond a
    vertex, is pushed away from the mid-surface on its own side: over the face along ± the face
    normal, at an edge or vertex away from its nearest point (a shell's free edge is rounded);
    f and K are the derivatives of the energy as above."""
    rng = np.random.default_rng(11)
    x = np.vstack([[slave[0], slave[1], 0.03 * side], _face(k, rng)])
    g, f = _check_derivatives(x, k, mode, which, 0.4, 0.0, side=side)
    assert g < 0.0
    N, n = np.zeros(k), np.zeros(3)
    dist = k3._contact_point(x, k, mode, which, side, N, n)
    assert dist > 0.0 and dist == pytest.approx(g + 0.4, abs=1e-14)
    xc = N @ x[1:]
    assert np.allclose(n, (x[0] - xc) / np.linalg.norm(x[0] - xc), atol=1e-12)  # towards the slave
    assert np.allclose(f[:3], -AREA * EPS * (-g) * n, atol=1e-12)  # the push on the slave is +p A n


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("mode, which", [(1, 0), (2, 0)])
def test_beyond_the_border_of_a_solid_a_slave_is_inside_only_below_the_45_degree_line(k, mode, which):
    """A one-sided master's border edge (mode 1) or vertex (2), ``side`` BORDER: a slave beyond it
    by d and below the face's plane by δ has the gap +|x_s − x_c| (outside: beside the body) for
    δ < d, whatever the sign of δ — at the face's level (grazing) too, where the sign of the face
    normal's component is round-off — and −|x_s − x_c| for δ > d (sunk below a border shared with
    another body); there the force and tangent are the energy's derivatives."""
    face = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float) if k == 3 else
            np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float))
    beyond = np.array([0.4, -0.1, 0.0]) if mode == 1 else np.array([-0.06, -0.08, 0.0])  # d = 0.1
    d = np.linalg.norm(beyond[:2] - (np.array([0.4, 0.0]) if mode == 1 else 0.0))
    for depth, inside in ((0.0, False), (1e-17, False), (-1e-17, False), (0.05, False), (-0.05, False),
                          (0.099, False), (0.101, True), (0.3, True)):
        x = np.vstack([beyond - [0.0, 0.0, depth], face])
        N, n = np.zeros(k), np.zeros(3)
        dist = k3._contact_point(x, k, mode, which, k3.BORDER, N, n)
        assert dist == pytest.approx((-1.0 if inside else 1.0) * np.hypot(d, depth), rel=1e-12), depth
    # a one-sided master inside the surface keeps the sign of the face normal's component
    x = np.vstack([beyond - [0.0, 0.0, 0.05], face])
    assert k3._contact_point(x, k, mode, which, 0.0, np.zeros(k), np.zeros(3)) < 0.0
    _check_derivatives(np.vstack([beyond - [0.0, 0.0, 0.3], face]), k, mode, which, 0.0, 0.0, side=k3.BORDER)


@pytest.mark.parametrize("k", [3, 4])
def test_closest_point_and_gap_on_a_flat_face(k):
    """A flat face in the plane z = 0.2 (counter-clockwise from +z): the projection of a slave at
    height z is its foot, the gap z − 0.2 − offset, the normal +z; a point off the face is
    flagged outside."""
    face = (np.array([[0, 0, 0.2], [2, 0, 0.2], [0, 2, 0.2]]) if k == 3 else
            np.array([[0, 0, 0.2], [2, 0, 0.2], [2, 2, 0.2], [0, 2, 0.2]]))
    xs = np.array([[0.5, 0.4, 0.15], [0.5, 0.4, 0.35], [3.0, 0.5, 0.1]])
    xi, eta, dist = np.zeros(3), np.zeros(3), np.zeros(3)
    on = np.zeros(3, dtype=bool)
    k3.closest_on_faces(xs, face.astype(float), np.array([[0, 1, 2, 3][:k] + [0] * (4 - k)]), np.array([k]),
                        np.arange(3), np.zeros(3, dtype=np.int64), 1e-9, xi, eta, dist, on)
    assert np.allclose(dist, [-0.05, 0.15, -0.1], atol=1e-14)
    assert on.tolist() == [True, True, False]
    g, f, _ = _evaluate(np.vstack([xs[0], face]), k, 0, 0, 0.01, 0.0)
    assert g == pytest.approx(-0.06, abs=1e-14)
    assert np.allclose(f[:3], [0.0, 0.0, -AREA * EPS * 0.06], atol=1e-12)


def test_broad_phase_finds_every_slave_in_every_box():
    """Random slaves and boxes, and empty inputs: the pairs are exactly those of the brute-force
    test, sorted by slave then face."""
    rng = np.random.default_rng(1)
    for ns, nm in [(0, 5), (5, 0), (300, 200), (2000, 1500)]:
        s = rng.uniform(0, 1, (ns, 3))
        lo = rng.uniform(0, 1, (nm, 3))
        hi = lo + rng.uniform(0, 0.2, (nm, 3))
        pairs = broad_phase_boxes(s, lo, hi)
        brute = np.argwhere(((s[:, None, :] >= lo[None]) & (s[:, None, :] <= hi[None])).all(axis=2))
        assert np.array_equal(pairs, brute.reshape(-1, 2))


def test_broad_phase_of_a_surface_of_faces():
    """Slaves over a wavy surface of quadrilaterals (boxes inflated by half a face): every slave
    finds the face it lies over, and not more than the few faces around it."""
    n = 21
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    X = np.column_stack([x.ravel(), y.ravel(), 0.01 * np.sin(6 * x.ravel())])
    idx = np.arange(n * n).reshape(n, n)
    faces = np.column_stack([idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()])
    h = 1.0 / (n - 1)
    slaves = X[faces].mean(axis=1) + [0.0, 0.0, 0.2 * h]
    lo, hi = face_boxes(X, faces, 0.5 * h)
    pairs = broad_phase_boxes(slaves, lo, hi)
    own = {tuple(p) for p in pairs}
    assert all((i, i) in own for i in range(len(faces)))
    assert np.bincount(pairs[:, 0]).max() <= 9
    with pytest.raises(ValueError, match="coordinates must be finite"):
        broad_phase_boxes(np.array([[np.nan, 0.0, 0.0]]), lo, hi)


def test_the_search_projection_agrees_with_the_kernels():
    """The allocation-free projection of the narrow phase and the kernels' (complex-capable) one give
    the same closest point and distance on warped quadrilaterals and on triangles, for slaves
    near and far (1e-12)."""
    rng = np.random.default_rng(5)
    for k in (3, 4):
        for _ in range(50):
            face = _face(k, rng)
            xs = rng.uniform(-0.5, 1.5, (1, 3)) * [1, 1, 0.5]
            xi, eta, dist = np.zeros(1), np.zeros(1), np.zeros(1)
            on = np.zeros(1, dtype=bool)
            k3.closest_on_faces(xs, face, np.array([list(range(k)) + [0] * (4 - k)]), np.array([k]),
                                np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64), 1e-9, xi, eta, dist, on)
            x = np.vstack([xs, face])
            ref_xi, ref_eta, ok = k3.project(x, k)
            assert ok
            assert abs(xi[0] - ref_xi) < 1e-12 and abs(eta[0] - ref_eta) < 1e-12
            g, _, _ = _evaluate(x, k, 0, 0, 0.0, 0.0)
            assert abs(dist[0] - g) < 1e-12
            assert on[0] == k3.inside(k, ref_xi, ref_eta, 1e-9)

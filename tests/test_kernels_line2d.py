"""2D beam and bar kernels: finite-difference tangents, objectivity, linear limit."""
import numpy as np
import pytest

from dolfinx_corot.kernels import compiled
from dolfinx_corot.kernels import line2d as k
from dolfinx_corot.rotations import exp_so2

PROPS = {
    "bernoulli": np.array([1000.0, 0.8333, 0.0, 0.0]),
    "timoshenko": np.array([1000.0, 0.8333, 416.67, 0.0]),
    "bar": np.array([1000.0, 0.0, 0.0, 0.0]),
    "prestressed bar": np.array([1000.0, 0.0, 0.0, 5.0]),
}


def _eval(X, d, props, large=True, impl="numba"):
    """(f, K) of one element by the numba kernels or by the C kernels DOLFINx is handed
    (:mod:`dolfinx_corot.kernels.compiled`)."""
    if impl == "C":
        return compiled.line2d_element(np.c_[X, np.zeros(2)], np.concatenate([d, props]), 1.0 if large else 0.0)
    f, K = np.empty(6), np.empty((6, 6))
    k.evaluate(X[0, 0], X[0, 1], X[1, 0], X[1, 1], d, props, large, f, K)
    return f, K


IMPLS = ["numba", "C"]


def _random_state(rng, big_rotation=True):
    """An element of random length/orientation in a large-rotation state with small strain."""
    l0 = rng.uniform(0.05, 3.0)
    a0 = rng.uniform(-np.pi, np.pi)
    X = np.array([[0.3, -1.2], [0.3 + l0 * np.cos(a0), -1.2 + l0 * np.sin(a0)]])
    rigid = rng.uniform(-7 * np.pi, 7 * np.pi) if big_rotation else rng.uniform(-0.3, 0.3)
    Q = exp_so2(rigid)
    t = rng.normal(size=2) * 5
    x = (Q @ X.T).T * (1 + rng.uniform(-0.02, 0.02)) + t
    d = np.zeros(6)
    d[[0, 1]] = x[0] - X[0]
    d[[3, 4]] = x[1] - X[1]
    d[[2, 5]] = rigid + rng.uniform(-0.4, 0.4, size=2)
    return X, d


@pytest.mark.parametrize("impl", IMPLS)
@pytest.mark.parametrize("kind", list(PROPS))
@pytest.mark.parametrize("large", [True, False])
def test_tangent_matches_finite_differences(kind, large, impl):
    """K = ∂f/∂d by central differences at random large-rotation states (rel. error < 1e-6)."""
    rng = np.random.default_rng(11)
    for _ in range(50):
        X, d = _random_state(rng)
        f, K = _eval(X, d, PROPS[kind], large, impl)
        h = 1e-6 * max(1.0, np.abs(d).max())
        Kfd = np.empty((6, 6))
        for j in range(6):
            e = np.zeros(6)
            e[j] = h
            Kfd[:, j] = (_eval(X, d + e, PROPS[kind], large, impl)[0]
                         - _eval(X, d - e, PROPS[kind], large, impl)[0]) / (2 * h)
        err = np.linalg.norm(K - Kfd) / np.linalg.norm(K)
        assert err < 1e-6, (kind, err)
        np.testing.assert_allclose(K, K.T, atol=1e-9 * np.abs(K).max())


@pytest.mark.parametrize("impl", IMPLS)
@pytest.mark.parametrize("kind", list(PROPS))
def test_rigid_motion_gives_no_force(kind, impl):
    """Objectivity: any rigid motion (rotations of up to 7π) leaves only the prestress."""
    rng = np.random.default_rng(5)
    X = np.array([[0.0, 0.0], [1.3, 0.4]])
    f0, _ = _eval(X, np.zeros(6), PROPS[kind], impl=impl)
    for angle in np.concatenate([rng.uniform(-7 * np.pi, 7 * np.pi, 20), [np.pi, -np.pi, 2 * np.pi]]):
        Q = exp_so2(angle)
        t = rng.normal(size=2)
        x = (Q @ X.T).T + t
        d = np.array([*(x[0] - X[0]), angle, *(x[1] - X[1]), angle])
        f, _ = _eval(X, d, PROPS[kind], impl=impl)
        # the force co-rotates with the element: Qᵀ f equals f at rest
        fr = f.copy()
        fr[[0, 1]] = Q.T @ f[[0, 1]]
        fr[[3, 4]] = Q.T @ f[[3, 4]]
        np.testing.assert_allclose(fr, f0, atol=1e-10 * max(1.0, np.abs(f0).max()))


@pytest.mark.parametrize("impl", IMPLS)
def test_linear_element_is_the_classical_frame_element(impl):
    """Large rotations off: K is the textbook 2D frame element stiffness rotated to 30°."""
    EA, EI, L = 7.0, 3.0, 2.0
    a = np.pi / 6
    X = np.array([[1.0, 1.0], [1.0 + L * np.cos(a), 1.0 + L * np.sin(a)]])
    _, K = _eval(X, np.zeros(6), np.array([EA, EI, 0.0, 0.0]), large=False, impl=impl)
    kl = np.zeros((6, 6))
    kl[np.ix_([0, 3], [0, 3])] = EA / L * np.array([[1, -1], [-1, 1]])
    b = EI / L**3 * np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                              [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L**2, -6 * L, 4 * L**2]])
    kl[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = b
    c, s = np.cos(a), np.sin(a)
    T = np.zeros((6, 6))
    for n in (0, 3):
        T[n:n + 3, n:n + 3] = [[c, s, 0], [-s, c, 0], [0, 0, 1]]
    np.testing.assert_allclose(K, T.T @ kl @ T, rtol=1e-13, atol=1e-12)


def test_corotational_tangent_at_rest_equals_linear_stiffness():
    X = np.array([[0.0, 0.0], [0.6, -0.8]])
    for props in PROPS.values():
        if props[3]:
            continue
        _, Kc = _eval(X, np.zeros(6), props, True)
        _, Kl = _eval(X, np.zeros(6), props, False)
        np.testing.assert_allclose(Kc, Kl, atol=1e-12 * np.abs(Kl).max())


def test_evaluate_all_matches_single_evaluations():
    rng = np.random.default_rng(2)
    n = 20
    X = np.empty((n, 2, 2))
    D = np.empty((n, 6))
    for e in range(n):
        X[e], D[e] = _random_state(rng)
    P = np.tile(PROPS["timoshenko"], (n, 1))
    F, K = np.empty((n, 6)), np.empty((n, 6, 6))
    k.evaluate_all(X, D, P, True, F, K)
    for e in range(n):
        f, Ke = _eval(X[e], D[e], P[e])
        np.testing.assert_array_equal(F[e], f)
        np.testing.assert_array_equal(K[e], Ke)


@pytest.mark.parametrize("kind", list(PROPS))
def test_the_c_kernels_give_the_numba_kernels_numbers(kind):
    """The C kernels DOLFINx is handed equal the numba ones bit for bit (the same operations in the same
    order), co-rotational and geometrically linear, at rigid rotations up to 7π."""
    rng = np.random.default_rng(7)
    for _ in range(100):
        X, d = _random_state(rng)
        for large in (True, False):
            f, K = _eval(X, d, PROPS[kind], large, "C")
            fn, Kn = _eval(X, d, PROPS[kind], large)
            assert np.array_equal(f, fn) and np.array_equal(K, Kn), (kind, large)


def test_the_c_element_loop_gives_the_numba_numbers():
    """The end forces of many elements (the element results' path), C against
    :func:`~dolfinx_corot.kernels.line2d.evaluate_all`, bit for bit."""
    rng = np.random.default_rng(12)
    n = 50
    X, D, props = np.empty((n, 2, 2)), np.empty((n, 6)), np.empty((n, 4))
    for e in range(n):
        X[e], D[e] = _random_state(rng)
        props[e] = PROPS[list(PROPS)[e % len(PROPS)]]
    for large in (True, False):
        F, K = np.empty((n, 6)), np.empty((n, 6, 6))
        compiled.evaluate_all_2d(X, D, props, large, F, K)
        Fn, Kn = np.empty((n, 6)), np.empty((n, 6, 6))
        k.evaluate_all(X, D, props, large, Fn, Kn)
        assert np.array_equal(F, Fn) and np.array_equal(K, Kn)

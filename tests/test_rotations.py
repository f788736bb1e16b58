"""Property tests of the rotation algebra (exp, log, tangent maps, updates)."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from dolfinx_corot import rotations as rot

finite = st.floats(-1.0, 1.0, allow_nan=False)
vec3 = st.tuples(finite, finite, finite).filter(lambda v: np.linalg.norm(v) > 1e-6)


def _rotvec(direction, angle):
    d = np.asarray(direction, float)
    return angle * d / np.linalg.norm(d)


def _matrix_exp(W, terms=60):
    """Reference: exp of a (3, 3) matrix by scaling and squaring of the series."""
    k = max(0, int(np.ceil(np.log2(max(np.linalg.norm(W), 1e-300)))) + 2)
    A = W / 2.0**k
    E, term = np.eye(3), np.eye(3)
    for n in range(1, terms):
        term = term @ A / n
        E = E + term
    for _ in range(k):
        E = E @ E
    return E


@settings(max_examples=300, deadline=None)
@given(vec3, st.floats(0.0, np.pi - 1e-9))
def test_log_of_exp_is_identity_below_pi(direction, angle):
    w = _rotvec(direction, angle)
    np.testing.assert_allclose(rot.log_so3(rot.exp_so3(w)), w, atol=2e-12)


@settings(max_examples=300, deadline=None)
@given(vec3, st.floats(0.0, 30.0))
def test_exp_of_log_is_identity(direction, angle):
    R = rot.exp_so3(_rotvec(direction, angle))
    w = rot.log_so3(R)
    assert np.linalg.norm(w) <= np.pi + 1e-12
    np.testing.assert_allclose(rot.exp_so3(w), R, atol=2e-14)


@settings(max_examples=100, deadline=None)
@given(vec3, st.floats(0.0, 20.0))
def test_exp_matches_matrix_exponential(direction, angle):
    w = _rotvec(direction, angle)
    np.testing.assert_allclose(rot.exp_so3(w), _matrix_exp(rot.spin(w)), atol=1e-12)


@pytest.mark.parametrize("angle", [1e-12, 1e-8, 1e-3, 0.5, np.pi - 1e-9, np.pi, 7 * np.pi])
def test_special_angles(angle):
    """Angles of 1e-12, π − 1e-9 and 7π about a skew axis."""
    axis = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    w = angle * axis
    R = rot.exp_so3(w)
    assert rot.orthogonality_error(R) < 1e-15
    np.testing.assert_allclose(R, _matrix_exp(rot.spin(w)), atol=1e-14)
    # the logarithm returns the equivalent vector of norm in [0, π]
    wl = rot.log_so3(R)
    reduced = angle - 2 * np.pi * np.round(angle / (2 * np.pi))  # in [-π, π]
    if abs(abs(reduced) - np.pi) < 1e-6:
        # at π, ±axis·π are the same rotation
        assert abs(np.linalg.norm(wl) - abs(reduced)) < 1e-9
        assert abs(abs(wl @ axis) - np.linalg.norm(wl)) < 1e-9
    else:
        np.testing.assert_allclose(wl, reduced * axis, rtol=1e-12, atol=1e-22 + 1e-15 * angle)
    np.testing.assert_allclose(rot.exp_so3(wl), R, atol=1e-14)
    # quaternion path agrees with the matrix path
    np.testing.assert_allclose(rot.quat_to_matrix(rot.quat_from_rotvec(w)), R, atol=1e-14)


def test_log_near_pi_keeps_all_digits():
    """arccos((tr R - 1)/2) would lose ~half the digits at π - 1e-9."""
    axis = np.array([0.3, 0.4, np.sqrt(1 - 0.25)])
    for eps in [1e-6, 1e-9, 1e-12]:
        w = (np.pi - eps) * axis
        wl = rot.log_so3(rot.exp_so3(w))
        assert abs(np.linalg.norm(wl) - (np.pi - eps)) < 4e-15
        np.testing.assert_allclose(wl, w, atol=1e-14)


def test_orthogonality_after_1e5_multiplicative_updates():
    rng = np.random.default_rng(1)
    increments = rng.normal(scale=0.3, size=(100_000, 3))
    R = np.eye(3)
    q = np.array([1.0, 0.0, 0.0, 0.0])
    for dtheta in increments:
        R = rot.update_so3(R, dtheta)
        q = rot.quat_update(q, dtheta)
    assert rot.orthogonality_error(R) < 1e-12
    assert rot.orthogonality_error(rot.quat_to_matrix(q)) < 1e-14
    # both representations describe the same rotation
    assert np.max(np.abs(R - rot.quat_to_matrix(q))) < 1e-10


def test_updates_compose_like_exponentials():
    """exp(a)·exp(b) == exp(log(exp(a)·exp(b))) and the quaternion product agrees."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        a, b = rng.normal(size=3) * 2, rng.normal(size=3) * 2
        R = rot.compose(rot.exp_so3(a), rot.exp_so3(b))
        q = rot.quat_mul(rot.quat_from_rotvec(a), rot.quat_from_rotvec(b))
        np.testing.assert_allclose(rot.quat_to_matrix(q), R, atol=1e-14)
        np.testing.assert_allclose(rot.quat_from_matrix(R), q * np.sign(q[0]), atol=1e-14)


@settings(max_examples=100, deadline=None)
@given(vec3, st.floats(1e-9, 6.0))
def test_tangent_operator_by_finite_differences(direction, angle):
    """δR Rᵀ = spin(T(θ) δθ): central differences of exp, relative error < 1e-6."""
    w = _rotvec(direction, angle)
    R = rot.exp_so3(w)
    T = rot.tangent_so3(w)
    h = 1e-6
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        dR = (rot.exp_so3(w + e) - rot.exp_so3(w - e)) / (2 * h)
        col = rot.axial(dR @ R.T)
        assert np.linalg.norm(col - T[:, j]) < 1e-6 * np.linalg.norm(T[:, j]) + 1e-9
    if angle < 2 * np.pi - 1e-3:
        np.testing.assert_allclose(rot.tangent_inv_so3(w) @ T, np.eye(3), atol=1e-10)


def test_tangent_series_branch_is_continuous():
    axis = np.array([0.0, 0.6, 0.8])
    for f in (rot.tangent_so3, rot.tangent_inv_so3, rot.exp_so3):
        below, above = f((1e-3 - 1e-15) * axis), f((1e-3 + 1e-15) * axis)
        assert np.max(np.abs(below - above)) < 4e-15  # = |df/dθ|·2e-15


def test_so2_multiplicative_update_is_angle_addition():
    theta = 0.0
    R = np.eye(2)
    rng = np.random.default_rng(0)
    for d in rng.normal(scale=0.7, size=1000):
        theta = rot.update_so2(theta, d)
        R = rot.exp_so2(d) @ R
    np.testing.assert_allclose(rot.exp_so2(theta), R, atol=1e-12)
    assert abs(rot.log_so2(R) - (np.mod(theta + np.pi, 2 * np.pi) - np.pi)) < 1e-10
    assert abs(rot.log_so2(rot.exp_so2(7 * np.pi)) - np.pi) < 1e-12


def test_derivative_of_the_inverse_tangent_map_in_closed_form():
    """∂(T⁻¹(θ)ᵀm)/∂θ (the moment term of the beams' and shells' tangents) in closed form against
    its complex-step derivative, at angles from 0 through the Taylor branch (|θ|² < 10⁻²) and its
    edge to 6 rad: 1e-12."""
    rng = np.random.default_rng(5)
    for t in (0.0, 1e-8, 1e-4, 0.05, 0.0999, 0.1001, 0.3, 1.0, 3.0, 6.0):
        for _ in range(10):
            d = rng.normal(size=3)
            th, m = t * d / np.linalg.norm(d), rng.normal(size=3)
            A, B = np.empty((3, 3)), np.empty((3, 3))
            rot.tangent_inv_so3_derivative(th, m, A)
            rot.tangent_inv_so3_derivative_complex_step(th, m, B)
            assert np.abs(A - B).max() <= 1e-12 * np.abs(B).max()

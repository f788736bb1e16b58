"""Co-rotational flat shell triangle: FD tangent, objectivity, tangent at rest = rotated local stiffness."""
import numpy as np
import pytest

from dolfinx_corot import rotations as rot
from dolfinx_corot.elements import shell_triangle as law
from dolfinx_corot.kernels import shell3d as k

PROPS = np.array([2.1e4, 0.3, 0.05, 1e-2])


def _eval(X, S, large=True):
    f, K = np.empty(18), np.empty((18, 18))
    k.evaluate(X, S, PROPS, large, f, K)
    return f, K


def _state(rng, X, strain=0.01, rot_scale=0.2):
    Q = rot.exp_so3(rng.normal(size=3) * 2)
    t = rng.normal(size=3)
    S = np.empty((3, 7))
    for a in range(3):
        S[a, :3] = Q @ X[a] + t + rng.normal(size=3) * strain - X[a]
        S[a, 3:] = rot.quat_from_matrix(rot.exp_so3(rng.normal(size=3) * rot_scale) @ Q)
    return S, Q


def _triangle(rng):
    X = rng.normal(size=(3, 3))
    return X


def test_tangent_matches_finite_differences():
    rng = np.random.default_rng(5)
    for _ in range(10):
        X = _triangle(rng)
        S, _ = _state(rng, X)
        f, K = _eval(X, S)
        h = 1e-6
        Kfd = np.empty((18, 18))
        for j in range(18):
            a, c = divmod(j, 6)
            P, M = S.copy(), S.copy()
            if c < 3:
                P[a, c] += h
                M[a, c] -= h
            else:
                e = np.zeros(3)
                e[c - 3] = h
                P[a, 3:] = rot.quat_mul(rot.quat_from_rotvec(e), S[a, 3:])
                M[a, 3:] = rot.quat_mul(rot.quat_from_rotvec(-e), S[a, 3:])
            Kfd[:, j] = (_eval(X, P)[0] - _eval(X, M)[0]) / (2 * h)
        assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()


def test_rigid_motion_rotates_the_forces():
    rng = np.random.default_rng(9)
    X = _triangle(rng)
    S, _ = _state(rng, X)
    f0, _ = _eval(X, S)
    for angle in (1.0, np.pi, 10.0):
        Q = rot.exp_so3(angle * rng.normal(size=3) / np.sqrt(3))
        t = rng.normal(size=3)
        moved = S.copy()
        for a in range(3):
            moved[a, :3] = Q @ (X[a] + S[a, :3]) + t - X[a]
            moved[a, 3:] = rot.quat_mul(rot.quat_from_matrix(Q), S[a, 3:])
        f, _ = _eval(X, moved)
        expected = np.concatenate([Q @ f0[3 * i:3 * i + 3] for i in range(6)])
        assert np.abs(f - expected).max() < 1e-10 * np.abs(f0).max()
    # a rigidly moved undeformed element carries no force
    rest = np.zeros((3, 7))
    Q = rot.exp_so3(np.array([3.0, -4.0, 5.0]))
    for a in range(3):
        rest[a, :3] = Q @ X[a] + 1.0 - X[a]
        rest[a, 3:] = rot.quat_from_matrix(Q)
    f, _ = _eval(X, rest)
    assert np.abs(f).max() < 1e-10 * np.abs(f0).max()


def test_tangent_at_rest_is_the_local_stiffness_rotated():
    rng = np.random.default_rng(2)
    X = _triangle(rng)
    rest = np.zeros((3, 7))
    rest[:, 3] = 1.0
    _, Kc = _eval(X, rest, True)
    _, Kl = _eval(X, rest, False)
    R0, xbar0 = np.empty((3, 3)), np.empty((3, 3))
    from dolfinx_corot.corotation import frame_triangle

    frame_triangle.initial(X, R0, xbar0)
    Kbar = np.empty((18, 18))
    law.local_stiffness(np.ascontiguousarray(xbar0[:, :2]), PROPS, Kbar)
    T = np.kron(np.eye(6), R0)
    np.testing.assert_allclose(Kl, T @ Kbar @ T.T, atol=1e-9 * np.abs(Kbar).max())
    np.testing.assert_allclose(Kc, Kl, atol=1e-8 * np.abs(Kbar).max())

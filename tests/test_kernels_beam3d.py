"""3D beam and bar kernels: finite-difference tangents, objectivity, linear limit, assembly."""
import numpy as np
import pytest

import dolfinx_corot as dc
from dolfinx_corot import rotations as rot
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.kernels import beam3d as k
from dolfinx_corot.kernels import compiled

PROPS = {
    "bernoulli": np.array([1000.0, 50.0, 0.8, 1.2, 0.0, 0.0, 0.0, 0.3, 1.0, 0.2]),
    "timoshenko": np.array([1000.0, 50.0, 0.8, 1.2, 400.0, 300.0, 0.0, 0.3, 1.0, 0.2]),
    "bar": np.array([1000.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
    "prestressed bar": np.array([1000.0, 0.0, 0.0, 0.0, 0.0, 0.0, 7.0, 0.0, 0.0, 1.0]),
}


def _eval(X1, X2, s1, s2, props, large=True, impl="numba"):
    """(f, K) of one element by the numba kernels or by the C kernels DOLFINx is handed
    (:mod:`dolfinx_corot.kernels.compiled`)."""
    if impl == "C":
        return compiled.beam3d_element(np.array([X1, X2]), np.concatenate([s1, s2, props]), 1.0 if large else 0.0)
    f, K = np.empty(12), np.empty((12, 12))
    k.evaluate(X1, X2, s1, s2, props, large, f, K)
    return f, K


IMPLS = ["numba", "C"]


def _spin_perturbed(s, dw):
    out = s.copy()
    out[3:] = rot.quat_mul(rot.quat_from_rotvec(dw), s[3:])
    return out


def _random_state(rng):
    """Element of random length/orientation, moved by a large rigid motion plus small strain."""
    X1 = rng.normal(size=3)
    X2 = X1 + rng.normal(size=3) * rng.uniform(0.2, 2.0)
    Q = rot.exp_so3(rng.normal(size=3) * 3)
    t = rng.normal(size=3)
    s = []
    for X in (X1, X2):
        x = Q @ X + t + rng.normal(size=3) * 0.01
        q = rot.quat_from_matrix(rot.exp_so3(rng.normal(size=3) * 0.3) @ Q)
        s.append(np.r_[x - X, q])
    return X1, X2, s[0], s[1], Q


@pytest.mark.parametrize("impl", IMPLS)
@pytest.mark.parametrize("kind", list(PROPS))
@pytest.mark.parametrize("large", [True, False])
def test_tangent_matches_finite_differences(kind, large, impl):
    """K = ∂f/∂d with spin columns R ← exp(h e_k) R, central differences (relative error < 1e-6)."""
    rng = np.random.default_rng(3)
    props = PROPS[kind].copy()
    for _ in range(25):
        X1, X2, s1, s2, _ = _random_state(rng)
        if not large:  # the linear element uses rotation vectors: stay below π
            s1[3:], s2[3:] = rot.quat_from_rotvec(rng.normal(size=3) * 0.3), rot.quat_from_rotvec(rng.normal(size=3) * 0.3)
        f, K = _eval(X1, X2, s1, s2, props, large, impl)
        h = 1e-6
        Kfd = np.empty((12, 12))
        for j in range(12):
            node, c = divmod(j, 6)
            plus, minus = [s1.copy(), s2.copy()], [s1.copy(), s2.copy()]
            if c < 3:
                plus[node][c] += h
                minus[node][c] -= h
            elif large:
                e = np.zeros(3)
                e[c - 3] = h
                plus[node] = _spin_perturbed(plus[node], e)
                minus[node] = _spin_perturbed(minus[node], -e)
            else:  # linear: additive rotation vectors
                for sgn, lst in ((1, plus), (-1, minus)):
                    r = rot.rotvec_from_quat(lst[node][3:].copy())
                    r[c - 3] += sgn * h
                    lst[node][3:] = rot.quat_from_rotvec(r)
            Kfd[:, j] = (_eval(X1, X2, *plus, props, large, impl)[0]
                         - _eval(X1, X2, *minus, props, large, impl)[0]) / (2 * h)
        err = np.abs(K - Kfd).max() / np.abs(K).max()
        assert err < 1e-6, (kind, large, err)


@pytest.mark.parametrize("impl", IMPLS)
@pytest.mark.parametrize("kind", list(PROPS))
@pytest.mark.parametrize("scale", [0.0, 0.3, 3.0])
def test_closed_form_tangent_equals_the_complex_step_derivative(kind, scale, impl):
    """The closed-form tangent (Bᵀ K̄ B + ∂Bᵀ/∂d : f̄) equals the complex-step derivative of f, exact to
    rounding, at rest, at moderate and at large relative rotations (|θ| up to ~5 rad, element
    stretched and bent, with and without initial axial force)."""
    rng = np.random.default_rng(11)
    props = PROPS[kind].copy()
    for trial in range(20):
        X1, X2, s1, s2, _ = _random_state(rng)
        props[k.law.N0] = PROPS[kind][k.law.N0] + (trial % 2) * rng.normal() * 20.0
        for s in (s1, s2):
            s[:3] += scale * rng.normal(size=3) * 0.2
            s[3:] = rot.quat_mul(rot.quat_from_rotvec(scale * rng.normal(size=3)), s[3:])
        f, K = _eval(X1, X2, s1, s2, props, impl=impl)
        fc, Kc = np.empty(12), np.empty((12, 12))
        k.corotational_complex_step(X1, X2, s1, s2, props, fc, Kc)
        assert np.abs(f - fc).max() <= 1e-13 * max(np.abs(fc).max(), 1.0)
        assert np.abs(K - Kc).max() <= 1e-11 * np.abs(Kc).max(), (kind, scale, trial)


@pytest.mark.parametrize("impl", IMPLS)
@pytest.mark.parametrize("kind", list(PROPS))
def test_rigid_motion_rotates_the_forces(kind, impl):
    """Objectivity: a rigid motion (rotations up to 10 rad) of a deformed element rotates f."""
    rng = np.random.default_rng(8)
    X1, X2, s1, s2, _ = _random_state(rng)
    f0, _ = _eval(X1, X2, s1, s2, PROPS[kind], impl=impl)
    for angle in (0.5, np.pi, 10.0):
        Q = rot.exp_so3(angle * rng.normal(size=3) / np.sqrt(3))
        t = rng.normal(size=3)
        moved = []
        for X, s in ((X1, s1), (X2, s2)):
            x = Q @ (X + s[:3]) + t
            moved.append(np.r_[x - X, rot.quat_mul(rot.quat_from_matrix(Q), s[3:])])
        f, _ = _eval(X1, X2, *moved, PROPS[kind], impl=impl)
        expected = np.concatenate([Q @ f0[3 * i:3 * i + 3] for i in range(4)])
        assert np.abs(f - expected).max() < 1e-10 * max(1.0, np.abs(f0).max())


@pytest.mark.parametrize("impl", IMPLS)
def test_tangent_at_rest_is_the_linear_frame_element(impl):
    """At rest the co-rotational tangent equals the textbook 3D frame element (Przemieniecki)."""
    L, EA, GJ, EIy, EIz = 2.0, 7.0, 3.0, 5.0, 11.0
    X1, X2 = np.zeros(3), np.array([L, 0.0, 0.0])
    props = np.array([EA, GJ, EIy, EIz, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0])
    rest = np.r_[np.zeros(3), 1.0, 0.0, 0.0, 0.0]
    _, Kc = _eval(X1, X2, rest, rest, props, True, impl)
    _, Kl = _eval(X1, X2, rest, rest, props, False, impl)
    K = np.zeros((12, 12))
    # axial and torsion
    for i, v in ((0, EA / L), (3, GJ / L)):
        K[np.ix_([i, 6 + i], [i, 6 + i])] = v * np.array([[1, -1], [-1, 1]])
    # bending in x-y (uy, rz) with EIz, in x-z (uz, ry) with EIy
    for (u, r, EI, s) in ((1, 5, EIz, 1.0), (2, 4, EIy, -1.0)):
        idx = [u, r, 6 + u, 6 + r]
        c = EI / L**3
        K[np.ix_(idx, idx)] = c * np.array([[12, 6 * L * s, -12, 6 * L * s], [6 * L * s, 4 * L**2, -6 * L * s, 2 * L**2],
                                            [-12, -6 * L * s, 12, -6 * L * s], [6 * L * s, 2 * L**2, -6 * L * s, 4 * L**2]])
    np.testing.assert_allclose(Kc, K, atol=1e-9 * np.abs(K).max())
    np.testing.assert_allclose(Kl, K, atol=1e-12 * np.abs(K).max())


def test_linear_3d_cantilever_and_orientation():
    """Tip deflections PL³/(3EI) about both axes of a rectangle, for a skew member."""
    a = np.array([2.0, -1.0, 2.0]) / 3.0
    L, b, h, E = 3.0, 0.2, 0.5, 1e4
    tm = polyline([[0, 0, 0], L * a], 6, line_name="m", gdim=3)
    y = np.cross([0.0, 0.0, 1.0], a)
    y /= np.linalg.norm(y)
    z = np.cross(a, y)
    sc = dc.Scene(large_rotations=False)
    m = sc.add_beam(tm, "m", section=dc.Rectangle(b, h), material=dc.Elastic(E), orientation=y)
    sc.fix(m, "base")
    sc.load(m, "tip", force=1e-2 * y + 2e-2 * z)
    sc.monitor("tip", m, "tip")
    res = dc.solve(sc, dc.LoadControl(steps=1))
    u = np.array([res.history.column(c)[-1] for c in ("tip_ux", "tip_uy", "tip_uz")])
    Iz, Iy = b * h**3 / 12, h * b**3 / 12
    np.testing.assert_allclose(u @ y, 1e-2 * L**3 / (3 * E * Iz), rtol=1e-10)
    np.testing.assert_allclose(u @ z, 2e-2 * L**3 / (3 * E * Iy), rtol=1e-10)
    assert abs(u @ a) < 1e-12


def test_orientation_parallel_to_the_member_is_refused():
    tm = polyline([[0, 0, 0], [0, 0, 1]], 2, line_name="m", gdim=3)
    with pytest.raises(ValueError, match="orientation vector .* is parallel to 2 element"):
        dc.Scene().add_beam(tm, "m", section=dc.Rectangle(1, 1), material=dc.Elastic(1.0), orientation=(0, 0, 2))


@pytest.mark.parametrize("kind", list(PROPS))
def test_the_c_kernels_give_the_numba_kernels_numbers(kind):
    """The C kernels DOLFINx is handed (:mod:`dolfinx_corot.kernels.compiled`) equal the numba ones to
    rounding in all three modes (geometrically linear, co-rotational, symmetrized), from rest to
    relative rotations near π, with Timoshenko, Bernoulli and bar sections (co-rotational: the same
    operations in the same order; linear: f = K d is a BLAS product in numba)."""
    rng = np.random.default_rng(5)
    props = PROPS[kind].copy()
    for trial in range(60):
        X1, X2, s1, s2, _ = _random_state(rng)
        scale = (0.0, 1e-5, 0.3, 1.5, 3.0)[trial % 5]
        for s in (s1, s2):
            s[3:] = rot.quat_mul(rot.quat_from_rotvec(scale * rng.normal(size=3)), s[3:])
        w = np.concatenate([s1, s2, props])
        X = np.array([X1, X2])
        for mode, tol in ((0.0, 1e-12), (1.0, 1e-14), (2.0, 1e-14)):
            f, K = compiled.beam3d_element(X, w, mode)
            fn, Kn = np.empty(12), np.empty((12, 12))
            k._tabulate(w, np.array([mode]), X, fn, Kn, True)
            fv, Kv = np.empty(12), np.empty((12, 12))
            k._tabulate(w, np.array([mode]), X, fv, Kv, False)  # the vector kernel's path
            assert np.abs(f - fv).max() <= tol * max(np.abs(fv).max(), 1.0), (mode, trial)
            assert np.abs(K - Kn).max() <= tol * np.abs(Kn).max(), (mode, trial)
        if scale < 1.0:
            assert np.array_equal(K, Kn)  # (rounding alike: bit for bit)


def test_the_c_nodal_updates_give_the_numba_updates_numbers():
    """u ← u + du, q ← exp(dw)∘q (renormalized) and the rotation vectors of quaternions (both signs,
    angles up to π) in C equal :func:`~dolfinx_corot.rotations.quat_update` and
    :func:`~dolfinx_corot.rotations.rotvecs_from_quats`."""
    rng = np.random.default_rng(2)
    n = 200
    state = np.zeros((n + 3, 7))
    state[:, :3] = rng.normal(size=(n + 3, 3))
    for i in range(n + 3):
        state[i, 3:] = rot.quat_from_rotvec(rng.normal(size=3) * (i % 4))
    dx = rng.normal(size=(n, 6)) * np.repeat([1e-9, 1e-4, 0.1, 2.0], n // 4)[:, None]
    expected = state.copy()
    for i in range(n):
        expected[i, :3] += dx[i, :3]
        expected[i, 3:] = rot.quat_update(expected[i, 3:].copy(), dx[i, 3:].copy())
    compiled.update_quaternions(state, dx, n)
    assert np.array_equal(state, expected)  # the last 3 nodes (ghosts) untouched, the others bit for bit
    Q = state[:, 3:].copy()
    Q[::2] *= -1.0
    got = compiled.rotvecs_from_quats(Q)
    assert np.abs(got - rot.rotvecs_from_quats(Q)).max() <= 1e-15 * np.pi
    assert np.linalg.norm(got, axis=1).max() <= np.pi
    with pytest.raises(ValueError, match="states"):
        compiled.update_quaternions(state, dx, n + 10)


@pytest.mark.parametrize("large", [True, False])
def test_the_c_section_forces_give_the_numba_numbers(large):
    """The section forces and element axes of many elements at random states (the element results'
    path), C against :func:`~dolfinx_corot.kernels.beam3d.section_forces_all`."""
    rng = np.random.default_rng(9)
    n = 40
    X, S, props = np.empty((n, 2, 3)), np.empty((n, 2, 7)), np.empty((n, 10))
    for e in range(n):
        X1, X2, s1, s2, _ = _random_state(rng)
        X[e], S[e] = (X1, X2), (s1, s2)
        props[e] = PROPS[list(PROPS)[e % len(PROPS)]]
    out, axes = np.empty((n, 2, 6)), np.empty((n, 3, 3))
    compiled.section_forces_all(X, S, props, large, out, axes)
    expected, expected_axes = np.empty((n, 2, 6)), np.empty((n, 3, 3))
    k.section_forces_all(X, S, props, large, expected, expected_axes)
    assert np.array_equal(axes, expected_axes)
    assert np.abs(out - expected).max() <= (1e-15 if large else 1e-12) * np.abs(expected).max()
    with pytest.raises(ValueError, match="props"):
        compiled.section_forces_all(X, S, props[:, :4].copy(), large, out, axes)

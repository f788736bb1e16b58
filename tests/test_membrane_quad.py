"""Four-node co-rotational membranes: FD tangent, objectivity, patch test, a rotated strip in tension."""
import numpy as np
import pytest

import dolfinx_corot as dc
from dolfinx_corot import rotations as rot
from dolfinx_corot.elements import membrane_quad as law
from dolfinx_corot.io.mesh import from_arrays
from dolfinx_corot.kernels import membrane_quad as k

PROPS = np.array([2.1e4, 0.3, 0.05])
# a warped quadrilateral, nodes in DOLFINx order (0, 0), (1, 0), (0, 1), (1, 1)
X = np.array([[0.0, 0.0, 0.0], [1.1, 0.1, 0.05], [-0.1, 0.05, 1.0], [1.0, 0.0, 0.95]])


def _eval(S, large=True, X=X):
    f, K = np.empty(24), np.empty((24, 24))
    k.evaluate(X, S, PROPS, large, f, K)
    return f, K


def _state(rng, strain=0.02):
    Q = rot.exp_so3(rng.normal(size=3) * 2.0)
    t = rng.normal(size=3)
    S = np.zeros((4, 7))
    S[:, 3] = 1.0
    for a in range(4):
        S[a, :3] = Q @ X[a] + t + strain * rng.normal(size=3) - X[a]
    return S, Q, t


def test_tangent_matches_finite_differences():
    rng = np.random.default_rng(4)
    for _ in range(8):
        S, _, _ = _state(rng)
        f, K = _eval(S)
        h = 1e-6
        Kfd = np.zeros((24, 24))
        for j in range(24):
            a, c = divmod(j, 6)
            if c >= 3:
                continue
            P, M = S.copy(), S.copy()
            P[a, c] += h
            M[a, c] -= h
            Kfd[:, j] = (_eval(P)[0] - _eval(M)[0]) / (2 * h)
        assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()


def test_rigid_motions_produce_no_force():
    rng = np.random.default_rng(6)
    for _ in range(10):
        S, _, _ = _state(rng, strain=0.0)
        f, _ = _eval(S)
        assert np.abs(f).max() < 1e-10 * np.abs(_eval(_state(rng)[0])[0]).max()


def test_frame_does_not_depend_on_the_first_node():
    """Renumbering the nodes by a quarter turn gives the same nodal forces (bisector frame)."""
    rng = np.random.default_rng(8)
    S, _, _ = _state(rng)
    f, _ = _eval(S)
    ccw = [0, 1, 3, 2]
    perm_ccw = [1, 2, 3, 0]                      # node 2 becomes node 1
    order = [ccw[p] for p in perm_ccw]           # counter-clockwise list, starting at old node 2
    new = np.array(order)[[0, 1, 3, 2]]          # back to DOLFINx order
    f2, _ = _eval(S[new], X=X[new])
    np.testing.assert_allclose(f2.reshape(4, 6), f.reshape(4, 6)[new], atol=1e-10 * np.abs(f).max())


def test_q4_patch_test():
    """A linear displacement field on a patch of distorted quadrilaterals is reproduced exactly."""
    pts = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [0.9, 1.1], [2, 1], [0, 2], [1.1, 2], [2, 2]], float)
    quads = [(0, 1, 4, 3), (1, 2, 5, 4), (3, 4, 7, 6), (4, 5, 8, 7)]
    K = np.zeros((18, 18))
    for q in quads:
        Ke = np.empty((8, 8))
        law.local_stiffness(pts[list(q)].copy(), PROPS, Ke)
        dofs = np.array([[2 * v, 2 * v + 1] for v in q]).ravel()
        K[np.ix_(dofs, dofs)] += Ke
    exact = np.array([[1e-3 * x - 2e-3 * y, 0.5e-3 * x + 1.5e-3 * y] for x, y in pts]).ravel()
    free = np.array([8, 9])  # the interior node 4
    fixed = np.setdiff1d(np.arange(18), free)
    u = exact.copy()
    u[free] = np.linalg.solve(K[np.ix_(free, free)], -K[np.ix_(free, fixed)] @ exact[fixed])
    np.testing.assert_allclose(u, exact, atol=1e-14)


def test_membrane_sheet_in_tension_after_a_large_rotation():
    """A sheet of 6 × 2 quadrilaterals turned rigidly by 2 rad about z and stretched by δ along its
    turned axis (edge nodes prescribed, ν = 0): the pull is E t b δ/L to rounding, because the
    bisector frame of a rectangle turns exactly with the uniform stretch."""
    L, b, t, E, nx, ny = 3.0, 0.5, 0.01, 1e3, 6, 2
    xs, ys = np.linspace(0, L, nx + 1), np.linspace(0, b, ny + 1)
    pts = np.array([(x, y, 0.0) for y in ys for x in xs])
    nid = lambda i, j: j * (nx + 1) + i  # noqa: E731
    quads = [(nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)) for j in range(ny) for i in range(nx)]
    left, right = [nid(0, j) for j in range(ny + 1)], [nid(nx, j) for j in range(ny + 1)]
    groups = {"all": np.arange(len(pts)), **{f"n{v}": [v] for v in left + right}, "right": right}
    tm = from_arrays(pts, np.array(quads), "sheet", groups)
    Q = rot.exp_so3(np.array([0.0, 0.0, 2.0]))
    a = Q @ np.array([1.0, 0.0, 0.0])
    delta = 3e-3
    sc = dc.Scene()
    m = sc.add_membrane(tm, "sheet", thickness=t, material=dc.Elastic(E, 0.0))
    sc.fix(m, "all", dofs=("uz",))
    for v in left + right:
        target = Q @ pts[v] - pts[v] + (delta * a if pts[v, 0] > 0 else 0.0)
        sc.prescribe(m, f"n{v}", ux=target[0], uy=target[1])
    sc.monitor_reaction("right", m, "right")
    # the edges move along straight lines to their turned places: half-way the sheet is strongly
    # compressed and its tangent indefinite (critical points, recorded); the end state is the test
    res = dc.solve(sc, dc.LoadControl(steps=4, at_critical_point="continue"))
    assert [(c.negative_before, c.negative_after) for c in res.critical_points] == [(0, 2), (2, 0)]
    row = res.history.rows[-1]
    pull = np.array([row["right_Fx"], row["right_Fy"], row["right_Fz"]]) @ a
    assert abs(pull - E * t * b * delta / L) < 1e-9 * E * t * b * delta / L
    assert "membrane elements" in sc.effects()[0]


def test_bad_quads_are_named_for_membranes_and_shells():
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    tm = from_arrays(pts, np.array([[0, 1, 2, 3]]), "q")
    bow = from_arrays(pts, np.array([[0, 1, 3, 2]]), "q")  # nodes out of order: a bow tie
    for add in (dc.Scene().add_membrane, dc.Scene().add_shell):
        with pytest.raises(dc.MeshError, match=r"self-intersecting \(a bow tie.* at \(0\.5, 0\.5, 0\)"):
            add(bow, "q", thickness=0.1, material=dc.Elastic(1.0))
    with pytest.raises(ValueError, match="thickness"):
        dc.Scene().add_membrane(tm, "q", thickness=0.0, material=dc.Elastic(1.0))

"""Co-rotational flat shell triangle: FD tangent, objectivity, tangent at rest = rotated local stiffness."""
import numpy as np
import pytest

from dolfinx_corot import rotations as rot
from dolfinx_corot.elements import shell_triangle as law
from dolfinx_corot.kernels import shell3d as k

PROPS = law.isotropic_props(2.1e4, 0.3, 0.05, 1e-2, True, True)
KINDS = {"shell": PROPS, "shell_cst": law.isotropic_props(2.1e4, 0.3, 0.05, 1e-2, True, False),
         "membrane": law.isotropic_props(2.1e4, 0.3, 0.05, 0.0, False, False),
         # the shallow-shell term of the local law (elements/shallow_shell.py)
         "shell_shallow": law.isotropic_props(2.1e4, 0.3, 0.05, 1e-2, True, True, shallow=True),
         "shell_cst_shallow": law.isotropic_props(2.1e4, 0.3, 0.05, 1e-2, True, False, shallow=True)}


def _eval(X, S, large=True, props=PROPS):
    f, K = np.empty(18), np.empty((18, 18))
    k.evaluate(X, S, props, large, f, K)
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


@pytest.mark.parametrize("kind", list(KINDS))
def test_closed_form_tangent_equals_complex_step_tangent(kind):
    """The closed-form EICR tangent and the complex-step derivative of the same internal force
    agree to rounding, at random states with rigid rotations up to several radians."""
    props = KINDS[kind]
    rng = np.random.default_rng(11)
    for trial in range(20):
        X = _triangle(rng)
        S, _ = _state(rng, X, strain=0.05, rot_scale=0.2 if trial % 2 else 1.0)
        f1, K1 = np.empty(18), np.empty((18, 18))
        f2, K2 = np.empty(18), np.empty((18, 18))
        k.corotational(X, S, props, f1, K1)
        k.corotational_complex_step(X, S, props, f2, K2)
        np.testing.assert_allclose(f1, f2, rtol=0, atol=1e-13 * np.abs(f2).max())
        assert np.abs(K1 - K2).max() < 1e-10 * np.abs(K2).max()


@pytest.mark.parametrize("kind", list(KINDS))
def test_tangent_matches_finite_differences(kind):
    props = KINDS[kind]
    rng = np.random.default_rng(5)
    for _ in range(10):
        X = _triangle(rng)
        S, _ = _state(rng, X)
        f, K = _eval(X, S, props=props)
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
            Kfd[:, j] = (_eval(X, P, props=props)[0] - _eval(X, M, props=props)[0]) / (2 * h)
        assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()


@pytest.mark.parametrize("kind", list(KINDS))
def test_rigid_motion_rotates_the_forces(kind):
    props = KINDS[kind]
    rng = np.random.default_rng(9)
    X = _triangle(rng)
    S, _ = _state(rng, X)
    f0, _ = _eval(X, S, props=props)
    for angle in (1.0, np.pi, 10.0):
        Q = rot.exp_so3(angle * rng.normal(size=3) / np.sqrt(3))
        t = rng.normal(size=3)
        moved = S.copy()
        for a in range(3):
            moved[a, :3] = Q @ (X[a] + S[a, :3]) + t - X[a]
            moved[a, 3:] = rot.quat_mul(rot.quat_from_matrix(Q), S[a, 3:])
        f, _ = _eval(X, moved, props=props)
        expected = np.concatenate([Q @ f0[3 * i:3 * i + 3] for i in range(6)])
        assert np.abs(f - expected).max() < 1e-10 * np.abs(f0).max()
    # a rigidly moved undeformed element carries no force
    rest = np.zeros((3, 7))
    Q = rot.exp_so3(np.array([3.0, -4.0, 5.0]))
    for a in range(3):
        rest[a, :3] = Q @ X[a] + 1.0 - X[a]
        rest[a, 3:] = rot.quat_from_matrix(Q)
    f, _ = _eval(X, rest, props=props)
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


def test_membrane_strip_in_tension_after_a_large_rotation():
    """A membrane strip turned rigidly by 2 rad and stretched by δ along its turned axis (edge nodes
    prescribed): the pull is E t b δ/L (ν = 0) and the interior nodes follow the rotated uniform
    stretch, up to the O(ε) relative error of an element frame tied to a side: in the triangles whose
    side 1–2 is a diagonal, the stretch turns that side by φ ≈ ε/2, and the small-strain law then
    sees ε − φ²/2 (here ε = 1e-3: about 1.3e-4 relative)."""
    import dolfinx.mesh
    import ufl
    from mpi4py import MPI

    import dolfinx_corot as dc
    from dolfinx_corot.io.mesh import TaggedMesh

    L, b, t, E, nx = 3.0, 0.5, 0.01, 1e3, 6
    pts = np.array([(x, y, 0.0) for x in np.linspace(0, L, nx + 1) for y in (0.0, b)])
    cells = []
    for i in range(nx):
        a0, a1, b0, b1 = 2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3
        cells += [(a0, b0, b1), (a0, b1, a1)]
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.Cell("triangle", geometric_dimension=3), 1))
    msh = dolfinx.mesh.create_mesh(MPI.COMM_SELF, np.array(cells, dtype=np.int64), pts, domain)
    ncell = msh.topology.index_map(2).size_local
    tags = dolfinx.mesh.meshtags(msh, 2, np.arange(ncell, dtype=np.int32), np.ones(ncell, dtype=np.int32))
    edge_nodes = {"n0": 0, "n1": 1, "n2": len(pts) - 2, "n3": len(pts) - 1}
    groups = {"m": (2, 1), "all": (0, 2), **{k: (0, 3 + i) for i, k in enumerate(edge_nodes)}}
    points = {"all": pts, **{k: pts[i:i + 1] for k, i in edge_nodes.items()}}
    tm = TaggedMesh(msh, tags, groups, points)
    Q = rot.exp_so3(np.array([0.0, 0.0, 2.0]))
    a = Q @ np.array([1.0, 0.0, 0.0])
    delta = 3e-3
    sc = dc.Scene()
    m = sc.add_membrane(tm, "m", thickness=t, material=dc.Elastic(E, 0.0))
    sc.fix(m, "all", dofs=("uz",))
    for name, i in edge_nodes.items():
        target = Q @ pts[i] - pts[i] + (delta * a if pts[i, 0] > 0 else 0.0)
        sc.prescribe(m, name, ux=target[0], uy=target[1])
    for name in ("n2", "n3"):
        sc.monitor_reaction(name, m, name)
    res = dc.solve(sc, dc.LoadControl(steps=4))
    row = res.history.rows[-1]
    pull = sum(np.array([row[f"{n}_Fx"], row[f"{n}_Fy"], row[f"{n}_Fz"]]) @ a for n in ("n2", "n3"))
    eps = delta / L
    np.testing.assert_allclose(pull, E * t * b * eps, rtol=eps)
    X, st = sc.model.nodes()
    expected = (Q @ X.T).T * 1.0 + np.outer(X[:, 0] / L * delta, a) - X
    np.testing.assert_allclose(st[:, :3], expected, atol=eps * delta)
    assert sc.effects()[0].startswith("membrane elements")


def test_line_elements_on_a_triangle_mesh_are_refused():
    import dolfinx_corot as dc
    from dolfinx_corot.io import from_arrays

    pts = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    tm = from_arrays(pts, np.array([[0, 1, 2]]), "s")
    with pytest.raises(ValueError, match="beams need a mesh of lines; this mesh has triangles"):
        dc.Scene().add_beam(tm, "s", section=dc.Rectangle(1, 1), material=dc.Elastic(1.0))
    with pytest.raises(ValueError, match="thickness = 0.0 must be positive"):
        dc.Scene().add_shell(tm, "s", thickness=0.0, material=dc.Elastic(1.0))

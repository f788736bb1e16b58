"""Four-node co-rotational shells (incompatible-mode membrane with drilling; DKQ or MITC4 bending):
patch tests, rigid-body modes, tangents (complex step and finite differences), objectivity,
warping, node-numbering independence, a simply supported plate and a strip rolled into a circle."""
import numpy as np
import pytest

import dolfinx_corot as dc
from dolfinx_corot import rotations as rot
from dolfinx_corot.elements import shell_quad as law
from dolfinx_corot.io.mesh import from_arrays
from dolfinx_corot.kernels import shell_quad as k

E, NU, T = 2.1e4, 0.3, 0.05
PROPS = law.isotropic_props(E, NU, T, 1e-2)  # DKQ
MITC4 = law.isotropic_props(E, NU, T, 1e-2, kirchhoff=False)
KINEMATICS = {"kirchhoff": PROPS, "mindlin": MITC4}
# the tangents with the shallow-shell term of the local law as well (elements/shallow_shell.py)
SHALLOW = law.isotropic_props(E, NU, T, 1e-2, shallow=True)
TANGENTS = {**KINEMATICS, "kirchhoff_shallow": SHALLOW,
            "mindlin_shallow": law.isotropic_props(E, NU, T, 1e-2, kirchhoff=False, shallow=True)}
C = E / (1 - NU**2) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
# a warped quadrilateral in DOLFINx's vertex order (0, 0), (1, 0), (0, 1), (1, 1)
XW = np.array([[0.0, 0.0, 0.0], [1.1, 0.1, 0.05], [-0.1, 0.05, 1.0], [1.0, 0.0, 0.95]])
# a patch of four distorted quadrilaterals (counter-clockwise), one interior node (4)
PATCH = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [0.9, 1.15], [2, 1], [0, 2], [1.1, 2], [2, 2]], float)
QUADS = [(0, 1, 4, 3), (1, 2, 5, 4), (3, 4, 7, 6), (4, 5, 8, 7)]


def _eval(X, S, large=True, props=PROPS):
    f, K = np.empty(24), np.empty((24, 24))
    k.evaluate(X, S, props, large, f, K)
    return f, K


def _state(rng, X, strain=0.02, rot_scale=0.3, rigid=2.0):
    """Nodal states: a rigid motion (rotation vector of about ``rigid`` rad) plus random strains
    and nodal rotations."""
    Q = rot.exp_so3(rng.normal(size=3) * rigid)
    t = rng.normal(size=3)
    S = np.empty((4, 7))
    for a in range(4):
        S[a, :3] = Q @ X[a] + t + rng.normal(size=3) * strain - X[a]
        S[a, 3:] = rot.quat_from_matrix(rot.exp_so3(rng.normal(size=3) * rot_scale) @ Q)
    return S, Q, t


def _patch_stiffness(props):
    K = np.zeros((54, 54))
    for q in QUADS:
        Ke = np.empty((24, 24))
        law.flat_stiffness(PATCH[list(q)].copy(), props, Ke)
        dofs = np.array([np.arange(6 * v, 6 * v + 6) for v in q]).ravel()
        K[np.ix_(dofs, dofs)] += Ke
    return K


def _solve_patch(field, props):
    """The patch with its boundary nodes moved by ``field(x, y)`` (6 values per node) and the
    interior node free: returns (computed, exact) dofs of the interior node."""
    K = _patch_stiffness(props)
    d = np.array([field(x, y) for x, y in PATCH]).ravel()
    free = np.arange(24, 30)
    fixed = np.setdiff1d(np.arange(54), free)
    df = np.linalg.solve(K[np.ix_(free, free)], -K[np.ix_(free, fixed)] @ d[fixed])
    return df, d[free]


@pytest.mark.parametrize("kinematics", list(KINEMATICS))
def test_patch_tests_membrane_bending_and_shear(kinematics):
    """On a patch of distorted quadrilaterals the interior node reproduces exactly (1e-10) a
    constant membrane strain with its rotation and a constant curvature (w quadratic, rotations
    linear): the incompatible modes with Taylor's correction, the DKQ and MITC4 pass the patch
    tests (MacNeal & Harder 1985; Batoz & Ben Tahar 1982). For MITC4 a constant transverse shear
    (w linear, rotations zero; without moments it is not in equilibrium, so it is checked element
    by element) has the exact energy ½·κGt·A·|γ|² on every distorted element of the patch."""
    props = KINEMATICS[kinematics]
    exx, eyy, gxy, w0 = 1e-3, -2e-3, 5e-4, 3e-4

    def membrane(x, y):  # u = εx x + (γ/2 − ω0) y, v = εy y + (γ/2 + ω0) x: θz = ω0
        return [exx * x + (0.5 * gxy - w0) * y, eyy * y + (0.5 * gxy + w0) * x, 0, 0, 0, w0]

    kx, ky, kxy = 1e-2, -3e-3, 4e-3

    def bending(x, y):  # βx = θy = κx x + κxy y/2, βy = −θx = κy y + κxy x/2, w = −∫β
        bx, by = kx * x + 0.5 * kxy * y, ky * y + 0.5 * kxy * x
        return [0, 0, -(kx * x * x + ky * y * y + kxy * x * y) / 2, -by, bx, 0]

    for field in (membrane, bending):
        got, want = _solve_patch(field, props)
        assert np.abs(got - want).max() < 1e-10 * np.abs(want).max()
    if kinematics == "kirchhoff":
        return
    gx, gy = 2e-3, -1e-3
    for q in QUADS:
        xy = PATCH[list(q)].copy()
        Ke = np.empty((24, 24))
        law.flat_stiffness(xy, props, Ke)
        d = np.concatenate([[0, 0, gx * x + gy * y, 0, 0, 0] for x, y in xy])
        area = 0.5 * abs(np.cross(xy[2] - xy[0], xy[3] - xy[1]))
        G = E / (2 * (1 + NU))
        assert 0.5 * d @ Ke @ d == pytest.approx(0.5 * 5 / 6 * G * T * area * (gx**2 + gy**2), rel=1e-12)


@pytest.mark.parametrize("kinematics", list(KINEMATICS))
def test_rigid_body_modes_and_energies(kinematics):
    """The flat element has exactly six zero-energy modes (the rigid motions; no spurious
    mechanism), and reproduces the energy of pure in-plane bending of a rectangle (the
    incompatible modes) exactly."""
    props = KINEMATICS[kinematics]
    xy = np.array([[0, 0], [2.0, 0.2], [2.3, 1.5], [-0.2, 1.2]])
    K = np.empty((24, 24))
    law.flat_stiffness(xy, props, K)
    w = np.linalg.eigvalsh(K)
    assert np.all(np.abs(w[:6]) < 1e-12 * w[-1]) and w[6] > 1e-6 * w[-1]
    for v in np.eye(6):
        d = np.concatenate([np.r_[v[:3] + np.cross(v[3:], [x, y, 0.0]), v[3:]] for x, y in xy])
        assert np.abs(K @ d).max() < 1e-12 * np.abs(K).max()
    # pure in-plane bending of a 3 × 1 rectangle: σxx = E κ y, U = ½ E κ² I t a
    a, b, kap = 3.0, 1.0, 1e-3
    xr = np.array([[0, 0], [a, 0], [a, b], [0, b]]) - [a / 2, b / 2]
    law.flat_stiffness(xr, props, K)
    d = np.concatenate([[kap * x * y, -kap * x * x / 2 + NU * kap * y * y / 2, 0, 0, 0, -kap * x] for x, y in xr])
    assert 0.5 * d @ K @ d == pytest.approx(0.5 * E * kap**2 * b**3 / 12 * T * a, rel=1e-12)


@pytest.mark.parametrize("kinematics", list(TANGENTS))
def test_closed_form_tangent_equals_complex_step_tangent(kinematics):
    """The tangent (closed form, the frame spin's variation included) against complex-step
    differentiation of the internal force, at random states of a warped element with rigid
    rotations of several radians and nodal rotations up to 1.5 rad: 1e-10."""
    props = TANGENTS[kinematics]
    rng = np.random.default_rng(3)
    for trial in range(12):
        X = XW + 0.1 * rng.normal(size=(4, 3)) if trial % 3 else XW
        S, _, _ = _state(rng, X, strain=0.05, rot_scale=0.3 if trial % 2 else 1.5)
        f1, K1 = _eval(X, S, props=props)
        f2, K2 = np.empty(24), np.empty((24, 24))
        k.evaluate_complex_step(X, S, props, f2, K2)
        np.testing.assert_allclose(f1, f2, rtol=0, atol=1e-13 * np.abs(f2).max())
        assert np.abs(K1 - K2).max() < 1e-10 * np.abs(K2).max()


def test_frame_spin_variation_in_closed_form():
    """∂(Ω(y)ᵀv)/∂y, the frame spin's variation in the tangent, in closed form against the
    complex-step derivative of the frame spin Ω(y), on a flat and on warped, distorted cells: 1e-13."""
    from dolfinx_corot.corotation import frame_quad

    rng = np.random.default_rng(8)
    for trial in range(30):
        X = np.array([[0.0, 0.0, 0.0], [1.2, 0.0, 0.0], [1.0, 0.8, 0.0], [0.0, 1.0, 0.0]])
        if trial % 3:
            X += 0.15 * rng.normal(size=(4, 3))  # distorted and warped
        R0, y = np.empty((3, 3)), np.empty((4, 3))
        frame_quad.initial(X, R0, y)
        v = rng.normal(size=3) * 10.0 ** rng.uniform(-2, 2)
        J, Jc = np.empty((24, 12)), np.empty((24, 12))
        frame_quad.shape_spin_derivative(y, v, J)
        frame_quad.shape_spin_derivative_complex_step(y, v, Jc)
        assert np.abs(J - Jc).max() <= 1e-13 * np.abs(Jc).max()


@pytest.mark.parametrize("kinematics", list(TANGENTS))
def test_tangent_matches_finite_differences(kinematics):
    """Central differences of the internal force, translations added and rotations updated
    multiplicatively (R ← exp(h e_k) R, as Newton updates them), h = 1e-6: 1e-6."""
    props = TANGENTS[kinematics]
    rng = np.random.default_rng(4)
    for _ in range(4):
        S, _, _ = _state(rng, XW, strain=0.05, rot_scale=0.5)
        f, K = _eval(XW, S, props=props)
        h = 1e-6
        Kfd = np.zeros((24, 24))
        for j in range(24):
            a, c = divmod(j, 6)
            P, M = S.copy(), S.copy()
            if c < 3:
                P[a, c] += h
                M[a, c] -= h
            else:
                e = np.zeros(3)
                e[c - 3] = h
                P[a, 3:] = rot.quat_update(S[a, 3:].copy(), e)
                M[a, 3:] = rot.quat_update(S[a, 3:].copy(), -e)
            Kfd[:, j] = (_eval(XW, P, props=props)[0] - _eval(XW, M, props=props)[0]) / (2 * h)
        assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()


@pytest.mark.parametrize("props", [PROPS, SHALLOW], ids=["linear", "shallow"])
def test_objectivity_under_rotations_up_to_ten_radians(props):
    """A deformed state moved rigidly (rotations of 0.5 to 10 rad about random axes): the nodal
    forces turn with it, and a rigid motion of the undeformed element gives no force (1e-10)."""
    rng = np.random.default_rng(6)
    S, _, _ = _state(rng, XW, rigid=0.0)
    f, K = _eval(XW, S, props=props)
    x = XW + S[:, :3]
    for angle in (0.5, 3.0, 6.0, 10.0):
        axis = rng.normal(size=3)
        Q = rot.exp_so3(angle * axis / np.linalg.norm(axis))
        t = rng.normal(size=3)
        S2 = S.copy()
        for a in range(4):
            S2[a, :3] = Q @ x[a] + t - XW[a]
            S2[a, 3:] = rot.quat_from_matrix(Q @ rot.quat_to_matrix(S[a, 3:].copy()))
        f2, K2 = _eval(XW, S2, props=props)
        fr = np.concatenate([Q @ f[3 * b:3 * b + 3] for b in range(8)])
        np.testing.assert_allclose(f2, fr, atol=1e-10 * np.abs(f).max())
        L = np.kron(np.eye(8), Q)
        np.testing.assert_allclose(K2, L @ K @ L.T, atol=1e-9 * np.abs(K).max())
        S0 = np.zeros((4, 7))
        for a in range(4):
            S0[a, :3] = Q @ XW[a] + t - XW[a]
            S0[a, 3:] = rot.quat_from_matrix(Q)
        assert np.abs(_eval(XW, S0, props=props)[0]).max() < 1e-10 * np.abs(f).max()


def test_frame_and_forces_do_not_depend_on_the_first_node():
    """Numbering the nodes from another corner (a quarter turn) gives the same nodal forces and
    tangent (the frame bisects the diagonals; the element is symmetric under relabelling)."""
    rng = np.random.default_rng(8)
    S, _, _ = _state(rng, XW)
    f, K = _eval(XW, S)
    ccw = [0, 1, 3, 2]
    order = [ccw[p] for p in (1, 2, 3, 0)]  # counter-clockwise, from old node 2
    new = np.array(order)[[0, 1, 3, 2]]    # back to DOLFINx's order
    f2, K2 = _eval(XW[new], S[new])
    np.testing.assert_allclose(f2.reshape(4, 6), f.reshape(4, 6)[new], atol=1e-10 * np.abs(f).max())
    dofs = np.array([np.arange(6 * v, 6 * v + 6) for v in new]).ravel()
    np.testing.assert_allclose(K2, K[np.ix_(dofs, dofs)], atol=1e-9 * np.abs(K).max())


@pytest.mark.parametrize("kinematics", list(KINEMATICS))
def test_twisted_element_at_rest_and_linear_analysis(kinematics):
    """A twisted (warped) element: at rest the co-rotational tangent equals the geometrically
    linear stiffness B₀ᵀK̄B₀, which is symmetric and has exactly the six rigid motions as zero
    modes (the rigid links carry the warping)."""
    props = KINEMATICS[kinematics]
    X = np.array([[0, 0, 0.1], [1, 0, -0.1], [0, 1, -0.1], [1, 1, 0.1]], float)
    S = np.zeros((4, 7))
    S[:, 3] = 1.0
    f, K = _eval(X, S, large=True, props=props)
    fl, Kl = _eval(X, S, large=False, props=props)
    assert np.abs(f).max() < 1e-12
    np.testing.assert_allclose(K, Kl, atol=1e-10 * np.abs(Kl).max())
    assert np.abs(Kl - Kl.T).max() < 1e-12 * np.abs(Kl).max()
    w = np.linalg.eigvalsh(Kl)
    assert np.all(np.abs(w[:6]) < 1e-10 * w[-1]) and w[6] > 1e-8 * w[-1]


def _plate(n, distort=0.0, comm=None):
    """A unit square plate of n × n quadrilaterals (interior nodes moved randomly by up to
    ``distort`` of an element), groups 'edge' and 'centre'."""
    xs = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    pts = np.c_[X.ravel(), Y.ravel(), np.zeros(X.size)]
    inner = (X.ravel() > 0) & (X.ravel() < 1) & (Y.ravel() > 0) & (Y.ravel() < 1)
    pts[inner, :2] += distort / n * np.random.default_rng(0).uniform(-1, 1, (inner.sum(), 2))
    pts[n // 2 * (n + 1) + n // 2, :2] = 0.5
    cells = [[i * (n + 1) + j, (i + 1) * (n + 1) + j, (i + 1) * (n + 1) + j + 1, i * (n + 1) + j + 1]
             for i in range(n) for j in range(n)]
    edge = np.flatnonzero(~inner)
    kw = {} if comm is None else {"comm": comm}
    return from_arrays(pts, np.array(cells), "plate", {"edge": edge, "centre": [n // 2 * (n + 1) + n // 2]}, **kw)


@pytest.mark.parametrize("kinematics", list(KINEMATICS))
def test_simply_supported_plate_converges_to_kirchhoff(kinematics):
    """A simply supported square plate a = 1, t/a = 0.01 (edges held in translation, rotations
    free), under a uniform pressure q: the centre deflection against w = 0.00406 q a⁴/D
    (Timoshenko & Woinowsky-Krieger 1959, table 8) on regular meshes of 4, 8, 16 cells a side and
    on a distorted one (elements moved by up to a quarter of their size). DKQ: −0.41 %, −0.06 %,
    −0.01 %, distorted −0.06 %, from below. MITC4: −2.2 %, −0.39 %, +0.07 %, distorted −0.04 %
    (its limit lies a little above Kirchhoff's, +0.3 % on 32 cells: the Reissner–Mindlin plate
    on these soft supports)."""
    E_, nu, t, q = 1e4, 0.3, 0.01, 1e-3
    w_ref = 0.00406235 * q / (E_ * t**3 / (12 * (1 - nu**2)))
    found = {}
    for n, distort in ((4, 0.0), (8, 0.0), (16, 0.0), (16, 0.25)):
        sc = dc.Scene(large_rotations=False)
        p = sc.add_shell(_plate(n, distort), "plate", thickness=t, material=dc.Elastic(E_, nu), kinematics=kinematics)
        sc.fix(p, "edge", dofs=("ux", "uy", "uz"))
        sc.fix(p, "centre", dofs=("rz",))
        sc.pressure(p, None, q)
        sc.monitor("w", p, "centre")
        found[n, distort] = dc.solve(sc, dc.LoadControl(steps=1), quiet=True).history.column("w_uz")[-1] / w_ref
    expected = {"kirchhoff": (0.99592, 0.99942, 0.99988, 0.99944), "mindlin": (0.97795, 0.99611, 1.00073, 0.99963)}
    for (key, value), want in zip(found.items(), expected[kinematics]):
        assert value == pytest.approx(want, abs=2e-5), key
    if kinematics == "kirchhoff":
        assert found[4, 0.0] < found[8, 0.0] < found[16, 0.0] < 1.0


def _strip(nx, L=12.0, b=1.0, comm=None):
    pts = np.array([[x, y, 0.0] for x in np.linspace(0, L, nx + 1) for y in (0.0, b)])
    cells = [[2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1] for i in range(nx)]
    kw = {} if comm is None else {"comm": comm}
    return from_arrays(pts, np.array(cells), "strip", {"clamp": [0, 1], "tip": [2 * nx, 2 * nx + 1]}, **kw)


def test_strip_rolls_into_a_circle():
    """A strip L = 12, b = 1, t = 0.1, ν = 0 of 16 quadrilaterals rolled into a full circle by an
    end moment M = 2πEI/L in 30 steps (benchmark B2a, closed form): the tip at every step within
    2e-3 L of the closed form, back at (−L, 0) to 1e-6 L, no cut step; every cell's resultants
    are the moment M/b (0.5 %) and nothing else."""
    L, b, t, E_ = 12.0, 1.0, 0.1, 1.2e6
    EI = E_ * b * t**3 / 12
    sc = dc.Scene()
    s = sc.add_shell(_strip(16), "strip", thickness=t, material=dc.Elastic(E_, 0.0))
    sc.fix(s, "clamp")
    sc.load(s, "tip", moment=(0.0, -np.pi * EI / L, 0.0))
    sc.monitor("tip", s, "tip", reduce="mean")
    result = dc.solve(sc, dc.LoadControl(steps=30), quiet=True)
    h = result.history
    phi = 2 * np.pi * np.array(h.column("load_factor"))
    err = np.hypot(np.array(h.column("tip_ux_mean")) - L * (np.sin(phi) / phi - 1),
                   np.array(h.column("tip_uz_mean")) - L * (1 - np.cos(phi)) / phi) / L
    assert err.max() < 2e-3 and err[-1] < 1e-6
    assert result.totals["cuts"] == 0
    # every cell carries the end moment per unit width about its width axis, and nothing else
    r = sc.element_results(s)
    assert r.values.shape == (16, 1, 16)
    np.testing.assert_allclose(np.abs(r["Mxx"][:, 0]), 2 * np.pi * EI / L / b, rtol=5e-3)
    for name in ("Nxx", "Nyy", "Nxy", "Myy", "Mxy", "Qx", "Qy"):
        assert np.abs(r[name][:, 0]).max() < 1e-3 * 2 * np.pi * EI / L


def test_quadrilateral_shells_refuse_what_they_cannot_do():
    """A triangle membrane name on quadrilaterals, a bad drilling factor, unknown kinematics,
    Reissner–Mindlin triangles, and shells asked for on a quadrilateral mesh that was given
    membranes first: each a clear error."""
    sc = dc.Scene()
    with pytest.raises(ValueError, match="membrane 'opt' is for triangles"):
        sc.add_shell(_strip(2), "strip", thickness=0.1, material=dc.Elastic(1e3, 0.3), membrane="opt")
    with pytest.raises(ValueError, match="drilling factor 0.0 must be positive"):
        sc.add_shell(_strip(2), "strip", thickness=0.1, material=dc.Elastic(1e3, 0.3), drilling=0.0)
    with pytest.raises(ValueError, match="kinematics 'timoshenko' is not 'kirchhoff' \\(DKQ\\) or 'mindlin'"):
        sc.add_shell(_strip(2), "strip", thickness=0.1, material=dc.Elastic(1e3, 0.3), kinematics="timoshenko")
    tri = from_arrays(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]), np.array([[0, 1, 2]]), "t")
    with pytest.raises(ValueError, match="need a quadrilateral mesh"):
        sc.add_shell(tri, "t", thickness=0.1, material=dc.Elastic(1e3, 0.3), kinematics="mindlin")
    tm = _strip(2)
    sc.add_membrane(tm, "strip", thickness=0.1, material=dc.Elastic(1e3, 0.3))
    with pytest.raises(ValueError, match="add its shells before its membranes"):
        sc.add_shell(tm, "strip", thickness=0.1, material=dc.Elastic(1e3, 0.3))


def test_mixed_triangle_and_quadrilateral_mesh():
    """A square plate meshed by gmsh with triangles on one half and quadrilaterals on the other
    (recombined), read as two meshes that share the nodes of their common edge
    (``from_gmsh(..., cells=...)``; read at once it is refused with that advice): simply
    supported under a pressure, its centre deflection lies between those of the all-triangle
    and all-quadrilateral meshes of the same grid and within 0.6 % of Timoshenko's
    0.00406 qa⁴/D (8 cells a side: −0.51 %; on the 8 × 8 grids of the test above, triangles
    −0.96 %, quadrilaterals −0.06 %)."""
    from mpi4py import MPI

    from gmsh_square import half_recombined_square

    comm = MPI.COMM_WORLD
    E_, nu, t, q = 1e4, 0.3, 0.01, 1e-3
    w_ref = 0.00406235 * q / (E_ * t**3 / (12 * (1 - nu**2)))
    with half_recombined_square(comm, lambda i: 9 if i in (2, 5, 6) else 5, [("edge", range(6))]) as model:
        with pytest.raises(ValueError, match="both triangles and quadrilaterals.*cells='quadrilateral'"):
            dc.from_gmsh(model, 3)
        meshes = [dc.from_gmsh(model, 3, cells=shape) for shape in ("triangle", "quadrilateral")]
    assert [tm.mesh.topology.cell_name() for tm in meshes] == ["triangle", "quadrilateral"]
    sc = dc.Scene(large_rotations=False)
    parts = [sc.add_shell(tm, "plate", thickness=t, material=dc.Elastic(E_, nu)) for tm in meshes]
    for p in parts:
        sc.fix(p, "edge", dofs=("ux", "uy", "uz"))
        sc.pressure(p, None, q)
    meshes[1].add_point_group("centre", [[0.5, 0.5, 0.0]])
    sc.monitor("w", parts[1], "centre")
    w = dc.solve(sc, dc.LoadControl(steps=1), quiet=True).history.column("w_uz")[-1] / w_ref
    assert w == pytest.approx(0.9949, abs=1e-4)

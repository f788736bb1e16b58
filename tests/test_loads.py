"""Distributed and follower loads: pressures on shells, membranes and solid faces, loads per length
on beams, dead or turning with the structure.

References:
- a thin ring under uniform external pressure buckles (n = 2) at p = 3EI/R³ when the pressure follows
  the deformed ring (hydrostatic; Lévy 1884; (n² − 1)EI/R³ with n = 2) and at p = 4EI/R³ when each
  load keeps its initial direction (n²EI/R³: for the inextensible ring w = a cos nθ, v = −(a/n) sin nθ,
  the dead loads' potential V = qR∫w dθ = −(q/2)∫(w' − v)² dθ by the second-order inextensibility
  condition, against U = EI/(2R³)∫(w'' + w)² dθ);
- the elastica of a cantilever under a uniform dead load, qL³/EI = 10, solved here by collocation
  (:func:`dolfinx_corot.closed_forms.cantilever_uniform_load`);
- a sphere of radius R inflated by a pressure p, membrane forces from the engineering strain of the
  co-rotational element (N = Et(λ − 1)/(1 − ν) per reference length): p = 2Et(λ − 1)/((1 − ν)λ²R);
- a plane-strain neo-Hookean block in uniaxial stress under a pressure on its end: follower p = −σ_xx
  (Cauchy), dead p = −P_xx (first Piola–Kirchhoff), the homogeneous stretches from the law.
"""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.closed_forms import cantilever_uniform_load
from dolfinx_corot.elements import follower
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import from_arrays, rectangles
from dolfinx_corot.staging import Stage, solve_stages

comm = MPI.COMM_WORLD
rng = np.random.default_rng(7)


# -- kernels ------------------------------------------------------------------------------------------
def _fd_tangent(evaluate, x, h=1e-6):
    f, K = evaluate(x)
    flat = x.reshape(len(x), -1)
    fd = np.zeros((len(x), f.shape[1], flat.shape[1]))
    for j in range(flat.shape[1]):
        up, down = flat.copy(), flat.copy()
        up[:, j] += h
        down[:, j] -= h
        fd[:, :, j] = (evaluate(up.reshape(x.shape))[0] - evaluate(down.reshape(x.shape))[0]) / (2 * h)
    return K, fd


@pytest.mark.parametrize("kind", ["line2d", "triangle", "quad"])
def test_follower_load_stiffness_against_finite_differences(kind):
    """The load stiffness ∂f/∂x of each kernel against central differences (random elements, random
    loads; 2D lines with and without fixed-end moments), to 1e-8 of its size."""
    if kind == "line2d":
        x, q, bending = rng.normal(size=(6, 2, 2)), rng.normal(size=(6, 2)), np.array([1, 0, 1, 1, 0, 1.0])
        K, fd = _fd_tangent(lambda y: (lambda f, K: (f, K[:, :, [0, 1, 3, 4]]))(*follower.line2d(y, q, bending)), x)
    else:
        x, p = rng.normal(size=(6, 3 if kind == "triangle" else 4, 3)), rng.normal(size=6)
        K, fd = _fd_tangent(lambda y: getattr(follower, kind)(y, p), x)
    assert np.abs(K - fd).max() < 1e-8 * max(np.abs(K).max(), 1.0)


@pytest.mark.parametrize("kind", ["triangle", "quad"])
def test_pressure_forces_are_objective_and_add_up_to_p_times_the_projected_area(kind):
    """Rotated elements get rotated forces; their sum is p A n (a flat element: its area and normal)."""
    n = 3 if kind == "triangle" else 4
    flat = np.array([[0, 0], [2, 0], [0, 1]] if n == 3 else [[0, 0], [2, 0], [0, 1], [2, 1]], dtype=float)
    x = np.column_stack([flat, np.zeros(n)])[None]
    f, _ = getattr(follower, kind)(x, np.array([3.0]))
    area = 1.0 if n == 3 else 2.0
    np.testing.assert_allclose(f.reshape(n, 3).sum(axis=0), [0, 0, 3.0 * area], atol=1e-13)
    Q = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    Q *= np.sign(np.linalg.det(Q))
    fr, Kr = getattr(follower, kind)(x @ Q.T, np.array([3.0]))
    np.testing.assert_allclose(fr.reshape(n, 3), f.reshape(n, 3) @ Q.T, atol=1e-12)


# -- beams: a ring under pressure, a cantilever under a uniform load ------------------------------------
R_RING, H_RING, E_RING = 1.0, 0.01, 1e6
EI_RING = E_RING * H_RING**3 / 12


def _quarter_ring(n: int, follower_load: bool):
    """A quarter of the ring (n beams), symmetric at both ends (no rigid rotation: the n = 2 mode),
    under p = EI/R³ per unit length times λ, inward (the normal e_z × t of an anticlockwise arc)."""
    t = np.linspace(0.0, np.pi / 2, n + 1)
    tm = polyline(np.column_stack([R_RING * np.cos(t), R_RING * np.sin(t)]), 1, line_name="arc", comm=comm)
    sc = dc.Scene()
    arc = sc.add_beam(tm, "arc", section=dc.Rectangle(1.0, H_RING), material=dc.Elastic(E_RING, 0.0))
    sc.fix(arc, "base", dofs=("uy", "rz"))
    sc.fix(arc, "tip", dofs=("ux", "rz"))
    sc.load(arc, None, per_length=(0.0, EI_RING / R_RING**3), axes="element", follower=follower_load)
    return sc


@pytest.mark.parametrize("follower_load, exact", [(True, 3.0), (False, 4.0)], ids=["follower", "dead"])
def test_a_ring_under_pressure_buckles_at_the_closed_form(follower_load, exact, hard_case):
    """Load control stops at the bifurcation; its load within 1 % of 3EI/R³ (follower) or 4EI/R³ (dead)
    on 32 elements per quarter (measured 0.05 % for both), converging as h² (16 elements: 0.2 %)."""
    errors = []
    for n in (16, 32):
        with pytest.raises(dc.CriticalPointError) as err:
            dc.solve(_quarter_ring(n, follower_load), dc.LoadControl(steps=10, final=5.0), quiet=True)
        (cp,) = err.value.result.critical_points
        assert cp.kind == "bifurcation"
        errors.append(cp.load_factor / exact - 1.0)
    assert abs(errors[1]) < 1e-2 and abs(errors[1]) < 0.3 * abs(errors[0]), errors
    hard_case(f"A ring under {'follower' if follower_load else 'dead'} pressure",
              "Buckling of a thin ring: the load stiffness of a pressure that follows the ring lowers the "
              "critical load from 4EI/R³ (loads of fixed direction) to 3EI/R³; a load step must stop at the "
              "bifurcation.", {"p_cr R³/EI": exact * (1 + errors[1]), "closed form": exact,
                               "error on 16 and 32 elements per quarter": errors})


def _cantilever(n: int, k: float, **load):
    L, E, b, h = 1.0, 1e7, 0.05, 0.01
    EI = E * b * h**3 / 12
    tm = polyline([[0.0, 0.0], [L, 0.0]], n, line_name="beam", comm=comm)
    sc = dc.Scene()
    beam = sc.add_beam(tm, "beam", section=dc.Rectangle(b, h), material=dc.Elastic(E, 0.0))
    sc.fix(beam, "base")
    sc.monitor("tip", beam, "tip")
    sc.load(beam, None, per_length=(0.0, -k * EI / L**3), **load)
    return sc


def test_a_cantilever_under_a_uniform_dead_load_follows_the_elastica():
    """qL³/EI = 10 (tip rotation 60°): tip position and rotation within 0.5 % of the elastica on 20
    elements (measured 0.04 %, 0.02 %, 0.06 %); in element axes the dead load is the same on the
    straight cantilever (identical results)."""
    ref = cantilever_uniform_load(10.0)
    assert ref["theta_tip"] == pytest.approx(-1.0526431, rel=1e-6)  # the collocation's own answer
    rows = []
    for axes in ("global", "element"):
        res = dc.solve(_cantilever(20, 10.0, axes=axes), dc.LoadControl(steps=10), quiet=True)
        rows.append(res.history.rows[-1])
    tip = rows[0]
    assert 1.0 + tip["tip_ux"] == pytest.approx(ref["x_tip"], rel=5e-3)
    assert tip["tip_uy"] == pytest.approx(ref["y_tip"], rel=5e-3)
    assert tip["tip_rz"] == pytest.approx(ref["theta_tip"], rel=5e-3)
    for key in ("tip_ux", "tip_uy", "tip_rz"):
        assert rows[1][key] == pytest.approx(tip[key], rel=1e-12)


def test_a_follower_load_on_a_cantilever_turns_with_it():
    """A load normal to the beam that follows it bends the cantilever further than the dead one (the
    load's horizontal part pulls the tip back); the nodal forces of the first, straight step agree."""
    dead = dc.solve(_cantilever(20, 10.0, axes="element"), dc.LoadControl(steps=10), quiet=True)
    turning = dc.solve(_cantilever(20, 10.0, axes="element", follower=True), dc.LoadControl(steps=10), quiet=True)
    assert turning.history.column("tip_rz")[-1] < dead.history.column("tip_rz")[-1] < 0.0
    first = [r.history.rows[0] for r in (dead, turning)]
    assert first[1]["tip_uy"] == pytest.approx(first[0]["tip_uy"], rel=0.05)


def test_a_3d_follower_line_load_has_its_load_stiffness():
    """The 3D beam's follower load per current length in its current axes (e1 along the chord, e2
    and e3 from the nodal rotations): the complex-step tangent against central finite differences
    of the loads over the translations and the rotation increments (R ← exp(δθ) R), for random
    states with rotations up to 2 rad (1e-7), and the loads rotated with a rigid rotation of the
    element (objectivity, 1e-12)."""
    from dolfinx_corot import rotations
    from dolfinx_corot.kernels import beam3d as k3

    def states(u, R):
        S = np.zeros((2, 7))
        S[:, :3] = u
        for a in range(2):
            S[a, 3:] = rotations.quat_from_matrix(R[a])
        return S

    props = np.zeros(k3.law.NPROPS)
    props[k3.law.VX:k3.law.VZ + 1] = (0.3, 1.0, 0.2)
    for trial in range(3):
        X = rng.normal(size=(2, 3))
        u = 0.3 * rng.normal(size=(2, 3))
        R = np.array([rotations.exp_so3(rng.uniform(-2.0, 2.0, 3)) for _ in range(2)])
        q = rng.normal(size=3)
        f, K = np.empty(12), np.empty((12, 12))
        k3.follower_loads(X, states(u, R), props, q, 1.0, f, K)
        h, fd = 1e-6, np.empty((12, 12))
        for j in range(12):
            plus, minus = [u.copy(), R.copy()], [u.copy(), R.copy()]
            a, c = divmod(j, 6)
            if c < 3:
                plus[0][a, c] += h
                minus[0][a, c] -= h
            else:
                w = np.zeros(3)
                w[c - 3] = h
                plus[1][a] = rotations.exp_so3(w) @ R[a]
                minus[1][a] = rotations.exp_so3(-w) @ R[a]
            fp, fm = np.empty(12), np.empty(12)
            k3.follower_loads(X, states(*plus), props, q, 1.0, fp, np.empty((12, 12)))
            k3.follower_loads(X, states(*minus), props, q, 1.0, fm, np.empty((12, 12)))
            fd[:, j] = (fp - fm) / (2 * h)
        np.testing.assert_allclose(K, fd, atol=1e-7 * np.abs(fd).max())
        # a rigid rotation Q of the deformed element turns its loads with it
        Q = rotations.exp_so3(rng.uniform(-3.0, 3.0, 3))
        x = X + u
        uq = (x @ Q.T) - X
        fq = np.empty(12)
        k3.follower_loads(X, states(uq, np.array([Q @ R[0], Q @ R[1]])), props, q, 1.0, fq, np.empty((12, 12)))
        np.testing.assert_allclose(fq.reshape(4, 3), f.reshape(4, 3) @ Q.T, atol=1e-12 * np.abs(f).max())


def test_a_3d_follower_load_on_a_cantilever_is_the_2d_one():
    """The cantilever of the 2D follower test (qL³/EI = 10 normal to the beam, per current length)
    as 3D beams in the plane z = 0, the load along the section axis that lies in that plane: the
    tip moves and turns as the 2D run's (1e-8), the load stiffness keeping Newton quadratic."""
    L, E, b, h, k = 1.0, 1e7, 0.05, 0.01, 10.0
    EI = E * b * h**3 / 12
    plane = dc.solve(_cantilever(20, k, axes="element", follower=True), dc.LoadControl(steps=10), quiet=True)
    tm = polyline([[0.0, 0.0, 0.0], [L, 0.0, 0.0]], 20, line_name="beam", gdim=3, comm=comm)
    sc = dc.Scene()
    # the section's y axis along global z: the bending in the plane (about z, the section's y) takes
    # Iy = b h³/12, the 2D beam's I
    beam = sc.add_beam(tm, "beam", section=dc.Section(A=b * h, I=h * b**3 / 12, Iy=b * h**3 / 12, J=1e-6),
                       material=dc.Elastic(E, 0.0), orientation=(0.0, 0.0, 1.0))
    sc.fix(beam, "base")
    sc.fix(beam, "beam", dofs=("uz", "rx", "ry"))
    sc.monitor("tip", beam, "tip")
    # e2 = global z, e3 = e1 × e2 = −y at the start: the 2D load −q along +y is +q along e3
    sc.load(beam, None, per_length=(0.0, 0.0, k * EI / L**3), axes="element", follower=True)
    space = dc.solve(sc, dc.LoadControl(steps=10), quiet=True)
    a, c = plane.history.rows[-1], space.history.rows[-1]
    for key in ("tip_ux", "tip_uy"):
        assert c[key] == pytest.approx(a[key], abs=1e-8 * L)
    assert c["tip_rz"] == pytest.approx(a["tip_rz"], abs=1e-8)
    assert space.history.column("iterations").max() <= plane.history.column("iterations").max() + 1


# -- surfaces: an inflated sphere ----------------------------------------------------------------------
E_S, NU_S, T_S = 1e3, 0.3, 0.01


def _octant(N: int):
    """A triangulated eighth of the unit sphere (nodes on the sphere), normals outward."""
    index, points = {}, []
    for i in range(N + 1):
        for j in range(N + 1 - i):
            p = np.array([i, j, N - i - j], dtype=float)
            index[i, j] = len(points)
            points.append(p / np.linalg.norm(p))
    cells = []
    for i in range(N):
        for j in range(N - i):
            cells.append([index[i, j], index[i + 1, j], index[i, j + 1]])
            if j < N - i - 1:
                cells.append([index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]])
    points, cells = np.array(points), np.array(cells)
    normal = np.cross(points[cells[:, 1]] - points[cells[:, 0]], points[cells[:, 2]] - points[cells[:, 0]])
    inward = np.einsum("ni,ni->n", normal, points[cells].mean(axis=1)) < 0
    cells[inward] = cells[inward][:, [0, 2, 1]]
    groups = {name: np.flatnonzero(np.abs(points[:, k]) < 1e-12) for k, name in enumerate(("x0", "y0", "z0"))}
    return from_arrays(points, cells, "skin", groups, comm=comm)


def _inflation_pressure(stretch):
    return 2 * E_S * T_S * (stretch - 1) / ((1 - NU_S) * stretch**2)


@pytest.mark.parametrize("kind", ["membrane", "shell"])
def test_an_inflated_sphere_follows_its_pressure_stretch_curve(kind):
    """An eighth of a sphere (symmetry planes), inflated to a stretch of 1.5 (p is 93 % of its maximum,
    reached at λ = 2): at every step the pressure is within 1 % of the closed form at the computed
    stretch (16 triangles along an edge; measured 0.3 % at the end), the radius uniform to 1e-3."""
    sc = dc.Scene()
    add = sc.add_membrane if kind == "membrane" else sc.add_shell
    skin = add(_octant(16), "skin", thickness=T_S, material=dc.Elastic(E_S, NU_S))
    rotations = {"x0": ("ry", "rz"), "y0": ("rx", "rz"), "z0": ("rx", "ry")} if kind == "shell" else {}
    for k, name in enumerate(("x0", "y0", "z0")):
        sc.fix(skin, name, dofs=(("ux", "uy", "uz")[k],) + rotations.get(name, ()))
    final = _inflation_pressure(1.5)
    sc.pressure(skin, None, final)
    stretches = []

    def radius(row):
        X, u = skin.model.nodes()
        r = np.linalg.norm(X[:, :3] + u[:, :3], axis=1)
        stretches.append((row["load_factor"], r.mean(), r.std() / r.mean()))

    dc.solve(sc, dc.LoadControl(steps=6), on_step=radius, quiet=True)
    for lam, stretch, spread in stretches:
        assert lam * final == pytest.approx(_inflation_pressure(stretch), rel=1e-2)
        assert spread < 1e-3
    assert stretches[-1][1] == pytest.approx(1.5, rel=5e-3)


# -- solids: a block pressed on its end ------------------------------------------------------------------
@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("follower_load", [True, False], ids=["follower", "dead"])
def test_a_pressure_on_a_solid_gives_the_exact_uniaxial_state(follower_load, degree):
    """A plane-strain neo-Hookean block on rollers, p = 0.2E on its end (17 % shortening): the stretches
    of the homogeneous state solve σ_xx = −p (follower: per current area) or P_xx = −p (dead: per
    reference area) with σ_yy = 0; any mesh gives them to 1e-9."""
    from scipy.optimize import fsolve

    E, nu, p = 1.0, 0.3, 0.2
    lm, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))

    def stresses(z):
        a, b = z
        Pxx = mu * (a - 1 / a) + lm * np.log(a * b) / a
        Pyy = mu * (b - 1 / b) + lm * np.log(a * b) / b
        return [Pxx - (-p * b if follower_load else -p), Pyy]

    a, b = fsolve(stresses, [0.8, 1.05], xtol=1e-12)
    tm = rectangles({"block": (0.0, 0.0, 2.0, 1.0, 4, 2)},
                    {"left": [("block", "left")], "bottom": [("block", "bottom")], "right": [("block", "right")]},
                    comm=comm)
    sc = dc.Scene()
    block = sc.add_solid(tm, material=dc.NeoHookean(E, nu), degree=degree)
    sc.fix(block, "left", dofs=("ux",))
    sc.fix(block, "bottom", dofs=("uy",))
    sc.pressure(block, "right", p, follower=follower_load)
    dc.solve(sc, dc.LoadControl(steps=4), quiet=True)
    X, u = block.model.nodes()
    np.testing.assert_allclose(X[:, 0] + u[:, 0], a * X[:, 0], atol=1e-9)
    np.testing.assert_allclose(X[:, 1] + u[:, 1], b * X[:, 1], atol=1e-9)


# -- what is refused -----------------------------------------------------------------------------------------
def test_unsupported_follower_loads_are_refused_with_the_reason():
    with pytest.raises(NotImplementedError, match="arc-length with follower loads"):
        dc.solve(_quarter_ring(4, True), dc.ArcLength(max_steps=2), quiet=True)
    with pytest.raises(NotImplementedError, match="follower loads .* cannot be staged"):
        solve_stages(_quarter_ring(4, True), [Stage("one")])
    sc = dc.Scene()
    tm = polyline([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], 2, line_name="bar", gdim=3, comm=comm)
    beam = sc.add_beam(tm, "bar", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1e6, 0.3))
    with pytest.raises(ValueError, match="give it in element axes"):
        sc.load(beam, None, per_length=(0.0, 1.0, 0.0), follower=True)
    with pytest.raises(ValueError, match="a pressure acts on surfaces"):
        sc.pressure(beam, None, 1.0)
    sc2 = dc.Scene()
    tm2 = polyline([[0.0, 0.0], [1.0, 0.0]], 2, line_name="beam", comm=comm)
    beam2 = sc2.add_beam(tm2, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1e6, 0.3))
    with pytest.raises(ValueError, match="give it in element axes"):
        sc2.load(beam2, None, per_length=(0.0, 1.0), follower=True)
    with pytest.raises(ValueError, match="axes = 'local' is not 'global' or 'element'"):
        sc2.load(beam2, None, per_length=(0.0, 1.0), axes="local")
    with pytest.raises(ValueError, match="p = nan must be a finite number"):
        sc2.pressure(beam2, None, float("nan"))
    with pytest.raises(ValueError, match="follower=True is for distributed loads"):
        sc2.load(beam2, "tip", force=(0.0, 1.0), follower=True)
    with pytest.raises(ValueError, match="group 'tip' has dimension 0; a group of cells"):
        sc2.load(beam2, "tip", per_length=(0.0, 1.0))
    # a load per length on a shell, a pressure on a solid without a facet group
    sc3 = dc.Scene()
    plate = sc3.add_shell(_octant(2), "skin", thickness=0.01, material=dc.Elastic(1e3, 0.3))
    with pytest.raises(ValueError, match="load per length on shell 'skin': name the edges it acts on"):
        sc3.load(plate, None, per_length=(0.0, 0.0, 1.0))
    tm4 = rectangles({"block": (0.0, 0.0, 1.0, 1.0, 2, 2)}, {"right": [("block", "right")]}, comm=comm)
    sc4 = dc.Scene()
    block = sc4.add_solid(tm4, material=dc.NeoHookean(1.0, 0.3), degree=1)
    with pytest.raises(ValueError, match=r"pressure on a solid: name the group of facets it acts on \(where=...\)"):
        sc4.pressure(block, None, 1.0)


# -- loads per length on the edges of shells and membranes ---------------------------------------------
def _free_plate(nx, kind):
    """A free square plate of nx × nx cells (quadrilaterals, or each cut into two triangles), held
    only against rigid motion; node groups along x = 0 ('left') and x = 1 ('right')."""
    X, Y = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 1, nx + 1), indexing="ij")
    pts = np.c_[X.ravel(), Y.ravel(), np.zeros(X.size)]
    idx = np.arange(X.size).reshape(nx + 1, nx + 1)
    a0, a1, b0, b1 = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()
    cells = np.c_[a0, a1, b1, b0] if kind == "quad" else np.concatenate([np.c_[a0, a1, b1], np.c_[a0, b1, b0]])
    groups = {"plate": None, "left": idx[0, :], "right": idx[-1, :], "corner": [idx[0, 0]], "x1": [idx[-1, 0]],
              "y1": [idx[0, -1]], "centre": [idx[nx // 2, nx // 2]]}
    groups.pop("plate")
    return from_arrays(pts, cells, "plate", groups, comm=comm)


def _pulled_plate(kind, membrane, nx, edge_load):
    """The free plate (t = 0.01, E = 10⁶, ν = 0.3) pulled by Nx = 1 on x = 0 and x = 1: as a load per
    length, or as the nodal forces of one (Nx l/2 at the corners, Nx l between)."""
    t, E, nu = 0.01, 1e6, 0.3
    tm = _free_plate(nx, kind)
    sc = dc.Scene(large_rotations=False)
    p = sc.add_shell(tm, "plate", thickness=t, material=dc.Elastic(E, nu), membrane=membrane)
    sc.fix(p, "corner", dofs=("ux", "uy", "uz"))
    sc.fix(p, "x1", dofs=("uy", "uz"))
    sc.fix(p, "y1", dofs=("uz",))
    for edge, sign in (("right", 1.0), ("left", -1.0)):
        if edge_load:
            sc.load(p, edge, per_length=(sign, 0.0, 0.0))
            continue
        for j, y in enumerate(np.linspace(0.0, 1.0, nx + 1)):
            tm.add_point_group(f"{edge}{j}", [[0.5 + 0.5 * sign, y, 0.0]])
            sc.load(p, f"{edge}{j}", force=(sign / nx * (0.5 if j in (0, nx) else 1.0), 0.0, 0.0))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    X, u = p.model.nodes()
    strain = 1.0 / (E * t)
    return X, u, strain, nu


@pytest.mark.parametrize("kind, membrane", [("triangle", "opt"), ("triangle", "cst"), ("quad", None)])
def test_a_uniform_edge_load_stretches_a_free_plate_uniformly(kind, membrane):
    """A load per length on a shell's edges is a constant-stress load: a free plate pulled by
    Nx on two opposite edges takes the uniaxial state u = Nx x/(Et), v = −ν Nx y/(Et) exactly
    (1e-10) on 4 × 4 cells. On OPT triangles this needs the drilling moments ±α_b Nx l²/12 of
    the quadratic edge field (Allman 1984; α_b = 3/2, Felippa 2003) at the edges' ends: with
    the nodal forces alone they do not cancel at the free corners and the loaded edges move
    37 % (4 × 4), 20 % (8 × 8), 10 % (16 × 16) too far at their middle (77 %, 40 %, 20 % at
    the corners); CST triangles and quadrilaterals have
    linear edges, and there nodal forces are the same load."""
    X, u, strain, nu = _pulled_plate(kind, membrane, 4, edge_load=True)
    np.testing.assert_allclose(u[:, 0], strain * X[:, 0], atol=1e-10 * strain)
    np.testing.assert_allclose(u[:, 1], -nu * strain * X[:, 1], atol=1e-10 * strain)
    X, u, strain, nu = _pulled_plate(kind, membrane, 4, edge_load=False)
    too_far = u[np.argmin(np.hypot(X[:, 0] - 1.0, X[:, 1] - 0.5)), 0] / strain - 1.0  # mid-edge
    if membrane == "opt":
        assert too_far == pytest.approx(0.37, abs=0.01)
    else:
        assert abs(too_far) < 1e-10


@pytest.mark.parametrize("kind, kinematics, exact", [("quad", "kirchhoff", 1e-8), ("triangle", "kirchhoff", 4e-3),
                                                     ("quad", "mindlin", 2e-2)])
def test_a_transverse_edge_load_on_a_cantilever_strip(kind, kinematics, exact):
    """A cantilever strip (L = 1, b = 1/4, ν = 0: a beam of width b) under a uniform transverse
    load q per length on its free end: tip deflection q b L³/(3EI), I = b t³/12 (Euler–Bernoulli).
    The nodal forces q l/2 are the load of the discrete Kirchhoff quadrilateral's edges (exact,
    1e-8, on 4 × 2 cells), within 0.4 % on DKT triangles and 2 % on MITC4 (its shear)."""
    L, b, t, E, q, nx, ny = 1.0, 0.25, 0.01, 1e6, 1e-6, 4, 2
    X, Y = np.meshgrid(np.linspace(0, L, nx + 1), np.linspace(0, b, ny + 1), indexing="ij")
    pts = np.c_[X.ravel(), Y.ravel(), np.zeros(X.size)]
    idx = np.arange(X.size).reshape(nx + 1, ny + 1)
    a0, a1, b0, b1 = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()
    cells = np.c_[a0, a1, b1, b0] if kind == "quad" else np.concatenate([np.c_[a0, a1, b1], np.c_[a0, b1, b0]])
    tm = from_arrays(pts, cells, "strip", {"root": idx[0], "tip": idx[-1]}, comm=comm)
    sc = dc.Scene(large_rotations=False)
    p = sc.add_shell(tm, "strip", thickness=t, material=dc.Elastic(E, 0.0), kinematics=kinematics)
    sc.fix(p, "root")
    sc.load(p, "tip", per_length=(0.0, 0.0, q))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    Xn, u = p.model.nodes()
    w = u[np.isclose(Xn[:, 0], L), 2]
    np.testing.assert_allclose(w / (q * b * L**3 / (3 * E * b * t**3 / 12)), 1.0, atol=exact)


T_PLATE, E_PLATE, NU_PLATE = 0.01, 1e6, 0.3


def _pull_two_halves(sc, left, right, groups=("corner", "top", "foot", "x0", "x1")):
    """Hold the plate of ``left`` and ``right`` (PartRefs) against rigid motion (all translations at
    the left's corner, u_z at its top, u_y and u_z at the right's foot), pull it by Nx = 1 on the
    left's edge x = 0 and the right's x = 1 (dead edge loads), solve, and check the exact
    uniaxial state in both (1e-10)."""
    corner, top, foot, x0, x1 = groups
    sc.fix(left, corner, dofs=("ux", "uy", "uz"))
    sc.fix(left, top, dofs=("uz",))
    sc.fix(right, foot, dofs=("uy", "uz"))
    sc.load(left, x0, per_length=(-1.0, 0.0, 0.0))
    sc.load(right, x1, per_length=(1.0, 0.0, 0.0))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    strain = 1.0 / (E_PLATE * T_PLATE)
    for part in (left, right):
        X, u = part.model.nodes()
        np.testing.assert_allclose(u[:, 0], strain * X[:, 0], atol=1e-10 * strain)
        np.testing.assert_allclose(u[:, 1], -NU_PLATE * strain * X[:, 1], atol=1e-10 * strain)


@pytest.mark.parametrize("membrane", ["cst", "opt"])
def test_edge_loads_on_the_lines_of_a_mixed_gmsh_surface(membrane):
    """A square read from gmsh as a triangle mesh (left half) and a quadrilateral mesh (right half)
    sharing their middle nodes, pulled by Nx on its physical lines x = 0 and x = 1 (one per part):
    the uniaxial state exactly (1e-10), with CST and with OPT triangles. The OPT's constant-stress
    state puts drilling moments ±α_b σ l²/12 on the ends of its edges (Allman's quadratic edge);
    on the edges it shares with the quadrilaterals' linear edges they would cancel along the
    interface but not where it meets the free edges (before the OPT kept those edges linear: the
    plate's middle line stretched 1.1 % too much on 4 cells per half, the quadrilaterals'
    corners were off by 18 % of the stretch)."""
    from gmsh_square import half_recombined_square

    with half_recombined_square(comm, lambda i: 5, [("x0", [5]), ("x1", [2])]) as model:
        tri, quad = (dc.from_gmsh(model, 3, cells=shape) for shape in ("triangle", "quadrilateral"))
    sc = dc.Scene(large_rotations=False)
    material = dc.Elastic(E_PLATE, NU_PLATE)
    left_part = sc.add_shell(tri, "plate", thickness=T_PLATE, material=material, membrane=membrane)
    right_part = sc.add_shell(quad, "plate", thickness=T_PLATE, material=material)
    tri.add_point_group("origin", [[0.0, 0.0, 0.0]])
    tri.add_point_group("top", [[0.0, 1.0, 0.0]])
    quad.add_point_group("foot", [[1.0, 0.0, 0.0]])
    _pull_two_halves(sc, left_part, right_part, ("origin", "top", "foot", "x0", "x1"))


@pytest.mark.parametrize("right", ["cst", "quad"])
def test_opt_triangles_beside_linear_edges_pass_the_patch_test(right):
    """The free plate of 8 × 8 squares: its left half OPT triangles, its right half on a second
    mesh sharing the middle nodes — CST triangles or quadrilaterals — pulled by Nx = 1 on x = 0
    and x = 1 (dead edge loads): the exact uniaxial state in both halves (1e-10). The OPT keeps
    the edges it shares with them linear."""
    nx = 8
    X, Y = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 1, nx + 1), indexing="ij")
    pts = np.c_[X.ravel(), Y.ravel(), np.zeros(X.size)]
    idx = np.arange(X.size).reshape(nx + 1, nx + 1)
    half = {}
    for name, cols in (("left", slice(0, nx // 2)), ("right", slice(nx // 2, nx))):
        i = idx[cols.start:cols.stop + 1, :]
        a0, a1, b0, b1 = i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel()
        quads = name == "right" and right == "quad"
        half[name] = np.c_[a0, a1, b1, b0] if quads else np.concatenate([np.c_[a0, a1, b1], np.c_[a0, b1, b0]])
    groups = {"x0": idx[0, :], "x1": idx[-1, :], "corner": [idx[0, 0]], "foot": [idx[-1, 0]], "top": [idx[0, -1]]}
    left = from_arrays(pts, half["left"], "plate", groups, comm=comm, node_source="split")
    rightm = from_arrays(pts, half["right"], "plate", groups, comm=comm, node_source="split")
    sc = dc.Scene(large_rotations=False)
    material = dc.Elastic(E_PLATE, NU_PLATE)
    lp = sc.add_shell(left, "plate", thickness=T_PLATE, material=material)
    rp = sc.add_shell(rightm, "plate", thickness=T_PLATE, material=material, membrane="cst" if right == "cst" else None)
    _pull_two_halves(sc, lp, rp)


def test_opt_and_cst_groups_of_one_mesh_pass_the_patch_test():
    """One triangle mesh of 8 × 8 squares, its left half OPT and its right half CST (two cell
    groups), pulled as above: the exact uniaxial state (1e-10)."""
    tm = _free_plate(8, "triangle")
    tm.add_cell_group("left_half", lambda x: x[0] < 0.5)
    tm.add_cell_group("right_half", lambda x: x[0] > 0.5)
    sc = dc.Scene(large_rotations=False)
    material = dc.Elastic(E_PLATE, NU_PLATE)
    p = sc.add_shell(tm, "left_half", thickness=T_PLATE, material=material)
    q = sc.add_shell(tm, "right_half", thickness=T_PLATE, material=material, membrane="cst")
    _pull_two_halves(sc, p, q, ("corner", "y1", "x1", "left", "right"))


def test_bad_edge_loads_are_named():
    """An edge load without edges, on a group of cells, in element axes or following the surface,
    or on a group with no boundary edge (one node) is refused, naming the group."""
    tm = _free_plate(2, "triangle")
    sc = dc.Scene(large_rotations=False)
    p = sc.add_shell(tm, "plate", thickness=0.01, material=dc.Elastic(1e6, 0.3))
    with pytest.raises(ValueError, match="name the edges"):
        sc.load(p, None, per_length=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="'plate' is a group of cells"):
        sc.load(p, "plate", per_length=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="dead load in global axes"):
        sc.load(p, "right", per_length=(1.0, 0.0, 0.0), axes="element")
    with pytest.raises(ValueError, match="dead load in global axes"):
        sc.load(p, "right", per_length=(1.0, 0.0, 0.0), axes="element", follower=True)
    with pytest.raises(ValueError, match="group 'centre' has no boundary edges"):
        sc.load(p, "centre", per_length=(1.0, 0.0, 0.0))
    with pytest.raises(dc.GroupNotFoundError if hasattr(dc, "GroupNotFoundError") else Exception, match="'edge'"):
        sc.load(p, "edge", per_length=(1.0, 0.0, 0.0))

"""Self-weight of structures (density on the materials, ``scene.gravity`` on every part kind) and
plane-strain 2D beams, each against a hand calculation; bad input named."""
import numpy as np
import pytest
from mpi4py import MPI
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import dolfinx_corot as dc
from dolfinx_corot.elements import uniform_load
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import from_arrays

comm = MPI.COMM_WORLD
E, NU, B, H, L = 1e5, 0.3, 0.1, 0.1, 2.0
A, I = B * H, B * H**3 / 12


def _cantilever(n: int, large: bool, rho: float = 2.0, g: float = 1e-3, section=None, **beam):
    tm = polyline([[0.0, 0.0], [L, 0.0]], n, line_name="beam")
    sc = dc.Scene(large_rotations=large)
    b = sc.add_beam(tm, "beam", section=section or dc.Rectangle(B, H), material=dc.Elastic(E, NU, density=rho),
                    **beam)
    sc.fix(b, "base")
    sc.gravity(b, (0.0, -g))
    sc.monitor("tip", b, "tip")
    sc.monitor_reaction("root", b, "base")
    return sc, b


@pytest.mark.parametrize("kinematics", ["bernoulli", "timoshenko"])
@pytest.mark.parametrize("large", [False, True], ids=["linear", "co-rotational"])
@pytest.mark.parametrize("n", [1, 2, 8])
def test_cantilever_under_self_weight_is_exact(n, large, kinematics):
    """q = ρAg: tip deflection qL⁴/8EI (+ qL²/2GAs for Timoshenko), tip rotation qL³/6EI, root reaction
    qL and moment qL²/2, with any number of elements (work-equivalent forces and fixed-end moments
    ±ql²/12: nodally exact for the linear beam). Co-rotational at qL³/EI = 2e-5: the O((qL³/EI)²)
    difference is measured ≤ 8e-10; bounds 1e-12 (linear) and 5e-9 (co-rotational)."""
    rho, g = 2.0, 1e-3
    res = dc.solve(_cantilever(n, large, rho, g, kinematics=kinematics)[0], dc.LoadControl(steps=1))
    row = res.history.rows[-1]
    q = rho * A * g
    tol = 5e-9 if large else 1e-12
    deflection = -q * L**4 / (8 * E * I)
    if kinematics == "timoshenko":
        deflection -= q * L**2 / (2 * E / (2 * (1 + NU)) * dc.Rectangle(B, H).As)
    for key, exact in (("tip_uy", deflection), ("tip_rz", -q * L**3 / (6 * E * I)),
                       ("root_Fy", q * L), ("root_Mz", q * L**2 / 2)):
        assert abs(row[key] / exact - 1.0) < tol, (key, row[key], exact)
    assert abs(row["root_Fx"]) < tol * q * L


def _elastica_tip(q: float, EI: float) -> np.ndarray:
    """Inextensible elastica of a cantilever under a uniform dead load q per unit length (Rohde 1953):
    EI θ'' = q (L − s) cos θ, θ(0) = 0, θ'(L) = 0; x' = cos θ, y' = sin θ, solved by shooting on
    θ'(0). Returns (θ, x, y) at the tip."""
    def shoot(curvature):
        rhs = lambda s, y: [y[1], q * (L - s) * np.cos(y[0]) / EI, np.cos(y[0]), np.sin(y[0])]  # noqa: E731
        return solve_ivp(rhs, (0.0, L), [0.0, curvature, 0.0, 0.0], method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]

    linear = -q * L**2 / (2 * EI)
    curvature = brentq(lambda c: shoot(c)[1], 2.0 * linear, 0.0, xtol=1e-15)
    theta, _, x, y = shoot(curvature)
    return np.array([theta, x, y])


def test_large_deflection_under_self_weight_converges_to_the_elastica():
    """qL³/EI = 5 (tip rotation −0.697 rad, tip drop 0.50 L) on a slender strip (L/h = 200: the
    axial strain, ~1e-5, is below the discretization error). The reference fixed-end moments
    stay dead as the elements rotate; the tip errors still fall as h²: measured |Δy| 9.3e-4,
    2.3e-4, 5.4e-5 for 8, 16, 32 elements (orders 2.03, 2.08); bounds: order in (1.8, 2.3),
    |Δ| < 1e-4 at 32 (measured 7.7e-5, on θ)."""
    h = 0.01
    EI = E * B * h**3 / 12
    q = 5.0 * EI / L**3
    rho = 1.0
    exact = _elastica_tip(q, EI)
    errors = []
    for n in (8, 16, 32):
        sc, _ = _cantilever(n, True, rho, q / (rho * B * h), section=dc.Rectangle(B, h))
        row = dc.solve(sc, dc.LoadControl(steps=5)).history.rows[-1]
        errors.append(np.array([row["tip_rz"], L + row["tip_ux"], row["tip_uy"]]) - exact)
    errors = np.abs(np.array(errors))
    order = np.log2(errors[:-1] / errors[1:])
    assert np.all((order > 1.8) & (order < 2.3)), order
    assert errors[-1].max() < 1e-4, errors


@pytest.mark.parametrize("gdim", [2, 3])
@pytest.mark.parametrize("large", [False, True], ids=["linear", "co-rotational"])
def test_bar_hanging_under_its_own_weight(gdim, large):
    """A bar of length L hanging from its top: support reaction ρAgL, elongation ρgL²/2E (nodally
    exact with linear bars; also co-rotationally, whose axial strain is Δl/l₀ = N/EA)."""
    rho, g, area, n = 3.0, 0.5, 0.02, 5
    up = np.zeros(gdim)
    up[-1] = 1.0
    pts = np.outer(np.linspace(0.0, -L, n + 1), up)
    tm = from_arrays(pts, np.column_stack([np.arange(n), np.arange(1, n + 1)]), "bar", {"top": [0], "bottom": [n]})
    sc = dc.Scene(large_rotations=large)
    bar = sc.add_truss(tm, "bar", area=area, material=dc.Elastic(E, NU, density=rho))
    sc.fix(bar, "top")
    sc.fix(bar, "bar", dofs=("ux", "uy")[: gdim - 1])  # a hanging chain has no lateral stiffness
    sc.gravity(bar, -g * up)
    sc.monitor("bottom", bar, "bottom")
    sc.monitor_reaction("top", bar, "top")
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    vertical = "uy" if gdim == 2 else "uz"
    force = "Fy" if gdim == 2 else "Fz"
    assert abs(row[f"bottom_{vertical}"] + rho * g * L**2 / (2 * E)) < 1e-10 * rho * g * L**2 / E
    assert abs(row[f"top_{force}"] - rho * area * g * L) < 1e-10 * rho * area * g * L


def _plate_mesh(nx: int, ny: int, lx: float, ly: float, triangles: bool):
    """Rectangle [0, lx] × [0, ly] in the xy plane (3D) of nx × ny triangle pairs or quadrilaterals,
    the boundary nodes 'edge' and the nodes of y = ly 'top'."""
    x, y = np.meshgrid(np.linspace(0, lx, nx + 1), np.linspace(0, ly, ny + 1))
    pts = np.column_stack([x.ravel(), y.ravel(), 0 * x.ravel()])
    idx = np.arange(len(pts)).reshape(ny + 1, nx + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    cells = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])]) if triangles \
        else np.column_stack([a, b, c, d])
    edge = np.unique(np.concatenate([idx[0], idx[-1], idx[:, 0], idx[:, -1]]))
    return from_arrays(pts, cells, "plate", {"edge": edge, "top": idx[-1]})


def test_shell_plate_self_weight_total_reaction():
    """A shell plate clamped on its boundary under gravity not normal to it: the reactions sum to
    −ρ t A g (every component), and the normal part q = ρ t g_z bends it as a clamped plate."""
    rho, t, lx, ly = 2.5, 0.02, 2.0, 1.0
    g = np.array([0.3, -0.2, -1.0])
    tm = _plate_mesh(12, 6, lx, ly, triangles=True)
    sc = dc.Scene(large_rotations=False)
    plate = sc.add_shell(tm, "plate", thickness=t, material=dc.Elastic(E, NU, density=rho))
    sc.fix(plate, "edge")
    sc.gravity(plate, g)
    sc.monitor_reaction("edge", plate, "edge")
    res = dc.solve(sc, dc.LoadControl(steps=1))
    row = res.history.rows[-1]
    weight = rho * t * lx * ly * g
    for comp, w in zip(("Fx", "Fy", "Fz"), weight):
        assert abs(row[f"edge_{comp}"] + w) < 1e-10 * np.linalg.norm(weight), (comp, row[f"edge_{comp}"], w)
    # the normal part bends the clamped plate: w_max = 0.00254 q a⁴/D for b/a = 2 (Timoshenko &
    # Woinowsky-Krieger 1959, table 35); DKT measured 1.088, 1.017, 1.002 of it on 6×4, 12×6,
    # 24×12 cells; bound 3 % on 12×6
    _, state = sc.model.nodes()
    D = E * t**3 / (12 * (1 - NU**2))
    ratio = state[:, 2].min() / (0.00254 * rho * t * g[2] * ly**4 / D)
    assert abs(ratio - 1.0) < 0.03, ratio


@pytest.mark.parametrize("large", [False, True], ids=["linear", "co-rotational"])
def test_membrane_hanging_from_its_top_edge(large):
    """A vertical membrane of quadrilaterals (ν = 0) hung from its top edge under its weight in
    its plane: the top reaction is ρ t g A, and the vertical displacement of the bottom is that of a
    hanging bar, ρ g H²/2E (columns of Q4 cells carry u_y(y) exactly: nodally exact)."""
    rho, t, lx, ly, g = 2.0, 0.05, 1.0, 2.0, 0.5
    tm = _plate_mesh(3, 4, lx, ly, triangles=False)
    sc = dc.Scene(large_rotations=large)
    plate = sc.add_membrane(tm, "plate", thickness=t, material=dc.Elastic(E, 0.0, density=rho))
    sc.fix(plate, "top")
    sc.fix(plate, "plate", dofs=("uz",))  # a flat membrane has no stiffness across its plane
    sc.gravity(plate, (0.0, -g, 0.0))
    sc.monitor_reaction("top", plate, "top")
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    assert abs(row["top_Fy"] - rho * t * g * lx * ly) < 1e-10 * rho * t * g * lx * ly
    X, state = sc.model.nodes()
    bottom = np.isclose(X[:, 1], 0.0)
    exact = -rho * g * ly**2 / (2 * E)
    tol = 1e-8 if large else 1e-10
    np.testing.assert_allclose(state[bottom, 1], exact, rtol=tol)


def test_nodal_loads_carry_the_weight_and_its_moment():
    """The work-equivalent nodal forces of a uniform load sum to q times the reference length or area
    and act at its centroid (Σ X_a f_a = q ∫ X dA: the moment of the weight is exact), on a
    trapezoid (centroid by hand: x̄ = (a² + ab + b²)/3(a + b) for parallel sides a, b at y = 0, 1),
    a triangle and a line; a beam adds the fixed-end moments ±(l/12) d × q."""
    q = np.array([0.3, -1.0, 0.2])
    # trapezoid: side 0..3 at y = 0, side 0..1 at y = 1 (nodes in DOLFINx's order)
    quad = np.array([[[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]])
    f = uniform_load.quad_loads(quad, q)[0]
    area, a, b = 2.0, 3.0, 1.0
    centroid = np.array([(a * a + a * b + b * b) / (3 * (a + b)), (a + 2 * b) / (3 * (a + b)), 0.0])
    np.testing.assert_allclose(f.sum(axis=0), area * q, rtol=1e-14)
    np.testing.assert_allclose(quad[0].T @ f[:, 1] / (area * q[1]), centroid, rtol=1e-14, atol=1e-15)
    tri = np.array([[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 1.0]]])
    f = uniform_load.triangle_loads(tri, q)[0]
    np.testing.assert_allclose(f.sum(axis=0), np.sqrt(2.0) * q, rtol=1e-14)
    np.testing.assert_allclose(tri[0].T @ f[:, 1] / f[:, 1].sum(), tri[0].mean(axis=0), rtol=1e-14)
    line = np.array([[[1.0, 0.0, 0.0], [1.0, 3.0, 4.0]]])
    forces, moments = uniform_load.line_loads(line, q, np.array([True]))
    np.testing.assert_allclose(forces[0].sum(axis=0), 5.0 * q, rtol=1e-14)
    np.testing.assert_allclose(moments[0, 0], 5.0 / 12.0 * np.cross([0.0, 3.0, 4.0], q), rtol=1e-14)
    np.testing.assert_allclose(moments[0, 1], -moments[0, 0], rtol=1e-14)
    assert not uniform_load.line_loads(line, q, np.array([False]))[1].any()


def test_plane_strain_beam_takes_the_plate_modulus():
    """A 2D beam for a plate strip of unit width (tunnel lining) uses E' = E/(1 − ν²) in bending and
    extension: a tip load gives PL³/3E'I (ratio 1 − ν² to the plain beam) and N L/E'A; Timoshenko
    adds PL/(G As) with G = E/2(1 + ν) unchanged; under its own weight a simply supported strip sags
    5qL⁴/384E'I at mid-span (two-node beams with work-equivalent loads: nodally exact)."""
    t, P, N = 0.3, 1e-2, 5.0
    section = dc.Rectangle(1.0, t)
    Ep = E / (1 - NU**2)
    tm = polyline([[0.0, 0.0], [L, 0.0]], 4, line_name="beam")
    tips = {}
    for plane_strain in (False, True):
        for kinematics in ("bernoulli", "timoshenko"):
            sc = dc.Scene(large_rotations=False)
            b = sc.add_beam(tm, "beam", section=section, material=dc.Elastic(E, NU), kinematics=kinematics,
                            plane_strain=plane_strain)
            sc.fix(b, "base")
            sc.load(b, "tip", force=(N, -P))
            sc.monitor("tip", b, "tip")
            tips[plane_strain, kinematics] = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    bending = -P * L**3 / (3 * Ep * section.I)
    shear = -P * L / (E / (2 * (1 + NU)) * section.As)
    assert abs(tips[True, "bernoulli"]["tip_uy"] - bending) < 1e-10 * abs(bending)
    assert abs(tips[True, "timoshenko"]["tip_uy"] - bending - shear) < 1e-10 * abs(bending)
    assert abs(tips[True, "bernoulli"]["tip_ux"] - N * L / (Ep * section.A)) < 1e-10 * N * L / (E * section.A)
    ratio = tips[True, "bernoulli"]["tip_uy"] / tips[False, "bernoulli"]["tip_uy"]
    assert abs(ratio - (1 - NU**2)) < 1e-12

    rho, g = 2.4, 1.0
    tm = polyline([[0.0, 0.0], [L / 2, 0.0], [L, 0.0]], 3, line_name="lining",
                  point_names={0: "left", 1: "middle", 2: "right"})
    sc = dc.Scene(large_rotations=False)
    lining = sc.add_beam(tm, "lining", section=section, material=dc.Elastic(E, NU, density=rho), plane_strain=True)
    sc.fix(lining, "left", dofs=("ux", "uy"))
    sc.fix(lining, "right", dofs=("uy",))
    sc.gravity(lining, (0.0, -g))
    sc.monitor("middle", lining, "middle")
    sc.monitor_reaction("left", lining, "left")
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    q = rho * section.A * g
    exact = -5 * q * L**4 / (384 * Ep * section.I)
    assert abs(row["middle_uy"] - exact) < 1e-10 * abs(exact)
    assert abs(row["left_Fy"] - q * L / 2) < 1e-10 * q * L


@pytest.mark.parametrize("large", [False, True], ids=["linear", "co-rotational"])
def test_3d_beam_under_skew_gravity(large):
    """A 3D cantilever along x (depth h along y, width b along z) under gravity g = (0.3, −1, 0.5) g₀:
    tip u_x = q_x L²/2EA, u_y = q_y L⁴/8EI_z, u_z = q_z L⁴/8EI_y, rotations r_z = q_y L³/6EI_z,
    r_y = −q_z L³/6EI_y; root reaction −qL and moment −(L²/2) e_x × q, q = ρ A g (exact for the
    linear beam; measured ≤ 1e-14 of the largest value of each kind, bound 1e-11). Co-rotationally
    the second-order effects (the bent axis's shortening, stiffening by the axial tension, the
    torsion of skew bending) are small in g₀: at g₀ = 1e-4 measured ≤ 8.6e-7, bound 3e-6."""
    b_, h_, rho = 0.1, 0.2, 2.0
    g = np.array([0.3, -1.0, 0.5]) * (1e-4 if large else 1e-3)
    section = dc.Rectangle(b_, h_)
    pts = np.column_stack([np.linspace(0.0, L, 5), np.zeros(5), np.zeros(5)])
    tm = from_arrays(pts, np.column_stack([np.arange(4), np.arange(1, 5)]), "beam", {"base": [0], "tip": [4]})
    sc = dc.Scene(large_rotations=large)
    beam = sc.add_beam(tm, "beam", section=section, material=dc.Elastic(E, NU, density=rho), orientation=(0, 1, 0))
    sc.fix(beam, "base")
    sc.gravity(beam, g)
    sc.monitor("tip", beam, "tip")
    sc.monitor_reaction("root", beam, "base")
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    q = rho * section.A * g
    Iz, Iy = section.I, section.second_moment_y
    moment = -(L**2 / 2) * np.cross([1.0, 0.0, 0.0], q)
    expected = {"tip_ux": q[0] * L**2 / (2 * E * section.A), "tip_uy": q[1] * L**4 / (8 * E * Iz),
                "tip_uz": q[2] * L**4 / (8 * E * Iy), "tip_rz": q[1] * L**3 / (6 * E * Iz),
                "tip_ry": -q[2] * L**3 / (6 * E * Iy), "tip_rx": 0.0,
                "root_Fx": -q[0] * L, "root_Fy": -q[1] * L, "root_Fz": -q[2] * L,
                "root_Mx": moment[0], "root_My": moment[1], "root_Mz": moment[2]}
    tol = 3e-6 if large else 1e-11
    scale = {"u": np.abs([v for k, v in expected.items() if "_u" in k]).max(),
             "r": np.abs([v for k, v in expected.items() if "_r" in k]).max(),
             "F": np.linalg.norm(q) * L, "M": np.linalg.norm(q) * L**2}
    for key, value in expected.items():
        assert abs(row[key] - value) < tol * scale[key.split("_")[1][0]], (key, row[key], value)


def test_gravity_then_surcharge_with_amplitudes():
    """Self-weight applied first (amplitude 0 → 1 over λ ∈ [0, 1], then held), a tip load after
    (λ ∈ [1, 2]): the root reaction is qL at λ = 1 and qL + P at λ = 2."""
    rho, g, P = 2.0, 1e-3, 3e-5
    tm = polyline([[0.0, 0.0], [L, 0.0]], 4, line_name="beam")
    sc = dc.Scene(large_rotations=True)
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(B, H), material=dc.Elastic(E, NU, density=rho))
    sc.fix(b, "base")
    sc.gravity(b, (0.0, -g), amplitude=dc.Amplitude(((0.0, 0.0), (1.0, 1.0))))
    sc.load(b, "tip", force=(0.0, -P), amplitude=dc.Amplitude(((1.0, 0.0), (2.0, 1.0))))
    sc.monitor_reaction("root", b, "base")
    hist = dc.solve(sc, dc.LoadControl(steps=4, final=2.0)).history
    lam, Fy = np.array(hist.column("load_factor")), np.array(hist.column("root_Fy"))
    q = rho * A * g
    assert abs(Fy[np.isclose(lam, 1.0)][0] - q * L) < 1e-10 * q * L
    assert abs(Fy[np.isclose(lam, 2.0)][0] - q * L - P) < 1e-10 * q * L


def test_solid_takes_the_density_of_each_region():
    """Without a density argument a solid's gravity uses each cell's material: two blocks of
    densities ρ₁, ρ₂ give the reaction g (ρ₁V₁ + ρ₂V₂); the positional density argument keeps its
    meaning (ρ for every cell)."""
    from dolfinx_corot.io.mesh import rectangles
    tm = rectangles({"a": (0.0, 0.0, 1.0, 1.0, 2, 2), "b": (1.0, 0.0, 2.0, 1.0, 2, 2)},
                    {"bottom": [("a", "bottom"), ("b", "bottom")]}, comm=comm)
    rho1, rho2, g = 2.0, 3.0, 9.81
    expected = {None: g * (rho1 * 1.0 + rho2 * 2.0), 1.5: g * 1.5 * 3.0}
    for density, reaction in expected.items():
        sc = dc.Scene(large_rotations=False)
        s = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, NU, density=rho1), degree=1)
        sc.add_solid(tm, "b", material=dc.SaintVenantKirchhoff(E, NU, density=rho2), degree=1)
        sc.fix(s, "bottom")
        sc.gravity(s, (0.0, -g), density)
        sc.monitor_reaction("base", s, "bottom")
        row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
        assert abs(row["base_Fy"] - reaction) < 1e-10 * reaction


def test_gravity_on_a_region_of_a_solid_loads_that_region_only():
    """A part added with a region (``add_solid(mesh, "b", …)``) carries its own weight only:
    gravity on it gives the reaction ρ₂ g V₂ (V₂ = 2), not the weight of every cell of the mesh;
    ``where`` still names any group of cells."""
    from dolfinx_corot.io.mesh import rectangles
    tm = rectangles({"a": (0.0, 0.0, 1.0, 1.0, 2, 2), "b": (1.0, 0.0, 2.0, 1.0, 2, 2)},
                    {"bottom": [("a", "bottom"), ("b", "bottom")]}, comm=comm)
    rho1, rho2, g = 2.0, 3.0, 9.81
    for where, reaction in ((None, g * rho2 * 2.0), ("a", g * rho1 * 1.0)):
        sc = dc.Scene(large_rotations=False)
        s = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, NU, density=rho1), degree=1)
        b = sc.add_solid(tm, "b", material=dc.SaintVenantKirchhoff(E, NU, density=rho2), degree=1)
        sc.fix(s, "bottom")
        sc.gravity(b, (0.0, -g), where=where)
        sc.monitor_reaction("base", s, "bottom")
        row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
        assert abs(row["base_Fy"] - reaction) < 1e-10 * reaction, (where, row["base_Fy"])


def test_density_leaves_the_scene_description_unchanged():
    """Density and gravity are loads, not part of what defines the model: the scene's description
    (the fingerprint of its checkpoints) is the same with and without them; plane strain changes
    the beam's stiffness and so its description."""
    tm = polyline([[0.0, 0.0], [L, 0.0]], 2, line_name="beam")

    def describe(density, gravity, plane_strain=False):
        sc = dc.Scene()
        b = sc.add_beam(tm, "beam", section=dc.Rectangle(B, H), material=dc.Elastic(E, NU, density=density),
                        plane_strain=plane_strain)
        if gravity:
            sc.gravity(b, (0.0, -1.0))
        return sc.describe()

    assert describe(None, False) == describe(2.0, True)
    assert describe(None, False) != describe(None, False, plane_strain=True)


# -- bad input ------------------------------------------------------------------------------
@pytest.mark.parametrize("density", [-1.0, float("nan"), float("inf"), True, "2"])
def test_bad_density_is_refused_naming_the_material(density):
    with pytest.raises(ValueError, match=r"Elastic\(E=100000.0, nu=0.3\): density = .* must be a finite number"):
        dc.Elastic(E, NU, density=density)
    with pytest.raises(ValueError, match=r"SaintVenantKirchhoff\(E=100000.0, nu=0.3\): density"):
        dc.SaintVenantKirchhoff(E, NU, density=density)


def test_gravity_without_density_is_refused_naming_the_part():
    tm = polyline([[0.0, 0.0], [L, 0.0]], 2, line_name="beam")
    sc = dc.Scene()
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(B, H), material=dc.Elastic(E, NU))
    with pytest.raises(ValueError, match="gravity on beam 'beam': its material has no density"):
        sc.gravity(b, (0.0, -1.0))
    with pytest.raises(ValueError, match=r"gravity on beam 'beam': density = -2.0 must be a finite number ≥ 0"):
        sc.gravity(b, (0.0, -1.0), -2.0)
    with pytest.raises(ValueError, match="gravity on beam 'beam': acceleration must be 2 finite numbers"):
        sc.gravity(b, (0.0, 0.0, -1.0), 1.0)
    with pytest.raises(ValueError, match="physical group 'tip' has dimension 0"):
        sc.gravity(b, (0.0, -1.0), 1.0, where="tip")
    plate = dc.Scene().add_shell(_plate_mesh(2, 2, 1.0, 1.0, True), "plate", thickness=0.1, material=dc.Elastic(E))
    with pytest.raises(ValueError, match="gravity on shell 'plate': its material has no density"):
        plate.model.add_gravity(plate, np.array([0.0, 0.0, -1.0]), None, None)
    tm2 = from_arrays(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), np.array([[0, 1, 2]]), "block")
    sc = dc.Scene()
    s = sc.add_solid(tm2, material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    with pytest.raises(ValueError, match="solid 'all cells' has no density"):
        sc.gravity(s, (0.0, -1.0))


def test_gravity_on_a_group_without_the_parts_elements_is_refused():
    tm = polyline([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], 2, line_name="frame")
    tm.add_cell_group("left_half", lambda x: x[0] < 1.0)
    tm.add_cell_group("right_half", lambda x: x[0] > 1.0)
    sc = dc.Scene()
    left = sc.add_beam(tm, "left_half", section=dc.Rectangle(B, H), material=dc.Elastic(E, NU, density=1.0))
    with pytest.raises(ValueError, match="gravity on beam 'left_half': group 'right_half' holds none of its"):
        sc.gravity(left, (0.0, -1.0), where="right_half")


def test_plane_strain_beam_in_3d_is_refused():
    tm = from_arrays(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), np.array([[0, 1]]), "beam")
    with pytest.raises(ValueError, match="beam 'beam': plane_strain is for 2D beams"):
        dc.Scene().add_beam(tm, "beam", section=dc.Rectangle(B, H), material=dc.Elastic(E, NU), plane_strain=True)

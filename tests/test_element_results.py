"""Element results in engineering terms (seed §1: stresses and strains in the rotated element
frame): section forces of beams, stress resultants of shells and membranes, stresses and strains of
solids, as values, monitor columns and field output.

References:
- a cantilever rolled up by an end moment M carries M, and nothing else, in every section at
  every turn (equilibrium of the free part beyond the section: exact, whatever the mesh);
- a cantilever under a dead tip force P has M(s) = −P (x_tip − x(s)) in its deformed geometry and
  V, N the components of P on the section's axes (equilibrium, exact); the tip position and the
  root moment against the elastica (Mattiasson 1981, Table 1, k = PL²/EI = 2, and the
  collocation of :func:`dolfinx_corot.closed_forms.cantilever_tip_load`);
- a shell strip bent by an end moment M over its width b carries Mxx = M/b in every element;
- a membrane and a solid bar in uniaxial states: the exact homogeneous stresses and strains.
"""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.closed_forms import cantilever_tip_load
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import box, from_arrays, rectangles

comm = MPI.COMM_WORLD
L, E, B, H = 1.0, 1e4, 0.1, 0.1
EI = E * B * H**3 / 12


def _cantilever(n: int, gdim: int, large_rotations: bool = True):
    end = [L, 0.0] if gdim == 2 else [L, 0.0, 0.0]
    tm = polyline([[0.0] * gdim, end], n, line_name="beam", gdim=gdim, comm=comm)
    sc = dc.Scene(large_rotations=large_rotations)
    beam = sc.add_beam(tm, "beam", section=dc.Rectangle(B, H), material=dc.Elastic(E, 0.0))
    sc.fix(beam, "base")
    return sc, beam


# -- beams ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("gdim", [2, 3])
def test_a_rolled_up_cantilever_carries_the_end_moment_in_every_section(gdim):
    """M = 2πEI/L rolls the cantilever once, 4πEI/L twice: at the end of each turn every element end
    carries M (measured 1e-13 relative), N and V vanish (1e-10 M/L); in 3D (a beam along x: the
    section's y axis e2 is the global z, its z axis e3 = e1 × e2) the moment about global z is My,
    T and Mz vanish. The monitor columns agree."""
    sc, beam = _cantilever(12, gdim)
    turns = 2.0
    M = 2 * np.pi * EI / L
    sc.load(beam, "tip", moment=turns * M if gdim == 2 else (0.0, 0.0, turns * M))
    sc.monitor_results("tip", beam, "tip")
    sc.monitor_results("all", beam, None, reduce="absmax")
    seen = []

    def check(row):
        if abs(row["load_factor"] * turns - round(row["load_factor"] * turns)) < 1e-9:
            r = sc.element_results(beam)
            seen.append(row["load_factor"])
            applied = row["load_factor"] * turns * M
            bending = r["M"] if gdim == 2 else r["My"]
            assert len(r) == 12 and r.values.shape == (12, 2, len(r.components))
            np.testing.assert_allclose(bending, applied, rtol=1e-9)
            forces = ("N", "V") if gdim == 2 else ("N", "Vy", "Vz")
            for c in forces:
                assert np.abs(r[c]).max() < 1e-10 * M / L, c
            if gdim == 3:
                for c in ("T", "Mz"):
                    assert np.abs(r[c]).max() < 1e-10 * M, c
            name = "M" if gdim == 2 else "My"
            assert row[f"tip_{name}"] == pytest.approx(applied, rel=1e-9)
            assert row[f"all_{name}_absmax"] == pytest.approx(applied, rel=1e-9)

    # the dead moment of a 3D beam loses definiteness on the way (see the demo rollup_3d): go on
    dc.solve(sc, dc.LoadControl(steps=8, at_critical_point="continue"), on_step=check, quiet=True)
    assert seen == pytest.approx([0.5, 1.0])


@pytest.mark.parametrize("gdim", [2, 3])
def test_a_cantilever_under_a_tip_force_has_the_moment_of_the_force_in_the_deformed_geometry(gdim):
    """k = PL²/EI = 2 (tip rotation 45°): at every node M = −P (x_tip − x) with the computed
    positions, and V, N are the components of the tip force on the elements' axes (equilibrium:
    1e-9 PL); the tip moves as the elastica (Mattiasson 1981: (L − x_tip, −y_tip)/L = (0.16064,
    0.49346)) and the root moment is P x_tip of the elastica, within 0.5 % on 16 elements
    (measured 0.03 % and 0.06 %)."""
    k = 2.0
    P = k * EI / L**2
    ref = cantilever_tip_load(k)
    assert (1.0 - ref["x_tip"], -ref["y_tip"]) == pytest.approx((0.16064, 0.49346), abs=1e-5)
    sc, beam = _cantilever(16, gdim)
    sc.load(beam, "tip", force=(0.0, -P) if gdim == 2 else (0.0, -P, 0.0))
    sc.monitor("tip", beam, "tip")
    sc.monitor_results("root", beam, "base")
    res = dc.solve(sc, dc.LoadControl(steps=6), quiet=True)
    row = res.history.rows[-1]
    r = sc.element_results(beam)
    x_tip = L + row["tip_ux"]
    bending = r["M"] if gdim == 2 else r["My"]  # 3D: about e2 = global z
    np.testing.assert_allclose(bending, -P * (x_tip - r.points[:, :, 0]), atol=1e-9 * P * L)
    force = np.zeros(gdim)
    force[1] = -P
    e1, normal = r.axes[:, 0], r.axes[:, 1 if gdim == 2 else 2]
    shear = "V" if gdim == 2 else "Vz"  # 3D: along e3, in the plane of bending
    for end in range(2):
        np.testing.assert_allclose(r["N"][:, end], e1 @ force, atol=1e-9 * P)
        np.testing.assert_allclose(r[shear][:, end], normal @ force, atol=1e-9 * P)
    assert x_tip == pytest.approx(ref["x_tip"] * L, rel=5e-3)
    assert row["tip_uy"] == pytest.approx(ref["y_tip"] * L, rel=5e-3)
    root = row["root_M" if gdim == 2 else "root_My"]
    assert root == pytest.approx(-P * L * ref["x_tip"], rel=5e-3)
    assert root == pytest.approx(-P * x_tip, rel=1e-9)


def test_linear_beams_report_their_forces_in_the_initial_axes():
    """With large_rotations=False the section forces are those of linear beam theory in the
    initial axes: a tip force P on a cantilever gives V = −P and M = −P(L − x) exactly."""
    P = 1.0
    sc, beam = _cantilever(4, 2, large_rotations=False)
    sc.load(beam, "tip", force=(0.0, -P))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    r = sc.element_results(beam)
    np.testing.assert_allclose(r.axes[:, 0], [[1.0, 0.0]] * 4, atol=1e-15)
    np.testing.assert_allclose(r["M"], -P * (L - r.points[:, :, 0]), atol=1e-12)
    np.testing.assert_allclose(r["V"], -P, atol=1e-12)
    np.testing.assert_allclose(r["N"], 0.0, atol=1e-12)


@pytest.mark.parametrize("gdim", [2, 3])
def test_a_cantilever_under_a_uniform_load_has_the_moments_of_the_load(gdim):
    """A uniform dead load q per length: linear beams report M = −q(L − x)²/2 and V = −q(L − x) at
    every node (3D: My and Vz = +q(L − x), dMy/ds = Vz), exactly (the span's fixed-end forces taken off its ends: 1e-10 qL²); at large
    deflection (qL³/EI = 10) the end moments are the load's moments in the deformed geometry and
    the root moment that of the elastica (:func:`~dolfinx_corot.closed_forms.cantilever_uniform_load`,
    within 0.5 % on 20 elements, measured 0.1 %)."""
    from dolfinx_corot.closed_forms import cantilever_uniform_load

    q = 0.7
    load = (0.0, -q) if gdim == 2 else (0.0, -q, 0.0)
    bending = "M" if gdim == 2 else "My"
    shear = "V" if gdim == 2 else "Vz"
    sc, beam = _cantilever(5, gdim, large_rotations=False)
    sc.load(beam, None, per_length=load)
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    r = sc.element_results(beam)
    x = r.points[:, :, 0]
    np.testing.assert_allclose(r[bending], -q * (L - x) ** 2 / 2, atol=1e-10 * q * L**2)
    np.testing.assert_allclose(r[shear] * (-1 if gdim == 2 else 1), q * (L - x), atol=1e-10 * q * L)

    k = 10.0
    q = k * EI / L**3
    sc, beam = _cantilever(20, gdim)
    sc.load(beam, None, per_length=(0.0, -q) if gdim == 2 else (0.0, -q, 0.0))
    sc.monitor_results("root", beam, "base")
    res = dc.solve(sc, dc.LoadControl(steps=10), quiet=True)
    r = sc.element_results(beam)
    ref = cantilever_uniform_load(k)
    assert res.history.rows[-1][f"root_{bending}"] == pytest.approx(q * L**2 * ref["moment"][0], rel=5e-3)
    # each node: the moment of the dead load beyond it, q per reference length on the elements beyond
    # (lumped as the kernels apply it: half an element's load at each of its nodes, with its end moments)
    ends = r.points[:, 1, 0]
    x_nodes = np.concatenate([r.points[:1, 0, 0], ends])
    h = L / 20
    for i, xi in enumerate(x_nodes[:-1]):
        beyond = x_nodes[i:]
        weights = np.full(len(beyond), h)
        weights[0] = weights[-1] = h / 2
        # the exact moment of the load beyond is ∫ q (x(σ) − x) dσ: the trapezoidal rule of the nodes,
        # plus the end moments of the lumping (q h²/12 · cos θ of the first element): within q h² / 10
        assert -r[bending][i, 0] == pytest.approx(q * np.sum(weights * (beyond - xi)), abs=0.1 * q * h * h)


# -- shells and membranes -----------------------------------------------------------------------------------
def _strip(nx: int, width: float, quads: bool = False):
    """A strip [0, L] × [0, width] in z = 0 of nx × 1 cells (triangles or quadrilaterals) with the
    point groups 'clamp' (x = 0) and 'tip' (x = L)."""
    x = np.linspace(0.0, L, nx + 1)
    points = np.array([[xi, yj, 0.0] for yj in (0.0, width) for xi in x])
    n = nx + 1
    if quads:
        cells = np.array([[i, i + 1, n + i + 1, n + i] for i in range(nx)])
    else:
        cells = np.array([c for i in range(nx) for c in ([i, i + 1, n + i + 1], [i, n + i + 1, n + i])])
    groups = {"clamp": np.array([0, n]), "tip": np.array([nx, n + nx]), "nodes": np.arange(2 * n)}
    return from_arrays(points, cells, "strip", groups, comm=comm)


def test_a_shell_strip_under_an_end_moment_carries_the_moment_per_width():
    """M = πEI/L over the width b bends a strip (ν = 0) into a half circle towards its normal e3 (+z
    at the start): every triangle carries the moment −M/b (M = ∫σ z dz: the top face, on the e3 side,
    in compression) about the strip's width and nothing else, whichever side of the triangle its
    axis e1 follows (within 0.5 %, measured 1e-4: the moment of the co-rotated DKT's curvature);
    top and bottom stresses ∓6M/(bt²); membrane forces and transverse shears vanish."""
    t, b = H, B
    sc = dc.Scene(large_rotations=True)
    strip = sc.add_shell(_strip(16, b), "strip", thickness=t, material=dc.Elastic(E, 0.0))
    sc.fix(strip, "clamp")
    M = np.pi * E * b * t**3 / 12 / L
    sc.load(strip, "tip", moment=(0.0, -M / 2, 0.0))  # two nodes, half each: bends the strip towards +z
    sc.monitor_results("strip", strip, None, reduce="absmax", components=("Mxx", "mises_top"))
    res = dc.solve(sc, dc.LoadControl(steps=8, at_critical_point="continue"), quiet=True)
    r = sc.element_results(strip)
    assert r.kind == "shell resultants" and r.values.shape == (32, 1, 16)
    # e1 of each triangle is along its side 1–2: the strip's axis or a diagonal; the moment
    # tensor's invariants do not depend on that: trace −M/b (+ 0, ν = 0), determinant 0
    Mxx, Myy, Mxy = r["Mxx"][:, 0], r["Myy"][:, 0], r["Mxy"][:, 0]
    np.testing.assert_allclose(Mxx + Myy, -M / b, rtol=5e-3)
    det = Mxx * Myy - Mxy**2
    np.testing.assert_allclose(det, 0.0, atol=5e-3 * (M / b) ** 2)  # uniaxial bending
    # the shears are the moments' gradients: 0.5 % of M/b across a cell of L/16 (measured 4e-3 M/(bL))
    np.testing.assert_allclose(r["Qx"], 0.0, atol=0.08 * M / b / L)
    np.testing.assert_allclose(r["Qy"], 0.0, atol=0.08 * M / b / L)
    for c in ("Nxx", "Nyy", "Nxy"):  # membrane stress below 0.2 % of the bending stress (measured 0.09 %)
        assert np.abs(r[c]).max() / t < 2e-3 * 6 * M / b / t**2, c
    np.testing.assert_allclose((r["sxx_top"] + r["syy_top"])[:, 0], -6 * M / b / t**2, rtol=5e-3)
    np.testing.assert_allclose((r["sxx_bottom"] + r["syy_bottom"])[:, 0], 6 * M / b / t**2, rtol=5e-3)
    np.testing.assert_allclose(r["mises_top"], 6 * M / b / t**2, rtol=5e-3)  # uniaxial: |σ|
    np.testing.assert_allclose(r["mises_bottom"], 6 * M / b / t**2, rtol=5e-3)
    assert res.history.rows[-1]["strip_Mxx_absmax"] == pytest.approx(np.abs(Mxx).max() * np.sign(Mxx[np.argmax(np.abs(Mxx))]))


@pytest.mark.parametrize("quads", [False, True], ids=["triangles", "quadrilaterals"])
def test_a_stretched_membrane_carries_the_engineering_stress_of_its_stretch(quads):
    """A membrane strip (ν = 0, flat, held across its plane) pulled by ε: every element carries
    N = E t ε along the strip and nothing across it (the invariants of N: trace E t ε, determinant 0),
    the stress N/t on both faces, no moments or shears. The quadrilaterals' frame between the
    diagonals does not turn in a stretch: exact at ε = 30 % (1e-9). A triangle whose axis e1 is its
    diagonal sees the stretch as a stretch and a turn of that axis, measured by the element's small
    strain: the turn δφ ~ ε/2 errs by δφ²/2, N within O(ε) relative (ε = 1 %: 0.5 %; measured
    0.25 %; the quadrilaterals' frame is the better one in large membrane strain)."""
    t = 0.01
    stretch, rtol = (0.3, 1e-9) if quads else (0.01, 5e-3)
    sc = dc.Scene(large_rotations=True)
    skin = sc.add_membrane(_strip(6, B, quads), "strip", thickness=t, material=dc.Elastic(E, 0.0))
    sc.fix(skin, "clamp")
    sc.fix(skin, "nodes", dofs=("uz",))  # a flat membrane has no stiffness across its plane
    sc.prescribe(skin, "tip", ux=stretch * L, uy=0.0, uz=0.0)
    dc.solve(sc, dc.LoadControl(steps=2), quiet=True)
    r = sc.element_results(skin)
    N = np.stack([r["Nxx"][:, 0], r["Nyy"][:, 0], r["Nxy"][:, 0]], axis=1)
    np.testing.assert_allclose(N[:, 0] + N[:, 1], E * t * stretch, rtol=rtol)
    np.testing.assert_allclose(N[:, 0] * N[:, 1] - N[:, 2] ** 2, 0.0, atol=rtol * (E * t * stretch) ** 2)
    np.testing.assert_allclose(r["sxx_top"], r["Nxx"] / t, rtol=1e-12)
    np.testing.assert_allclose(r["mises_bottom"], r["mises_top"], rtol=1e-12)
    for c in ("Mxx", "Myy", "Mxy", "Qx", "Qy"):
        assert np.abs(r[c]).max() == 0.0


# -- solids ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("large_rotations", [True, False], ids=["finite", "linear"])
def test_a_solid_bar_in_uniaxial_stretch_has_the_exact_cauchy_stress(large_rotations):
    """A plane-strain St Venant–Kirchhoff bar (ν = 0.3) stretched by 20 % with free sides: the lateral
    stretch t solves S_yy = 0; then E_xx = (s² − 1)/2, σ_xx = s S_xx / t, σ_zz = λ tr E / (s t) (F_zz
    = 1), von Mises from σ (exact for any mesh: 1e-9). Small strain: σ_xx = E' ε with the plane-strain
    modulus, σ_yy = 0."""
    nu, s = 0.3, 1.2
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    tm = rectangles({"bar": (0.0, 0.0, 2.0, 1.0, 4, 2)},
                    {"left": [("bar", "left")], "bottom": [("bar", "bottom")], "right": [("bar", "right")]},
                    comm=comm, quads=False)
    sc = dc.Scene(large_rotations=large_rotations)
    bar = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, nu) if large_rotations else dc.Elastic(E, nu))
    sc.fix(bar, "left", dofs=("ux",))
    sc.fix(bar, "bottom", dofs=("uy",))
    sc.prescribe(bar, "right", ux=2.0 * (s - 1))
    sc.monitor_results("bar", bar, None, reduce="mean", components=("sxx", "mises"))
    res = dc.solve(sc, dc.LoadControl(steps=2), quiet=True)
    r = sc.element_results(bar)
    if large_rotations:
        Exx = 0.5 * (s * s - 1)
        Eyy = -lam * Exx / (lam + 2 * mu)          # S_yy = λ(Exx + Eyy) + 2μ Eyy = 0
        t = np.sqrt(1 + 2 * Eyy)
        Sxx = lam * (Exx + Eyy) + 2 * mu * Exx
        sxx, szz = s * Sxx / t, lam * (Exx + Eyy) / (s * t)
        strains = {"Exx": Exx, "Eyy": Eyy, "Exy": 0.0}
    else:
        eps = s - 1
        eyy = -lam * eps / (lam + 2 * mu)
        sxx, szz = lam * (eps + eyy) + 2 * mu * eps, lam * (eps + eyy)
        strains = {"Exx": eps, "Eyy": eyy, "Exy": 0.0}
    mises = np.sqrt(0.5 * ((sxx - szz) ** 2 + szz**2 + sxx**2))
    exact = {"sxx": sxx, "syy": 0.0, "sxy": 0.0, "szz": szz, "mises": mises, **strains}
    for c, v in exact.items():
        np.testing.assert_allclose(r[c], v, atol=1e-9 * (abs(sxx) if c[0] in "sm" else strains["Exx"]),
                                   err_msg=c)
    row = res.history.rows[-1]
    assert row["bar_sxx_mean"] == pytest.approx(sxx, rel=1e-9)
    assert row["bar_mises_mean"] == pytest.approx(mises, rel=1e-9)
    assert r.points.shape == (len(r), 1, 2) and r.axes is None
    assert r.points[:, 0, 0].max() <= 2.0 * s + 1e-12  # current centres
    assert r.points[:, 0, 0].max() > 2.0


def test_a_3d_bar_in_uniaxial_stretch_has_the_exact_cauchy_stress():
    """A neo-Hookean hexahedral bar (ν = 0) stretched by 25 %: F = diag(s, 1, 1), σ_xx = (μ(s² − 1)
    + λ ln s)/s, σ_yy = σ_zz = λ ln s / s, E_xx = (s² − 1)/2 (exact, 1e-9)."""
    nu, s = 0.25, 1.25
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    tm = box((2.0, 1.0, 1.0), (3, 2, 2), comm=comm)
    sc = dc.Scene()
    bar = sc.add_solid(tm, material=dc.NeoHookean(E, nu))
    for face, dof in (("x0", "ux"), ("y0", "uy"), ("z0", "uz"), ("y1", "uy"), ("z1", "uz")):
        sc.fix(bar, face, dofs=(dof,))
    sc.prescribe(bar, "x1", ux=2.0 * (s - 1))
    dc.solve(sc, dc.LoadControl(steps=2), quiet=True)
    r = sc.element_results(bar)
    sxx = (mu * (s * s - 1) + lam * np.log(s)) / s
    slat = lam * np.log(s) / s
    exact = {"sxx": sxx, "syy": slat, "szz": slat, "sxy": 0.0, "syz": 0.0, "sxz": 0.0,
             "mises": abs(sxx - slat), "Exx": 0.5 * (s * s - 1), "Eyy": 0.0, "Ezz": 0.0}
    for c, v in exact.items():
        np.testing.assert_allclose(r[c], v, atol=1e-9 * (sxx if c[0] in "sm" else s - 1), err_msg=c)
    assert len(r) == 12 and r.points.shape == (12, 1, 3)


# -- what is refused ----------------------------------------------------------------------------------------
def test_element_results_refuse_what_they_cannot_give():
    sc, beam = _cantilever(4, 2)
    with pytest.raises(ValueError, match="no component.*'Mz'"):
        sc.monitor_results("m", beam, None, reduce="max", components="Mz")
    with pytest.raises(ValueError, match="reduce="):
        sc.monitor_results("m", beam, "beam")
    with pytest.raises(ValueError, match="group of one node"):
        sc.monitor_results("m", beam, "base", reduce="max")
    with pytest.raises(KeyError, match="nowhere"):
        sc.monitor_results("m", beam, "nowhere", reduce="max")
    r = sc.element_results(beam)
    with pytest.raises(KeyError, match="have no component 'Mz'"):
        r["Mz"]
    with pytest.raises(ValueError, match="no element point"):
        r.at((5.0, 5.0))
    from matplotlib.figure import Figure

    ax = Figure().subplots()
    with pytest.raises(ValueError, match="section forces have no component 'Mz'"):
        dc.plot.diagram(ax, r, "Mz")
    with pytest.raises(ValueError, match="diagrams are drawn for the section forces of beams"):
        dc.plot.diagram(ax, r.__class__("stresses", ("sxx",), [], np.zeros((0, 1, 2)), np.zeros((0, 1, 1))), "sxx")

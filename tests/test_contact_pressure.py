"""The interface pressure of a contact pair: both passes of two-pass contact combined, on the actual
contact faces (a beam's face at half its depth), and its resultant — against hand calculations."""
import gmsh
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.mesh import rectangles

comm = MPI.COMM_WORLD
E, NU, P = 1.0, 0.3, 0.01  # the patch test of test_contact.py (B5_contact_patch_test.json)
EXACT = dc.AugmentedLagrangian(gap_tolerance=1e-12, factor=1e4)  # gaps closed to round-off


def _blocks(n_low, n_up):
    """Unit blocks [0,1]² and [0,1]×[1,2], n_low and n_up quadrilaterals along x (non-matching
    interface y = 1), on rollers, pressed by a uniform traction P on the top."""
    tm = rectangles({"lower": (0.0, 0.0, 1.0, 1.0, n_low, 3), "upper": (0.0, 1.0, 1.0, 1.0, n_up, 3)},
                    {"base": [("lower", "bottom")], "lower_top": [("lower", "top")],
                     "upper_bottom": [("upper", "bottom")], "top": [("upper", "top")],
                     "left": [("lower", "left"), ("upper", "left")]}, comm=comm)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    sc.fix(b, "base", dofs=("uy",))
    sc.fix(b, "left", dofs=("ux",))
    sc.load(b, "top", traction=(0.0, -P))
    return sc, b


@pytest.mark.parametrize("n_low,n_up", [(3, 4), (5, 7)])
def test_two_pass_pressure_of_two_blocks_is_the_applied_stress(n_low, n_up):
    """Two equal blocks pressed together by a uniform stress P, two-pass contact on straight
    segments (augmented Lagrangian, gaps closed): the state is homogeneous (the two-pass patch
    test), so the contact forces at each interface node are the consistent loads P·L_i of the
    uniform stress. Hand calculation: the combined pressure is P at every node of either side, the
    resultant on the upper block (0, P·1), on the lower one its opposite, Σ p L = P. Each pass
    alone carries only a share that varies from node to node (measured 0.34 … 0.70 P on the
    slave nodes of the first pass): what Interface.pressure reported as the pressure."""
    sc, b = _blocks(n_low, n_up)
    pair = sc.contact(slaves=(b, "upper_bottom"), masters=(b, "lower_top"), law=EXACT, symmetric=True,
                      smooth=False)
    assert isinstance(pair, dc.ContactPair) and len(pair) == 2
    sc.monitor_contact("interface", pair)
    res = dc.solve(sc, dc.LoadControl(steps=1))
    upper, lower = pair.pressure("slaves"), pair.pressure("masters")
    # measured: |p/P − 1| ≤ 1.4e-9, |Σ p L / P − 1| ≤ 2e-10, |R_x| ≤ 1e-15 P: the Newton tolerance
    # (residual below 1e-9 of the load; the residual's round-off floor with this stiff penalty is
    # 3e-10 of it); bounds 5 × that
    for side in (upper, lower):
        assert np.abs(side.pressure / P - 1.0).max() < 7e-9, side.pressure / P
        assert abs(side.length.sum() - 1.0) < 1e-14 and abs(side.normal_force / P - 1.0) < 1e-9
    np.testing.assert_allclose(upper.resultant, [0.0, P], rtol=0, atol=1e-9 * P)
    np.testing.assert_allclose(lower.resultant, [0.0, -P], rtol=0, atol=1e-9 * P)
    row = res.history.rows[-1]
    assert abs(row["interface_Fy"] / P - 1.0) < 1e-9 and abs(row["interface_Fx"]) < 1e-12 * P
    assert abs(row["interface_N"] / P - 1.0) < 1e-9 and abs(row["interface_pmax"] / P - 1.0) < 7e-9
    # one pass alone (the slave pressure of each interface): a share, nowhere the whole stress
    for itf in pair:
        share = itf.pressure()[1]
        assert share.max() < 0.8 * P, share / P


def test_true_pressure_is_per_current_face_length():
    """``current=True`` divides the same forces by the current face lengths: the blocks expand
    sideways (rollers on one side only), so the true pressure is P / (1 + ε_xx) with ε_xx the
    lateral stretch, read off the interface's current length."""
    sc, b = _blocks(3, 4)
    pair = sc.contact(slaves=(b, "upper_bottom"), masters=(b, "lower_top"), law=EXACT, symmetric=True,
                      smooth=False)
    dc.solve(sc, dc.LoadControl(steps=1))
    true = pair.pressure("slaves", current=True)
    stretch = true.length.sum()  # the interface's current length (reference 1)
    assert stretch > 1.0 + 1e-3  # the blocks expand sideways
    assert np.abs(true.pressure * stretch / P - 1.0).max() < 7e-9
    assert np.allclose(true.x[:, 1], true.x[0, 1]) and true.x[:, 0].max() > 1.0


def _beam_on_block(n_beam, n_soil, depth, q, flip=False):
    """A beam (depth ``depth``, n_beam elements) lying on a soil block 4 wide and 1 deep (n_soil × 4
    quadrilaterals) over its whole width, its lower face on the soil's top y = 0; the block on
    rollers (base and sides), the beam held horizontally at its left end; a uniform load q on the
    beam (lumped: q·l at inner nodes, q·l/2 at the ends). Two-pass contact on straight segments."""
    width = 4.0
    soil_mesh = rectangles({"soil": (0.0, -1.0, width, 1.0, n_soil, 4)},
                           {"base": [("soil", "bottom")], "top": [("soil", "top")],
                            "sides": [("soil", "left"), ("soil", "right")]}, comm=comm)
    xb = np.linspace(0.0, width, n_beam + 1)
    cells = np.column_stack([np.arange(n_beam), np.arange(1, n_beam + 1)])
    if flip:
        cells[::2] = cells[::2, ::-1]
    beam_mesh = dc.io.mesh.from_arrays(np.column_stack([xb, np.full_like(xb, depth / 2)]), cells, "beam",
                                       point_groups={"ends": np.array([0, n_beam]), "inner": np.arange(1, n_beam),
                                                     "left": np.array([0])}, comm=comm)
    sc = dc.Scene()
    soil = sc.add_solid(soil_mesh, material=dc.SaintVenantKirchhoff(100.0, 0.3), degree=1)
    beam = sc.add_beam(beam_mesh, section=dc.Rectangle(1.0, depth), material=dc.Elastic(1.0e4, 0.3))
    sc.fix(soil, "base", dofs=("uy",))
    sc.fix(soil, "sides", dofs=("ux",))
    sc.fix(beam, "left", dofs=("ux",))
    length = width / n_beam
    sc.load(beam, "inner", force=(0.0, -q * length))
    sc.load(beam, "ends", force=(0.0, -q * length / 2))
    sc.monitor_reaction("base", soil, "base")
    pair = sc.contact(slaves=(beam, "beam"), masters=(soil, "top"), law=EXACT, symmetric=True, smooth=False)
    return sc, pair, width


@pytest.mark.parametrize("n_beam,flip", [(12, False), (9, True)], ids=["12", "9-flipped"])
def test_beam_on_a_block_under_uniform_load(n_beam, flip):
    """A beam of depth 0.2 lying on a confined soil block under a uniform load q: the soil is
    compressed homogeneously and the beam sinks without bending. Hand calculation: the pressure on
    the beam's lower face (half its depth below the axis, y = 0) is q at every node, and pressure ×
    face length is the load, Σ p L = q · 4; likewise on the soil's top (measured: the nodal
    pressures to 1.5e-8 and Σ p L to 1.3e-10, the Newton tolerance; bounds 5 ×). Each pass alone
    carries a share (measured 0 … 0.89 q). The face is found whichever way the beam's elements run."""
    q = 0.5
    sc, pair, width = _beam_on_block(n_beam, 16, 0.2, q, flip)
    res = dc.solve(sc, dc.LoadControl(steps=1))
    beam_face, soil_top = pair.pressure("slaves"), pair.pressure("masters")
    assert np.allclose(beam_face.x[:, 1], 0.0, atol=1e-14)  # the face, not the axis (y = 0.1)
    for side in (beam_face, soil_top):
        assert np.abs(side.pressure / q - 1.0).max() < 7e-8, side.pressure / q
        assert abs(side.normal_force - q * width) < 1e-9 * q * width
        assert abs(side.length.sum() - width) < 1e-13
    np.testing.assert_allclose(beam_face.resultant, [0.0, q * width], rtol=0, atol=1e-9 * q * width)
    assert abs(res.history.column("base_Fy")[-1] - q * width) < 1e-9 * q * width
    assert max(itf.pressure()[1].max() for itf in pair) < 0.95 * q  # one pass: a share


def _soil_with_hole(radius, segments, half_width):
    """A square soil block [−w, w]² (groups 'soil', 'outer') with a circular hole of ``radius`` at the
    origin whose boundary 'cavity' has ``segments`` equal segments."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        c = g.addPoint(0.0, 0.0, 0.0)
        q = [g.addPoint(radius * np.cos(a), radius * np.sin(a), 0.0) for a in np.pi / 2 * np.arange(4)]
        arcs = [g.addCircleArc(q[i], c, q[(i + 1) % 4]) for i in range(4)]
        w = half_width
        p = [g.addPoint(x, y, 0.0) for x, y in ((-w, -w), (w, -w), (w, w), (-w, w))]
        lines = [g.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
        s = g.addPlaneSurface([g.addCurveLoop(lines), g.addCurveLoop(arcs)])
        for a in arcs:
            g.mesh.setTransfiniteCurve(a, segments // 4 + 1)
        g.synchronize()
        for dim, tags, name in ((2, [s], "soil"), (1, lines, "outer"), (1, arcs, "cavity")):
            gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(2)
    tm = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _lame_hole_compliance(b, c, E_s, nu):
    """u(b)/p: radial displacement of a hole of radius b in a thick cylinder of outer radius c,
    fixed there, under a pressure p in the hole (plane strain; Timoshenko & Goodier §33)."""
    lam, mu = E_s * nu / ((1 + nu) * (1 - 2 * nu)), E_s / (2 * (1 + nu))
    B = 1.0 / (2 * (lam + mu) / c**2 + 2 * mu / b**2)
    return B * (1.0 / b - b / c**2)


def test_a_lining_presses_with_its_outer_face():
    """A ring (beam, axis radius R = 1, depth h = 0.2, 32 elements) in a circular hole of radius
    R + h/2 in a soil block 6 × 6 (fixed outside; 48 hole segments), loaded by equal radial forces
    f at its nodes (two-pass contact, smooth master curves). Hand calculation: each node balances
    f = c + 2 N sin(π/n) (c its contact force, N the hoop force EA·u/R), and the contact acts on
    the ring's outer face of radius R + h/2, whose length per node is 2(R + h/2) sin(π/n): with
    f = P·2(R + h/2) sin(π/n), p = P / (1 + EA·(u/p)/(R(R + h/2))), u/p the compliance of the
    hole (Lamé: a thick cylinder fixed at an outer radius between the block's inscribed and
    circumscribed circles bound it). Referred to the axis (per 2R sin(π/n)) the pressure would be
    10 % larger, and one pass alone carries a share."""
    R, h, n, E_soil, E_ring, Pn = 1.0, 0.2, 32, 1.0e3, 1.0, 1.0
    b = R + h / 2
    a = 2 * np.pi * (np.arange(n) + 0.5) / n
    ring = dc.io.mesh.from_arrays(np.column_stack([R * np.cos(a), R * np.sin(a)]),
                                  np.column_stack([np.arange(n), (np.arange(n) + 1) % n]), "lining",
                                  point_groups={f"node{i}": np.array([i]) for i in range(n)}, comm=comm)
    sc = dc.Scene()
    soil = sc.add_solid(_soil_with_hole(b, 48, 3.0), material=dc.SaintVenantKirchhoff(E_soil, 0.3), degree=1)
    lining = sc.add_beam(ring, section=dc.Rectangle(1.0, h), material=dc.Elastic(E_ring, 0.2))
    sc.fix(soil, "outer")
    f = Pn * 2 * b * np.sin(np.pi / n)
    for i in range(n):
        sc.load(lining, f"node{i}", force=(f * np.cos(a[i]), f * np.sin(a[i])))
    pair = sc.contact(slaves=(lining, "lining"), masters=(soil, "cavity"), law=dc.AugmentedLagrangian(),
                      symmetric=True)
    sc.monitor_contact("lining", pair)
    res = dc.solve(sc, dc.LoadControl(steps=2))
    face = pair.pressure("slaves")
    radius = np.linalg.norm(face.x, axis=1)
    assert np.allclose(radius, b, rtol=1e-12)  # the outer face, reference configuration
    np.testing.assert_allclose(face.length, 2 * b * np.sin(np.pi / n), rtol=1e-12)
    EA = E_ring * h
    bounds = [Pn / (1 + EA * _lame_hole_compliance(b, c, E_soil, 0.3) / (R * b)) for c in (3.0, 3.0 * np.sqrt(2))]
    # measured: mean 0.999818, nodes 0.999779 … 0.999867 (the unstructured soil mesh); the Lamé
    # bounds 0.999794 … 0.999830; the pressure referred to the axis would be 1.0998
    assert min(bounds) - 2e-5 < face.pressure.mean() < max(bounds) + 2e-5, (face.pressure.mean(), bounds)
    assert np.abs(face.pressure / Pn - 1.0).max() < 5e-4
    # the ring is in equilibrium: no net force, the total normal force is n f (less the hoop share)
    assert np.abs(face.resultant).max() < 1e-9 * n * f
    assert abs(res.history.column("lining_N")[-1] / (n * f) - face.pressure.mean() / Pn) < 1e-12
    # the other side (the soil's cavity nodes, masters of the first pass) carries the same forces
    cavity = pair.pressure("masters")
    assert abs(cavity.normal_force / face.normal_force - 1.0) < 1e-3
    np.testing.assert_allclose(cavity.resultant, -face.resultant, atol=1e-12 * n * f)
    # what one pass reports per length of the axis: the first carries nearly all, 10 % too high
    first = pair[0].pressure()[1]
    assert first.min() > 1.05 * Pn


def test_contact_monitor_refuses_bad_input():
    sc, b = _blocks(2, 3)
    pair = sc.contact(slaves=(b, "upper_bottom"), masters=(b, "lower_top"), symmetric=True)
    with pytest.raises(ValueError, match="on = 'upper'"):
        sc.monitor_contact("c", pair, on="upper")
    with pytest.raises(TypeError, match="scene.contact returned"):
        sc.monitor_contact("c", list(pair))
    sc.monitor_reaction("base", b, "base")
    with pytest.raises(ValueError, match="monitor 'base' exists already"):
        sc.monitor_contact("base", pair)
    other, ob = _blocks(2, 3)
    foreign = other.contact(slaves=(ob, "upper_bottom"), masters=(ob, "lower_top"))
    with pytest.raises(ValueError, match="another scene"):
        sc.monitor_contact("c", foreign)

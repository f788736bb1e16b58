"""Monitors address the nodes of the group they name (never a node of another body at the same
position), reduce a group to sums, means and extrema, or record it whole as a profile along it;
serial and under MPI with the same numbers."""
import gmsh
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import rectangles
from dolfinx_corot.result import read_profiles

comm = MPI.COMM_WORLD


def _same_on_every_rank(values):
    """The values, after checking that every rank holds them bit for bit."""
    values = np.asarray(values, dtype=float)
    for other in comm.allgather(values):
        np.testing.assert_array_equal(other, values)
    return values


# -- a cantilever under a tip load: the Bernoulli deflection line --------------------------------
L, E, B, H, P = 2.0, 1.0e3, 0.1, 0.1, 1.0e-3
EI = E * B * H**3 / 12


def deflection(x):
    """w(x) = −P x² (3L − x) / (6EI), θ(x) = −P x (2L − x) / (2EI) (cantilever, tip load −P)."""
    return -P * x**2 * (3 * L - x) / (6 * EI), -P * x * (2 * L - x) / (2 * EI)


def _cantilever(points=((0.0, 0.0), (L, 0.0)), n=8, monitors=()):
    """Geometrically linear cantilever (exact nodal values: Bernoulli elements are exact for a tip
    load), clamped at 'base', loaded at 'tip'."""
    tm = polyline(points, n, line_name="beam", comm=comm)
    sc = dc.Scene(large_rotations=False)
    beam = sc.add_beam(tm, "beam", section=dc.Rectangle(B, H), material=dc.Elastic(E))
    sc.fix(beam, "base")
    sc.load(beam, "tip", force=(0.0, -P))
    for args, kwargs in monitors:
        sc.monitor(*args[:1], beam, *args[1:], **kwargs)
    return sc, beam


def test_reductions_of_a_cantilever_match_the_closed_form():
    """sum, mean, max, min and absmax of (uy, rz) over the 9 nodes of the beam, against the closed
    form at x = 0, L/8, …, L; a group of one node keeps its columns tip_ux, tip_uy, tip_rz."""
    reductions = ("sum", "mean", "max", "min", "absmax")
    sc, _ = _cantilever(monitors=[(("tip", "tip"), {})] + [((r, "beam"), {"reduce": r}) for r in reductions])
    res = dc.solve(sc, dc.LoadControl(steps=2))
    row = res.history.rows[-1]
    x = np.linspace(0.0, L, 9)
    w, theta = deflection(x)
    expected = {"sum": (w.sum(), theta.sum()), "mean": (w.mean(), theta.mean()), "max": (0.0, 0.0),
                "min": (w[-1], theta[-1]), "absmax": (w[-1], theta[-1])}
    scale = abs(w[-1])
    for r, (uy, rz) in expected.items():
        got = _same_on_every_rank([row[f"{r}_uy_{r}"], row[f"{r}_rz_{r}"], row[f"{r}_ux_{r}"]])
        assert abs(got[0] - uy) < 1e-10 * scale * (9 if r == "sum" else 1), (r, got[0], uy)
        assert abs(got[1] - rz) < 1e-10 * abs(theta[-1]) * (9 if r == "sum" else 1), (r, got[1], rz)
        assert abs(got[2]) < 1e-14, r  # no axial force: ux = 0
    assert abs(row["tip_uy"] - w[-1]) < 1e-10 * scale and abs(row["tip_rz"] - theta[-1]) < 1e-10 * abs(theta[-1])
    assert not any(c.startswith("tip_") and c.count("_") > 1 for c in res.history.columns)
    # absmax keeps the sign: the tip deflection is negative; max is the clamped node's 0
    assert row["absmax_uy_absmax"] < 0.0 and row["max_uy_max"] == 0.0
    # half the load: half of every value (linear kinematics)
    first = res.history.rows[0]
    assert abs(first["mean_uy_mean"] - 0.5 * w.mean()) < 1e-10 * scale


def test_profile_along_a_beam_is_the_deflection_line(tmp_path):
    """The profile of the beam group: its 9 nodes by arc length from x = 0, uy and rz the closed
    form at every step; written with the history and read back."""
    sc, _ = _cantilever(monitors=[(("w", "beam"), {"reduce": "profile"})])
    res = dc.solve(sc, dc.LoadControl(steps=2))
    prof = res.profiles["w"]
    x = np.linspace(0.0, L, 9)
    np.testing.assert_allclose(prof.X[:, 0], x, atol=1e-14)
    np.testing.assert_allclose(prof.s, x, atol=1e-14)
    assert prof.values.shape == (2, 9, 3) and prof.dofs == ("ux", "uy", "rz")
    np.testing.assert_array_equal(prof.steps, [1, 2])
    np.testing.assert_allclose(prof.load_factors, [0.5, 1.0])
    w, theta = deflection(x)
    uy = _same_on_every_rank(prof.column("uy"))
    np.testing.assert_allclose(uy[-1], w, rtol=1e-10, atol=1e-12 * abs(w[-1]))
    np.testing.assert_allclose(uy[0], 0.5 * w, rtol=1e-10, atol=1e-12 * abs(w[-1]))
    np.testing.assert_allclose(prof.column("rz")[-1], theta, rtol=1e-10, atol=1e-12 * abs(theta[-1]))
    assert "w_uy" not in res.history.columns  # a profile is no column
    folder = comm.bcast(str(tmp_path), root=0)
    if comm.rank == 0:
        res.write(folder)
        back = read_profiles(f"{folder}/history_profiles.npz")["w"]
        np.testing.assert_array_equal(back.values, prof.values)
        np.testing.assert_array_equal(back.X, prof.X)
        assert back.where == "beam" and back.along == "arc length"
        import json
        with open(f"{folder}/history_summary.json") as f:
            assert json.load(f)["profiles"]["w"]["nodes"] == 9


def test_profile_order_along_a_bent_beam_and_along_a_direction():
    """An L-shaped cantilever (x to L, then up by L/2) meshed from its tip: the profile starts at
    the end of smallest (x, y) and its arc length runs round the corner to 1.5 L; along='y' sorts
    by height, along=(-1, 0) by −x. The nodes are the same in every order."""
    pts = [(L, L / 2), (L, 0.0), (0.0, 0.0)]  # from the tip to the base
    tm = polyline(pts, [4, 8], line_name="beam", point_names={0: "tip", 2: "base"}, comm=comm)
    sc = dc.Scene(large_rotations=False)
    beam = sc.add_beam(tm, "beam", section=dc.Rectangle(B, H), material=dc.Elastic(E))
    sc.fix(beam, "base")
    sc.load(beam, "tip", force=(-P, 0.0))
    sc.monitor("arc", beam, "beam", reduce="profile")
    sc.monitor("up", beam, "beam", reduce="profile", along="y")
    sc.monitor("back", beam, "beam", reduce="profile", along=(-1.0, 0.0))
    res = dc.solve(sc, dc.LoadControl(steps=1))
    arc, up, back = (res.profiles[k] for k in ("arc", "up", "back"))
    assert len(arc.X) == 13
    np.testing.assert_allclose(arc.X[0], [0.0, 0.0], atol=1e-14)  # the base end: smallest x
    np.testing.assert_allclose(arc.X[-1], [L, L / 2], atol=1e-14)
    np.testing.assert_allclose(arc.s, np.r_[np.linspace(0, L, 9), L + np.linspace(0, L / 2, 5)[1:]], atol=1e-13)
    assert np.all(np.diff(up.s) >= 0) and np.all(np.diff(back.s) >= 0)
    np.testing.assert_allclose(back.s, -back.X[:, 0])
    # the horizontal arm does not move sideways under a horizontal tip load: its uy is the deflection
    # of a cantilever of length L under the force −P carried at the lever arm L/2 plus the moment
    # P·L/2 … here only checked as the same values in every order
    key = lambda p: np.lexsort(p.X.T[::-1])  # noqa: E731
    for other in (up, back):
        np.testing.assert_array_equal(other.values[:, key(other)], arc.values[:, key(arc)])


def test_monitor_arguments_are_checked_and_name_the_group():
    sc, beam = _cantilever()
    with pytest.raises(ValueError, match=r"monitor 'w': group 'beam' has 9 nodes; say which value to record: "
                                         r"reduce='sum', 'mean', 'max', 'min', 'absmax'"):
        sc.monitor("w", beam, "beam")
    with pytest.raises(ValueError, match=r"monitor 'w': reduce = 'median' is not one of None, 'sum'"):
        sc.monitor("w", beam, "beam", reduce="median")
    with pytest.raises(ValueError, match=r"monitor 'w': along orders the nodes of a profile"):
        sc.monitor("w", beam, "beam", reduce="mean", along="x")
    with pytest.raises(ValueError, match=r"along = 'z' is not one of \['x', 'y'\]"):
        sc.monitor("w", beam, "beam", reduce="profile", along="z")
    with pytest.raises(ValueError, match=r"along = \[0.0, 0.0\] is not a direction of 2 finite numbers"):
        sc.monitor("w", beam, "beam", reduce="profile", along=(0.0, 0.0))
    with pytest.raises(dc.GroupNotFoundError, match="physical group 'nowhere' not found"):
        sc.monitor("w", beam, "nowhere", reduce="mean")
    assert not sc.monitors


def test_a_profile_of_a_group_without_lines_needs_a_direction():
    """The top face of a 3D box is no chain of lines: a profile of it needs ``along``; with
    along='x' its nodes are sorted by x (ties by y, z)."""
    tm = dc.io.mesh.box((2.0, 1.0, 1.0), (2, 1, 1), comm=comm)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1.0, 0.3), degree=1)
    with pytest.raises(ValueError, match=r"the nodes of group 'z1' form no chain of lines .*: give along='x', "
                                         r"'y', 'z' or a direction"):
        sc.monitor("top", b, "z1", reduce="profile")
    sc.monitor("top", b, "z1", reduce="profile", along="x")
    (prof,) = sc.profiles().values()
    assert len(prof.X) == 6 and np.all(np.diff(prof.s) >= 0)


# -- two blocks in one gmsh model, meshed apart: their interface nodes share positions ------------
W, WL, HB, PUSH = 1.0, 1.5, 1.0, -0.05
NU_TOP = 0.3  # the lower block has ν = 0


def _stacked_blocks():
    """Blocks [0, 1.5]×[0, H] ('lower', 6 × 2 quadrilaterals) and [0, 1]×[H, 2H] ('upper', 4 × 2)
    of one gmsh model whose common edge is meshed twice (separate gmsh points and lines, no
    fragment): the upper block's bottom nodes and the lower block's top nodes at x ≤ 1 share
    positions, not tags. Groups: 'base', 'lower_top', 'upper_bottom', 'top', 'upper_left', the
    upper block's corner point (1, H) 'upper_corner' and the lower block's point there,
    'lower_mark'."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        names = {}
        for block, y0, width, nx in (("lower", 0.0, WL, 6), ("upper", HB, W, 4)):
            p = [g.addPoint(x, y, 0.0) for x, y in ((0, y0), (width, y0), (width, y0 + HB), (0, y0 + HB))]
            if block == "lower":  # the top edge in two lines, joined at the point (1, H)
                mark = g.addPoint(W, HB, 0.0)
                lines = [g.addLine(p[0], p[1]), g.addLine(p[1], p[2]), g.addLine(p[2], mark), g.addLine(mark, p[3]),
                         g.addLine(p[3], p[0])]
                counts = (6, 2, 2, 4, 2)
                top, left = [lines[2], lines[3]], lines[4]
                names["lower_mark"] = (0, [mark])
            else:
                lines = [g.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
                counts = (4, 2, 4, 2)
                top, left = [lines[2]], lines[3]
                names["upper_corner"] = (0, [p[1]])
            s = g.addPlaneSurface([g.addCurveLoop(lines)])
            for line, n in zip(lines, counts):
                g.mesh.setTransfiniteCurve(line, n + 1)
            g.mesh.setTransfiniteSurface(s, cornerTags=p)
            g.mesh.setRecombine(2, s)
            names[block] = (2, [s])
            names[f"{block}_left"] = (1, [left])
            names["base" if block == "lower" else "upper_bottom"] = (1, [lines[0]])
            names["lower_top" if block == "lower" else "top"] = (1, top)
        g.synchronize()
        dc.io.mesh.name_groups(names)
        gmsh.model.mesh.generate(2)
    tm = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _materials(sc, tm, E_lower):
    b = sc.add_solid(tm, "lower", material=dc.SaintVenantKirchhoff(E_lower, 0.0), degree=1)
    sc.add_solid(tm, "upper", material=dc.SaintVenantKirchhoff(1.0, NU_TOP), degree=1)
    return b


def test_the_nodes_of_a_group_are_its_own_not_those_at_its_positions():
    tm = _stacked_blocks()
    n_owned = tm.mesh.topology.index_map(0).size_local

    def count(name):
        return comm.allreduce(int(np.sum(tm.vertices(name) < n_owned)))

    assert count("upper_bottom") == 5 and count("lower_top") == 7 and count("upper_corner") == 1
    assert count("upper") == 15 and count("lower") == 21
    assert comm.allreduce(int(np.sum(np.isin(tm.vertices("upper_bottom"), tm.vertices("lower"))))) == 0
    # a point found by position is ambiguous where the bodies touch; within= says which body
    with pytest.raises(ValueError, match=r"point group 'p': 2 nodes at \[1.0, 1.0\] \(bodies meshed apart share "
                                         r"the position\): give within="):
        tm.add_point_group("p", [(W, HB)])
    tm.add_point_group("p", [(W, HB)], within="upper")
    assert count("p") == 1
    assert comm.allreduce(int(np.sum(np.isin(tm.vertices("p"), tm.vertices("lower"))))) == 0
    with pytest.raises(ValueError, match=r"point group 'q': no node at \[\[0.3, 0.3\]\]"):
        tm.add_point_group("q", [(0.3, 0.3)])


def test_monitors_on_a_contact_group_report_their_own_body():
    """The upper block (E = 1, ν = 0.3) pressed by ū_y = −0.05 on a lower block 10⁶ times stiffer,
    frictionless contact, small strain, plane strain: the upper block is in uniaxial stress
    σ = −0.05 E/(H (1 − ν²)) and spreads sideways, u_x = ε_x x with ε_x = −ν(1 + ν)σ/E = 0.0214286,
    on a foundation that stays put (u = O(10⁻⁶ |ū|)). Every monitor on the upper block's groups sees
    its own nodes (u_x(1) = 0.0214286), never the lower block's nodes at the same positions (0)."""
    tm = _stacked_blocks()
    sc = dc.Scene(large_rotations=False)
    b = _materials(sc, tm, E_lower=1.0e6)
    sc.fix(b, "base")
    sc.fix(b, "upper_left", dofs=("ux",))
    sc.prescribe(b, "top", uy=PUSH)
    sc.contact(slaves=(b, "upper_bottom"), masters=(b, "lower_top"),
               law=dc.AugmentedLagrangian(gap_tolerance=1e-10))
    sc.monitor("corner", b, "upper_corner")
    sc.monitor("mark", b, "lower_mark")
    for r in ("sum", "mean", "max", "min"):
        sc.monitor(r, b, "upper_bottom", reduce=r)
    sc.monitor("interface", b, "upper_bottom", reduce="profile")
    sc.monitor_reaction("top", b, "top")
    sc.monitor_reaction("base", b, "base")
    res = dc.solve(sc, dc.LoadControl(steps=1))
    row = res.history.rows[-1]
    sigma = PUSH / (HB * (1.0 - NU_TOP**2))
    exx = -NU_TOP * (1 + NU_TOP) * sigma  # 0.0214286
    x = np.linspace(0.0, W, 5)
    tol = 1e-6
    assert abs(row["corner_ux"] - exx * W) < tol and abs(row["corner_uy"]) < tol
    assert abs(row["mark_ux"]) < tol and abs(row["mark_uy"]) < tol
    expected = {"sum": exx * x.sum(), "mean": exx * x.mean(), "max": exx * W, "min": 0.0}
    for r, ux in expected.items():
        got = _same_on_every_rank([row[f"{r}_ux_{r}"], row[f"{r}_uy_{r}"]])
        assert abs(got[0] - ux) < 5 * tol and abs(got[1]) < 5 * tol, (r, got, ux)
    prof = res.profiles["interface"]
    np.testing.assert_allclose(prof.X, np.c_[x, np.full(5, HB)], atol=1e-14)
    np.testing.assert_allclose(_same_on_every_rank(prof.column("ux")[-1]), exx * x, atol=tol)
    np.testing.assert_allclose(prof.column("uy")[-1], 0.0, atol=tol)
    # the reactions: the plate on top pushes down with σW (to the foundation's compliance, 10⁻⁶),
    # the base pushes back with as much (equilibrium, to the solver's tolerance)
    assert abs(row["top_Fy"] - sigma * W) < 1e-5 * abs(sigma * W)
    assert abs(row["top_Fy"] + row["base_Fy"]) < 1e-12
    assert abs(row["top_Fx"]) < 1e-6 * abs(sigma * W) and abs(row["base_Fx"]) < 1e-6 * abs(sigma * W)


def test_supports_and_loads_on_coincident_groups_act_on_their_own_body():
    """No contact: the upper block sits on a support of its own bottom edge ('upper_bottom', u_y = 0;
    'upper_left', u_x = 0) and is pressed by ū_y = −0.05 at its top, so the support carries
    0.05 E W/(H (1 − ν²)) = 0.0549451, and a downward point force F = 0.01 at its corner
    'upper_corner', a supported node, on top of it. The lower block (E = 1, ν = 0, clamped 'base') is pulled up by a
    traction t = 0.02 on 'lower_top', the edge under the upper block's support: its top rises by
    tH/E = 0.02, and its base takes −t·1.5 and no horizontal force."""
    tm = _stacked_blocks()
    sc = dc.Scene(large_rotations=False)
    b = _materials(sc, tm, E_lower=1.0)
    sc.fix(b, "base")
    sc.fix(b, "upper_bottom", dofs=("uy",))
    sc.fix(b, "upper_left", dofs=("ux",))
    sc.prescribe(b, "top", uy=PUSH)
    t, F = 0.02, 0.01
    sc.load(b, "lower_top", traction=(0.0, t))
    sc.load(b, "upper_corner", force=(0.0, -F))
    sc.monitor("lift", b, "lower_top", reduce="mean")
    sc.monitor("mark", b, "lower_mark")
    sc.monitor("seat", b, "upper_bottom", reduce="absmax")
    for name in ("upper_bottom", "upper_left", "base"):
        sc.monitor_reaction(name, b, name)
    res = dc.solve(sc, dc.LoadControl(steps=1))
    row = res.history.rows[-1]
    tol = 1e-10
    assert abs(row["lift_uy_mean"] - t * HB) < tol and abs(row["lift_ux_mean"]) < tol
    assert abs(row["mark_uy"] - t * HB) < tol and abs(row["mark_ux"]) < tol
    assert abs(row["seat_uy_absmax"]) < tol  # the support holds the upper block only
    assert abs(row["upper_bottom_Fy"] - ((-PUSH) * W / (HB * (1 - NU_TOP**2)) + F)) < tol
    assert abs(row["upper_left_Fx"]) < tol
    assert abs(row["base_Fy"] + t * WL) < tol and abs(row["base_Fx"]) < tol


def test_two_beams_that_touch_end_to_end_are_monitored_and_loaded_apart():
    """Two cantilevers of one gmsh model whose tips meet at x = L (two gmsh points there): the tip
    load on 'tip_a' bends beam a only, w = −PL³/(3EI), and the monitor of 'tip_b' reads 0."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        a0, a1, b0, b1 = (g.addPoint(x, 0.0, 0.0) for x in (0.0, L, 2 * L, L))
        la, lb = g.addLine(a0, a1), g.addLine(b0, b1)
        g.synchronize()
        for line in (la, lb):
            gmsh.model.mesh.setTransfiniteCurve(line, 5)
        dc.io.mesh.name_groups({"beams": (1, [la, lb]), "bases": (0, [a0, b0]), "tip_a": (0, [a1]),
                                "tip_b": (0, [b1])})
        gmsh.model.mesh.generate(1)
    tm = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    sc = dc.Scene(large_rotations=False)
    beams = sc.add_beam(tm, "beams", section=dc.Rectangle(B, H), material=dc.Elastic(E))
    sc.fix(beams, "bases")
    sc.load(beams, "tip_a", force=(0.0, -P))
    sc.monitor("a", beams, "tip_a")
    sc.monitor("b", beams, "tip_b")
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    assert abs(row["a_uy"] + P * L**3 / (3 * EI)) < 1e-10 * P * L**3 / (3 * EI)
    assert row["b_uy"] == 0.0 and row["b_rz"] == 0.0


# -- quadratic solids: the mid-side nodes belong to a facet group ----------------------------------
def test_profile_of_a_quadratic_solid_edge_holds_its_mid_side_nodes():
    """A block 2 × 1 (ν = 0, small strain) stretched by ū_x = 0.01 at x = 2: u_x = 0.005 x on the
    bottom edge, whose profile holds the 4 vertices and 3 mid-side nodes of its P2 elements in
    arc-length order."""
    tm = rectangles({"block": (0.0, 0.0, 2.0, 1.0, 3, 1)},
                    {"left": [("block", "left")], "bottom": [("block", "bottom")], "right": [("block", "right")]},
                    comm=comm)
    sc = dc.Scene(large_rotations=False)
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1.0, 0.0), degree=2)
    sc.fix(b, "left", dofs=("ux",))
    sc.fix(b, "bottom", dofs=("uy",))
    sc.prescribe(b, "right", ux=0.01)
    sc.monitor("bottom", b, "bottom", reduce="profile")
    sc.monitor("sum", b, "bottom", reduce="sum")
    res = dc.solve(sc, dc.LoadControl(steps=1))
    prof = res.profiles["bottom"]
    x = np.linspace(0.0, 2.0, 7)
    np.testing.assert_allclose(prof.X[:, 0], x, atol=1e-13)
    np.testing.assert_allclose(prof.s, x, atol=1e-13)
    # exact to the solver's tolerance (Newton's rtol 1e-9 of ū_x = 0.01; CG + AMG to rtol 1e-10)
    np.testing.assert_allclose(_same_on_every_rank(prof.column("ux")[-1]), 0.005 * x, atol=1e-11)
    assert abs(res.history.rows[-1]["sum_ux_sum"] - 0.005 * x.sum()) < 1e-11


# -- restart: profiles continue from the checkpoint ------------------------------------------------
class Killed(Exception):
    pass


def test_profiles_are_restored_from_a_checkpoint(tmp_path):
    """A run killed after step 3 and restarted gives the uninterrupted run's profile (same steps,
    values to 1e-12); a profile monitor added at the restart has NaN for the steps before it."""
    path = comm.bcast(str(tmp_path / "beam.npz") if comm.rank == 0 else None, root=0)
    driver = dc.LoadControl(steps=5)
    profile = [(("w", "beam"), {"reduce": "profile"})]
    full = dc.solve(_cantilever(monitors=profile)[0], driver)

    def kill(row):
        if row["step"] == 4:
            raise Killed

    with pytest.raises(Killed):
        dc.solve(_cantilever(monitors=profile)[0], driver, checkpoint=path, on_step=kill)
    added = profile + [(("v", "beam"), {"reduce": "profile", "along": "x"})]
    resumed = dc.solve(_cantilever(monitors=added)[0], driver, restart=path)
    a, b = full.profiles["w"], resumed.profiles["w"]
    np.testing.assert_array_equal(b.steps, a.steps)
    np.testing.assert_allclose(b.values, a.values, rtol=1e-12, atol=1e-16)
    v = resumed.profiles["v"].values
    assert v.shape == (5, 9, 3) and np.isnan(v[:3]).all() and not np.isnan(v[3:]).any()
    np.testing.assert_allclose(v[3:], a.values[3:], rtol=1e-12, atol=1e-16)


def test_restart_refuses_a_profile_of_other_nodes(tmp_path):
    path = comm.bcast(str(tmp_path / "beam.npz") if comm.rank == 0 else None, root=0)
    dc.solve(_cantilever(monitors=[(("w", "beam"), {"reduce": "profile"})])[0], dc.LoadControl(steps=2),
             checkpoint=path)
    other = _cantilever(monitors=[(("w", "tip"), {"reduce": "profile", "along": "x"})])[0]
    with pytest.raises(dc.CheckpointError, match=r"profile 'w' was recorded on other nodes \(9\) than the monitor "
                                                 r"of that name now \(1, group 'tip'\)"):
        dc.solve(other, dc.LoadControl(steps=4), restart=path)


# -- the order along a chain of lines (pure geometry) ---------------------------------------------
def _chain(X, segments):
    from dolfinx_corot.parts.groups import NodeGroup
    n = len(X)
    return NodeGroup("g", np.arange(n), np.asarray(X, dtype=float), np.arange(n), np.arange(n),
                     np.asarray(segments).reshape(-1, 2))


def test_arc_length_of_open_and_closed_chains():
    """An open polyline runs from its end of smallest (x, y); a closed one (a ring: a tunnel
    lining) counter-clockwise from its node of smallest (x, y); a mid-side node takes its
    projection; branches and pieces are refused."""
    from dolfinx_corot.parts.groups import chain_coordinate
    # open: (2,0) – (1,0) – (1,1), listed in any order; the end (1,1) is smaller than (2,0)
    s = chain_coordinate(_chain([(2.0, 0.0), (1.0, 0.0), (1.0, 1.0), (1.0, 0.5)], [(0, 1), (1, 3), (3, 2)]))
    np.testing.assert_allclose(s, [2.0, 1.0, 0.0, 0.5])
    # a closed unit square, nodes listed clockwise from (1, 1)
    s = chain_coordinate(_chain([(1, 1), (1, 0), (0, 0), (0, 1)], [(0, 1), (1, 2), (2, 3), (3, 0)]))
    np.testing.assert_allclose(s, [2.0, 1.0, 0.0, 3.0])  # (0,0) → (1,0) → (1,1) → (0,1)
    # a node inside a line (a quadratic element's mid-side node), no line of its own
    s = chain_coordinate(_chain([(0, 0), (2, 0), (0.5, 0)], [(0, 1)]))
    np.testing.assert_allclose(s, [0.0, 2.0, 0.5])
    with pytest.raises(ValueError, match=r"the lines of group 'g' branch at \[0.0, 0.0\]: give along='x', 'y'"):
        chain_coordinate(_chain([(0, 0), (1, 0), (0, 1), (-1, 0)], [(0, 1), (0, 2), (0, 3)]))
    with pytest.raises(ValueError, match=r"the lines of group 'g' form several pieces"):
        chain_coordinate(_chain([(0, 0), (1, 0), (3, 0), (4, 0)], [(0, 1), (2, 3)]))

"""Stability of the tangent along the path: critical points under load control and arc-length,
singular models stopped at the first solve with their free motion named, absurd results refused.

References: Euler's critical load of a cantilever column, P = π²EI/(4L²); the limit load of
the shallow two-bar (von Mises) truss with bars of constant EA on the engineering strain,
P(w) = 2EA (1 − l/L)(h − w)/l, l = √(a² + (h − w)²), maximised over the apex deflection w.
"""
import math

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import box, from_arrays
from dolfinx_corot.result import limit_load, path_distance

E, B, H, L = 1.0e6, 0.01, 0.01, 1.0
I_WEAK = B * H**3 / 12
P_EULER = math.pi**2 * E * I_WEAK / (4 * L**2)  # cantilever column


def _column(gdim: int, n: int = 10):
    """A perfect cantilever column under its Euler load at λ = 1 (2D: I = bh³/12; 3D: a b × 1.5h
    section, whose weak axis has 1.5 I, so λ_cr = 1.5)."""
    pts = [[0.0, 0.0], [0.0, L]] if gdim == 2 else [[0.0, 0.0, 0.0], [0.0, 0.0, L]]
    tm = polyline(pts, n, line_name="col", gdim=gdim)
    sc = dc.Scene()
    section = dc.Rectangle(B, H) if gdim == 2 else dc.Rectangle(B, 1.5 * H)
    col = sc.add_beam(tm, "col", section=section, material=dc.Elastic(E, 0.3), orientation=(1.0, 0.0, 0.0))
    sc.fix(col, "base")
    sc.load(col, "tip", force=(0.0, -P_EULER) if gdim == 2 else (0.0, 0.0, -P_EULER))
    sc.monitor("tip", col, "tip")
    return sc


def test_load_control_stops_at_the_bifurcation_of_a_column(hard_case):
    """Load control on a perfect column past its Euler load: the tangent gains a negative
    eigenvalue between λ = 0.91 and 1.04; the run stops at the last state before it with the
    critical load, interpolated from the smallest eigenvalue, within 0.5 % of π²EI/(4L²)
    (it is within 1e-4: the rest is the column's axial shortening)."""
    with pytest.raises(dc.CriticalPointError, match=r"a bifurcation near load factor 1\.0000.*ArcLength") as err:
        dc.solve(_column(2), dc.LoadControl(steps=10, final=1.3))
    result = err.value.result
    assert not result.completed and len(result.history) == 7
    assert result.history.rows[-1]["load_factor"] == pytest.approx(0.91)
    (cp,) = result.critical_points
    assert cp.kind == "bifurcation" and cp.bracket == pytest.approx((0.91, 1.04))
    assert (cp.negative_before, cp.negative_after) == (0, 1)
    assert cp.load_factor == pytest.approx(1.0, rel=5e-3)
    assert cp.load_factor == pytest.approx(1.0, abs=1e-4)
    hard_case("A perfect column loaded past its Euler load under load control",
              "A straight path whose tangent turns indefinite at a bifurcation: load control would go on "
              "along the unstable straight path without a warning. The run must stop at the last stable "
              "state and estimate the critical load from the smallest eigenvalue (10 beams, 2D).",
              {"critical load / π²EI/(4L²)": cp.load_factor, "bracket of load factors": list(cp.bracket),
               "negative eigenvalues before → after": f"{cp.negative_before} → {cp.negative_after}",
               "steps kept": len(result.history), "Newton iterations": result.totals["newton_iterations"],
               "cuts": result.totals["cuts"]})


@pytest.mark.parametrize("gdim, critical", [(2, 1.0), (3, 1.5)])
def test_load_control_may_go_on_past_a_bifurcation(gdim, critical):
    """With at_critical_point='continue' the run completes on the straight (unstable) path and
    records the critical point; 3D frames, solved by LU, count the negative eigenvalues by an
    LDLᵀ of the symmetric part of the tangent at each converged state."""
    final = 1.3 * critical
    result = dc.solve(_column(gdim), dc.LoadControl(steps=10, final=final, at_critical_point="continue"))
    assert result.completed and len(result.history) == 10
    (cp,) = result.critical_points
    assert cp.kind == "bifurcation" and cp.load_factor == pytest.approx(critical, rel=5e-3)
    lam = result.history.column("load_factor")
    negative = result.history.column("negative_eigenvalues")
    assert np.array_equal(negative, (lam > critical).astype(float))


A_TRUSS, H_TRUSS, EA_TRUSS, F_TRUSS = 1.0, 0.1, 1.0e4, 10.0


def _truss_limit() -> float:
    L0 = math.hypot(A_TRUSS, H_TRUSS)
    w = np.linspace(0.0, H_TRUSS, 400001)
    ell = np.hypot(A_TRUSS, H_TRUSS - w)
    return float(np.max(2 * EA_TRUSS * (1 - ell / L0) * (H_TRUSS - w) / ell) / F_TRUSS)


def _truss():
    tm = from_arrays(np.array([[-A_TRUSS, 0.0], [0.0, H_TRUSS], [A_TRUSS, 0.0]]), np.array([[0, 1], [1, 2]]),
                     "bars", point_groups={"supports": [0, 2], "apex": [1]})
    sc = dc.Scene()
    bars = sc.add_truss(tm, "bars", area=1.0, material=dc.Elastic(EA_TRUSS))
    sc.fix(bars, "supports")
    sc.load(bars, "apex", force=(0.0, -F_TRUSS))
    sc.monitor("apex", bars, "apex")
    return sc


def test_load_control_past_a_limit_point_stops_instead_of_jumping(hard_case):
    """Past the truss's limit load, load control used to leap to the inverted branch (apex
    −0.04 → −0.216) and report completion. Now the step that leaps is recognised — its Newton
    iterates cross states with a negative eigenvalue — and the run stops before it; the bracket
    holds the exact limit load, and its estimate (smallest eigenvalue squared, extrapolated) is
    within 0.5 %. With 'continue' the leap is recorded and the run goes on."""
    exact = _truss_limit()
    with pytest.raises(dc.CriticalPointError, match="limit point") as err:
        dc.solve(_truss(), dc.LoadControl(steps=10, final=2.0))
    (cp,) = err.value.result.critical_points
    assert cp.kind == "limit point (jumped)"
    assert cp.bracket[0] <= exact <= cp.bracket[1]
    assert cp.load_factor == pytest.approx(exact, rel=5e-3)
    assert err.value.result.history.rows[-1]["apex_uy"] > -0.05  # nothing of the remote branch kept
    # the model itself: the first step's apex deflection satisfies P(w) of the bars exactly
    first = err.value.result.history.rows[0]
    w = -first["apex_uy"]
    L0, ell = math.hypot(A_TRUSS, H_TRUSS), math.hypot(A_TRUSS, H_TRUSS - w)
    assert 2 * EA_TRUSS * (1 - ell / L0) * (H_TRUSS - w) / ell == pytest.approx(F_TRUSS * first["load_factor"],
                                                                                 rel=1e-6)
    result = dc.solve(_truss(), dc.LoadControl(steps=10, final=2.0, at_critical_point="continue"))
    assert result.completed and [c.kind for c in result.critical_points] == ["limit point (jumped)"]
    hard_case("Load control past the limit load of a shallow truss",
              "Beyond its limit load the von Mises truss has no nearby equilibrium: Newton leaps to the "
              "inverted branch and, unchecked, reports a converged step. The leap must be recognised (its "
              "iterates cross unstable states) and the run stopped before it, with the limit load bracketed.",
              {"limit load estimate / exact": cp.load_factor / exact, "bracket of load factors": list(cp.bracket),
               "exact limit load factor": exact, "last apex deflection kept": err.value.result.history.rows[-1][
                   "apex_uy"], "Newton iterations": err.value.result.totals["newton_iterations"],
               "cuts": err.value.result.totals["cuts"]})


def _pressed_cap(n: int, shallow: bool = False):
    """The hinged cap of ``demos/hinged_sphere.py`` (sphere R = 100 over the square [−15, 15]², rise
    2.26, t = 0.25, E = 10⁶, ν = 0.3; one quarter, n × n four-node shells) under a dead uniform
    pressure of 12 at λ = 1, pressing down; ``shallow``: the shallow-shell local law."""
    R, a = 100.0, 15.0
    g = np.linspace(0.0, a, n + 1)
    pts = np.array([(x, y, np.sqrt(R**2 - x * x - y * y) - np.sqrt(R**2 - 2 * a * a)) for y in g for x in g])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    cells = np.c_[idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()]
    groups = {"sym_x": idx[:, 0], "sym_y": idx[0, :], "edges": np.concatenate([idx[:, -1], idx[-1, :]]),
              "centre": [0]}
    sc = dc.Scene(large_rotations=True)
    cap = sc.add_shell(from_arrays(pts, cells, "cap", groups), "cap", thickness=0.25, material=dc.Elastic(1e6, 0.3),
                       shallow=shallow)
    sc.fix(cap, "sym_x", dofs=("ux", "ry", "rz"))
    sc.fix(cap, "sym_y", dofs=("uy", "rx", "rz"))
    sc.fix(cap, "edges", dofs=("ux", "uy", "uz"))
    sc.pressure(cap, None, -12.0, follower=False)
    sc.monitor("centre", cap, "centre")
    return sc


def test_load_control_stops_at_a_limit_point_whose_leap_meets_no_negative_eigenvalue(hard_case):
    """A hinged spherical cap (12 × 12 quadrilaterals a quarter) under a uniform pressure snaps
    through at its limit pressure. Load control's step across it used to land on the inverted cap
    (centre −0.13 → −2.60) with every Newton iterate's tangent positive definite, so the count
    saw nothing and the run reported completion. The step went some 300 times as far as its
    tangent predicted; such a step (over 10 times, no contact) is now followed again in parts,
    and the run stops before the leap at p ≈ 4.59, within 1 % of the limit pressure 4.55 of this
    cap converged on 24 × 24 cells (4.553 with quadrilaterals, 4.560 with triangles, and 4.616
    with triangles on 12 × 12)."""
    with pytest.raises(dc.CriticalPointError, match="limit point") as err:
        dc.solve(_pressed_cap(12), dc.LoadControl(steps=60))
    (cp,) = err.value.result.critical_points
    assert cp.kind == "limit point (jumped)"
    assert 12.0 * cp.load_factor == pytest.approx(4.55, rel=0.015)
    kept = err.value.result.history.rows[-1]
    assert kept["centre_uz"] > -0.1  # nothing of the inverted cap kept
    hard_case("Load control across a limit point where no iterate meets a negative eigenvalue",
              "A pressed spherical cap of quadrilateral shells snaps through; Newton's iterates leap from "
              "the near branch to the inverted cap through states whose tangents are all positive "
              "definite, so the count alone misses the limit point. A step that goes over ten times as far "
              "as its tangent predicted must be checked in parts and the run stopped before the leap.",
              {"limit pressure estimate": 12.0 * cp.load_factor, "converged limit pressure (24 x 24)": 4.55,
               "bracket of pressures": [12.0 * b for b in cp.bracket], "last centre deflection kept": kept[
                   "centre_uz"], "Newton iterations": err.value.result.totals["newton_iterations"],
               "cuts": err.value.result.totals["cuts"]})


def test_the_shallow_shell_law_brings_a_coarse_pressed_cap_to_its_limit_pressure():
    """The pressed cap above on 6 × 6 quadrilaterals a quarter: its limit pressure with the linear
    local law is 4.6 % above the converged 4.55 (docs/theory.md), with the shallow-shell law
    (the membrane strain of each cell's own bending) within 2 % of it."""
    with pytest.raises(dc.CriticalPointError, match="limit point") as err:
        dc.solve(_pressed_cap(6, shallow=True), dc.LoadControl(steps=60))
    (cp,) = err.value.result.critical_points
    assert 12.0 * cp.load_factor == pytest.approx(4.55, rel=0.02)


def test_arc_length_lists_the_limit_point(hard_case):
    """Arc-length follows the truss through its limit point: the count of negative eigenvalues
    changes where λ turns, and the limit point's load (a parabola through the path points around
    it) is within 2 % of the exact one for this coarse path."""
    exact = _truss_limit()
    sc = _truss()
    shots = dc.plot.Snapshots(sc, every=2)
    result = dc.solve(sc, dc.ArcLength(initial_increment=0.05, max_steps=8), on_step=shots)
    first = result.critical_points[0]
    assert first.kind == "limit point" and (first.negative_before, first.negative_after) == (0, 1)
    assert first.load_factor == pytest.approx(exact, rel=2e-2)
    hard_case("Arc-length through the limit point of a shallow truss",
              "The load must fall after the limit point: arc-length follows the path through it and snaps "
              "the truss through, counting negative eigenvalues at every state to list the limit point.",
              {"limit load estimate / exact": first.load_factor / exact, "steps": len(result.history),
               "Newton iterations": result.totals["newton_iterations"], "cuts": result.totals["cuts"],
               "apex deflection at the end": result.history.rows[-1]["apex_uy"]},
              picture=(shots.states, {"field": "displacement", "title": "von Mises truss, arc-length states"}))


def test_limit_load_says_when_the_path_has_no_maximum():
    lam = np.linspace(0.0, 1.0, 6)
    with pytest.raises(ValueError, match="the path has no maximum of the load inside it: its maximum is at its "
                                         "last point"):
        limit_load(lam, lam**2)
    assert limit_load(np.array([0.0, 1.0, 1.6, 1.4]), np.array([0.0, 1.0, 2.0, 3.0])) == pytest.approx(1.625)


def test_path_distance_of_reference_points():
    """The distance of points from a traced path (a polyline) after scaling each coordinate: a
    point on a segment is at 0, one off a vertical segment at its horizontal offset, one beyond
    the end at its distance from the last state; on a steep segment the distance stays small
    where a difference of loads at equal displacement is large. A path of one state, points or
    scales of another width and a scale that is not positive are refused by name."""
    path = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 3.0]])
    points = np.array([[0.5, 0.5], [1.2, 2.0], [1.0, 4.0], [0.0, 1.0]])
    d = path_distance(path, points, [1.0, 1.0])
    np.testing.assert_allclose(d, [0.0, 0.2, 1.0, np.sqrt(0.5)], atol=1e-15)
    # scaled: x by 2, y by 10
    np.testing.assert_allclose(path_distance(path, points[[1]], [2.0, 10.0]), [0.1], atol=1e-15)
    steep = np.array([[0.0, 0.0], [1.0, 100.0]])
    assert path_distance(steep, np.array([[0.99, 100.0]]), [1.0, 100.0])[0] < 0.01
    with pytest.raises(ValueError, match="at least two states"):
        path_distance(path[:1], points, [1.0, 1.0])
    with pytest.raises(ValueError, match="need the path's 2 coordinates"):
        path_distance(path, points[:, :1], [1.0, 1.0])
    with pytest.raises(ValueError, match="need the path's 2 coordinates"):
        path_distance(path, points, [1.0])
    with pytest.raises(ValueError, match="must be positive"):
        path_distance(path, points, [1.0, 0.0])


# -- singular models ------------------------------------------------------------------------
def _beam(fix):
    tm = polyline([[0.0, 0.0], [1.0, 0.0]], 4, line_name="beam")
    sc = dc.Scene()
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1.0e3))
    if fix is not None:
        sc.fix(b, "base", fix)
    sc.load(b, "tip", force=(0.0, -1.0))
    return sc


@pytest.mark.parametrize("fix, motions", [
    (None, "translation along x, translation along y, rotation about z"),
    (("ux",), "translation along y, rotation about z"),
    (("ux", "uy"), "rotation about z through the point (0, 0)"),
])
def test_a_structure_without_enough_supports_stops_at_the_first_solve(fix, motions):
    """No step halving: the first tangent is singular, the run stops at once and names the
    part's free rigid motions (before: 'singular … Try smaller steps' after 8 cuts). Checked by
    the count of cuts and steps, not by a wall time (a loaded machine made 1 s into 1.7 s)."""
    with pytest.raises(dc.SingularModelError, match="the model is singular before any load") as err:
        dc.solve(_beam(fix), dc.LoadControl(steps=2))
    assert f"beam 'beam' moves freely ({motions})" in str(err.value)
    assert "no support holds it" in str(err.value)
    assert err.value.result.totals["cuts"] == 0 and len(err.value.result.history) == 0


def test_a_solid_without_supports_is_named_before_the_iterative_solver_runs():
    """CG + AMG does not see a singular tangent (before: 'diverged: |r| = 2.5e36'); the rigid-body
    modes applied to the first tangent do."""
    tm = box([1.0, 1.0, 1.0], [2, 2, 2])
    sc = dc.Scene()
    s = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1.0e3, 0.3), degree=1)
    sc.load(s, "x1", traction=(1.0, 0.0, 0.0))
    with pytest.raises(dc.SingularModelError, match=r"solid \(all cells\) moves freely \(translation along x, "
                                                    r"translation along y, translation along z, rotation about x"):
        dc.solve(sc, dc.LoadControl(steps=1))


def test_a_mechanism_is_located():
    """Two collinear bars pinned at their far ends: the middle node can move across the line
    without resistance (a mechanism at the start state); the message names the node."""
    tm = from_arrays(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), np.array([[0, 1], [1, 2]]), "bars",
                     point_groups={"ends": [0, 2], "middle": [1]})
    sc = dc.Scene()
    bars = sc.add_truss(tm, "bars", area=1.0, material=dc.Elastic(1.0e3))
    sc.fix(bars, "ends")
    sc.load(bars, "middle", force=(0.0, -1.0))
    with pytest.raises(dc.SingularModelError, match=r"truss 'bars' deforms without resistance \(a mechanism\): "
                                                    r"the node\(s\) at \(1, 0\) move most"):
        dc.solve(sc, dc.LoadControl(steps=1))


def test_an_absurd_result_stops_the_run():
    """A load of 1e20 on a small cantilever used to 'complete' with a tip rotation of −1e19 rad:
    a displacement a thousand times the model's size is refused at once, nothing is recorded."""
    sc = _beam(None)
    sc = dc.Scene()
    tm = polyline([[0.0, 0.0], [1.0, 0.0]], 4, line_name="beam")
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1.0e3))
    sc.fix(b, "base")
    sc.load(b, "tip", force=(0.0, -1e20))
    with pytest.raises(dc.ConvergenceError, match=r"times the model's size 1: the result is absurd") as err:
        dc.solve(sc, dc.LoadControl(steps=1))
    assert len(err.value.result.history) == 0 and err.value.result.totals["cuts"] == 0


def test_options_of_the_stability_checks():
    with pytest.raises(ValueError, match=r"LoadControl: at_critical_point = 'ignore' is not one of"):
        dc.LoadControl(at_critical_point="ignore")
    with pytest.raises(ValueError, match=r"ArcLength: stability = 'yes' is not one of"):
        dc.ArcLength(stability="yes")
    with pytest.raises(ValueError, match=r"NewtonOptions: max_displacement = 0.0 must be"):
        dc.NewtonOptions(max_displacement=0.0)
    # tracking off: no column, no critical point, the column runs through its Euler load
    result = dc.solve(_column(2), dc.LoadControl(steps=10, final=1.3, stability="off"))
    assert result.completed and not result.critical_points and "negative_eigenvalues" not in result.history.columns
    assert MPI.COMM_WORLD.allreduce(1) >= 1


@pytest.mark.parametrize("case, where", [
    ("duplicate node", r"\(2, 0\), \(1, 0\)"),   # the second member hangs from nothing
    ("I = 0", r"\(0.25, 0\)"),                   # no bending stiffness: the nodes swing
])
def test_duplicate_nodes_and_a_section_without_bending_stiffness_stop_at_the_first_solve(case, where):
    """Before: 'the tangent stiffness is singular … Try smaller steps' after 8 halvings. Now the
    first tangent's singularity stops the run at once (no cut, nothing recorded) and the nodes of
    the free motion are named."""
    if case == "duplicate node":  # two members meeting at x = 1 on separate nodes
        tm = from_arrays(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), np.array([[0, 1], [2, 3]]),
                         "beam", point_groups={"base": [0], "tip": [3]})
        section = dc.Rectangle(0.1, 0.1)
    else:
        tm = polyline([[0.0, 0.0], [1.0, 0.0]], 4, line_name="beam")
        section = dc.Section(A=0.01, I=0.0)
    sc = dc.Scene()
    b = sc.add_beam(tm, "beam", section=section, material=dc.Elastic(1.0e3))
    sc.fix(b, "base")
    sc.load(b, "tip", force=(0.0, -1.0))
    with pytest.raises(dc.SingularModelError, match=r"beam 'beam' deforms without resistance \(a mechanism\): "
                                                    r"the node\(s\) at .*" + where) as err:
        dc.solve(sc, dc.LoadControl(steps=2))
    assert err.value.result.totals["cuts"] == 0 and len(err.value.result.history) == 0

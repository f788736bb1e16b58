"""Newton's convergence test does not depend on the units, and badly scaled data converge to the
right answer (issue 13, "Newton on stiff or badly scaled data").

The residual is judged field by field — forces, and moments on rotational dofs — each against its
own scale, so the same model in m and in mm takes the same iterations; a residual that has reached
the round-off floor set by the tangent's stiffness (ε‖diag(K)·c‖, c the coordinates' size) and
stopped falling there is converged, so data out of scale (a stiffness 10⁴ times too large, a load
10⁹ times below the stiffness) no longer fail every step. Reference answers: Euler–Bernoulli
cantilever, tip deflection F L³ / (3 E I) (small loads), and each model's own answer in the other
unit system (large deflection; a co-rotational Euler–Bernoulli beam's tip converges in the mesh to
the elastica, which is not what is asserted here: the scaled answers must agree to round-off).
"""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import rectangles

comm = MPI.COMM_WORLD
MM = 1e3  # mm per m


def _cantilever(length_unit: float, force: float, stiffness_factor: float = 1.0, gdim: int = 2, n: int = 16):
    """A 1 m cantilever, 0.1 m × 0.1 m, E = 1 GPa, tip force ``force`` N (in ``length_unit`` per m:
    1 for m, 1000 for mm; E in N per length unit squared)."""
    L = 1.0 * length_unit
    start, end = [0.0, 0.0, 0.0][:gdim], [L, 0.0, 0.0][:gdim]
    tm = polyline([start, end], n, line_name="beam", gdim=gdim)
    sc = dc.Scene()
    kw = {"orientation": (0, 1, 0)} if gdim == 3 else {}
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1 * length_unit, 0.1 * length_unit),
                    material=dc.Elastic(1e9 * stiffness_factor / length_unit**2, 0.3), **kw)
    sc.fix(b, "base")
    sc.load(b, "tip", force=[0.0, -force, 0.0][:gdim])
    sc.monitor("tip", b, "tip")
    return sc


def _tip_linear(force: float, stiffness_factor: float = 1.0) -> float:
    EI = 1e9 * stiffness_factor * 0.1**4 / 12
    return -force * 1.0**3 / (3 * EI)


@pytest.mark.parametrize("gdim", [2, 3])
def test_a_large_deflection_in_m_and_in_mm_takes_the_same_iterations(gdim, hard_case):
    """F L²/(EI) = 12 bends the tip by 0.84 L (rotations of order one; 4 steps, cut where needed):
    the runs in m and in mm take the same Newton iterations and cuts in every step and agree to 1e-9
    after scaling. With one norm over all
    dofs the mm model, whose moments are 1000 times larger in N·mm, converged differently."""
    histories = []
    for unit in (1.0, MM):
        res = dc.solve(_cantilever(unit, 1e5, gdim=gdim, n=20), dc.LoadControl(steps=4))
        histories.append(res.history)
    m, mm = histories
    np.testing.assert_array_equal(m.column("cuts"), mm.column("cuts"))
    np.testing.assert_array_equal(m.column("iterations"), mm.column("iterations"))
    assert m.column("tip_uy")[-1] < -0.8  # a large deflection
    for dof in ("ux", "uy"):
        np.testing.assert_allclose(mm.column(f"tip_{dof}") / MM, m.column(f"tip_{dof}"), rtol=1e-9, atol=1e-12)
    hard_case(f"The same large deflection in m and in mm ({gdim}D)",
              "Units change the sizes of forces and moments by factors of 10³–10⁹: a convergence test on one "
              "norm over all dofs converges differently in mm. Field-by-field criteria must give the same "
              "iterations and cuts in every step.",
              {"iterations per step (m)": m.column("iterations").astype(int).tolist(),
               "iterations per step (mm)": mm.column("iterations").astype(int).tolist(),
               "cuts (m, mm)": [int(m.column("cuts").sum()), int(mm.column("cuts").sum())],
               "tip deflection / L": float(m.column("tip_uy")[-1]),
               "largest difference after scaling": float(np.max(np.abs(mm.column("tip_uy") / MM - m.column("tip_uy"))))})


def test_a_solid_in_m_and_in_mm_takes_the_same_iterations():
    """Plane-strain St Venant–Kirchhoff block 4 × 1 m, bent by a shear traction of 20 kPa on its
    free end (MUMPS): same iterations, scaled displacements equal to 1e-9."""
    out = []
    for unit in (1.0, MM):
        tm = rectangles({"block": (0.0, 0.0, 4.0 * unit, 1.0 * unit, 12, 3)},
                        {"left": [("block", "left")], "right": [("block", "right")]}, comm=comm)
        sc = dc.Scene(linear_solver="direct")  # (CG + AMG under MPI is not scale-invariant to the last iterate)
        s = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1e7 / unit**2, 0.3), degree=1)
        sc.fix(s, "left")
        sc.load(s, "right", traction=(0.0, -2e4 / unit**2))  # a stress (plane strain, per unit thickness)
        sc.monitor("end", s, "right", reduce="mean")
        res = dc.solve(sc, dc.LoadControl(steps=4))
        out.append(res.history)
    m, mm = out
    np.testing.assert_array_equal(m.column("iterations"), mm.column("iterations"))
    assert m.column("end_uy_mean")[-1] < -0.4
    np.testing.assert_allclose(mm.column("end_uy_mean") / MM, m.column("end_uy_mean"), rtol=1e-9)


@pytest.mark.parametrize("gdim", [2, 3])
def test_a_load_far_below_the_stiffness_converges_to_the_beam_theory_answer(gdim):
    """F = 10⁻³ N on a beam of EA = 10⁷ N: the residual's round-off floor (about 1e-9 N here) is far
    above rtol·F = 1e-12 N. Before, the iterates wandered at the floor and the steps were cut until
    the run failed ("diverged: |r| = 3.9e-08"); now the floor is recognised, every step converges in
    at most 3 iterations, and the tip deflection is F L³/(3EI) to 1e-6."""
    res = dc.solve(_cantilever(1.0, 1e-3, gdim=gdim), dc.LoadControl(steps=4))
    h = res.history
    assert h.column("cuts").sum() == 0 and h.column("iterations").max() <= 3
    assert h.column("tip_uy")[-1] == pytest.approx(_tip_linear(1e-3), rel=1e-6)


def test_a_stiffness_out_of_scale_converges_in_few_iterations():
    """E entered 10⁴ times too large (MPa taken for kPa…): the displacements are 10⁴ times smaller
    and the run converges as quickly as the intended one, to F L³/(3EI) of the stiffer beam."""
    intended = dc.solve(_cantilever(1.0, 1e3), dc.LoadControl(steps=2)).history
    stiff = dc.solve(_cantilever(1.0, 1e3, stiffness_factor=1e4), dc.LoadControl(steps=2)).history
    assert stiff.column("cuts").sum() == 0
    assert stiff.column("iterations").max() <= intended.column("iterations").max() + 1
    assert stiff.column("tip_uy")[-1] == pytest.approx(_tip_linear(1e3, 1e4), rel=1e-6)


def test_a_failed_step_says_which_criterion_stalled_and_at_what_level():
    """One Newton iteration cannot bend the beam by 0.6 L: the message names the field, its residual
    relative to its scale, the tolerance and the round-off floor."""
    with pytest.raises(dc.ConvergenceError) as err:
        dc.solve(_cantilever(1.0, 2e4), dc.LoadControl(steps=1, max_cuts=0,
                                                       newton=dc.NewtonOptions(max_iterations=1)))
    msg = str(err.value)
    assert "no convergence in 1 iterations" in msg
    assert "residual |r| = " in msg and "of its scale" in msg and "(rtol 1e-09)" in msg
    assert "round-off floor" in msg and ("force residual" in msg or "moment residual" in msg)

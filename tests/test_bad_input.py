"""Bad input ends in a clear error naming the culprit, or in the right answer (issue 13, first part)."""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import from_arrays

comm = MPI.COMM_WORLD


@pytest.mark.parametrize("make, message", [
    (lambda: dc.LoadControl(steps=2.5), r"LoadControl: steps = 2.5 must be a whole number ≥ 1"),
    (lambda: dc.LoadControl(steps=0), r"LoadControl: steps = 0 must be a whole number ≥ 1"),
    (lambda: dc.LoadControl(max_cuts=-1), r"LoadControl: max_cuts = -1 must be a whole number ≥ 0"),
    (lambda: dc.LoadControl(final=0.0), r"LoadControl: final = 0.0 must be a finite load factor other than 0"),
    (lambda: dc.LoadControl(final=float("nan")), r"LoadControl: final = nan"),
    (lambda: dc.LoadControl(load_factors=[]), r"load factors must be finite and not empty"),
    (lambda: dc.ArcLength(max_steps=0), r"ArcLength: max_steps = 0 must be a whole number ≥ 1"),
    (lambda: dc.ArcLength(initial_increment=0.0), r"ArcLength: initial_increment = 0.0 must be"),
    (lambda: dc.ArcLength(psi=-1.0), r"ArcLength: psi = -1.0 must be a finite number ≥ 0"),
    (lambda: dc.NewtonOptions(max_iterations=0), r"NewtonOptions: max_iterations = 0 must be a whole number ≥ 1"),
    (lambda: dc.NewtonOptions(rtol=-1e-9), r"NewtonOptions: rtol = -1e-09 must be a finite number ≥ 0"),
    (lambda: dc.NewtonOptions(rtol=0.0, atol=0.0), r"rtol and atol are both 0"),
    (lambda: dc.NewtonOptions(preconditioner="never"), r"preconditioner = 'never' is not"),
    (lambda: dc.Penalty(factor=-10.0), r"Penalty: factor = -10.0 must be a finite number > 0"),
    (lambda: dc.Penalty(factor=0.0), r"Penalty: factor = 0.0 must be a finite number > 0"),
    (lambda: dc.Penalty(penalty=0.0), r"Penalty: penalty = 0.0 must be a finite number > 0"),
    (lambda: dc.AugmentedLagrangian(max_updates=-1), r"AugmentedLagrangian: max_updates = -1 must be"),
    (lambda: dc.AugmentedLagrangian(gap_tolerance=0.0), r"AugmentedLagrangian: gap_tolerance = 0.0 must be"),
])
def test_options_are_checked_when_given(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def _cantilever(force=(0.0, -1.0)):
    tm = polyline([[0.0, 0.0], [1.0, 0.0]], 4, line_name="beam")
    sc = dc.Scene()
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1.0e3))
    sc.fix(b, "base")
    sc.load(b, "tip", force=force)
    return sc, b


def test_two_monitors_with_one_name_are_refused():
    """Two monitors whose columns would collide are refused; a dof monitor and a reaction monitor
    may share a name (columns tip_ux… and tip_Fx…)."""
    sc, b = _cantilever()
    sc.monitor("tip", b, "tip")
    with pytest.raises(ValueError, match="monitor 'tip' exists already \\(on group 'tip'\\)"):
        sc.monitor("tip", b, "base")
    sc.monitor_reaction("tip", b, "base")
    with pytest.raises(ValueError, match="monitor 'tip' exists already \\(on group 'base'\\)"):
        sc.monitor_reaction("tip", b, "tip")


def test_an_overflowing_load_is_a_failure_not_convergence():
    """A load of 1e300 overflows the residual: the step fails with the reason; before, it
    'converged' in 0 iterations with u = 0."""
    sc, _ = _cantilever(force=(0.0, -1e300))
    with pytest.raises(dc.ConvergenceError, match="the residual is not finite") as err:
        dc.solve(sc, dc.LoadControl(steps=1, max_cuts=1))
    assert len(err.value.result.history) == 0 and not err.value.result.completed


def test_every_history_column_is_readable():
    """Every column of the history reads as an array; ``residuals`` as the per-step arrays of the
    Newton residual norms (first one the step's initial residual, decreasing to below the tolerance)."""
    sc, b = _cantilever(force=(0.0, -1e-3))
    sc.monitor("tip", b, "tip")
    res = dc.solve(sc, dc.LoadControl(steps=2))
    for name in res.history.columns:
        assert len(res.history.column(name)) == 2, name
    residuals = res.history.column("residuals")
    for r, its in zip(residuals, res.history.column("iterations")):
        assert len(r) == its + 1 and r[-1] < r[0]


def test_a_solid_on_a_line_mesh_is_told_to_use_beams():
    tm = polyline([[0.0, 0.0], [1.0, 0.0]], 2, line_name="beam")
    with pytest.raises(ValueError, match="a mesh of lines carries beams or bars") as err:
        dc.Scene().add_solid(tm, material=dc.SaintVenantKirchhoff(1.0, 0.3))
    assert "gdim=1" not in str(err.value)


def test_nan_coordinates_are_refused_at_set_up():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [np.nan, 0.5]])
    tm = from_arrays(pts, np.array([[0, 1], [1, 2]]), "beam", comm=comm)
    with pytest.raises(ValueError, match="node coordinates that are not finite"):
        dc.Scene().add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1.0))


def test_box_in_pit_refuses_a_structure_outside_its_pit():
    """gmsh_models.box_in_pit: a structure wider than the pit (or no layer) is refused by name."""
    from dolfinx_corot.io.gmsh_models import box_in_pit

    with pytest.raises(ValueError, match="the structure .* must lie in the pit"):
        box_in_pit(12.0, 8.0, 4.0, 4.0, 4.0, 2.0, 0.2, 2, 2, 0.5)
    with pytest.raises(ValueError, match="at least one layer beside the structure"):
        box_in_pit(12.0, 8.0, 8.0, 4.0, 4.0, 2.0, 0.2, 0, 2, 0.5)

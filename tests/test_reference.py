"""Structures own their reference configuration: captured in a deformed configuration (a structure
added stress-free there, seed §3.1.2), they are the structure meshed at those positions."""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import from_arrays

comm = MPI.COMM_WORLD
E = 1.0e3


def _arc(X, R=2.0):
    """Positions on a circle of radius R tangent to the x axis at the origin (arc length = x)."""
    return np.column_stack([R * np.sin(X[:, 0] / R), R * (1.0 - np.cos(X[:, 0] / R))] +
                           ([X[:, 2]] if X.shape[1] == 3 else []))


def _set_state(model, positions):
    """Displacements to ``positions(X)`` and arbitrary rotations (a deformed configuration)."""
    X = model.V.tabulate_dof_coordinates()[:, : model.gdim]
    st = model.state.x.array.reshape(-1, model.state_size)
    st[:, : model.gdim] = positions(X) - X
    if model.gdim == 2:
        st[:, 2] = 0.3 * X[:, 0]                      # angles the capture must forget
    else:
        st[:, 3:7] = [np.cos(0.2), 0.0, 0.0, np.sin(0.2)]


def _beam_scene(tm, gdim):
    sc = dc.Scene()
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(E), orientation=(0, 0, 1))
    sc.fix(b, "base")
    sc.load(b, "tip", force=(0.0, 0.02) if gdim == 2 else (0.0, 0.02, 0.01),
            moment=0.0 if gdim == 2 else (0.0, 0.0, 0.0))
    sc.monitor("tip", b, "tip")
    return sc


@pytest.mark.parametrize("gdim", [2, 3])
def test_beam_captured_in_a_deformed_configuration_is_the_beam_meshed_there(gdim):
    n = 8
    tm = polyline([[0.0, 0.0, 0.0][:gdim], [1.0, 0.0, 0.0][:gdim]], n, line_name="beam", gdim=gdim)
    captured = _beam_scene(tm, gdim)
    _set_state(captured.model, _arc)
    captured.model.capture_reference()
    assert np.abs(captured.model.state.x.array.reshape(-1, captured.model.state_size)[:, :gdim]).max() == 0.0
    X = np.column_stack([np.linspace(0.0, 1.0, n + 1)] + [np.zeros(n + 1)] * (gdim - 1))
    lines = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    direct_mesh = from_arrays(_arc(X), lines, "beam", {"base": [0], "tip": [n]}, comm=comm)
    direct = _beam_scene(direct_mesh, gdim)
    a = dc.solve(captured, dc.LoadControl(steps=2)).history
    b = dc.solve(direct, dc.LoadControl(steps=2)).history
    names = ("ux", "uy") if gdim == 2 else ("ux", "uy", "uz")
    for c in names:
        np.testing.assert_allclose(a.column(f"tip_{c}"), b.column(f"tip_{c}"), rtol=1e-10, atol=1e-13)
    assert abs(a.column("tip_uy")[-1]) > 1e-3
    np.testing.assert_array_equal(a.column("iterations"), b.column("iterations"))


def test_shell_captured_on_a_cylinder_is_the_shell_meshed_there():
    nx, ny = 6, 2
    x, y = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 0.3, ny + 1))
    flat = np.column_stack([x.ravel(), y.ravel(), 0.0 * x.ravel()])
    idx = np.arange(len(flat)).reshape(ny + 1, nx + 1)
    q = np.column_stack([idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()])
    tri = np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    groups = {"base": np.flatnonzero(flat[:, 0] == 0.0), "tip": np.flatnonzero(flat[:, 0] == 1.0)}

    def cylinder(P, R=1.5):   # the strip bent about the y axis
        return np.column_stack([R * np.sin(P[:, 0] / R), P[:, 1], R * (1.0 - np.cos(P[:, 0] / R))])

    def scene(tm):
        sc = dc.Scene()
        s = sc.add_shell(tm, "plate", thickness=0.02, material=dc.Elastic(E, 0.3))
        sc.fix(s, "base")
        sc.load(s, "tip", force=(0.0, 0.0, 1e-3))
        sc.monitor("tip", s, "tip", reduce="mean")
        return sc

    captured = scene(from_arrays(flat, tri, "plate", groups, comm=comm))
    _set_state(captured.model, cylinder)
    captured.model.capture_reference()
    direct = scene(from_arrays(cylinder(flat), tri, "plate", groups, comm=comm))
    a = dc.solve(captured, dc.LoadControl(steps=2)).history
    b = dc.solve(direct, dc.LoadControl(steps=2)).history
    for c in ("ux", "uy", "uz"):
        np.testing.assert_allclose(a.column(f"tip_{c}_mean"), b.column(f"tip_{c}_mean"), rtol=1e-9, atol=1e-12)
    assert abs(a.column("tip_uz_mean")[-1]) > 1e-3

"""Pictures (dolfinx_corot.plot): every part kind drawn off screen, states kept along a run, the
cells gathered from every rank, bodies that touch kept apart, bad options refused."""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot import plot
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import from_arrays, rectangles

comm = MPI.COMM_WORLD
pytest.importorskip("pyvista")


def _image(path):
    from matplotlib.image import imread

    return imread(path)


def _coloured_fraction(path) -> float:
    """The fraction of pixels that are neither white nor grey (drawn in colour)."""
    rgb = _image(path)[:, :, :3]
    spread = rgb.max(axis=2) - rgb.min(axis=2)
    return float(np.mean(spread > 0.1))


def _rollup():
    tm = polyline([[0.0, 0.0], [1.0, 0.0]], 8, line_name="beam", comm=comm)
    sc = dc.Scene()
    beam = sc.add_beam(tm, "beam", section=dc.Rectangle(0.05, 0.05), material=dc.Elastic(1e5, 0.0))
    sc.fix(beam, "base")
    sc.load(beam, "tip", moment=np.pi * 1e5 * 0.05**4 / 12)
    return sc, beam


def test_snapshots_keep_the_first_steps_past_their_load_factors_and_draw_them(tmp_path):
    sc, _ = _rollup()
    shots = plot.Snapshots(sc, at=(0.3, 0.5, 1.0))
    dc.solve(sc, dc.LoadControl(steps=4), on_step=shots, quiet=True)
    assert [s.load_factor for s in shots.states] == [0.5, 1.0]  # 0.5 is the first past 0.3 and 0.5
    path = shots.picture(str(tmp_path / "rollup.png"), field="rotation")
    if comm.rank == 0:
        assert path and _coloured_fraction(path) > 0.002
        state = shots.states[-1]
        X, u = state.parts[0]["X"], state.parts[0]["u"]
        assert X.shape == (8, 2, 2)  # every cell, gathered from every rank
        tip = (X + u).reshape(-1, 2)[np.argmax(X.reshape(-1, 2)[:, 0])]
        # half a circle: the tip at (0, 2L/π) for M = πEI/L
        np.testing.assert_allclose(tip, [0.0, 2.0 / np.pi], atol=0.01)
        np.testing.assert_allclose(state.parts[0]["rotation"].max(), np.pi, rtol=1e-9)
        np.testing.assert_allclose(state.parts[0]["size"], 0.025, rtol=1e-12)  # half the depth
    else:
        assert path is None and shots.states[-1].parts == []


def test_every_part_kind_is_drawn(tmp_path):
    """A shell plate, a 3D beam, a membrane of quadrilaterals and a 3D solid: coloured pictures,
    each part's cells there once."""
    n = 4
    g = np.linspace(0.0, 1.0, n + 1)
    pts = np.array([(x, y, 0.0) for y in g for x in g])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a0, a1, b0, b1 = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    tri = from_arrays(pts, np.concatenate([np.c_[a0, a1, b1], np.c_[a0, b1, b0]]), "plate",
                      {"edge": idx[:, 0], "corner": [idx[-1, -1]]}, comm=comm)
    sc = dc.Scene()
    plate = sc.add_shell(tri, "plate", thickness=0.02, material=dc.Elastic(1e6, 0.3))
    sc.fix(plate, "edge")
    sc.load(plate, "corner", force=(0.0, 0.0, 1.0))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    state = plot.capture(sc, "plate")
    path = plot.picture(state, str(tmp_path / "plate.png"))
    if comm.rank == 0:
        assert state.parts[0]["cell"] == "triangle" and len(state.parts[0]["X"]) == 2 * n * n
        np.testing.assert_allclose(state.parts[0]["size"], 0.02)
        assert _coloured_fraction(path) > 0.01

    quad = from_arrays(pts, np.c_[a0, a1, b1, b0], "sheet", {"edge": idx[:, 0], "far": idx[:, -1], "every": idx.ravel()}, comm=comm)
    sc = dc.Scene()
    sheet = sc.add_membrane(quad, "sheet", thickness=0.01, material=dc.Elastic(1e6, 0.3))
    sc.fix(sheet, "edge")
    sc.fix(sheet, "every", dofs=("uz",))  # a flat membrane has no stiffness across its plane
    sc.prescribe(sheet, "far", ux=0.1)
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    path = plot.picture(sc, str(tmp_path / "sheet.png"), title="membrane")
    if comm.rank == 0:
        assert _coloured_fraction(path) > 0.01

    tm = polyline([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], 6, line_name="bar", gdim=3, comm=comm)
    sc = dc.Scene()
    beam = sc.add_beam(tm, "bar", section=dc.Pipe(0.05, 0.005), material=dc.Elastic(1e6, 0.3))
    sc.fix(beam, "base")
    sc.load(beam, "tip", force=(0.0, 0.0, 1.0))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    state = plot.capture(sc)
    path = plot.picture(state, str(tmp_path / "beam.png"))
    if comm.rank == 0:
        np.testing.assert_allclose(state.parts[0]["size"], 0.025)  # the pipe's outer radius d/2
        assert _coloured_fraction(path) > 0.002


def test_bodies_that_touch_stay_apart_in_the_drawing(tmp_path):
    """Two squares of one plane-strain mesh that share positions but not nodes along y = 1: the
    drawing merges each body's vertices (4 + 4 points) and keeps the coincident ones apart once
    the upper square is lifted."""
    square = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    pts = np.concatenate([square, square + [0.0, 1.0]])
    tri = np.array([[0, 1, 3], [0, 3, 2]])
    tm = from_arrays(pts, np.concatenate([tri, tri + 4]), "blocks",
                     {"bottom": [0, 1], "upper_bottom": [4, 5]}, comm=comm)
    sc = dc.Scene()
    blocks = sc.add_solid(tm, "blocks", material=dc.Elastic(1e3, 0.3), degree=1)
    sc.fix(blocks, "bottom")
    sc.fix(blocks, "upper_bottom", dofs=("ux",))
    sc.prescribe(blocks, "upper_bottom", uy=0.5)
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    state = plot.capture(sc, "lifted")
    if comm.rank == 0:
        grid = plot.grid_of(state.parts[0])
        assert grid.n_points == 8 and grid.n_cells == 4
        y = np.sort(grid.points[:, 1])
        np.testing.assert_allclose(y, [0, 0, 1, 1, 1.5, 1.5, 2.5, 2.5], atol=1e-12)  # lifted rigidly
        np.testing.assert_allclose(np.sort(grid.point_data["field"]), [0, 0, 0, 0, 0.5, 0.5, 0.5, 0.5], atol=1e-12)
    path = plot.picture(state, str(tmp_path / "blocks.png"))
    if comm.rank == 0:
        assert _coloured_fraction(path) > 0.01


def test_a_stretched_block_is_drawn_with_its_von_mises_stress(tmp_path):
    """A plane-strain block (ν = 0) stretched by 1 % with free sides, small strain: every node of
    the picture carries the exact von Mises stress of the uniaxial state (σ_xx = Eε, σ_zz = 0: Eε),
    from the cells' element results averaged at the nodes."""
    E, eps = 1e3, 0.01
    tm = from_arrays(np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0], [2.0, 1.0]]), np.array([[0, 1, 3], [0, 3, 2]]),
                     "block", {"left": [0, 2], "corner": [0], "right": [1, 3]}, comm=comm)
    sc = dc.Scene(large_rotations=False)
    block = sc.add_solid(tm, "block", material=dc.Elastic(E, 0.0), degree=1)
    sc.fix(block, "left", dofs=("ux",))
    sc.fix(block, "corner", dofs=("uy",))
    sc.prescribe(block, "right", ux=2.0 * eps)
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    state = plot.capture(sc)
    if comm.rank == 0:
        grid = plot.grid_of(state.parts[0], field="mises")
        np.testing.assert_allclose(grid.point_data["field"], E * eps, rtol=1e-9)
    path = plot.picture(state, str(tmp_path / "mises.png"), field="mises")
    if comm.rank == 0:
        assert _coloured_fraction(path) > 0.01


@pytest.mark.parametrize("rows", [2, 3])
def test_two_pressed_blocks_are_drawn_with_their_contact_pressure(tmp_path, rows):
    """Two blocks pressed together by a uniform stress P (the two-pass patch test of
    test_contact_pressure.py): the picture's contact field is P at the nodes of both faces in
    contact and 0 at every other node; one point per node on two ranks too (with 3 rows of
    cells a node's copies on the two ranks had positions differing by round-off, and the
    picture drew them as two points)."""
    P = 0.01
    tm = rectangles({"lower": (0.0, 0.0, 1.0, 1.0, 3, rows), "upper": (0.0, 1.0, 1.0, 1.0, 4, rows)},
                    {"base": [("lower", "bottom")], "lower_top": [("lower", "top")],
                     "upper_bottom": [("upper", "bottom")], "top": [("upper", "top")],
                     "left": [("lower", "left"), ("upper", "left")]}, comm=comm)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1.0, 0.3), degree=1)
    sc.fix(b, "base", dofs=("uy",))
    sc.fix(b, "left", dofs=("ux",))
    sc.load(b, "top", traction=(0.0, -P))
    sc.contact(slaves=(b, "upper_bottom"), masters=(b, "lower_top"), symmetric=True, smooth=False,
               law=dc.AugmentedLagrangian(gap_tolerance=1e-12, factor=1e4))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    state = plot.capture(sc)
    if comm.rank == 0:
        grid = plot.grid_of(state.parts[0], field="contact", deformed=False)
        on = np.isclose(grid.points[:, 1], 1.0)
        p = grid.point_data["field"]
        assert on.sum() == 9  # the lower block's 4 nodes at y = 1 and the upper one's 5
        np.testing.assert_allclose(p[on], P, rtol=1e-7)
        assert np.all(p[~on] == 0.0)
    path = plot.picture(state, str(tmp_path / "contact.png"), field="contact")
    if comm.rank == 0:
        assert _coloured_fraction(path) > 0.001


def test_bad_picture_options_are_refused(tmp_path):
    sc, _ = _rollup()
    state = plot.capture(sc)
    with pytest.raises(ValueError, match="field 'stress' is not one of"):
        plot.picture(state, str(tmp_path / "x.png"), field="stress")
    with pytest.raises(ValueError, match="layout 'stack' is not one of"):
        plot.picture(state, str(tmp_path / "x.png"), layout="stack")
    with pytest.raises(ValueError, match="no state was kept"):
        plot.Snapshots(sc).picture(str(tmp_path / "x.png"))
    if comm.rank == 0:  # (the states are drawn on rank 0: it refuses what it cannot draw)
        with pytest.raises(ValueError, match="field 'contact' draws contact pressure, and the states hold no contact"):
            plot.picture(state, str(tmp_path / "x.png"), field="contact")
        with pytest.raises(ValueError, match="field 'mises' draws von Mises stress, and the states hold no solids"):
            plot.picture(state, str(tmp_path / "x.png"), field="mises")


def test_snapshots_keep_the_last_step_of_each_stage(tmp_path):
    from dolfinx_corot.staging import Stage, solve_stages

    sc, beam = _rollup()
    extra = sc.load(beam, "tip", force=(0.0, -1.0))
    shots = plot.Snapshots(sc)
    solve_stages(sc, [Stage("moment", driver=dc.LoadControl(steps=2)),
                      Stage("and a force", add=[extra], driver=dc.LoadControl(steps=3))],
                 approach="I", on_step=shots, quiet=True)
    assert [s.label for s in shots.states] == ["moment", "and a force"]
    assert [s.load_factor for s in shots.states] == [1.0, 1.0]
    if comm.rank == 0:
        assert not np.allclose(shots.states[0].parts[0]["u"], shots.states[1].parts[0]["u"])
    shots.picture(str(tmp_path / "stages.png"))

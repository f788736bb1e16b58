"""Checkpoint files and restart: exact continuation (contact multipliers included), a driver asking
for more, a scene that changed, files that are damaged (DESIGN.md, "Contributions": the state contract)."""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import rectangles

comm = MPI.COMM_WORLD


class Killed(Exception):
    """Raised from on_step: the run dies after a step (its checkpoint holds the step before)."""


def _kill_at(step):
    def on_step(row):
        if row["step"] == step:
            raise Killed
    return on_step


def _path(tmp_path, name):
    return str(tmp_path / name) if comm.rank == 0 else None


def _shared(tmp_path, name):
    return comm.bcast(_path(tmp_path, name), root=0)


# -- (a) augmented-Lagrangian contact: killed at a step and restarted = the uninterrupted run ------
def _pressed_blocks():
    """Two blocks with non-matching meshes pressed together by a growing pressure (one-pass
    augmented Lagrangian: the multipliers carry the contact pressure from step to step)."""
    tm = rectangles({"lower": (0.0, 0.0, 1.0, 1.0, 4, 3), "upper": (0.0, 1.0, 1.0, 1.0, 7, 3)},
                    {"base": [("lower", "bottom")], "lower_top": [("lower", "top")],
                     "upper_bottom": [("upper", "bottom")], "top": [("upper", "top")],
                     "left": [("lower", "left"), ("upper", "left")]}, comm=comm)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.NeoHookean(1.0, 0.3), degree=1)
    sc.fix(b, "base", dofs=("uy",))
    sc.fix(b, "left", dofs=("ux",))
    sc.load(b, "top", traction=(0.02, -0.05))
    (itf,) = sc.contact(slaves=(b, "upper_bottom"), masters=(b, "lower_top"),
                        law=dc.AugmentedLagrangian(gap_tolerance=1e-6), smooth=True)
    sc.monitor_reaction("base", b, "base")
    return sc, itf


def test_augmented_lagrangian_contact_restart_is_exact(tmp_path):
    driver = dc.LoadControl(steps=6)
    full_scene, _ = _pressed_blocks()
    full = dc.solve(full_scene, driver)
    path = _shared(tmp_path, "contact.npz")
    killed_scene, killed_itf = _pressed_blocks()
    with pytest.raises(Killed):
        dc.solve(killed_scene, driver, checkpoint=path, on_step=_kill_at(4))  # the file holds step 3
    resumed_scene, resumed_itf = _pressed_blocks()
    resumed = dc.solve(resumed_scene, driver, restart=path)
    # the checkpoint carried real multipliers (else this test would not test them)
    assert comm.allreduce(float(np.abs(killed_itf.multiplier).max()), op=MPI.MAX) > 1e-3
    assert np.asarray(full.history.column("uzawa_updates")).sum() > 0
    for col in ("iterations", "uzawa_updates", "cuts"):
        np.testing.assert_array_equal(resumed.history.column(col), full.history.column(col), err_msg=col)
    np.testing.assert_allclose(resumed.history.column("base_Fy"), full.history.column("base_Fy"), rtol=1e-10)
    a = full_scene.model.to_global(full_scene.model.state.x.array)
    b = resumed_scene.model.to_global(resumed_scene.model.state.x.array)
    if comm.rank == 0:
        assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max()
    np.testing.assert_allclose(resumed_itf.multiplier, full_scene.interfaces[0].multiplier, rtol=1e-9, atol=1e-14)


# -- (b) a restart that asks for more ---------------------------------------------------------------
def _cantilever(P=1.0, x_end=1.0, E=1.0e3):
    tm = polyline([[0.0, 0.0], [x_end, 0.0]], 8, line_name="beam")
    sc = dc.Scene()
    beam = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(E))
    sc.fix(beam, "base")
    sc.load(beam, "tip", force=(0.0, -P))
    sc.monitor("tip", beam, "tip")
    return sc


def test_restart_with_a_larger_final_continues_where_the_run_stopped(tmp_path):
    path = _shared(tmp_path, "beam.npz")
    dc.solve(_cantilever(), dc.LoadControl(steps=4, final=1.0), checkpoint=path)
    # the same step, a larger final: the uninterrupted run's steps exactly
    more = dc.solve(_cantilever(), dc.LoadControl(steps=8, final=2.0), restart=path)
    straight = dc.solve(_cantilever(), dc.LoadControl(steps=8, final=2.0))
    np.testing.assert_allclose(more.history.column("load_factor"), straight.history.column("load_factor"))
    np.testing.assert_allclose(more.history.column("tip_uy"), straight.history.column("tip_uy"), rtol=1e-12)
    np.testing.assert_array_equal(more.history.column("iterations")[4:], straight.history.column("iterations")[4:])
    # another step: a smooth continuation from λ = 1 with this driver's targets beyond it
    other = dc.solve(_cantilever(), dc.LoadControl(steps=4, final=2.0), restart=path)
    np.testing.assert_allclose(other.history.column("load_factor"), [0.25, 0.5, 0.75, 1.0, 1.5, 2.0])
    assert abs(other.history.column("tip_uy")[-1] - straight.history.column("tip_uy")[-1]) < 1e-9
    # a finished run asked for nothing more: it stays where it is
    same = dc.solve(_cantilever(), dc.LoadControl(steps=4, final=1.0), restart=path)
    assert len(same.history) == 4 and same.completed


def test_arc_length_restart_with_more_steps_continues(tmp_path):
    path = _shared(tmp_path, "arc.npz")
    driver = lambda n: dc.ArcLength(initial_increment=0.25, max_steps=n)  # noqa: E731
    full = dc.solve(_cantilever(), driver(8))
    dc.solve(_cantilever(), driver(4), checkpoint=path)
    resumed = dc.solve(_cantilever(), driver(8), restart=path)
    np.testing.assert_allclose(resumed.history.column("load_factor"), full.history.column("load_factor"),
                               rtol=1e-12)
    with pytest.raises(dc.CheckpointError, match="written by ArcLength, not LoadControl"):
        dc.solve(_cantilever(), dc.LoadControl(steps=4), restart=path)


# -- (c) a scene that changed is refused, whatever its node count ------------------------------------
def test_restart_refuses_another_scene_with_the_same_node_count(tmp_path):
    path = _shared(tmp_path, "beam.npz")
    dc.solve(_cantilever(), dc.LoadControl(steps=2), checkpoint=path)
    with pytest.raises(dc.CheckpointError, match=r"another scene: .*geometry"):
        dc.solve(_cantilever(x_end=1.5), dc.LoadControl(steps=4), restart=path)   # same nodes, longer
    with pytest.raises(dc.CheckpointError, match=r"another scene: .*elements"):
        dc.solve(_cantilever(E=2.0e3), dc.LoadControl(steps=4), restart=path)     # another material
    tm = rectangles({"block": (0.0, 0.0, 1.0, 1.0, 2, 2)}, {"bottom": [("block", "bottom")]}, comm=comm)
    solid = dc.Scene()
    b = solid.add_solid(tm, material=dc.SaintVenantKirchhoff(1.0, 0.3), degree=1)
    solid.fix(b, "bottom")
    solid.gravity(b, (0.0, -1.0), 1e-3)
    with pytest.raises(dc.CheckpointError, match="another scene"):                # a beam's file on a solid
        dc.solve(solid, dc.LoadControl(steps=2), restart=path)


# -- (d) damaged files ---------------------------------------------------------------------------------
@pytest.mark.parametrize("damage", ["truncated", "garbage", "bit-flip", "missing"])
def test_damaged_checkpoint_is_refused_naming_the_file(tmp_path, damage):
    path = _shared(tmp_path, "beam.npz")
    dc.solve(_cantilever(), dc.LoadControl(steps=2), checkpoint=path)
    if comm.rank == 0:
        data = open(path, "rb").read()
        if damage == "truncated":
            data = data[: len(data) // 2]
        elif damage == "garbage":
            data = b"not a checkpoint" * 10
        elif damage == "bit-flip":
            data = bytearray(data)
            data[len(data) // 3] ^= 0xFF
            data = bytes(data)
        with open(path, "wb") as f:
            if damage != "missing":
                f.write(data)
        if damage == "missing":
            import os
            os.remove(path)
    comm.barrier()
    with pytest.raises(dc.CheckpointError, match=path.replace(".", r"\.")):
        dc.solve(_cantilever(), dc.LoadControl(steps=4), restart=path)


def test_checkpoint_in_a_folder_that_cannot_be_made_fails_before_the_first_step(tmp_path):
    blocker = _shared(tmp_path, "file")
    if comm.rank == 0:
        open(blocker, "w").close()
    comm.barrier()
    steps = []
    with pytest.raises(dc.CheckpointError, match="cannot write"):
        dc.solve(_cantilever(), dc.LoadControl(steps=2), checkpoint=blocker + "/sub/run.npz",
                 on_step=steps.append)
    assert steps == []


def test_restart_refuses_a_solid_whose_reference_was_captured_differently(tmp_path):
    """A solid's captured reference (its reference shift) is part of the scene's fingerprint."""
    def solid(shifted):
        tm = rectangles({"block": (0.0, 0.0, 1.0, 1.0, 2, 2)}, {"bottom": [("block", "bottom")]}, comm=comm)
        sc = dc.Scene()
        b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1.0, 0.3), degree=1)
        sc.fix(b, "bottom")
        sc.gravity(b, (0.0, -1.0), 1e-3)
        if shifted:
            sc.model.capture_reference(0.1 * sc.model.V.tabulate_dof_coordinates()[:, :2].ravel())
        return sc

    path = _shared(tmp_path, "solid.npz")
    dc.solve(solid(True), dc.LoadControl(steps=1), checkpoint=path)
    with pytest.raises(dc.CheckpointError, match="reference_shift"):
        dc.solve(solid(False), dc.LoadControl(steps=2), restart=path)
    assert dc.solve(solid(True), dc.LoadControl(steps=2), restart=path).completed

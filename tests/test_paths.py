"""Hard cases of the load path: path independence, load-unload loops, amplitudes."""
import numpy as np
import pytest

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline

L, B, H, E = 2.0, 0.1, 0.05, 1e5


@pytest.fixture(scope="module")
def member():
    return polyline([[0.0, 0.0, 0.0], [L, 0.0, 0.0]], 8, line_name="m", gdim=3)


def _scene(tm, loads):
    sc = dc.Scene()
    m = sc.add_beam(tm, "m", section=dc.Rectangle(B, H), material=dc.Elastic(E, 0.3), orientation=(0, 1, 0))
    sc.fix(m, "base")
    for force, moment, amp in loads:
        sc.load(m, "tip", force=force, moment=moment, amplitude=amp)
    sc.monitor("tip", m, "tip")
    return sc


def test_dead_forces_in_either_order_reach_the_same_configuration(member):
    """Conservative (dead) forces: F1 then F2, F2 then F1, or both together end in one state (1e-9)."""
    EIz = E * B * H**3 / 12
    F1 = np.array([0.0, 2.0 * EIz / L**2, 0.0])   # bends about z, tip rotation > 0.8 rad
    F2 = np.array([0.0, 0.0, 1.5 * EIz / L**2])
    first, second = dc.Amplitude([(0, 0), (1, 1)]), dc.Amplitude([(1, 0), (2, 1)])
    both = dc.Amplitude([(0, 0), (2, 1)])
    states = []
    for a1, a2 in ((first, second), (second, first), (both, both)):
        sc = _scene(member, [(F1, None, a1), (F2, None, a2)])
        dc.solve(sc, dc.LoadControl(steps=16, final=2.0))
        X, st = sc.model.nodes()
        order = np.argsort(X[:, 0])
        q = st[order, 3:] * np.sign(st[order, 3:4])  # q and −q are one rotation
        states.append(np.c_[st[order, :3], q])
    assert np.abs(states[0][:, :3]).max() > 0.3 * L  # a large-rotation state
    for s in states[1:]:
        np.testing.assert_allclose(s, states[0], atol=1e-9)


def test_load_unload_loop_returns_to_the_start(member):
    """Force and moment up to large rotations, then back to zero: displacements 0, rotations identity."""
    EIz = E * B * H**3 / 12
    sc = _scene(member, [(np.array([0.0, 1.0, 0.5]) * EIz / L**2, np.array([0.3, 0.0, 0.0]) * EIz / L, None)])
    res = dc.solve(sc, dc.LoadControl(load_factors=np.r_[np.linspace(0.25, 2.0, 8), np.linspace(1.75, 0.0, 8)]))
    lam = res.history.column("load_factor")
    assert lam.max() == 2.0 and lam[-1] == 0.0
    assert np.hypot(res.history.column("tip_uy"), res.history.column("tip_uz")).max() > 0.4 * L
    _, st = sc.model.nodes()
    assert np.abs(st[:, :3]).max() < 1e-10
    np.testing.assert_allclose(np.abs(st[:, 3]), 1.0, atol=1e-12)


def test_prescribed_motion_with_an_amplitude_unloads(member):
    """Displacement control up and down with an amplitude: the reaction retraces its path."""
    sc = dc.Scene()
    m = sc.add_beam(member, "m", section=dc.Rectangle(B, H), material=dc.Elastic(E), orientation=(0, 1, 0))
    sc.fix(m, "base")
    sc.prescribe(m, "tip", uy=0.8 * L, amplitude=dc.Amplitude([(0, 0), (1, 1), (2, 0)]))
    sc.monitor_reaction("jack", m, "tip")
    res = dc.solve(sc, dc.LoadControl(steps=8, final=2.0))
    fy = res.history.column("jack_Fy")
    np.testing.assert_allclose(fy[:3], fy[6:3:-1], rtol=1e-8)  # up and down meet at the same points
    assert abs(fy[-1]) < 1e-10 * abs(fy).max()


def test_amplitude_validation_and_arc_length_refusal(member):
    with pytest.raises(ValueError, match="load factors must increase"):
        dc.Amplitude([(1, 0), (0, 1)])
    sc = _scene(member, [(np.array([0.0, 1e-3, 0.0]), None, dc.Amplitude([(0, 0), (1, 1)])),
                         (np.array([0.0, 0.0, 1e-3]), None, None)])
    with pytest.raises(NotImplementedError, match="proportional loading only"):
        dc.solve(sc, dc.ArcLength(max_steps=2))


def test_field_output_for_paraview(member, tmp_path):
    """XDMF/HDF5 output: the stored displacement of the last step equals the monitored tip value."""
    import h5py

    from mpi4py import MPI

    sc = _scene(member, [(np.array([0.0, 1e-2, 0.0]), None, None)])
    path = MPI.COMM_WORLD.bcast(str(tmp_path / "member.xdmf"), root=0)  # one file for all ranks
    with dc.io.FieldWriter(sc, path) as writer:
        res = dc.solve(sc, dc.LoadControl(steps=3), on_step=writer)
    with h5py.File(path.replace(".xdmf", ".h5"), "r") as f:
        steps = sorted(f["Function/displacement"].keys(), key=lambda k: float(k.replace("_", ".")))
        assert len(steps) == 3
        u = f["Function/displacement"][steps[-1]][:]
        x = f["Mesh/mesh/geometry"][:]
    tip = np.argmax(x[:, 0])
    assert abs(u[tip, 1] - res.history.column("tip_uy")[-1]) < 1e-14


def test_prescribed_motion_as_a_function_of_the_load_factor(member):
    """A motion given as a function m(λ, stage) is followed exactly (the tip sits at m(λ) at every
    step), and equals the same path given as a piecewise-linear amplitude at the steps' load factors."""
    def motion(lam, stage):
        return 0.4 * L * np.sin(np.pi * lam / 2.0) ** 2

    lams = np.linspace(0.25, 2.0, 8)
    runs = []
    for prescribed in (motion, dc.Amplitude([(0.0, 0.0)] + [(x, motion(x, None) / (0.4 * L)) for x in lams])):
        sc = dc.Scene()
        m = sc.add_beam(member, "m", section=dc.Rectangle(B, H), material=dc.Elastic(E), orientation=(0, 1, 0))
        sc.fix(m, "base")
        if callable(prescribed) and not isinstance(prescribed, dc.Amplitude):
            sc.prescribe(m, "tip", uy=prescribed)
        else:
            sc.prescribe(m, "tip", uy=0.4 * L, amplitude=prescribed)
        sc.monitor("tip", m, "tip")
        sc.monitor_reaction("jack", m, "tip")
        runs.append(dc.solve(sc, dc.LoadControl(load_factors=lams)).history)
    np.testing.assert_allclose(runs[0].column("tip_uy"), [motion(x, None) for x in lams], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(runs[0].column("jack_Fy"), runs[1].column("jack_Fy"), rtol=1e-9)
    assert abs(runs[0].column("jack_Fy")).max() > 0.0
    with pytest.raises(ValueError, match="function of the load factor already"):
        sc.prescribe(m, "tip", uy=motion, amplitude=dc.Amplitude([(0, 0), (1, 1)]))


def test_the_secant_predictor_on_the_rotation_group(member):
    """LoadControl(extrapolate=True) with 3D rotations: each nodal rotation's last increment is
    applied again, scaled (exp(f log(q₁q₀⁻¹))q₁), and the translations' too. A tip moment
    rolling the member up to a full circle (rotations to 2π; exact: the tip at the base): the
    same end state as without the predictor (1e-9). (Its nodes move on circles, which the
    secant of positions misses: 9 iterations a step against 8 from the last state. The moment
    about the strong axis passes a lateral bifurcation on the way: its tracking is off.) A tip
    force bending the member by 60°: fewer iterations with the predictor."""
    EIz = E * B * H**3 / 12
    M = 2.0 * np.pi * EIz / L
    F = 2.0 * EIz / L**2
    for loads, steps in (([((0.0, 0.0, 0.0), (0.0, 0.0, M), None)], 8), ([((0.0, F, 0.0), (0.0, 0.0, 0.0), None)], 10)):
        runs = {}
        for extrapolate in (False, True):
            runs[extrapolate] = dc.solve(_scene(member, loads),
                                         dc.LoadControl(steps=steps, extrapolate=extrapolate, stability="off"))
        tip = {k: np.array([r.history.column(c)[-1] for c in ("tip_ux", "tip_uy", "tip_uz")]) for k, r in runs.items()}
        assert np.linalg.norm(tip[True] - tip[False]) < 1e-9 * L
        its = {k: int(r.totals["newton_iterations"]) for k, r in runs.items()}
        if loads[0][1][2]:  # the roll-up
            assert np.linalg.norm(tip[True] - [-L, 0.0, 0.0]) < 1e-6 * L
        else:
            assert its[True] < its[False], its
    with pytest.raises(NotImplementedError, match=r"extrapolate='quadratic'\) is not available for 3D rotations"):
        dc.solve(_scene(member, [((0.0, 0.0, 0.0), (0.0, 0.0, M), None)]),
                 dc.LoadControl(steps=4, extrapolate="quadratic"))

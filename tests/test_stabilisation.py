"""Stabilisation of bodies that are free until contact closes (dolfinx_corot.stabilisation): a
tunnel lining in a hole larger than itself, a block above its support; the springs' residual
force and work, exactness once contact holds the body, tangent, restart and bad input."""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import block_with_hole, ring
from dolfinx_corot.io.mesh import rectangles
from dolfinx_corot.stabilisation import Stabilisation
from fd import tangent_and_fd

comm = MPI.COMM_WORLD

# a lining (ring of 2D beams, 1 m wide plate strip) in a hole 5 mm larger than its outer face
R_AXIS, T, GAP, DEPTH = 3.0, 0.3, 0.005, 10.0
R_HOLE = R_AXIS + T / 2 + GAP
WIDTH, HEIGHT = 30.0, 25.0
E_SOIL, NU_SOIL, E_LINING = 50e6, 0.3, 30e9
N_RING = 32
W_RING = 25e3 * T * 2 * np.pi * R_AXIS     # self-weight of the lining per metre (N)
Q = 100e3                                   # surcharge on the ground surface (Pa)
SELF_WEIGHT = dc.Amplitude(((0.0, 0.0), (1.0, 1.0)))
SURCHARGE = dc.Amplitude(((1.0, 0.0), (2.0, 1.0)))


def _lining(stabilise: bool):
    """The lining in the hole of a soil block (base clamped, sides on rollers): its self-weight as
    nodal forces for 0 ≤ λ ≤ 1, then a surcharge on the surface for 1 ≤ λ ≤ 2; the lining's nodes
    are the slaves of the cavity. Nothing but contact holds the lining."""
    soil_mesh = block_with_hole(WIDTH, HEIGHT, DEPTH, R_HOLE, 2.0, 48, comm=comm)
    ring_mesh = ring(R_AXIS, N_RING, centre=(0.0, -DEPTH), name="lining", comm=comm)
    sc = dc.Scene()
    soil = sc.add_solid(soil_mesh, material=dc.SaintVenantKirchhoff(E_SOIL, NU_SOIL), degree=1)
    lining = sc.add_beam(ring_mesh, section=dc.Rectangle(1.0, T), material=dc.Elastic(E_LINING, 0.2))
    sc.fix(soil, "base")
    sc.fix(soil, "sides", dofs=("ux",))
    sc.load(lining, "lining", force=(0.0, -W_RING / N_RING), amplitude=SELF_WEIGHT)
    sc.load(soil, "top", traction=(0.0, -Q), amplitude=SURCHARGE)
    made = sc.contact(slaves=(lining, "lining"), masters=(soil, "cavity"))
    sc.monitor("crown", lining, "crown")
    sc.monitor("invert", lining, "invert")
    sc.monitor_reaction("base", soil, "base")
    stab = sc.stabilise(lining) if stabilise else None
    return sc, soil, lining, made, stab


def test_lining_in_a_larger_hole_fails_without_the_stabilisation():
    """Held only by contact with an open gap, the lining has no stiffness at the first solve: the
    tangent is singular and no step size helps."""
    sc, *_ = _lining(stabilise=False)
    assert not any(isinstance(c, Stabilisation) for c in sc.contributions())  # nothing asked, nothing paid
    with pytest.raises(dc.ConvergenceError, match="singular"):
        dc.solve(sc, dc.LoadControl(steps=4, final=2.0, max_cuts=2))


def test_lining_in_a_larger_hole_runs_through_with_the_stabilisation(hard_case):
    """With the stabilisation the lining falls 5 mm onto the bottom of the hole, then carries the
    surcharge's squeeze, in 4 steps without cuts. Hand calculations (global equilibrium): the
    soil's base carries the lining's weight and the surcharge, Σ F = W + q·B, so nothing is left
    on the springs; the contact forces on the lining add up to its weight W. The springs' work is
    tiny against the external work (trapezoidal sum of the loads times the nodal displacements)."""
    sc, soil, lining, made, stab = _lining(stabilise=True)
    assert any("stabilisation of beam" in e for e in sc.effects())
    work = {"external": 0.0, "last": None}

    def external_work(row):
        """Σ over steps of the mean load times the displacement increment: the lining's nodal forces
        and the surcharge over the surface nodes (trapezoidal along the surface)."""
        lam = row["load_factor"]
        _, u_ring = lining.model.nodes()
        X_soil, u_soil = soil.model.nodes()
        top = np.flatnonzero(np.abs(X_soil[:, 1]) < 1e-9)
        top = top[np.argsort(X_soil[top, 0])]
        now = (lam, u_ring[:, 1].sum(), np.trapz(u_soil[top, 1], X_soil[top, 0]))
        last = work["last"] or (0.0, 0.0, 0.0)
        g1 = 0.5 * (SELF_WEIGHT(last[0]) + SELF_WEIGHT(lam))
        g2 = 0.5 * (SURCHARGE(last[0]) + SURCHARGE(lam))
        work["external"] += g1 * (-W_RING / N_RING) * (now[1] - last[1]) + g2 * (-Q) * (now[2] - last[2])
        work["last"] = now

    shots = dc.plot.Snapshots(sc)

    def step(row):
        external_work(row)
        shots(row)

    res = dc.solve(sc, dc.LoadControl(steps=4, final=2.0), on_step=step)
    h = res.history
    assert h.column("cuts").sum() == 0
    # global equilibrium: the base carries everything (springs to ground would take their share)
    assert abs(h.column("base_Fy")[-1] - (W_RING + Q * WIDTH)) < 1e-8 * (W_RING + Q * WIDTH)
    assert abs(h.column("base_Fy")[1] - W_RING) < 1e-8 * W_RING  # end of the self-weight stage
    # the contact forces on the lining's nodes (minus its internal contact forces) equal its weight
    itf = made[0]
    _, _, f = itf._forces
    resultant = comm.allreduce(f[:, :2].sum(axis=0) if len(f) else np.zeros(2), op=MPI.SUM)
    assert abs(-resultant[1] - W_RING) < 1e-6 * W_RING and abs(resultant[0]) < 1e-6 * W_RING, resultant
    # the springs: used (the lining fell onto the soil), then released to the solver's tolerance
    assert h.column("stab_peak")[0] > 1e-3
    assert h.column("stab_force").max() < 1e-6
    assert 0.0 < h.column("stab_work")[-1] < 2e-3 * work["external"], (h.column("stab_work")[-1], work)
    # the lining rests on the bottom of the hole: it moved down by more than the gap, and stayed
    # centred and unspun although frictionless contact with a circle leaves its spin free
    assert h.column("invert_uy")[1] < -GAP and h.column("crown_uy")[-1] < h.column("invert_uy")[-1]
    assert np.abs(h.column("crown_ux")).max() < 1e-4 and np.abs(h.column("crown_rz")).max() < 1e-5
    # the serial numbers on every partition (measured on one rank)
    np.testing.assert_allclose([h.column("invert_uy")[-1], h.column("crown_uy")[-1]], [-0.021557810199, -0.030429353895],
                               rtol=1e-8)
    hard_case("A lining in a larger hole, held by contact alone",
              "Before contact closes the lining floats: the tangent is singular at the first solve and no step "
              "size helps (the run without stabilisation fails). Weak springs to ground, re-anchored after each "
              "converged solve, must carry it onto the bottom of the hole and then release everything.",
              {"steps": len(h), "Newton iterations": res.totals["newton_iterations"], "cuts": res.totals["cuts"],
               "peak spring force (first step)": float(h.column("stab_peak")[0]),
               "spring force left at the end": float(h.column("stab_force").max()),
               "spring work / external work": float(h.column("stab_work")[-1] / work["external"]),
               "base reaction − (W + qB), relative": float(h.column("base_Fy")[-1] / (W_RING + Q * WIDTH) - 1.0)},
              picture=(shots.states, {"title": "lining settled in the hole, then squeezed (×1)"}))


# -- a block pressed onto a support through contact ------------------------------------------------
E, NU, P = 1.0, 0.3, 0.01  # plane strain, as the contact patch test (B5)


def _blocks(gap: float, stabilise: bool, **options):
    """A unit block [0,1] × [1 + gap, 2 + gap] (4 × 2 quadrilaterals) pressed by a pressure P onto a
    unit block below (3 × 2, base clamped) through augmented-Lagrangian contact; the left sides on
    rollers: only contact holds the upper block vertically."""
    tm = rectangles({"lower": (0.0, 0.0, 1.0, 1.0, 3, 2), "upper": (0.0, 1.0 + gap, 1.0, 1.0, 4, 2)},
                    {"base": [("lower", "bottom")], "lower_top": [("lower", "top")],
                     "upper_bottom": [("upper", "bottom")], "top": [("upper", "top")],
                     "left": [("lower", "left"), ("upper", "left")]}, comm=comm)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    sc.fix(b, "base")
    sc.fix(b, "left", dofs=("ux",))
    sc.load(b, "top", traction=(0.0, -P))
    sc.contact(slaves=(b, "upper_bottom"), masters=(b, "lower_top"), law=dc.AugmentedLagrangian())
    sc.monitor_reaction("base", b, "base")
    stab = sc.stabilise(b, where="upper", **options) if stabilise else None
    return sc, b, stab


def _displacements(sc, gap: float) -> np.ndarray:
    """All nodal displacements (partition-independent order), the upper block's shifted by the gap
    it closed (u_y + gap): comparable with a run that starts in contact."""
    X, u = sc.model.nodes()
    u = u.copy()
    u[X[:, 1] > 1.0 + gap / 2, 1] += gap
    return u


def test_stabilised_block_equals_the_unstabilised_one_once_contact_is_closed():
    """Starting in contact (zero gap) the block needs no stabilisation: that run is the reference.
    Stabilised, the same block — and the block started 1 mm above its support — end in the same
    state to the solver's tolerance (the upper block shifted by the gap it closed), because the
    springs are re-anchored until they carry nothing; springs kept on the step's increment instead
    (max_updates=0, as a viscous stabilisation) leave an error of k/K. The base reaction equals
    the applied load P·1 in every run (global equilibrium)."""
    steps = dc.LoadControl(steps=2)
    sc, _, _ = _blocks(0.0, stabilise=False)
    ref = dc.solve(sc, steps)
    assert "stab_work" not in ref.history.columns
    u_ref = _displacements(sc, 0.0)
    scale = np.abs(u_ref).max()
    assert scale > 0.01  # settles by P (1 − ν²) · 2 / E ≈ 0.018, and the penalty's share
    errors = {}
    # "crawl": stiff springs, 0.05 per node (a thirtieth of the block's mean tangent diagonal, 3·10⁴ times
    # the default): each re-anchoring releases only part of their force, more than ten re-anchorings in
    # the first step, and the same answer
    for label, gap, options in (("closed", 0.0, {}), ("gap", 1e-3, {}), ("viscous", 0.0, {"max_updates": 0}),
                                ("crawl", 1e-3, {"stiffness": 0.05, "max_updates": 50})):
        sc, _, stab = _blocks(gap, stabilise=True, **options)
        res = dc.solve(sc, steps)
        h = res.history
        assert abs(h.column("base_Fy")[-1] - P) < (1e-9 if options == {} else 1e-4) * P, (label, h.column("base_Fy"))
        errors[label] = np.abs(_displacements(sc, gap) - u_ref).max() / scale
        if label != "viscous":
            assert h.column("stab_updates").min() >= 1 and h.column("stab_force").max() < 1e-9, label
        if label == "crawl":
            assert h.column("stab_updates")[0] > 10 and h.column("stab_peak")[0] > 0.1, h.column("stab_updates")
    assert errors["closed"] < 1e-8 and errors["gap"] < 1e-8 and errors["crawl"] < 1e-8, errors
    assert errors["viscous"] > 1e3 * errors["closed"], errors  # the re-anchoring is what removes them


def test_stabilised_block_under_arc_length():
    """Arc-length from a closed contact: every step ends in equilibrium with the springs released
    (base reaction λ·P, the springs' force below the solver's tolerance)."""
    sc, _, _ = _blocks(0.0, stabilise=True)
    res = dc.solve(sc, dc.ArcLength(initial_increment=0.25, max_load_factor=1.0, max_steps=10))
    h = res.history
    lam = h.column("load_factor")
    assert lam[-1] >= 1.0 and h.column("cuts").sum() == 0
    np.testing.assert_allclose(h.column("base_Fy"), lam * P, rtol=1e-8)
    assert h.column("stab_force").max() < 1e-9 and h.column("stab_updates").min() >= 1


@pytest.mark.skipif(comm.size > 1, reason="dense finite differences of the assembled system: serial")
@pytest.mark.parametrize("kind", ["beam", "solid"])
def test_stabilisation_tangent_matches_finite_differences(kind):
    """The system's tangent (part + springs) against central differences of its residual at a
    perturbed state away from the anchors; and the springs' force k·d under a rigid translation d
    (the elements carry nothing: the internal force is the springs' alone)."""
    from dolfinx_corot.assembly import make_system

    sc = dc.Scene()
    if kind == "beam":
        tm = dc.io.gmsh_models.polyline([[0.0, 0.0], [1.0, 0.5], [2.0, 0.0]], 2)
        part = sc.add_beam(tm, section=dc.Rectangle(0.1, 0.2), material=dc.Elastic(1e4, 0.3))
        stab = sc.stabilise(part, stiffness=30.0, rotational_stiffness=2.0)
    else:
        tm = rectangles({"block": (0.0, 0.0, 1.0, 1.0, 2, 2)}, comm=comm)
        part = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, NU), degree=1)
        stab = sc.stabilise(part, stiffness=0.7)
    system = make_system(sc.model, contributions=sc.contributions())
    model = sc.model
    k = stab.k
    assert np.allclose(k, [30.0, 30.0, 2.0] if kind == "beam" else [0.7, 0.7])
    # a rigid translation: f_int = k d on every node
    d = np.array([0.013, -0.021])
    state = model.state.x.array.reshape(-1, model.state_size)
    state[:, :2] = d
    system.residual(0.0)
    fint = system.internal_force().array.reshape(-1, model.ndof)
    np.testing.assert_allclose(fint[:, :2], np.broadcast_to(k[:2] * d, fint[:, :2].shape), rtol=1e-9, atol=1e-12)
    # finite differences at a perturbed state
    rng = np.random.default_rng(3)
    model.state.x.array[:] += rng.uniform(-0.02, 0.02, model.state.x.array.shape)
    K, Kfd = tangent_and_fd(system, model.state.x.array, 0.0)
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()
    # the springs alone: K − K without them is k on the diagonal
    bare = make_system(model)
    bare.residual(0.0)
    bare.jacobian()
    springs = K - bare.A.convert("dense").getDenseArray()
    np.testing.assert_allclose(springs, np.diag(np.tile(k, len(K) // len(k))), atol=1e-9 * np.abs(K).max())
    bare.destroy()
    system.destroy()


def test_restart_from_a_checkpoint_reproduces_the_uninterrupted_run(tmp_path):
    """The block starting 1 mm above its support, 4 steps: stopped after 2 with a checkpoint and
    restarted in a new scene, the run gives the uninterrupted numbers (work of the springs,
    reactions, displacements) exactly; a scene without the stabilisation refuses the file."""
    path = str(tmp_path / "block.npz") if comm.rank == 0 else None
    path = comm.bcast(path, root=0)
    sc, _, _ = _blocks(1e-3, stabilise=True)
    whole = dc.solve(sc, dc.LoadControl(steps=4))
    u_whole = _displacements(sc, 1e-3)
    sc, _, _ = _blocks(1e-3, stabilise=True)
    dc.solve(sc, dc.LoadControl(load_factors=[0.25, 0.5]), checkpoint=path)
    sc, _, _ = _blocks(1e-3, stabilise=True)
    again = dc.solve(sc, dc.LoadControl(steps=4), restart=path)
    assert len(again.history) == 4
    for col in ("load_factor", "stab_work", "stab_force", "stab_updates", "base_Fy", "iterations"):
        np.testing.assert_allclose(again.history.column(col), whole.history.column(col), rtol=1e-12, atol=1e-15,
                                   err_msg=col)
    np.testing.assert_allclose(_displacements(sc, 1e-3), u_whole, rtol=0, atol=1e-14)
    sc, _, _ = _blocks(1e-3, stabilise=False)
    with pytest.raises(dc.CheckpointError, match="stabilisation"):
        dc.solve(sc, dc.LoadControl(steps=4), restart=path)


def test_bad_stabilisation_input_is_refused_naming_the_culprit():
    tm = rectangles({"lower": (0.0, 0.0, 1.0, 1.0, 2, 2), "upper": (0.0, 1.0, 1.0, 1.0, 2, 2)},
                    {"base": [("lower", "bottom")], "top": [("upper", "top")]}, comm=comm)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    upper = sc.add_solid(tm, "upper", material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    with pytest.raises(ValueError, match=r"stabilise solid 'all cells': stiffness = -1\.0 must be a finite number > 0"):
        sc.stabilise(b, stiffness=-1.0)
    with pytest.raises(ValueError, match="stiffness = 0"):
        sc.stabilise(b, stiffness=0)
    with pytest.raises(ValueError, match="factor = nan"):
        sc.stabilise(b, factor=float("nan"))
    with pytest.raises(ValueError, match="max_updates = -1"):
        sc.stabilise(b, max_updates=-1)
    with pytest.raises(dc.GroupNotFoundError, match="'nowhere' not found"):
        sc.stabilise(b, where="nowhere")
    with pytest.raises(ValueError, match="solid 'upper' at 'base': group 'base' has no node of this part"):
        sc.stabilise(upper, where="base")  # the base is the lower block's
    with pytest.raises(ValueError, match="without planar rotations"):
        sc.stabilise(b, rotational_stiffness=1.0)
    with pytest.raises(TypeError, match="part must be a part of the scene"):
        sc.stabilise(tm)
    sc.stabilise(upper, where="top")
    with pytest.raises(ValueError, match="solid 'upper' at 'top' is stabilised already"):
        sc.stabilise(upper, where="top")

"""3D node-to-face contact between solids (issue 15, first part): two blocks of tetrahedra with
non-matching faces pressed together. References: the homogeneous uniaxial state of the patch test
(u_z = −p z/E, u_x = ν p x/E, u_y = ν p y/E), global equilibrium, and central differences of the
assembled residual."""
import gmsh
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.mesh import from_gmsh
from fd import free_part, tangent_and_fd

comm = MPI.COMM_WORLD
E, NU, P = 100.0, 0.3, 1.0


def _two_blocks(h_low: float, h_up: float, gap: float = 0.0, matching: bool = False):
    """Blocks [0, 1]² × [0, 0.5] ('lower') and [0, 1]² × [0.5, 1] + gap ('upper') of tetrahedra of
    sizes h_low and h_up, not joined: faces 'lower_face' at z = 0.5 and 'upper_face' at 0.5 + gap
    (non-matching; ``matching``: the upper face meshed as a copy of the lower one), 'base' (z = 0),
    'top', 'x0' and 'y0' (the symmetry planes of both)."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("blocks")
        occ = gmsh.model.occ
        low, up = occ.addBox(0, 0, 0, 1, 1, 0.5), occ.addBox(0, 0, 0.5 + gap, 1, 1, 0.5)
        occ.synchronize()
        groups = {}
        for vol, name, h in ((low, "lower", h_low), (up, "upper", h_up)):
            gmsh.model.mesh.setSize(gmsh.model.getBoundary([(3, vol)], recursive=True), h)
            for _, tag in gmsh.model.getBoundary([(3, vol)], oriented=False):
                x, y, z = occ.getCenterOfMass(2, tag)
                face = ("base" if z < 1e-9 else "top" if z > 1 + gap - 1e-9 else
                        f"{name}_face" if min(abs(z - 0.5), abs(z - 0.5 - gap)) < 1e-9 else
                        "x0" if x < 1e-9 else "y0" if y < 1e-9 else None)
                if face:
                    groups.setdefault(face, []).append(tag)
            gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [vol]), name)
        if matching:
            shift = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, gap, 0, 0, 0, 1]
            gmsh.model.mesh.setPeriodic(2, groups["upper_face"], groups["lower_face"], shift)
        for name, tags in groups.items():
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.model.mesh.generate(3)
    tm = from_gmsh(gmsh.model, 3, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _patch_scene(law, symmetric: bool = True, matching: bool = False, discretization: str = "node_to_face",
                 sizes: tuple[float, float] = (0.26, 0.35), smooth: bool = False):
    sc = dc.Scene(large_rotations=False, linear_solver="direct")
    tm = _two_blocks(sizes[0], sizes[0] if matching else sizes[1], matching=matching)
    b = sc.add_solid(tm, material=dc.Elastic(E, NU), degree=1)
    sc.fix(b, "base", dofs=("uz",))
    sc.fix(b, "x0", dofs=("ux",))
    sc.fix(b, "y0", dofs=("uy",))
    sc.load(b, "top", traction=(0.0, 0.0, -P))
    pair = sc.contact((b, "upper_face"), (b, "lower_face"), law=law, symmetric=symmetric,
                      discretization=discretization, smooth=smooth)
    sc.monitor_contact("c", pair)
    return sc, b, pair


def _nodal(b) -> dict:
    """{(reference position, in the upper block): displacement} of every node, on every rank
    (partition-independent; the two blocks have nodes at the same place on the interface)."""
    m = b.model
    n = m.V.dofmap.index_map.size_local
    upper = np.zeros(n + m.V.dofmap.index_map.num_ghosts, dtype=bool)
    cells = m.tmesh.cells("upper")
    upper[m.V.dofmap.list.array.reshape(-1, 4)[cells].ravel()] = True
    X = np.concatenate(comm.allgather(np.round(m.V.tabulate_dof_coordinates()[:n], 9)))
    side = np.concatenate(comm.allgather(upper[:n]))
    u = np.concatenate(comm.allgather(m.state.x.array.reshape(-1, 3)[:n]))
    return {(*p, s): v for p, s, v in zip(X, side, u)}


def _errors(b):
    """(largest error of the lower block, of the upper one less its mean) against the homogeneous
    state, in units of p/E, over all ranks."""
    m = b.model
    n = m.V.dofmap.index_map.size_local
    X = m.V.tabulate_dof_coordinates()[:n]
    u = m.state.x.array.reshape(-1, 3)[:n]
    d = u - np.column_stack([NU * P * X[:, 0] / E, NU * P * X[:, 1] / E, -P * X[:, 2] / E])
    up = X[:, 2] > 0.5 + 1e-9
    low = comm.allreduce(float(np.abs(d[~up]).max(initial=0.0)), op=MPI.MAX)
    total = comm.allreduce(d[up].sum(axis=0), op=MPI.SUM)
    count = comm.allreduce(int(up.sum()), op=MPI.SUM)
    upper = comm.allreduce(float(np.abs(d[up] - total / count).max(initial=0.0)), op=MPI.MAX)
    return low / (P / E), upper / (P / E), total / count


def test_two_blocks_pressed_through_a_non_matching_interface():
    """The contact patch test in 3D, two-pass, non-matching triangulations (face sizes 0.26 and
    0.35, different orientations). The interface transmits the whole load: its resultant is
    (0, 0, P) to solver tolerance (1e-9; tangential parts below 1e-4 P) and the nominal pressure
    is within 5.6 % of P at every node with the penalty (measured; bound 6 %: the two passes'
    penetrations, 1.5e-4 of the height, differ from node to node), within 0.92 % with the
    augmented Lagrangian (bound 1 %), whose ten Uzawa updates bring both blocks towards the
    homogeneous state: largest errors 3.0 % and 1.1 % of p/E with the penalty (lower block;
    upper less its mean shift), 0.25 % and 0.17 % after the updates (bounds: a tenth and a fifth
    of the penalty's). Two-pass node-to-face contact on non-matching faces does not pass the patch
    test exactly, and no penalty or number of updates makes it: see the next test."""
    sc, b, pair = _patch_scene(dc.Penalty())
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    assert row["c_Fz"] == pytest.approx(P, rel=1e-9)
    assert abs(row["c_Fx"]) < 1e-4 * P and abs(row["c_Fy"]) < 1e-4 * P
    p = pair.pressure("slaves").pressure
    assert np.abs(p - P).max() < 0.06 * P
    penalty = _errors(b)
    assert penalty[0] < 0.035 and penalty[1] < 0.015

    sc, b, pair = _patch_scene(dc.AugmentedLagrangian(gap_tolerance=1e-10))
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    assert row["uzawa_updates"] >= 5
    assert row["c_Fz"] == pytest.approx(P, rel=1e-9)
    p = pair.pressure("slaves").pressure
    assert np.abs(p - P).max() < 0.01 * P
    augmented = _errors(b)
    assert augmented[0] < 0.1 * penalty[0] and augmented[1] < 0.2 * penalty[1]


def test_two_pass_patch_test_is_exact_on_matching_faces_and_has_a_discrete_limit_on_non_matching_ones():
    """Why two-pass node-to-face contact cannot pass the 3D patch test on non-matching faces: the
    homogeneous state is a solution only if multipliers λ (one per slave of either pass) give
    every interface node its consistent share p∫N dA; that square system, λ_A + N_AB λ_B = p a_A
    and λ_B + N_BA λ_A = p a_B (N: the other side's shape functions at the slaves), has rank 47 for
    51 nodes on these meshes and a right-hand side outside its range (least-squares residual 1.6e-5
    of p; its left null space holds the affine functions and a corner mode). The augmented
    Lagrangian therefore converges to another state: 8.32e-5 p/E from the homogeneous one,
    the same to 1e-6 with penalties 10² and 10⁴ × the default (measured) — a property of the
    discretization, not of the solver; passing the patch test on non-matching faces takes a mortar
    (segment-to-segment) discretization. On matching faces (the upper face meshed as a copy of the
    lower) the same two-pass augmented Lagrangian reproduces the homogeneous state to 1e-12 p/E."""
    sc, b, pair = _patch_scene(dc.AugmentedLagrangian(factor=1e3, gap_tolerance=1e-12, max_updates=30),
                               matching=True)
    dc.solve(sc, dc.LoadControl(steps=1))
    low, upper, shift = _errors(b)
    assert low < 1e-12 and upper < 1e-12 and np.abs(shift).max() < 1e-12 * P / E
    limits = []
    for factor in (1e3, 1e5):
        sc, b, pair = _patch_scene(dc.AugmentedLagrangian(factor=factor, gap_tolerance=1e-12, max_updates=30))
        row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
        assert row["cuts"] == 0
        limits.append(_errors(b)[0])
    assert limits[0] == pytest.approx(limits[1], rel=1e-6)
    assert 5e-5 < limits[0] < 1.2e-4


@pytest.mark.skipif(comm.size > 1, reason="dense finite differences of the assembled system: serial")
@pytest.mark.parametrize("symmetric, smooth", [(False, False), (True, False), (True, True)])
def test_assembled_3d_contact_tangent_matches_finite_differences(symmetric, smooth):
    """The system's tangent (blocks + contact) against central differences of its residual at a
    penetrating, sheared, randomly perturbed state, with augmented-Lagrangian multipliers
    (slaves on faces, some beyond the border of the master surface): 1e-6 of the largest entry.
    With the smoothed masters the perturbation tilts every nodal normal: the tangent couples each
    slave to the whole stencil of its face, and is not symmetric; there the bound is 1e-4 (measured
    1.6e-5 in one entry of a slave at the surface's border; not yet explained: each kernel's own
    tangent matches its differences to 1e-7, tests/test_smooth3d.py)."""
    from dolfinx_corot.assembly import make_system

    sc, b, pair = _patch_scene(dc.AugmentedLagrangian(), symmetric, smooth=smooth)
    for itf in sc.interfaces:
        itf.multiplier[:] = 0.3 * P
    system = make_system(sc.model, contributions=sc.contributions())
    model = sc.model
    X = model.V.tabulate_dof_coordinates()
    u = model.state.x.array.reshape(-1, 3)
    rng = np.random.default_rng(5)
    upper = X[:, 2] > 0.5 - 1e-12
    u[:, 2] = np.where(upper, -0.02, 0.0)
    u[:, 0] = 0.01 * X[:, 2] ** 2
    u += rng.uniform(-1e-3, 1e-3, u.shape)
    K, Kfd = free_part(system, *tangent_and_fd(system, model.state.x.array, 1.0))
    assert sum(int((itf.active >= 0).sum()) for itf in sc.interfaces) > 10
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()
    assert (np.abs(K - K.T).max() > 1e-4 * np.abs(K).max()) == smooth
    system.destroy()


def test_3d_contact_input_is_checked_by_name():
    """Refused by name: a group that is not a face group of the solid, mortar contact on a smoothed
    master, a quadratic solid, and a 3D beam as the master (a beam meets faces by its nodes)."""
    from dolfinx_corot.io.gmsh_models import polyline

    tm = _two_blocks(0.5, 0.5)
    sc = dc.Scene(large_rotations=False)
    b = sc.add_solid(tm, material=dc.Elastic(E, NU), degree=1)
    with pytest.raises(dc.ContactError, match="mortar contact 'upper_face -> lower_face': the pressure acts along "
                                              "the slave faces' normals, a smoothed master surface does not apply"):
        sc.contact((b, "upper_face"), (b, "lower_face"), smooth=True, discretization="mortar")
    with pytest.raises(ValueError, match="contact surface 'lower' is not a group of boundary faces"):
        sc.contact((b, "upper_face"), (b, "lower"))
    beam = sc.add_beam(polyline([[0.2, 0.2, 0.9], [0.8, 0.2, 0.9]], 2, gdim=3), "beam", section=dc.Rectangle(0.1, 0.1),
                       material=dc.Elastic(E, NU), orientation=(0.0, 0.0, 1.0))
    with pytest.raises(dc.ContactError, match="the master 'beam' of beam 'beam' is a line, not a surface of faces: "
                                              "a 3D beam meets solids and shells by its nodes"):
        sc.contact((b, "upper_face"), (beam, "beam"))
    with pytest.raises(dc.ContactError, match="solid–beam contact is one-pass"):
        sc.contact((beam, "beam"), (b, "lower_face"), symmetric=True)
    assert len(sc.contact((beam, "beam"), (b, "lower_face"))) == 1
    quadratic = dc.Scene(large_rotations=False).add_solid(tm, material=dc.Elastic(E, NU), degree=2)
    with pytest.raises(ValueError, match="contact surface 'upper_face': node-to-face contact needs linear solids"):
        quadratic.model.surface("upper_face")


def _blocks_scene(law, swap: bool = False, contact: bool = True, lift: float = 0.0, gap: float = 0.3,
                  discretization: str = "node_to_face"):
    """The patch test's blocks, two-pass, contact monitored as 'c'; ``swap``: slaves and masters
    given the other way round; ``lift``: the upper block, ``gap`` above the lower one, has its top
    moved up by this much (prescribed) instead of loaded."""
    sc = dc.Scene(large_rotations=False, linear_solver="direct")
    b = sc.add_solid(_two_blocks(0.26, 0.35, gap if lift else 0.0), material=dc.Elastic(E, NU), degree=1)
    sc.fix(b, "base", dofs=("uz",))
    sc.fix(b, "x0", dofs=("ux",))
    sc.fix(b, "y0", dofs=("uy",))
    if lift:
        sc.prescribe(b, "top", uz=lift)
    else:
        sc.load(b, "top", traction=(0.0, 0.0, -P))
    if contact:
        sides = [(b, "upper_face"), (b, "lower_face")]
        sc.monitor_contact("c", sc.contact(*(sides[::-1] if swap else sides), law=law, symmetric=True,
                                           discretization=discretization))
    return sc, b


@pytest.mark.parametrize("scale", [1e-2, 1.0, 1e4])
def test_penalties_over_six_decades_converge_and_transmit_the_load(scale):
    """Hard case: the patch test's two-pass penalty contact with ε from 10⁻² to 10⁴ times the
    default converges without a cut step and the interface transmits the load to Newton's
    tolerance (1e-8: the residual is 1e-9 of the force scale, the stiffest penalty measured
    1.9e-9 on two ranks);
    each pass carries about half of it, so the slaves' mean penetration is about p/(2ε) (bounds
    0.3 and 0.7 of p/ε)."""
    sc, b = _blocks_scene(dc.Penalty(factor=10.0 * scale))
    result = dc.solve(sc, dc.LoadControl(steps=1))
    assert result.history.column("cuts").sum() == 0
    assert result.history.rows[-1]["c_Fz"] == pytest.approx(P, rel=1e-8)
    eps = sc.interfaces[0].penalty
    gaps = np.concatenate(comm.allgather(sc.interfaces[0].gaps()[1]))
    assert 0.3 * P / eps < -gaps.mean() < 0.7 * P / eps


def test_swapping_slaves_and_masters_of_symmetric_contact_gives_the_same_answer():
    """Hard case: two-pass contact declared either way round is the same pair of passes: the
    displacements agree to solver tolerance (1e-9 of the largest)."""
    states = []
    for swap in (False, True):
        sc, b = _blocks_scene(dc.Penalty(), swap=swap)
        dc.solve(sc, dc.LoadControl(steps=1))
        states.append(_nodal(b))
        assert len(states[-1]) == b.model.V.dofmap.index_map.size_global  # no two nodes under one key
    scale = max(np.abs(u).max() for u in states[0].values())
    assert max(np.abs(states[1][p] - u).max() for p, u in states[0].items()) < 1e-9 * scale


@pytest.mark.parametrize("discretization, gap", [("node_to_face", 0.3), ("mortar", 0.8)])
def test_an_idle_3d_interface_leaves_the_solution_bit_identical(discretization, gap):
    """Hard case (effects on demand): the upper block lifted away from the lower one (beyond the
    search's reach: a mortar pair's reaches by a slave face's size further), with and without a
    declared interface: the solutions are bit-identical, and no contact matrix is built (for
    mortar: the solver keeps its LDLᵀ factorization while the interface is idle)."""
    from dolfinx_corot.assembly import make_system

    states = []
    for contact in (False, True):
        sc, b = _blocks_scene(dc.Penalty(), contact=contact, lift=0.2, gap=gap, discretization=discretization)
        system = make_system(sc.model, solver=sc.linear_solver, contributions=sc.contributions())
        dc.solve(sc, dc.LoadControl(steps=2), system=system)
        if contact:
            assert system.C is None
        system.destroy()
        states.append(_nodal(b))
    assert all(np.array_equal(states[1][p], u) for p, u in states[0].items())


@pytest.mark.skipif(comm.size > 1, reason="one slave lifted by hand: serial")
def test_a_touching_pair_keeps_its_stiffness_only_in_the_first_evaluations_once_others_carry_load():
    """A pair open by less than the touch band (no force) keeps the penalty stiffness in the first
    ``TOUCH_EVALUATIONS`` evaluations of a Newton solve, then, while other pairs are closed, no
    longer: a stiffness without a force is not the residual's derivative (Newton converged linearly,
    0.83 per iteration, at the zero-pressure, zero-gap nodes of a two-pass interface between
    non-matching faces of 3268 nodes, measured). Pressed blocks, one slave lifted to half the band."""
    from dolfinx_corot.assembly import make_system
    from dolfinx_corot.contact.interface3d import Interface3D

    sc, b, pair = _patch_scene(dc.Penalty(), symmetric=False)
    system = make_system(sc.model, solver=sc.linear_solver, contributions=sc.contributions())
    itf = sc.interfaces[0]
    m = b.model
    X = m.V.tabulate_dof_coordinates()
    u = m.state.x.array.reshape(-1, 3)
    upper = np.zeros(len(X), dtype=bool)
    upper[m.V.dofmap.list.array.reshape(-1, 4)[m.tmesh.cells("upper")].ravel()] = True
    u[upper, 2] = -1e-3  # the upper block pressed 1e-3 into the lower one
    k = int(np.argmin(np.linalg.norm(itf.slave.X[:, :2] - 0.5, axis=1)))  # a slave inside the face
    node = np.flatnonzero(upper & np.all(np.isclose(X, itf.slave.X[k]), axis=1))
    assert len(node) == 1
    u[node, 2] = 0.5 * itf.touch  # open by half the band
    itf.first_evaluation = True
    kept = []
    for _ in range(Interface3D.TOUCH_EVALUATIONS + 2):
        dofs, f, K, (s, faces) = itf.evaluate()
        kept.append(k in s)
        if k in s:
            j = list(s).index(k)
            assert np.all(f[j] == 0.0) and np.abs(K[j]).max() > 0.0
    assert kept == [True] * Interface3D.TOUCH_EVALUATIONS + [False, False]
    assert len(s) > 10  # the others closed
    system.destroy()


def _slider_3d(quad: bool):
    """A base block [0, 3] × [0, 2] × [0, 0.5] with a coarse structured top (faces 0.5: squares, or
    each split in two triangles) and a slider [0.5, 1.5] × [0.5, 1.5] × [0.5, 1] of spacing 0.25
    on it, not joined: groups 'base', 'base_top', 'slider_bottom', 'top'. The slider's nodes sit
    over the base's vertices and edge midpoints."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        vols = {"base_block": occ.addBox(0, 0, 0, 3, 2, 0.5), "slider": occ.addBox(0.5, 0.5, 0.5, 1, 1, 0.5)}
        occ.synchronize()
        groups = {}
        for name, vol in vols.items():
            h = 0.5 if name == "base_block" else 0.25  # the spacing in plan; two layers through the height
            faces = [tag for _, tag in gmsh.model.getBoundary([(3, vol)], oriented=False)]
            for _, curve in gmsh.model.getBoundary([(2, f) for f in faces], combined=False, oriented=False):
                x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(1, abs(curve))
                n = 2 if z1 - z0 > 0.1 else int(round(max(x1 - x0, y1 - y0) / h))
                gmsh.model.mesh.setTransfiniteCurve(abs(curve), n + 1)
            for tag in faces:
                gmsh.model.mesh.setTransfiniteSurface(tag)
                if quad:
                    gmsh.model.mesh.setRecombine(2, tag)
                z = occ.getCenterOfMass(2, tag)[2]
                face = ("base" if z < 1e-9 else "top" if z > 1 - 1e-9 else None if abs(z - 0.5) > 1e-9 else
                        "base_top" if name == "base_block" else "slider_bottom")
                if face:
                    groups[face] = [tag]
            gmsh.model.mesh.setTransfiniteVolume(vol)
            if quad:
                gmsh.model.mesh.setRecombine(3, vol)
            gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [vol]), name)
        for name, tags in groups.items():
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.model.mesh.generate(3)
    tm = from_gmsh(gmsh.model, 3, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _slider_scene(tm, press: float, contact: bool = True):
    """The slider on the base (two-pass augmented Lagrangian, Uzawa to 1e-7 of a face: the
    settlement is 5e-5), its top prescribed: settled by the uniaxial strain of a pressure ``press``
    in the first of 17 steps, then moved by (1, 0.5); without ``contact`` the slider alone with
    its bottom on rollers (the rigid frictionless flat; the base unloaded)."""
    sc = dc.Scene(large_rotations=True, linear_solver="direct")
    b = sc.add_solid(tm, "slider", material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    sc.prescribe(b, "top", amplitude=dc.Amplitude(((0.0, 0.0), (1 / 17, 1.0), (1.0, 1.0))),
                 uz=-press * 0.5 / E if press else 0.0)
    sc.add_solid(tm, "base_block", material=dc.SaintVenantKirchhoff(1000 * E, NU), degree=1)
    sc.fix(b, "base")
    if contact:
        sc.prescribe(b, "top", ux=1.0, uy=0.5)
        sc.contact((b, "slider_bottom"), (b, "base_top"), law=dc.AugmentedLagrangian(gap_tolerance=1e-7),
                   symmetric=True)
    else:
        sc.prescribe(b, "top", ux=0.0, uy=0.0)
        sc.fix(b, "slider_bottom", dofs=("uz",))
    sc.monitor_reaction("top", b, "top")
    return sc


@pytest.mark.parametrize("quad", [False, True], ids=["triangles", "quadrilaterals"])
@pytest.mark.parametrize("press", [0.01, 0.0], ids=["pressed", "grazing"])
def test_a_block_slides_over_the_edges_and_vertices_of_a_coarse_master(quad, press):
    """Hard case: a slider (spacing 0.25) pushed by its top by (1, 0.5) over a base 1000 times
    stiffer whose top has faces of 0.5 (squares or triangles), pressed by a settlement of its top
    or only touching (grazing: zero gaps throughout). On the way its bottom nodes cross the base's
    edges and sit exactly on its vertices and edges (at the travels (0.5, 0.25) and (1, 0.5)), and
    the base's nodes pass under the border of the slider's bottom. Without friction, on a base
    this stiff, contact is the rigid frictionless flat: the normal force equals that of the slider
    on rollers at every step (0.3 %; measured 0.07 %: the base's compliance, 1e-3 of the slider's), the horizontal
    forces are nil (1e-5 of it; measured 3e-8); grazing, every force vanishes (1e-12). Every step
    converges without a cut (at most 20 Newton iterations over its two Uzawa updates). Before
    slaves beyond the border of a solid's surface met its edges from outside only, a base node a
    hair below the slider's bottom and beside it counted as penetrating by its distance to the
    edge, and no step converged."""
    tm = _slider_3d(quad)
    h = dc.solve(_slider_scene(tm, press), dc.LoadControl(steps=17)).history
    assert h.column("cuts").sum() == 0
    assert h.column("iterations").max() <= 20, h.column("iterations")
    Fz = h.column("top_Fz")
    Ft = np.hypot(h.column("top_Fx"), h.column("top_Fy"))
    if press:
        rollers = dc.solve(_slider_scene(tm, press, contact=False), dc.LoadControl(steps=1)).history.column("top_Fz")
        assert np.abs(Fz / rollers[-1] - 1.0).max() < 3e-3, (Fz, rollers)
        assert Ft.max() < 1e-5 * abs(Fz).max(), Ft
    else:
        assert np.abs(Fz).max() < 1e-12 and Ft.max() < 1e-12

"""3D contact of solids with shells and beams (issue 15): a shell plate and a pipe resting on an
elastic block under their own weight. The shell is a two-sided contact surface (its faces at ±t/2
from the mid-surface), met from either side and as slaves or masters; a beam meets the block's faces
by its nodes at the section's outer radius. References: global equilibrium (the contact resultant is
the weight), the uniaxial compression of the block under the mean pressure (settlement q H/E at the
top, 0.5·10⁻² here), the geometry of the offsets, and central differences of the interfaces' forces
(the kernels' own derivatives are in test_contact3d_kernels.py)."""
import gmsh
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import from_gmsh

comm = MPI.COMM_WORLD
E, NU, H = 100.0, 0.3, 0.5          # the block [0, 1]² × [0, H]
T, RHO, G = 0.05, 2.0, 10.0          # the plate: thickness, density; gravity
SIDE = 1.0                           # the plate covers the block's top
R_PIPE, T_PIPE = 0.05, 0.01          # the pipe: outer radius, wall


def _block(h: float, length: float = 1.0, sides=("x0", "y0")):
    """The block [0, length] × [0, 1] × [0, H] of tetrahedra of size h: faces 'base', 'top' and
    ``sides``: the faces x = 0 and y = 0 ('x0', 'y0'), or both x faces and both y faces
    ('xends', 'ysides')."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("block")
        occ = gmsh.model.occ
        v = occ.addBox(0, 0, 0, length, 1, H)
        occ.synchronize()
        gmsh.model.mesh.setSize(gmsh.model.getBoundary([(3, v)], recursive=True), h)
        groups = {}
        for _, tag in gmsh.model.getBoundary([(3, v)], oriented=False):
            x, y, z = occ.getCenterOfMass(2, tag)
            name = ("base" if z < 1e-9 else "top" if z > H - 1e-9 else
                    sides[0] if x < 1e-9 or (sides[0] == "xends" and x > length - 1e-9) else
                    sides[1] if y < 1e-9 or sides[1] == "ysides" else None)
            if name:
                groups.setdefault(name, []).append(tag)
        gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [v]), "block")
        for name, tags in groups.items():
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.model.mesh.generate(3)
    tm = from_gmsh(gmsh.model if comm.rank == 0 else None, 3, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _plate(n: int, z: float, flip: bool):
    """The square [0, SIDE]² at height z, n × n squares cut into triangles (normal +z, or −z if
    ``flip``): cells 'plate', edges 'px0' (x = 0) and 'py0' (y = 0)."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("plate")
        g = gmsh.model.geo
        p = [g.addPoint(x, y, z) for x, y in ((0, 0), (SIDE, 0), (SIDE, SIDE), (0, SIDE))]
        lines = [g.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
        loop = g.addCurveLoop([-t for t in lines[::-1]] if flip else lines)
        s = g.addPlaneSurface([loop])
        g.synchronize()
        for line in lines:
            gmsh.model.mesh.setTransfiniteCurve(line, n + 1)
        gmsh.model.mesh.setTransfiniteSurface(s)
        for dim, tags, name in ((2, [s], "plate"), (1, [lines[3]], "px0"), (1, [lines[0]], "py0")):
            gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)
        gmsh.model.mesh.generate(2)
    tm = from_gmsh(gmsh.model if comm.rank == 0 else None, 3, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _block_scene(law=None):
    sc = dc.Scene(large_rotations=True, linear_solver="direct")
    b = sc.add_solid(_block(0.26), material=dc.Elastic(E, NU), degree=1)
    sc.fix(b, "base", dofs=("uz",))
    sc.fix(b, "x0", dofs=("ux",))
    sc.fix(b, "y0", dofs=("uy",))
    return sc, b


def _plate_scene(direction: str, flip: bool = False, law=None):
    """The plate (1.1 × 1.1, E = 1000, t = 0.05, ρ g t = 1) resting on the block's top under its weight,
    symmetric about x = 0 and y = 0; ``direction``: 'shell slaves', 'solid slaves' or 'two-pass'."""
    sc, b = _block_scene()
    plate = sc.add_shell(_plate(5, H + T / 2, flip), "plate", thickness=T,
                         material=dc.Elastic(1000.0, 0.3, density=RHO))
    sc.fix(plate, "px0", dofs=("ux", "ry", "rz"))
    sc.fix(plate, "py0", dofs=("uy", "rx", "rz"))
    sc.gravity(plate, (0.0, 0.0, -G))
    law = law or dc.Penalty()
    sides = (plate, "plate"), (b, "top")
    if direction == "solid slaves":
        sides = sides[::-1]
    pair = sc.contact(*sides, law=law, symmetric=direction == "two-pass")
    sc.monitor_contact("c", pair)
    return sc, b, plate, pair


def _pipe_scene():
    """A pipe (outer radius 0.05, wall 0.01, E = 1000, ρ = 2) along x on the block's top, its axis
    one outer radius above it, under its weight; held against rolling (uy, rx) and symmetric at x = 0."""
    sc, b = _block_scene()
    section = dc.Pipe(2 * R_PIPE, T_PIPE)
    pipe = sc.add_beam(polyline([[0, 0.5, H + R_PIPE], [1, 0.5, H + R_PIPE]], 8, gdim=3), "beam", section=section,
                       material=dc.Elastic(1000.0, 0.3, density=RHO), orientation=(0, 0, 1))
    sc.fix(pipe, "beam", dofs=("uy", "rx"))
    sc.fix(pipe, "base", dofs=("ux", "ry", "rz"))
    sc.gravity(pipe, (0.0, 0.0, -G))
    pair = sc.contact((pipe, "beam"), (b, "top"))
    sc.monitor_contact("c", pair)
    return sc, b, pipe, pair, RHO * G * section.A


def _heights(part) -> np.ndarray:
    """(n,) current z of the part's owned nodes, all ranks."""
    m = part.model
    n = m.V.dofmap.index_map.size_local
    z = m.V.tabulate_dof_coordinates()[:n, 2] + m.translations_of(np.arange(n))[:, 2]
    return np.concatenate(comm.allgather(z))


def _block_top_settlement(b) -> float:
    m = b.model
    n = m.V.dofmap.index_map.size_local
    top = np.abs(m.V.tabulate_dof_coordinates()[:n, 2] - H) < 1e-9
    u = comm.allgather(m.state.x.array.reshape(-1, 3)[:n][top, 2])
    return float(np.mean(np.concatenate(u)))


@pytest.mark.parametrize("direction, flip", [("shell slaves", False), ("solid slaves", False),
                                             ("solid slaves", True), ("two-pass", False)])
def test_a_shell_plate_rests_on_a_block_through_either_face(direction, flip):
    """The plate's weight (ρ g t = 1 on the unit square) reaches the block through contact: the
    resultant is the weight to 1e-9 in all directions of the pairing. Its horizontal part is taken
    by the symmetry supports: with the plate's nodes as slaves it comes from the dimpled faces'
    tilt (4.8e-5 of the weight measured, bound 5e-4); with the block's nodes as slaves, those on
    its far edges, pushed 3e-3 (ν q/E) beyond the plate's edge by the block's lateral expansion,
    meet the plate's rounded edge of radius t/2 = 0.025 and are pushed out by its tilted normal:
    about 0.12 × the load on that row of nodes, 1.3e-2 of the weight measured (bound 2e-2;
    5.8e-4 when the two passes share the load, bound 1e-3); the
    block's top settles by the uniaxial q H/E on average (q = 1.21 over the unit top, within 5 %:
    the plate's nodal loads on the coarse block mesh dimple it locally); over the block, the
    plate's mid-surface rests half its thickness above the block's top face below it (within
    twice the penalty's penetration p/ε). The block's nodes meet the plate's lower face whichever
    way the plate's normal points (``flip``): a shell is two-sided."""
    sc, b, plate, pair = _plate_scene(direction, flip)
    result = dc.solve(sc, dc.LoadControl(steps=2))
    assert result.history.column("cuts").sum() == 0
    row = result.history.rows[-1]
    weight = RHO * G * T * SIDE**2
    assert row["c_Fz"] == pytest.approx(weight if direction != "solid slaves" else -weight, rel=1e-9)
    bound = {"shell slaves": 5e-4, "two-pass": 1e-3, "solid slaves": 2e-2}[direction]
    assert abs(row["c_Fx"]) < bound * weight and abs(row["c_Fy"]) < bound * weight
    assert _block_top_settlement(b) == pytest.approx(-weight * H / E, rel=0.05)
    penetration = weight / min(itf.penalty for itf in sc.interfaces)
    # at the slave nodes: the other side's surface interpolated between its nodes
    if direction == "solid slaves":
        mid, top = _surface_below(plate, b, lambda X: np.abs(X[:, 2] - H) < 1e-9)
    else:
        top, mid = _surface_below(b, plate)
    over = np.isfinite(top) & np.isfinite(mid)
    assert over.sum() >= 20
    assert np.all(np.abs(mid[over] - top[over] - T / 2) < 2 * penetration)


def test_a_pipe_rests_on_a_block_by_its_outer_radius():
    """The pipe's weight (ρ g A per length) reaches the block through its nodes: resultant to 1e-9;
    each node of its axis rests one outer radius above the block's (indented) top face below it,
    within twice the penalty's penetration; the pressure over the nodes' share of length × diameter
    sums to the weight (to 1e-5: it adds the nodal forces' magnitudes, whose tilt is 4e-7)."""
    sc, b, pipe, pair, weight = _pipe_scene()
    result = dc.solve(sc, dc.LoadControl(steps=2))
    assert result.history.column("cuts").sum() == 0
    row = result.history.rows[-1]
    assert row["c_Fz"] == pytest.approx(weight, rel=1e-9)
    p = pair.pressure("slaves")
    assert np.sum(p.pressure * p.length) == pytest.approx(weight, rel=1e-5)  # |F_i|: the faces tilt a little
    assert np.sum(p.length) == pytest.approx(1.0 * 2 * R_PIPE, rel=1e-12)
    penetration = weight / (1.0 * 2 * R_PIPE) / sc.interfaces[0].penalty
    top, axis = _surface_below(b, pipe)
    assert np.all(np.abs(axis - top - R_PIPE) < 2 * penetration)
    assert np.all(p.x[:, 2] < axis.max())  # the contact face lies below the axis


def _surface_below(b, structure, pick=None):
    """(the height of the surface of part ``b`` (its block's top face, or all of its nodes) below
    each node of ``structure`` (its nodes ``pick``; NaN beyond the surface), the nodes' heights),
    current, by linear interpolation of the surface nodes' heights in (x, y)."""
    from scipy.interpolate import LinearNDInterpolator

    def current(model, pick):
        n = model.V.dofmap.index_map.size_local
        x = model.V.tabulate_dof_coordinates()[:n] + model.translations_of(np.arange(n))
        return np.concatenate(comm.allgather(x[pick(model.V.tabulate_dof_coordinates()[:n])]))

    everything = (lambda X: np.ones(len(X), dtype=bool))  # noqa: E731
    top = current(b.model, (lambda X: np.abs(X[:, 2] - H) < 1e-9) if b.model.tdim == 3 else everything)
    axis = current(structure.model, pick or everything)
    return LinearNDInterpolator(top[:, :2], top[:, 2])(axis[:, :2]), axis[:, 2]


def _interface_forces(sc, itf, system):
    """f(x): the interface's forces as a dense vector over the system's dofs at the current state;
    and its tangent K (dense)."""
    n = system.layout.size_global if hasattr(system, "layout") else system.A.getSize()[0]
    dofs, f, K, _ = itf.evaluate()
    F = np.zeros(n)
    Kd = np.zeros((n, n))
    for d, fi, Ki in zip(dofs, f, K):
        ok = d >= 0
        np.add.at(F, d[ok], fi[ok])
        Kd[np.ix_(d[ok], d[ok])] += Ki[np.ix_(ok, ok)]
    return F, Kd


@pytest.mark.skipif(comm.size > 1, reason="dense finite differences: serial")
@pytest.mark.parametrize("case", ["shell master", "shell master flipped", "shell slaves", "beam slaves"])
def test_structure_contact_forces_and_tangents_match_finite_differences(case):
    """The interface's tangent against central differences of its forces (h = 1e-7: 1e-6 of the
    largest entry) at a penetrating, perturbed state: block nodes against a shell's lower face
    (its normal up or down), shell nodes and a pipe's nodes against the block's top."""
    from dolfinx_corot.assembly import make_system

    if case.startswith("beam"):
        sc, b, other, pair, _ = _pipe_scene()
    else:
        sc, b, other, pair = _plate_scene("solid slaves" if "master" in case else "shell slaves",
                                          flip="flipped" in case)
    itf = sc.interfaces[0]
    system = make_system(sc.model, solver=sc.linear_solver, contributions=sc.contributions())
    rng = np.random.default_rng(3)
    # push the structure 0.01 into the block, perturb every translation by 1e-3
    for part, shift in ((b.model, 0.0), (other.model, -0.01)):
        u = part.state.x.array.reshape(-1, part.state_size)
        u[:, 2] += shift
        u[:, :3] += rng.uniform(-1e-3, 1e-3, (len(u), 3))
    F0, K = _interface_forces(sc, itf, system)
    assert int((itf.active >= 0).sum()) >= 9
    h = 1e-7
    cols = np.flatnonzero(np.abs(K).sum(axis=0) > 0.0)
    assert len(cols) > 20
    index = {}  # global dof → (state array, entry)
    for surf, gd in ((itf.slave, itf.slave_gdofs), (itf.master, itf.master_gdofs)):
        arr = surf.part.state.x.array.reshape(-1, surf.part.state_size)
        for pos, block in zip(surf.local, surf.blocks):
            for d in range(3):
                index[int(gd[pos, d])] = (arr, block, d)
    Kfd = np.zeros_like(K)
    for j in cols:
        arr, block, d = index[int(j)]
        x0 = arr[block, d]
        arr[block, d] = x0 + h
        fp, _ = _interface_forces(sc, itf, system)
        arr[block, d] = x0 - h
        fm, _ = _interface_forces(sc, itf, system)
        arr[block, d] = x0
        Kfd[:, j] = (fp - fm) / (2 * h)
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()
    system.destroy()


def test_meshes_of_separate_gmsh_sessions_do_not_share_nodes():
    """Two meshes built in separate gmsh sessions number their nodes from 1 alike, and here both
    models have the default name: the block's and the plate's nodes stay apart (the plate's free
    dofs are not taken for the block's supports)."""
    sc, b, plate, pair = _plate_scene("shell slaves")
    from dolfinx_corot.assembly import make_system

    system = make_system(sc.model, solver=sc.linear_solver, contributions=sc.contributions())
    nodes = sum(comm.allreduce(m.V.dofmap.index_map.size_local) for m in sc.model.models)
    assert system.layout.size_global == 3 * (nodes - comm.allreduce(plate.model.V.dofmap.index_map.size_local)) \
        + 6 * comm.allreduce(plate.model.V.dofmap.index_map.size_local)
    system.destroy()


def test_structure_contact_input_is_checked_by_name():
    """A pipe's lines given as the master, bars without a section radius as slaves, a pipe wall
    thicker than its radius, a negative contact radius, and a shell group that is not a group of
    its cells are refused, each by name."""
    sc, b, pipe, pair, _ = _pipe_scene()
    with pytest.raises(dc.ContactError, match="the master 'beam' of beam 'beam' is a line"):
        sc.contact((b, "top"), (pipe, "beam"))
    sc2, b2 = _block_scene()
    bars = sc2.add_truss(polyline([[0, 0.5, 0.6], [1, 0.5, 0.6]], 4, line_name="bars", gdim=3), "bars", area=0.01,
                         material=dc.Elastic(1000.0, 0.3))
    with pytest.raises(dc.ContactError, match="the slaves 'bars' of truss 'bars' are lines without a section radius"):
        sc2.contact((bars, "bars"), (b2, "top"))
    with pytest.raises(ValueError, match="Pipe: diameter d = 0.1 and wall thickness t = 0.06"):
        dc.Pipe(0.1, 0.06)
    with pytest.raises(ValueError, match="outer = -1.0 must be finite and not negative"):
        dc.Section(A=1.0, I=1.0, outer=-1.0)
    sc3, b3, plate, _ = _plate_scene("shell slaves")
    with pytest.raises(ValueError, match="px0"):
        sc3.contact((b3, "top"), (plate, "px0"))


def test_a_pipe_dragged_over_the_edge_of_a_coarse_block_converges():
    """Hard case (sliding across faces, edges and vertices of a coarse faceted master, and off its
    border): a pipe (1.5 long, outer radius 0.05) pressed onto a 2 × 1 × 0.5 block of tetrahedra of
    size 0.2 by its weight (q = 1 per length, ramped over λ ≤ 0.2), then pulled 0.5 along its axis
    so that its end passes 0.19 beyond the block's edge. Its nodes cross many faces, sit in the
    grooves of concave edges of the indented surface (a node keeps its face while it still
    projects onto it: no alternation), and roll round the block's rounded border edge. Every step
    converges without a cut (at most 8 Newton iterations), the contact carries the weight at
    every step (1e-9), and the pull stays below 0.1 of it (frictionless: only the pipe's end
    tipping over the edge pulls it on) and balances the contact's horizontal force (1e-10 of the
    weight: the support's reaction holds the contact force on the supported node itself)."""
    tm = _block(0.2, length=2.0, sides=("xends", "ysides"))
    sc = dc.Scene(large_rotations=True, linear_solver="direct")
    soil = sc.add_solid(tm, material=dc.Elastic(E, NU), degree=1)
    sc.fix(soil, "base")
    sc.fix(soil, "xends", dofs=("ux",))
    sc.fix(soil, "ysides", dofs=("uy",))
    section = dc.Pipe(2 * R_PIPE, T_PIPE)
    pipe = sc.add_beam(polyline([[0.25, 0.5, H + R_PIPE], [1.75, 0.5, H + R_PIPE]], 40, line_name="pipe", gdim=3),
                       "pipe", section=section, material=dc.Elastic(2e4, 0.3, density=1.0 / (G * section.A)),
                       orientation=(0, 0, 1))
    sc.fix(pipe, "pipe", dofs=("uy", "rx"))
    sc.gravity(pipe, (0.0, 0.0, -G), amplitude=dc.Amplitude([(0.0, 0.0), (0.2, 1.0)]))
    sc.prescribe(pipe, "base", ux=lambda lam, stage: 0.5 * max(0.0, lam - 0.2) / 0.8)
    sc.monitor_contact("c", sc.contact((pipe, "pipe"), (soil, "top")))
    sc.monitor_reaction("pull", pipe, "base")
    history = dc.solve(sc, dc.LoadControl(steps=10)).history
    weight = 1.5 * np.minimum(history.column("load_factor") / 0.2, 1.0)
    assert history.column("cuts").sum() == 0
    assert history.column("iterations").max() <= 8
    assert np.allclose(history.column("c_Fz"), weight, rtol=1e-9)
    assert np.abs(history.column("pull_Fx")).max() < 0.1 * 1.5
    assert np.allclose(history.column("pull_Fx"), -history.column("c_Fx"), rtol=0, atol=1e-10 * 1.5)

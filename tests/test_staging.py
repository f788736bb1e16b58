"""Staged construction (issue 14, first part): existence of solid cells per stage, stage loads,
strain-free activation. Reference: the layered fill of a laterally confined column, in closed form."""
import gmsh
import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx_corot as dc
from dolfinx_corot.io.mesh import from_gmsh
from dolfinx_corot.assembly import make_system
from dolfinx_corot.staging import K0, Stage, solve_stages
from fd import free_part, tangent_and_fd

comm = MPI.COMM_WORLD
H, WIDTH, E, NU, RHO, G = 8.0, 1.0, 1.0e4, 0.25, 2.0, 10.0


def _physical_group(dim: int, tags, tag: int, name: str) -> None:
    gmsh.model.addPhysicalGroup(dim, tags, tag)
    gmsh.model.setPhysicalName(dim, tag, name)


def _meshes(gdim: int, structures: int | None = None):
    """The meshed gmsh model (on rank 0) read as a mesh of its cells and, with ``structures``, of its
    cells of that dimension too (beams, shells); gmsh is finalized."""
    tm = from_gmsh(gmsh.model, gdim, comm=comm)
    other = None if structures is None else from_gmsh(gmsh.model, gdim, comm=comm, dim=structures)
    if comm.rank == 0:
        gmsh.finalize()
    return tm if structures is None else (tm, other)


def _column(n: int):
    """A column WIDTH × H of n layers (one quadrilateral each, shared nodes): cell groups layer1…n
    from the bottom, line groups base and sides, point group 'z<k>' at the left node of height k·h."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("column")
        h = H / n
        left = [gmsh.model.geo.addPoint(0.0, k * h, 0.0) for k in range(n + 1)]
        right = [gmsh.model.geo.addPoint(WIDTH, k * h, 0.0) for k in range(n + 1)]
        base = gmsh.model.geo.addLine(left[0], right[0])
        horizontal = [base] + [gmsh.model.geo.addLine(left[k], right[k]) for k in range(1, n + 1)]
        lefts = [gmsh.model.geo.addLine(left[k], left[k + 1]) for k in range(n)]
        rights = [gmsh.model.geo.addLine(right[k], right[k + 1]) for k in range(n)]
        surfaces = []
        for k in range(n):
            loop = gmsh.model.geo.addCurveLoop([horizontal[k], rights[k], -horizontal[k + 1], -lefts[k]])
            surfaces.append(gmsh.model.geo.addPlaneSurface([loop]))
        for c in horizontal + lefts + rights:
            gmsh.model.geo.mesh.setTransfiniteCurve(c, 2)
        for sf in surfaces:
            gmsh.model.geo.mesh.setTransfiniteSurface(sf)
            gmsh.model.geo.mesh.setRecombine(2, sf)
        gmsh.model.geo.synchronize()
        group = _physical_group

        for k, sf in enumerate(surfaces):
            group(2, [sf], k + 1, f"layer{k + 1}")
        group(1, [base], n + 1, "base")
        group(1, lefts + rights, n + 2, "sides")
        for k in range(1, n + 1):
            group(0, [left[k]], n + 2 + k, f"z{k}")
        gmsh.model.mesh.generate(2)
    return _meshes(2)


def _column_scene(n: int, large: bool, modulus: float = E):
    """The column under its weight (base clamped, sides on rollers), each level monitored."""
    sc = dc.Scene(large_rotations=large, linear_solver="direct")
    soil = sc.add_solid(_column(n), material=dc.SaintVenantKirchhoff(modulus, NU, density=RHO), degree=1)
    sc.fix(soil, "base")
    sc.fix(soil, "sides", dofs=("ux",))
    sc.gravity(soil, (0.0, -G))
    for k in range(1, n + 1):
        sc.monitor(f"z{k}", soil, f"z{k}")
    return sc, soil


def _layered(n: int, approach: str, large: bool, modulus: float = E):
    sc, soil = _column_scene(n, large, modulus)
    stages = [Stage(f"layer {k}", add=[(soil, f"layer{k}")], driver=dc.LoadControl(steps=1)) for k in range(1, n + 1)]
    return solve_stages(sc, stages, approach=approach)


@pytest.mark.parametrize("approach", ["I", "II"])
@pytest.mark.parametrize("n", [1, 2, 8])
def test_layered_fill_settles_as_the_discrete_closed_form(n, approach):
    """Layer j of thickness h = H/n is placed stress-free on the column built so far and takes its
    own weight γh in stage j (one bilinear element per layer, consistent nodal loads γh/2 on its two
    levels). The settlement of the level z = k h counted from its placement is, at small strain,

        s_k = γ h² / M · (k − ½ + k (n − k)),   M = E(1 − ν)/((1 + ν)(1 − 2ν)),

    (stage k compresses layers 1 … k − 1 by γh·h/M each and layer k by ½γh·h/M; every later stage
    compresses layers 1 … k by γh·h/M each) → γ z (H − z)/M as n → ∞: zero at the top, largest at
    mid-height; the column loaded at once settles γ(Hz − z²/2)/M. Asserted to 1e-10 for each level
    and stage count, with either approach (they coincide at small strain)."""
    results = _layered(n, approach, large=False)
    assert len(results) == n and all(r.completed for r in results)
    gamma, h = RHO * G, H / n
    M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))
    for k in range(1, n + 1):
        # the level is held at rest until its layer appears: its displacement is its settlement
        assert all(r.history.rows[-1][f"z{k}_uy"] == 0.0 for r in results[: k - 1])
        settlement = results[-1].history.rows[-1][f"z{k}_uy"]
        exact = -gamma * h**2 / M * (k - 0.5 + k * (n - k))
        assert settlement == pytest.approx(exact, rel=1e-10, abs=1e-14)
    if n == 8:  # mid-height settles most, the top least: γ z (H − z)/M + γ h (z − h/2)/M
        uy = [results[-1].history.rows[-1][f"z{k}_uy"] for k in range(1, n + 1)]
        assert min(uy) == pytest.approx(uy[n // 2 - 1]) and uy[-1] > 0.4 * min(uy)  # top: 7.5/19.5 of it


def test_the_column_loaded_at_once_settles_as_the_bar_under_its_weight():
    """The same column without stages, its whole weight at once: γ (H z − z²/2)/M at every level
    (nodally exact for linear elements), the top settling most — and nothing of the staging in its
    forms (a scene without stages pays nothing)."""
    n = 8
    sc, soil = _column_scene(n, large=False)
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    assert soil.model.existing is None
    gamma, M = RHO * G, E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))
    for k in range(1, n + 1):
        z = k * H / n
        assert row[f"z{k}_uy"] == pytest.approx(-gamma * (H * z - z**2 / 2) / M, rel=1e-10)


def test_approach_one_at_large_strain_follows_the_uniaxial_law_layer_by_layer():
    """At 13 % strain (E = 1500) approach I keeps the discrete formula with the exact law: layer i
    (strain measured from its placement, on the original mesh) is in uniaxial strain with the
    constant displacement gradient g(N) that carries the nominal stress N above it, the St Venant–
    Kirchhoff P_yy = M (1 + g)(g + g²/2) = −N, so level k has settled since its placement by
        s_k = h [Σ_{i ≤ k} g(γh(n − i + ½)) − Σ_{i < k} g(γh(k − i − ½))].
    Asserted to 1e-9; approach II, whose new layers are referred to their deformed places, parts
    from it (by 0.5–2 % here)."""
    first = _layered(4, "I", large=True, modulus=1500.0)[-1].history.rows[-1]
    second = _layered(4, "II", large=True, modulus=1500.0)[-1].history.rows[-1]
    n, h, gamma = 4, H / 4, RHO * G
    M = 1500.0 * (1 - NU) / ((1 + NU) * (1 - 2 * NU))

    def g(N):  # the root near −N/M of M (1 + g)(g + g²/2) + N = 0
        roots = np.roots([M / 2, 3 * M / 2, M, N])
        real = roots[np.abs(roots.imag) < 1e-12].real
        return real[np.argmin(np.abs(real + N / M))]

    for k in range(1, n + 1):
        exact = h * (sum(g(gamma * h * (n - i + 0.5)) for i in range(1, k + 1))
                     - sum(g(gamma * h * (k - i - 0.5)) for i in range(1, k)))
        assert first[f"z{k}_uy"] == pytest.approx(exact, rel=1e-9)
        assert abs(second[f"z{k}_uy"] - exact) > 1e-3 * abs(exact) or k == 1


def test_bad_stage_input_is_named():
    """An unknown approach and a missing cell group each end in a clear error before anything is
    solved."""
    sc, soil = _column_scene(2, large=False)
    with pytest.raises(ValueError, match=r"approach = 'III' is not one of \('I', 'II'\)"):
        solve_stages(sc, [Stage("one", add=[(soil, "layer1")])], approach="III")
    with pytest.raises(dc.GroupNotFoundError, match="'layer9' not found"):
        solve_stages(sc, [Stage("one", add=[(soil, "layer9")])])


@pytest.mark.skipif(comm.size > 1, reason="dense finite differences of the assembled system: serial")
@pytest.mark.parametrize("approach", ["I", "II"])
def test_staged_tangent_matches_finite_differences(approach):
    """The tangent of a staged column at large strain — the top layer activated on the settled one,
    its shift s ≠ 0 and, for approach II, a reference shift m ≠ s as a mapping makes it
    (F = (I + ∇m + ∇(u − s))(I + ∇m)⁻¹ over X + m), with K₀ initial stresses (P₀ = F σ₀) — against
    central differences of the residual at a perturbed state, free dofs (1e-6 of its largest entry)."""
    sc, soil = _column_scene(2, large=True, modulus=1500.0)
    solve_stages(sc, [Stage(f"layer {k}", add=[(soil, f"layer{k}")]) for k in (1, 2)], approach=approach)
    model = soil.model
    assert np.abs(model.activation_shift.x.array).max() > 0.05  # the second layer's bottom had settled
    rng = np.random.default_rng(5)
    m = model.activation_reference.x.array
    m[:] += rng.uniform(-0.05, 0.05, m.shape) * (np.abs(model.activation_shift.x.array) > 0.0)
    model.set_k0_stress(0.6, surface=H, unit_weight=RHO * G)  # σ₀ up to 160: its work F σ₀ : ∇v too
    system = make_system(sc.model, solver="direct")
    try:
        model.state.x.array[:] += rng.uniform(-0.02, 0.02, model.state.x.array.shape)
        K, Kfd = free_part(system, *tangent_and_fd(system, model.state.x.array, 1.0))
    finally:
        system.destroy()
    assert np.abs(K).max() > 100.0
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()


# -- excavation -------------------------------------------------------------------------------
WG, HG, WP, DP = 6.0, 4.0, 2.0, 1.0  # ground width and height, pit width and depth (pit at x = 0, the axis)


def _ground(with_pit: bool, n: int = 2, beams: bool = False):
    """Ground WG × HG of quadrilaterals (n per metre): cell groups 'ground' and, if ``with_pit``,
    'pit' = [0, WP] × [HG − DP, HG]; line groups 'base', 'sides'; point groups 'floor' at (0, HG − DP)
    and, with the pit, 'top' at (0, HG). ``beams``: the pit is ground and the top surface carries
    the line groups 'beam_left' (x < WP) and 'beam_right' (read for beams too, dim = 1)."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("ground")
        geo = gmsh.model.geo
        xs, ys = [0.0, WP, WG], [0.0, HG - DP, HG]
        pts = {(i, j): geo.addPoint(xs[i], ys[j], 0.0) for i in range(3) for j in range(3)}
        hor = {(i, j): geo.addLine(pts[i, j], pts[i + 1, j]) for i in range(2) for j in range(3)}
        ver = {(i, j): geo.addLine(pts[i, j], pts[i, j + 1]) for i in range(3) for j in range(2)}
        surf = {}
        for i in range(2):
            for j in range(2):
                if (i, j) == (0, 1) and not with_pit:
                    continue
                loop = geo.addCurveLoop([hor[i, j], ver[i + 1, j], -hor[i, j + 1], -ver[i, j]])
                surf[i, j] = geo.addPlaneSurface([loop])
        for (i, j), c in hor.items():
            geo.mesh.setTransfiniteCurve(c, int(round(n * (xs[i + 1] - xs[i]))) + 1)
        for (i, j), c in ver.items():
            geo.mesh.setTransfiniteCurve(c, int(round(n * (ys[j + 1] - ys[j]))) + 1)
        for sf in surf.values():
            geo.mesh.setTransfiniteSurface(sf)
            geo.mesh.setRecombine(2, sf)
        geo.synchronize()

        group = _physical_group

        group(2, [s for k, s in surf.items() if beams or k != (0, 1)], 1, "ground")
        if with_pit and not beams:
            group(2, [surf[0, 1]], 2, "pit")
        group(1, [hor[0, 0], hor[1, 0]], 3, "base")
        group(1, [ver[0, 0], ver[0, 1], ver[2, 0], ver[2, 1]] if with_pit else [ver[0, 0], ver[2, 0], ver[2, 1]],
              4, "sides")
        if beams:  # the top surface, left of x = WP (loaded) and right of it
            group(1, [hor[0, 2]], 7, "beam_left")
            group(1, [hor[1, 2]], 8, "beam_right")
        group(0, [pts[0, 1]], 5, "floor")
        if with_pit and not beams:
            group(0, [pts[0, 2]], 6, "top")
        gmsh.model.mesh.generate(2)
    return _meshes(2, 1 if beams else None)


def _ground_scene(with_pit: bool):
    sc = dc.Scene(large_rotations=False, linear_solver="direct")
    soil = sc.add_solid(_ground(with_pit), material=dc.Elastic(E, NU, density=RHO), degree=1)
    sc.fix(soil, "base")
    sc.fix(soil, "sides", dofs=("ux",))
    sc.gravity(soil, (0.0, -G))
    sc.monitor("floor", soil, "floor")
    if with_pit:
        sc.monitor("top", soil, "top")
    return sc, soil


def _by_position(points: np.ndarray, values: np.ndarray) -> dict:
    """{rounded position: value} over all ranks (owned entries given)."""
    pts = np.concatenate(comm.allgather(np.round(points, 9)))
    vals = np.concatenate(comm.allgather(values))
    return {tuple(p): v for p, v in zip(pts, vals)}


def _nodal(soil) -> dict:
    m = soil.model
    n = m.V.dofmap.index_map.size_local
    return _by_position(m.V.tabulate_dof_coordinates()[:n, :2], m.state.x.array.reshape(-1, m.state_size)[:n, :2])


def _stresses(soil) -> dict:
    m = soil.model
    mesh = m.V.mesh
    n = mesh.topology.index_map(2).size_local
    x = mesh.geometry.x[:, :2]
    centres = np.array([x[mesh.geometry.dofmap.links(c)].mean(axis=0) for c in range(n)])
    return _by_position(centres, m.cell_stress())


def test_excavation_releases_the_pit_gradually_to_the_state_of_the_excavated_ground():
    """Ground under gravity (a geostatic stage: displacements discarded, stresses kept), then the
    pit excavated over two steps. Small strain: the final stresses in the remaining ground equal
    those of one gravity analysis of the ground without the pit, cell by cell (1e-9 of the largest),
    and the displacement since the geostatic stage equals that analysis' displacement minus the
    geostatic one, node by node. The pit's forces on the ground are released in proportion to λ:
    halfway the floor has heaved half of its final heave."""
    sc, soil = _ground_scene(with_pit=True)
    results = solve_stages(sc, [Stage("geostatic", add=[(soil, "ground"), (soil, "pit")], reset_displacements=True),
                                Stage("excavation", remove=[(soil, "pit")], driver=dc.LoadControl(steps=2))],
                           approach="I")
    assert results[0].history.rows[-1]["floor_uy"] < 0.0
    # the geostatic displacements, from a plain gravity run on the full ground
    full, full_soil = _ground_scene(with_pit=True)
    dc.solve(full, dc.LoadControl(steps=1))
    u_geo = _nodal(full_soil)
    cut, cut_soil = _ground_scene(with_pit=False)
    dc.solve(cut, dc.LoadControl(steps=1))
    u_cut, s_cut = _nodal(cut_soil), _stresses(cut_soil)
    # the excavation stage, from the staged run
    rows = results[1].history.rows
    heave = rows[-1]["floor_uy"]
    assert heave > 0.0 and rows[0]["floor_uy"] == pytest.approx(0.5 * heave, rel=1e-9)
    u_staged, s_staged = _nodal(soil), _stresses(soil)
    scale_u = max(abs(v).max() for v in u_cut.values())
    for p, u in u_cut.items():
        assert np.abs(u_staged[p] - (u - u_geo[p])).max() < 1e-9 * scale_u
    scale_s = max(abs(v).max() for v in s_cut.values())
    for p, s in s_cut.items():
        assert np.abs(s_staged[p] - s).max() < 1e-9 * scale_s
    pit_cells = [p for p in s_staged if p not in s_cut]
    assert len(pit_cells) == 8 and all(np.abs(s_staged[p]).max() == 0.0 for p in pit_cells)


def test_nodes_left_by_excavated_cells_stay_where_they_are():
    """Without a geostatic reset, the nodes that only the pit's cells touched (its top, on the
    axis) keep the displacement they had when the pit was removed; the floor heaves."""
    sc, soil = _ground_scene(with_pit=True)
    results = solve_stages(sc, [Stage("gravity", add=[(soil, "ground"), (soil, "pit")]),
                                Stage("excavation", remove=[(soil, "pit")])])
    before, after = results[0].history.rows[-1], results[1].history.rows[-1]
    assert before["top_uy"] < 0.0 and after["top_uy"] == before["top_uy"]
    assert after["floor_uy"] > before["floor_uy"]


def test_removing_what_does_not_exist_is_named():
    sc, soil = _ground_scene(with_pit=True)
    with pytest.raises(ValueError, match="stage 'dig' removes 'pit' of solid .* which does not exist"):
        solve_stages(sc, [Stage("fill", add=[(soil, "ground")]), Stage("dig", remove=[(soil, "pit")])])


# -- structures added in stages ------------------------------------------------------------------
Q_TOP, E_BEAM = 150.0, 1.0e6  # surcharge on the left of the surface; beam modulus (section 0.3 × 0.3)


def _ground_and_beam(large: bool, with_beam: bool = True):
    """The ground (its pit filled), a surcharge Q_TOP on its surface left of x = WP, and a beam along
    the whole surface sharing the ground's nodes (groups beam_left, beam_right)."""
    tm, lines = _ground(with_pit=True, beams=True)
    sc = dc.Scene(large_rotations=large, linear_solver="direct")
    material = dc.SaintVenantKirchhoff(E, NU) if large else dc.Elastic(E, NU)
    soil = sc.add_solid(tm, material=material, degree=1)
    sc.fix(soil, "base")
    sc.fix(soil, "sides", dofs=("ux",))
    sc.load(soil, "beam_left", traction=(0.0, -Q_TOP))
    sc.monitor("surface", soil, "beam_left", reduce="min")
    beams = []
    if with_beam:
        for group in ("beam_left", "beam_right"):
            beams.append(sc.add_beam(lines, group, section=dc.Rectangle(0.3, 0.3), material=dc.Elastic(E_BEAM)))
    return sc, soil, beams


def _activate_on_settled_ground(large: bool, approach: str):
    sc, soil, beams = _ground_and_beam(large)
    results = solve_stages(sc, [Stage("surcharge", driver=dc.LoadControl(steps=2)),
                                Stage("beam", add=[(b, b.name) for b in beams])], approach=approach)
    return results, soil, beams


@pytest.mark.parametrize("large", [False, True])
def test_a_beam_added_on_settled_ground_is_stress_free_with_approach_two(large):
    """Approach II (seed §3.1.2): a structure is added undeformed in the configuration of that
    moment, its deformation U − U_os. A beam activated along a surface that a surcharge has
    settled into a trough (of 2 % of the loaded width) carries no force (round-off: 1e-9 of the
    surcharge's resultant), and the ground does not move — geometrically linear or co-rotational."""
    results, soil, beams = _activate_on_settled_ground(large, "II")
    settled, after = results[0].history.rows[-1]["surface_uy_min"], results[1].history.rows[-1]["surface_uy_min"]
    assert settled < -0.02 * WP
    assert after == pytest.approx(settled, rel=1e-12)
    _, forces = beams[0].model.element_forces()
    assert comm.allreduce(len(forces)) == int(round(2 * WG))  # every element exists
    assert comm.allreduce(float(np.abs(forces).max(initial=0.0)), op=MPI.MAX) < 1e-9 * Q_TOP * WP
    sections = beams[0].model.element_results()  # section forces since the activation: none
    assert len(sections) == int(round(2 * WG)) and np.abs(sections.values).max() < 1e-9 * Q_TOP * WP


def test_a_beam_added_on_settled_ground_carries_the_settlement_with_approach_one():
    """Approach I: the mesh is the structure's reference and U its deformation, so a beam added
    on the settled surface takes the curvature of the trough as its own: the stage ends where a
    single analysis with the beam present from the start ends (geometrically linear, history
    does not matter), node by node to 1e-9. The beam bent into the trough pushes back: the trough
    rises (by 0.16 % here) and its elements carry end forces of 13 % of the surcharge's resultant."""
    results, soil, beams = _activate_on_settled_ground(False, "I")
    settled, after = results[0].history.rows[-1]["surface_uy_min"], results[1].history.rows[-1]["surface_uy_min"]
    direct, direct_soil, _ = _ground_and_beam(False)
    dc.solve(direct, dc.LoadControl(steps=1))
    staged, reference = _nodal(soil), _nodal(direct_soil)
    scale = max(abs(v).max() for v in reference.values())
    assert all(np.abs(staged[p] - u).max() < 1e-9 * scale for p, u in reference.items())
    assert after > settled + 1e-3 * abs(settled)  # (settlements are negative: the beam lifts the trough)
    _, forces = beams[0].model.element_forces()
    assert comm.allreduce(float(np.abs(forces).max(initial=0.0)), op=MPI.MAX) > 0.1 * Q_TOP * WP


@pytest.mark.skipif(comm.size > 1, reason="dense finite differences of the assembled system: serial")
@pytest.mark.parametrize("large", [False, True])
def test_staged_beam_tangent_matches_finite_differences(large):
    """The tangent of 2D beams added undeformed in a deformed configuration (approach II: reference
    X + a, deformation d − a, with a the memorized state of the nodes, here random and large: 0.3
    in translation, 0.5 rad) against central differences of the residual, free dofs (1e-6)."""
    from dolfinx_corot.io.gmsh_models import polyline
    sc = dc.Scene(large_rotations=large, linear_solver="direct")
    beam = sc.add_beam(polyline([[0.0, 0.0], [2.0, 0.5]], 4), "beam", section=dc.Rectangle(0.2, 0.3),
                       material=dc.Elastic(1.0e4))
    sc.fix(beam, "base")
    sc.load(beam, "tip", force=(0.0, -1.0))
    solve_stages(sc, [Stage("place", add=[(beam, "beam")])], approach="II")
    model = beam.model
    rng = np.random.default_rng(3)
    act = model.activation.x.array.reshape(-1, 2, 3)
    act[:] = rng.uniform(-0.3, 0.3, act.shape) * np.array([1.0, 1.0, 5.0 / 3.0])
    system = make_system(sc.model, solver="direct")
    try:
        model.state.x.array[:] += rng.uniform(-0.1, 0.1, model.state.x.array.shape)
        K, Kfd = free_part(system, *tangent_and_fd(system, model.state.x.array, 1.0))
    finally:
        system.destroy()
    assert np.abs(K).max() > 100.0
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()


def test_a_geostatic_stage_with_parts_that_cannot_discard_their_displacements_is_named():
    """A stage that discards the displacements needs every part staged and able to keep its
    strains without them (solids): an unstaged solid, or beams in that stage, are refused before
    anything is solved, naming the part."""
    sc, soil, beams = _ground_and_beam(False)
    adds = [(b, b.name) for b in beams]
    with pytest.raises(NotImplementedError, match=r"stage 'g' discards the displacements, but solid '.*' is not staged"):
        solve_stages(sc, [Stage("g", add=adds, reset_displacements=True)])
    sc, soil, beams = _ground_and_beam(False)
    adds = [(soil, "ground")] + [(b, b.name) for b in beams]
    with pytest.raises(NotImplementedError, match="but beam 'beam_left', beam 'beam_right' exists and cannot keep its strains"):
        solve_stages(sc, [Stage("g", add=adds, reset_displacements=True)])


# -- mapping of new continuum (approach II) and contact in stages -----------------------------
T_WALL, P_WALL, Q_PLATE, E_WALL = 0.2, 400.0, 200.0, 1.0e6


def _pit_wall_plate():
    """Ground [0, 6] × [0, 2] and a bank [0, 2] × [2, 4] on its left (density RHO), with a pit
    [2.1, 6] × [2, 3] ('fill': weightless) right of the bank; a wall of beams (section T_WALL, group
    'wall') along the bank's face x = 2 sharing its nodes, loaded at its top 'wall_top'; a plate of
    beams ('plate') on the surface x ∈ [4, 6] sharing the ground's and the fill's nodes, loaded at
    'plate_mid'. The fill's face 'fill_face' (x = 2.1: the wall's face in the mesh) has nodes of its
    own. Quadrilaterals of 0.5 m (0.1 m across the strip x ∈ [2, 2.1])."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("pit_wall_plate")
        geo = gmsh.model.geo
        xs, ys = [0.0, 2.0, 2.1, 4.0, 5.0, 6.0], [0.0, 2.0, 3.0]
        nx, ny = [4, 1, 4, 2, 2], [4, 2]
        pts = {(i, j): geo.addPoint(xs[i], ys[j], 0.0) for i in range(6) for j in range(3)}
        hor = {(i, j): geo.addLine(pts[i, j], pts[i + 1, j]) for i in range(5) for j in range(3)}
        ver = {(i, j): geo.addLine(pts[i, j], pts[i, j + 1]) for i in range(6) for j in range(2)}
        cells = {}
        for i in range(5):
            for j in range(2):
                if j == 1 and i == 1:
                    continue
                loop = geo.addCurveLoop([hor[i, j], ver[i + 1, j], -hor[i, j + 1], -ver[i, j]])
                cells[i, j] = geo.addPlaneSurface([loop])
        # the bank's upper part [0, 2] × [3, 4]
        b0, b1 = geo.addPoint(0.0, 4.0, 0.0), geo.addPoint(2.0, 4.0, 0.0)
        bank_top, bank_left, bank_right = geo.addLine(b0, b1), geo.addLine(pts[0, 2], b0), geo.addLine(pts[1, 2], b1)
        upper = geo.addPlaneSurface([geo.addCurveLoop([hor[0, 2], bank_right, -bank_top, -bank_left])])
        for (i, j), c in hor.items():
            geo.mesh.setTransfiniteCurve(c, nx[i] + 1)
        for (i, j), c in ver.items():
            geo.mesh.setTransfiniteCurve(c, ny[j] + 1)
        for c in (bank_top, bank_left, bank_right):
            geo.mesh.setTransfiniteCurve(c, {bank_top: nx[0], bank_left: 2, bank_right: 2}[c] + 1)
        for sf in list(cells.values()) + [upper]:
            geo.mesh.setTransfiniteSurface(sf)
            geo.mesh.setRecombine(2, sf)
        geo.synchronize()

        group = _physical_group

        group(2, [s for (i, j), s in cells.items() if j == 0 or i == 0] + [upper], 1, "ground")
        group(2, [s for (i, j), s in cells.items() if j == 1 and i >= 2], 2, "fill")
        group(1, [hor[i, 0] for i in range(5)], 3, "base")
        group(1, [ver[0, 0], ver[0, 1], bank_left, ver[5, 0], ver[5, 1]], 4, "sides")
        group(1, [ver[2, 1]], 5, "fill_face")
        group(1, [ver[1, 1], bank_right], 6, "wall")
        group(1, [hor[3, 1], hor[4, 1]], 7, "plate")
        group(1, [hor[2, 1]], 8, "pit_floor")
        group(0, [b1], 9, "wall_top")
        group(0, [pts[4, 1]], 10, "plate_mid")
        gmsh.model.mesh.generate(2)
    return _meshes(2, 1)


def _fill_against_a_wall(approach: str):
    """Ground, pit excavated (stage 'excavate'), wall and plate built and loaded ('build': the wall
    deflected away from the pit by P_WALL at its top, the plate pressed into the ground), then
    the weightless fill placed against the wall ('fill', slaves on the wall): nothing changes in
    the loads of the last stage, so it ends where it starts."""
    tm, lines = _pit_wall_plate()
    sc = dc.Scene(large_rotations=True, linear_solver="direct")
    ground = sc.add_solid(tm, "ground", material=dc.SaintVenantKirchhoff(E, NU, density=RHO), degree=1)
    fill = sc.add_solid(tm, "fill", material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    wall = sc.add_beam(lines, "wall", section=dc.Rectangle(T_WALL, T_WALL), material=dc.Elastic(E_WALL))
    plate = sc.add_beam(lines, "plate", section=dc.Rectangle(T_WALL, T_WALL), material=dc.Elastic(E_WALL))
    sc.fix(ground, "base")
    sc.fix(ground, "sides", dofs=("ux",))
    sc.gravity(ground, (0.0, -G), where="ground")
    sc.load(wall, "wall_top", force=(-P_WALL, 0.0))
    sc.load(plate, "plate_mid", force=(0.0, -Q_PLATE))
    pair = sc.contact((fill, "fill_face"), (wall, "wall"))
    sc.monitor("floor", ground, "pit_floor", reduce="profile", along="x")
    stages = [Stage("excavate", remove=[(fill, "fill")]),
              Stage("build", add=[(wall, "wall"), (plate, "plate")], driver=dc.LoadControl(steps=2)),
              Stage("fill", add=[(fill, "fill")])]
    results = solve_stages(sc, stages, approach=approach, initial=[(ground, "ground"), (fill, "fill")])
    return sc, results, ground, wall, pair


def _wall_face_gap(wall, points: np.ndarray) -> np.ndarray:
    """Distance of ``points`` from the wall's face on the side x > axis (half its depth from the
    current axis, on the C¹ curve through the wall's nodes, as contact sees it), by brute force
    over its segments."""
    from dolfinx_corot.contact.kernels2d import smooth_gap
    X, state = wall.model.nodes()
    on_wall = (np.abs(X[:, 0] - 2.0) < 1e-9) & (X[:, 1] > 2.0 - 1e-9)  # (the beam model has the plate too)
    x = X[on_wall] + state[on_wall, :2]
    order = np.argsort(x[:, 1])
    x = x[order]
    out = []
    for p in points:
        best = np.inf
        for k in range(len(x) - 1):
            ext = [x[max(k - 1, 0)], x[k], x[k + 1], x[min(k + 2, len(x) - 1)]]
            # the axis runs upwards: the body side (left) is x < axis, the fill on its right
            g, xi, ok = smooth_gap(np.hstack([p] + ext)[None, :])
            lo = -0.05 if k == 0 else -1e-9  # (a little beyond the free end, as contact allows)
            if ok[0] and lo <= xi[0] <= 1.0 + 1e-9 and abs(g[0]) < abs(best):
                best = g[0]
        out.append(best - 0.5 * T_WALL)
    return np.array(out)


def _assert_fill_stress_free(ground, pair) -> None:
    """The fill's stresses are 1e-9 of the ground's and the wall–fill contact carries nothing."""
    stress = _stresses(ground)
    in_fill = (lambda p: p[0] > 2.1 and p[1] > 2.0)
    ground_max = max(np.abs(v).max() for p, v in stress.items() if not in_fill(p))
    assert max(np.abs(v).max() for p, v in stress.items() if in_fill(p)) < 1e-9 * ground_max
    assert np.abs(pair.resultant(on="slaves")).max() < 1e-9 * Q_PLATE


def test_mapping_of_new_fill_onto_the_deformed_configuration():
    """Seed §3.1.2, approach II: before the fill appears, its nodes are mapped by the E = 1, ν = 0
    sub-problem with the seed's boundary shifts. Asserted class by class: the slaves of the fill's
    face lie on the deflected wall's face (to 1e-10 of the element size) — moved by up to 2 cm —;
    nodes shared with the existing ground are shifted by U − U_e (U_e: the displacement at the end
    of the excavation stage, read from a run stopped there), those shared with the plate by U;
    free top nodes keep their elevation (zero vertical shift); the supported side keeps u_x = 0.
    The fill appears stress-free (its stresses 1e-9 of the ground's), the contact carries nothing,
    and the last stage leaves every node where it was at activation."""
    sc, results, ground, wall, pair = _fill_against_a_wall("II")
    mapping = results[2].mappings[0]
    kinds = set(mapping.kind)
    assert {"slave", "existing continuum", "structure", "free boundary", "support"} <= kinds
    slave = mapping.kind == "slave"
    gap = _wall_face_gap(wall, mapping.X[slave] + mapping.shift[slave])
    assert np.abs(gap).max() < 1e-10 * 0.5
    assert np.abs(mapping.shift[slave][:, 0]).max() > 0.01  # the wall moved: the face follows
    # U − U_e on the ground, U on the plate (U: where the last stage ended, as it started)
    U = _nodal(ground)
    scale = max(np.abs(v).max() for v in U.values())
    floor = results[0].profiles["floor"]  # the pit's floor at the end of the excavation: U_e
    Ue = {tuple(np.round(x, 9)): np.array([ux, uy]) for x, ux, uy in
          zip(floor.X, floor.column("ux")[-1], floor.column("uy")[-1])}
    assert max(np.abs(v).max() for v in Ue.values()) > 1e-3  # the floor heaved
    for kind, expected in (("existing continuum", lambda p: U[p] - Ue[p]), ("structure", lambda p: U[p])):
        rows = np.flatnonzero(mapping.kind == kind)
        assert len(rows)
        for r in rows:
            p = tuple(np.round(mapping.X[r], 9))
            assert np.abs(mapping.shift[r] - expected(p)).max() < 1e-12 * scale
    free = mapping.kind == "free boundary"
    assert np.all(mapping.shift[free][:, 1] == 0.0)
    assert np.all(mapping.shift[mapping.kind == "support"][:, 0] == 0.0)
    # moved nodes sit at X + w now; the fill is stress-free; the contact carries nothing
    moved = np.flatnonzero(mapping.moved)
    assert len(moved) and all(np.abs(U[tuple(np.round(mapping.X[r], 9))] - mapping.shift[r]).max() < 1e-12 * scale
                              for r in moved)
    _assert_fill_stress_free(ground, pair)


def test_contact_appearing_in_approach_one_takes_its_initial_gap_as_zero():
    """Approach I (seed §3.1.2): the fill is placed on the mesh and its face meets the wall that
    deflected away from it: the interface takes each slave's initial gap as zero (the gaps equal
    the wall face's distance from the fill's face, up to 2 cm here), so the fill
    appears stress-free and the last stage leaves every node where it was."""
    sc, results, ground, wall, pair = _fill_against_a_wall("I")
    itf = pair[0]
    slaves = np.flatnonzero(itf.gap_cancelled)
    assert len(slaves) >= 2
    gaps = _wall_face_gap(wall, itf.slave.positions(comm)[slaves])  # (the fill does not move)
    assert np.abs(itf.initial_gap[slaves] - gaps).max() < 1e-9
    assert np.abs(gaps).max() > 0.01
    _assert_fill_stress_free(ground, pair)


def test_mapping_refuses_new_cells_that_nothing_holds():
    """Approach II: a block added in the air (no node shared with existing elements, no support, no
    slave) has nothing to map it horizontally: the stage is refused by name, on every rank."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("floating")
        geo = gmsh.model.geo
        surfaces = []
        for y0 in (0.0, 2.0):
            p = [geo.addPoint(x, y, 0.0) for x, y in ((0, y0), (1, y0), (1, y0 + 1), (0, y0 + 1))]
            lines = [geo.addLine(p[k], p[(k + 1) % 4]) for k in range(4)]
            surfaces.append(geo.addPlaneSurface([geo.addCurveLoop(lines)]))
            if y0 == 0.0:
                base = lines[0]
            for c in lines:
                geo.mesh.setTransfiniteCurve(c, 2)
        for sf in surfaces:
            geo.mesh.setTransfiniteSurface(sf)
            geo.mesh.setRecombine(2, sf)
        geo.synchronize()
        _physical_group(2, [surfaces[0]], 1, "ground")
        _physical_group(2, [surfaces[1]], 2, "block")
        _physical_group(1, [base], 3, "base")
        gmsh.model.mesh.generate(2)
    tm = _meshes(2)
    sc = dc.Scene(large_rotations=True, linear_solver="direct")
    soil = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    sc.fix(soil, "base")
    with pytest.raises(ValueError, match="mapping of new continuum .approach II.: the cells added are not held"):
        solve_stages(sc, [Stage("block", add=[(soil, "block")])], approach="II", initial=[(soil, "ground")])


# -- checkpoint and restart of a staged run ------------------------------------------------------
class Killed(Exception):
    """Raised from on_step: the run dies after a step (its checkpoint holds the step before)."""


def _box_in_pit_scene(slaves_on_fill: bool = True, size: float = 1.0, friction=None):
    """A coarse box frame in a pit, filled in two layers (the frame-filling demos' scene): geostatic
    stage (reset), excavation (U_e), frame (U_os), two fill layers with frame–fill contact (slaves
    on the fill's face, or on the frame; with ``friction``, a dc.Coulomb law)."""
    from dolfinx_corot.io.gmsh_models import box_in_pit
    tm, lines = box_in_pit(12.0, 8.0, 8.0, 4.0, 4.0, 2.0, 0.2, 1, 1, size)
    sc = dc.Scene(large_rotations=True, linear_solver="direct")
    soil = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(50e6, 0.3, density=2000.0), degree=1)
    fill = sc.add_solid(tm, "fill", material=dc.SaintVenantKirchhoff(10e6, 0.3, density=1800.0), degree=1)
    concrete = dc.Elastic(30e9, 0.2, density=2500.0)
    frame = sc.add_beam(lines, "frame", section=dc.Rectangle(1.0, 0.2), material=concrete, plane_strain=True)
    slab = sc.add_beam(lines, "slab", section=dc.Rectangle(1.0, 0.2), material=concrete, plane_strain=True)
    sc.fix(soil, "base")
    sc.fix(soil, "sides", dofs=("ux",))
    sc.fix(soil, "symmetry", dofs=("ux",))
    sc.fix(frame, "roof_centre", dofs=("rz",))
    sc.fix(slab, "slab_centre", dofs=("rz",))
    for part in (soil, frame, slab):
        sc.gravity(part, (0.0, -10.0))
    faces = [(fill, "fill_face"), (frame, "frame")]
    pair = sc.contact(*(faces if slaves_on_fill else faces[::-1]), friction=friction)
    sc.monitor_reaction("base", soil, "base")
    sc.monitor("floor", soil, "pit_floor", reduce="profile", along="x")
    stages = [Stage("geostatic", reset_displacements=True),
              Stage("excavation", remove=[(soil, "core"), (fill, "fill")], driver=dc.LoadControl(steps=2)),
              Stage("frame", add=[(frame, "frame"), (slab, "slab")]),
              Stage("layer 1", add=[(fill, "layer_1")], driver=dc.LoadControl(steps=3)),
              Stage("layer 2", add=[(fill, "layer_2")], driver=dc.LoadControl(steps=2))]
    initial = [(soil, "ground"), (soil, "core"), (fill, "fill")]
    return sc, stages, initial, pair


def _staged_state(sc) -> np.ndarray | None:
    """Every part's configuration in input order (rank 0; None elsewhere)."""
    found = [m.to_global(m.state.x.array) for m in sc.model.models]
    return np.concatenate([f.ravel() for f in found]) if comm.rank == 0 else None


@pytest.mark.parametrize("approach", ["I", "II"])
@pytest.mark.parametrize("kill", [("layer 1", 2), ("layer 1", 1)])
def test_a_staged_run_killed_and_restarted_reproduces_the_uninterrupted_one(tmp_path, approach, kill):
    """Killed in the middle of a fill stage (the file holds its first step), or at the first step
    of one (the file holds the last step of the frame stage): the restart goes on from there, with
    the mapped references, the structures' U_os, U_e, the interface's initial gaps and the
    stage's starting force as the file holds them, and reproduces the uninterrupted run step by
    step, stage by stage (results of the stages before come from the file)."""
    sc, stages, initial, _ = _box_in_pit_scene()
    full = solve_stages(sc, stages, approach=approach, initial=initial)
    path = comm.bcast(str(tmp_path / "staged.npz") if comm.rank == 0 else None, root=0)

    def die(stage, row):
        if (stage.name, row["step"]) == kill:
            raise Killed

    sc2, stages2, initial2, _ = _box_in_pit_scene()
    with pytest.raises(Killed):
        solve_stages(sc2, stages2, approach=approach, initial=initial2, on_step=die, checkpoint=path)
    sc3, stages3, initial3, pair3 = _box_in_pit_scene()
    resumed_steps = []
    resumed = solve_stages(sc3, stages3, approach=approach, initial=initial3, checkpoint=path, restart=path,
                           on_step=lambda stage, row: resumed_steps.append((stage.name, row["step"])))
    assert resumed_steps[0] == (kill if kill[1] > 1 else ("layer 1", 1))
    assert [len(r.history) for r in resumed] == [len(r.history) for r in full] == [1, 2, 1, 3, 2]
    for a, b in zip(full, resumed):
        np.testing.assert_array_equal(b.history.column("iterations"), a.history.column("iterations"))
        np.testing.assert_allclose(b.history.column("base_Fy"), a.history.column("base_Fy"), rtol=1e-9)
        np.testing.assert_allclose(b.profiles["floor"].values, a.profiles["floor"].values, rtol=1e-9,
                                   atol=1e-12)
        assert [m.part for m in b.mappings] == [m.part for m in a.mappings]
        for ma, mb in zip(a.mappings, b.mappings):
            np.testing.assert_array_equal(mb.kind, ma.kind)
            np.testing.assert_allclose(mb.shift, ma.shift, rtol=0, atol=1e-14)
    # the fill presses on the frame (the interface's state came through the file)
    assert np.abs(pair3.resultant(on="slaves")).max() > 1e3
    a, b = _staged_state(sc), _staged_state(sc3)
    if comm.rank == 0:
        assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max()


@pytest.mark.parametrize("approach", ["I", "II"])
def test_friction_on_an_interface_that_appears_in_a_stage(tmp_path, approach):
    """The box-in-pit scene with Coulomb friction μ = 0.3 between the fill and the frame: the
    interface appears with the first layer (approach I: the gaps it finds taken as zero; II: the
    fill's face mapped onto the frame) and the layers, settling under their weight, hang on the
    frame's walls. Asserted: no cut; Coulomb's law at every slave at the end of each fill stage
    (|t| ≤ μ p, to 1e-9 of the largest μ p; the slipping slaves at |t| = μ p); the fill's shear
    drags the frame down: the vertical force of the fill on the frame exceeds the frictionless
    run's (measured by 3.6 % (I) and 3.8 % (II); at the end 5 slaves in contact, 2 slipping);
    and a run killed in the middle of layer 1 and restarted reproduces the uninterrupted
    one step by step (1e-10). On two ranks the parallel direct solver's round-off differs from
    one run to the next, and the iteration count of a step with a slave at the limit of stick
    and slip follows it (layer 2's first step: 5, 7 or 10 iterations): there the state is
    compared, to 1e-8 (measured 1e-13)."""
    law = dc.Coulomb(mu=0.3)
    scenes = {}
    for name, friction in (("frictionless", None), ("friction", law)):
        sc, stages, initial, pair = _box_in_pit_scene(friction=friction)
        ends = {}  # each stage's last step: the fill's force on the frame, the slaves' p, t, slipping

        def record(stage, row, pair=pair, ends=ends):
            itf = pair.interfaces[0]
            ends[stage.name] = (pair.resultant(on="masters"), itf.pressure()[1], *itf.friction_traction()[1:])

        results = solve_stages(sc, stages, approach=approach, initial=initial, on_step=record)
        scenes[name] = (sc, results, ends)
    sc, results, ends = scenes["friction"]
    assert all(r.history.column("cuts").sum() == 0 for r in results)
    for name in ("layer 1", "layer 2"):
        resultant, p, t, slipping = ends[name]
        bound = 0.3 * p.max()
        assert bound > 0.0, name
        assert np.all(np.abs(t) <= 0.3 * p + 1e-9 * bound), name
        assert np.abs(np.abs(t[slipping]) - 0.3 * p[slipping]).max(initial=0.0) < 1e-9 * bound, name
        assert np.abs(t).max() > 0.05 * bound, name
    drag = [run[2]["layer 2"][0][1] for run in (scenes["frictionless"], scenes["friction"])]
    assert drag[1] < drag[0] < 0.0, drag  # (downwards: more of the fill's weight on the frame)
    path = comm.bcast(str(tmp_path / "staged.npz") if comm.rank == 0 else None, root=0)

    def die(stage, row):
        if (stage.name, row["step"]) == ("layer 1", 2):
            raise Killed

    sc2, stages2, initial2, _ = _box_in_pit_scene(friction=law)
    with pytest.raises(Killed):
        solve_stages(sc2, stages2, approach=approach, initial=initial2, on_step=die, checkpoint=path)
    sc3, stages3, initial3, _ = _box_in_pit_scene(friction=law)
    resumed = solve_stages(sc3, stages3, approach=approach, initial=initial3, checkpoint=path, restart=path)
    serial = comm.size == 1
    for a, b in zip(results, resumed):
        if serial:
            np.testing.assert_array_equal(b.history.column("iterations"), a.history.column("iterations"))
        np.testing.assert_allclose(b.history.column("base_Fy"), a.history.column("base_Fy"), rtol=1e-9)
    a, b = _staged_state(sc), _staged_state(sc3)
    if comm.rank == 0:
        assert np.abs(a - b).max() <= (1e-10 if serial else 1e-8) * np.abs(a).max()


def test_a_staged_restart_refuses_another_approach_other_stages_a_plain_solve_or_another_mesh(tmp_path):
    sc, stages, initial, _ = _box_in_pit_scene()
    path = comm.bcast(str(tmp_path / "staged.npz") if comm.rank == 0 else None, root=0)

    def die(stage, row):
        if stage.name == "frame":
            raise Killed

    with pytest.raises(Killed):
        solve_stages(sc, stages, approach="II", initial=initial, on_step=die, checkpoint=path)
    sc, stages, initial, _ = _box_in_pit_scene()
    with pytest.raises(dc.CheckpointError, match="approach II, this run asks for approach I"):
        solve_stages(sc, stages, approach="I", initial=initial, restart=path)
    renamed = [Stage("gravity", reset_displacements=True)] + stages[1:]
    with pytest.raises(dc.CheckpointError, match="stage 1 is 'geostatic', this run has 'gravity' there"):
        solve_stages(sc, renamed, approach="II", initial=initial, restart=path)
    with pytest.raises(dc.CheckpointError, match="written by a staged run: restart it with solve_stages"):
        dc.solve(sc, dc.LoadControl(steps=1), restart=path)
    sc, stages, initial, _ = _box_in_pit_scene(size=0.8)  # another mesh
    with pytest.raises(dc.CheckpointError, match="was written for another scene"):
        solve_stages(sc, stages, approach="II", initial=initial, restart=path)


def test_a_system_vector_goes_through_a_checkpoint_file_unchanged():
    """Partition-independent arrays of a vector of the coupled solid + beams system and back: equal
    on every rank (under MPI a beam's rotation at a node the solid owns elsewhere comes from the
    rank that holds the beam)."""
    sc, _, _, _ = _box_in_pit_scene()
    system = make_system(sc.model, solver="direct", contributions=sc.contributions())
    try:
        v, w = system.new_vector(), system.new_vector()
        v.array[:] = np.random.default_rng(comm.rank).random(len(v.array))
        arrays = comm.bcast(system.global_arrays({"v": v}), root=0)
        system.global_to_vector(arrays, "v", w)
        assert np.array_equal(w.array, v.array)
        # the solid's translations and the beams' translations and rotation
        assert sorted(a.shape[1] for k, a in arrays.items() if k.startswith("v")) == [2, 3]
    finally:
        system.destroy()


def test_approach_two_refuses_new_fill_whose_face_is_only_a_master():
    """Seed §3.1.2: with approach II the nodes of new continuum along an interface must be slaves
    (the mapping projects them on their master); the fill's face as the master of the frame's
    slaves is refused when the first layer comes, naming the interface and the reason."""
    sc, stages, initial, _ = _box_in_pit_scene(slaves_on_fill=False)
    with pytest.raises(ValueError, match=r"contact 'frame -> fill_face' .* must be slave nodes \(seed §3.1.2\)"):
        solve_stages(sc, stages, approach="II", initial=initial)


# -- 3D beams and shells in stages ---------------------------------------------------------------
def _tangent_and_fd_by_updates(system, load_factor: float, h: float = 1e-6):
    """(K, K_fd): the assembled tangent and −∂r/∂d by central differences of the state moved by
    ±h along each dof through the model's update (translations add, spins turn R ← exp(h e) R)."""
    cp = system.checkpoint()
    system.residual(load_factor)
    system.jacobian()
    K = system.A.convert("dense").getDenseArray().copy()
    n = K.shape[0]
    Kfd = np.zeros((n, n))
    for j in range(n):
        r = []
        for sign in (1, -1):
            system.restore(cp)
            system.dx.set(0.0)
            system.dx.setValue(j, sign * h)
            system.dx.assemble()
            system.dx.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
            system.update()
            system.residual(load_factor)
            r.append(system.b.array.copy())
        Kfd[:, j] = -(r[0] - r[1]) / (2 * h)
    system.restore(cp)
    return K, Kfd


def _random_states(model, rng, translation: float, angle: float) -> None:
    """Move every node's state by a random translation (up to ``translation``) and rotation (up to
    ``angle``), rotations composed multiplicatively."""
    from dolfinx_corot import rotations as rot
    state = model.state.x.array.reshape(-1, 7)
    for row in state:
        row[:3] += rng.uniform(-translation, translation, 3)
        row[3:] = rot.quat_mul(rot.quat_from_rotvec(rng.uniform(-angle, angle, 3)), row[3:].copy())


def _memorize_current_states(model) -> None:
    """Every cell's memorized states (approach II) = its nodes' current states."""
    n = model.nodes_per_cell
    blocks = model.V.dofmap.list.array.reshape(-1, n)
    act = model.activation.x.array.reshape(-1, n, 7)
    act[model.activation.function_space.dofmap.list.array] = model.state.x.array.reshape(-1, 7)[blocks]
    model._forms = None  # (the shells' constants follow the memorized translations)


def _staged_3d_scene(kind: str):
    from dolfinx_corot.io.gmsh_models import polyline
    from dolfinx_corot.io.mesh import from_arrays
    sc = dc.Scene(large_rotations=True, linear_solver="direct")
    if kind == "beam":
        part = sc.add_beam(polyline([[0.0, 0.0, 0.0], [2.0, 0.5, 0.3]], 3, gdim=3), "beam",
                           section=dc.Rectangle(0.2, 0.3), material=dc.Elastic(1.0e4), orientation=(0.0, 0.0, 1.0))
        sc.fix(part, "base")
        sc.load(part, "tip", force=(0.0, 0.0, -1.0))
    elif kind == "shell":
        points = np.array([[x, y, 0.1 * x * y] for y in (0.0, 0.5, 1.0) for x in (0.0, 0.5, 1.0)])
        cells = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]])
        tm = from_arrays(points, cells, cell_name="shell", point_groups={"edge": np.array([0, 3, 6])}, comm=comm)
        part = sc.add_shell(tm, "shell", thickness=0.05, material=dc.Elastic(2.0e4, 0.3))
        sc.fix(part, "edge")
    elif kind == "quad_shell":  # four-node shells (DKQ) on a warped sheet
        points = np.array([[x, y, 0.1 * x * y] for y in (0.0, 0.5, 1.0) for x in (0.0, 0.5, 1.0)])
        cells = np.array([[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]])
        tm = from_arrays(points, cells, cell_name="shell", point_groups={"edge": np.array([0, 3, 6])}, comm=comm)
        part = sc.add_shell(tm, "shell", thickness=0.05, material=dc.Elastic(2.0e4, 0.3))
        sc.fix(part, "edge")
    else:  # quadrilateral membranes on a warped sheet
        points = np.array([[x, y, 0.1 * x * y] for y in (0.0, 0.5, 1.0) for x in (0.0, 0.5, 1.0)])
        cells = np.array([[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]])
        tm = from_arrays(points, cells, cell_name="sheet", point_groups={"edge": np.array([0, 3, 6])}, comm=comm)
        part = sc.add_membrane(tm, "sheet", thickness=0.01, material=dc.Elastic(2.0e4, 0.3))
        sc.fix(part, "edge")
    return sc, part


@pytest.mark.skipif(comm.size > 1, reason="dense finite differences of the assembled system: serial")
@pytest.mark.parametrize("kind", ["beam", "shell", "quad_shell", "membrane"])
def test_staged_3d_tangent_matches_finite_differences(kind):
    """3D beams, shell triangles, four-node shells and quadrilateral membranes added undeformed in a deformed configuration (approach II:
    reference X + u_a, states since then (u − u_a, R R_aᵀ), a the memorized states): added at
    random states (0.3 in translation, rotations up to 2 rad about any axis) they carry no
    internal force (1e-12); moved on from there (0.1, 0.3 rad), their tangent against central
    differences of the residual along translations and spins (R ← exp(h e) R), free dofs (1e-6)."""
    sc, part = _staged_3d_scene(kind)
    model = part.model
    model.start_staging("II")  # every element exists (what a stage adding them does before its solve)
    model.set_existing(np.ones(len(model.cells_existing()), dtype=bool))
    rng = np.random.default_rng(7)
    _random_states(model, rng, 0.3, 2.0)  # a large rigid-looking motion and some strain
    _memorize_current_states(model)
    system = make_system(sc.model, solver="direct", tangent="consistent")  # K itself, off equilibrium
    try:
        # added undeformed there: no internal force, whatever the rotations (round-off)
        system.residual(0.0)
        system.jacobian()
        scale = system.A.norm() * 0.3
        assert np.abs(system.evaluate_internal_force()).max() < 1e-12 * scale
        _random_states(model, rng, 0.1, 0.3)
        K, Kfd = free_part(system, *_tangent_and_fd_by_updates(system, 1.0))
    finally:
        system.destroy()
    assert np.abs(K).max() > 10.0
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()


L3, W3, H3 = 4.0, 1.0, 2.0  # 3D ground: length, width, height; the surcharge on x < L3/2


def _ground_3d():
    """A block of ground [0, L3] × [0, W3] × [0, H3] of tetrahedra in two halves along x, whose top
    faces 'top_left' and 'top_right' carry a shell strip (the triangles of the same gmsh model)."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("ground3d")
        occ = gmsh.model.occ
        left, right = occ.addBox(0.0, 0.0, 0.0, L3 / 2, W3, H3), occ.addBox(L3 / 2, 0.0, 0.0, L3 / 2, W3, H3)
        occ.fragment([(3, left)], [(3, right)])
        occ.synchronize()
        faces = {}
        for _, tag in gmsh.model.getEntities(2):
            x, y, z = occ.getCenterOfMass(2, tag)
            name = ("base" if z < 1e-9 else ("top_left" if x < L3 / 2 else "top_right") if z > H3 - 1e-9 else
                    "ends" if min(x, L3 - x) < 1e-9 else "sides_y" if min(y, W3 - y) < 1e-9 else None)
            if name:
                faces.setdefault(name, []).append(tag)
        gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [v for _, v in gmsh.model.getEntities(3)]),
                                   "ground")
        for name, tags in faces.items():
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
    return _meshes(3, 2)


def _ground_and_shell(large: bool):
    tm, surfaces = _ground_3d()
    sc = dc.Scene(large_rotations=large, linear_solver="direct")
    soil = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, NU) if large else dc.Elastic(E, NU), degree=1)
    sc.fix(soil, "base")
    sc.fix(soil, "ends", dofs=("ux",))
    sc.fix(soil, "sides_y", dofs=("uy",))
    sc.load(soil, "top_left", traction=(0.0, 0.0, -Q_TOP))
    sc.monitor("surface", soil, "top_left", reduce="min")
    shells = [sc.add_shell(surfaces, group, thickness=0.3, material=dc.Elastic(E_BEAM, 0.2))
              for group in ("top_left", "top_right")]
    return sc, soil, shells


def _shell_forces(shells) -> float:
    """The largest nodal internal force of the shell strip (its model alone)."""
    system = make_system(shells[0].model, solver="direct")
    try:
        return comm.allreduce(float(np.abs(system.evaluate_internal_force()).max(initial=0.0)), op=MPI.MAX)
    finally:
        system.destroy()


def _nodal_3d(soil) -> dict:
    m = soil.model
    n = m.V.dofmap.index_map.size_local
    return _by_position(m.V.tabulate_dof_coordinates()[:n], m.state.x.array.reshape(-1, 3)[:n])


@pytest.mark.parametrize("approach", ["I", "II"])
def test_a_shell_strip_added_on_settled_ground(approach):
    """Seed §3.1.2 for shells. A surcharge settles half the top of a 3D block of ground into a
    trough (1.3 % of the loaded length); then a shell strip appears on the whole top, sharing the
    ground's nodes. Approach II (co-rotational, SVK ground): the strip is added undeformed in the
    settled configuration — its nodal forces vanish (1e-9 of the surcharge's resultant) and the
    ground does not move (1e-12). Approach I (geometrically linear): the mesh is the strip's
    reference, so it takes the trough as its own deformation; the stage ends where one analysis
    with the strip present from the start ends (1e-9), the strained strip acting on the ground."""
    large = approach == "II"
    sc, soil, shells = _ground_and_shell(large)
    results = solve_stages(sc, [Stage("surcharge", driver=dc.LoadControl(steps=2)),
                                Stage("shell", add=[(s, s.name) for s in shells])], approach=approach)
    settled, after = (r.history.rows[-1]["surface_uz_min"] for r in results)
    resultant = Q_TOP * L3 / 2 * W3
    assert settled < -0.01 * L3 / 2
    if approach == "II":
        assert after == pytest.approx(settled, rel=1e-12)
        assert _shell_forces(shells) < 1e-9 * resultant
        for shell in shells:  # the resultants of the strip added undeformed: none
            resultants = shell.model.element_results()
            assert len(resultants) > 0
            assert np.abs(resultants.values).max() < 1e-9 * Q_TOP
        return
    direct, direct_soil, _ = _ground_and_shell(False)
    dc.solve(direct, dc.LoadControl(steps=1))
    staged, reference = _nodal_3d(soil), _nodal_3d(direct_soil)
    scale = max(abs(v).max() for v in reference.values())
    assert all(np.abs(staged[p] - u).max() < 1e-9 * scale for p, u in reference.items())
    assert abs(after - settled) > 1e-3 * abs(settled)  # the strip bent into the trough acts on it
    assert _shell_forces(shells) > 0.01 * resultant


# -- K0 initial stresses ---------------------------------------------------------------------------
@pytest.mark.parametrize("large", [False, True])
def test_k0_initial_stresses_of_level_ground_are_in_equilibrium_with_its_weight(large):
    """The K₀ procedure: level ground (the pit's cells still there, top at HG) given
    σ_v = −ρg (HG − y), σ_h = K₀ σ_v with K₀ = 0.7 (not the elastic ν/(1 − ν) = 1/3) and its weight:
    the stage starts and ends at zero displacement (1e-12 of ρg HG²/E), and every cell's stress at
    its centre is the closed form (1e-9: the round-off of that zero) — small strain and
    co-rotational (SVK). The excavation
    that follows releases the pit's σ₀ over its steps: halfway the floor has heaved half its heave."""
    sc = dc.Scene(large_rotations=large, linear_solver="direct")
    material = dc.SaintVenantKirchhoff(E, NU, density=RHO) if large else dc.Elastic(E, NU, density=RHO)
    soil = sc.add_solid(_ground(with_pit=True), material=material, degree=1)
    sc.fix(soil, "base")
    sc.fix(soil, "sides", dofs=("ux",))
    sc.gravity(soil, (0.0, -G))
    sc.monitor("floor", soil, "floor")
    k0 = 0.7
    snapshots = []
    results = solve_stages(sc, [Stage("K0", add=[(soil, "ground"), (soil, "pit")],
                                      initial_stress=[K0(soil, k0, surface=HG)]),
                                Stage("excavation", remove=[(soil, "pit")], driver=dc.LoadControl(steps=2))],
                           approach="II", on_step=lambda stage, row: snapshots.append((stage.name, _nodal(soil),
                                                                                       _stresses(soil))))
    assert results[0].history.rows[-1]["iterations"] <= 1
    _, u_k0, s_k0 = snapshots[0]
    assert max(np.abs(u).max() for u in u_k0.values()) < 1e-12 * RHO * G * HG**2 / E
    scale = RHO * G * HG
    for (x, y), s in s_k0.items():
        sv = -RHO * G * (HG - y)
        assert np.abs(s - np.array([[k0 * sv, 0.0], [0.0, sv]])).max() < 1e-9 * scale
    heave = [row["floor_uy"] for row in results[1].history.rows]
    assert heave[-1] > 1e-4 * HG
    if not large:
        assert heave[0] == pytest.approx(0.5 * heave[-1], rel=1e-9)


def test_k0_input_is_checked_by_name():
    """K₀ on a structure, a surface below the top of the mesh, and a unit weight that cannot be
    taken from the materials are refused with the culprit named."""
    sc, soil = _ground_scene(with_pit=True)
    with pytest.raises(ValueError, match="the mesh rises to 4, above the ground's surface 3"):
        solve_stages(sc, [Stage("K0", add=[(soil, "ground"), (soil, "pit")], initial_stress=[K0(soil, 0.5, 3.0)])])
    sc = dc.Scene(large_rotations=False, linear_solver="direct")
    soil = sc.add_solid(_ground(with_pit=True), "ground", material=dc.Elastic(E, NU, density=RHO), degree=1)
    sc.add_solid(soil.model.tmesh, "pit", material=dc.Elastic(E, NU, density=2 * RHO), degree=1)
    sc.gravity(soil, (0.0, -G))
    with pytest.raises(ValueError, match=r"give unit_weight= \(the solid has 2 densities"):
        solve_stages(sc, [Stage("K0", add=[(soil, "ground"), (soil, "pit")], initial_stress=[K0(soil, 0.5, HG)])])
    from dolfinx_corot.io.gmsh_models import polyline
    sc = dc.Scene()
    beam = sc.add_beam(polyline([[0.0, 0.0], [1.0, 0.0]], 2), "beam", section=dc.Rectangle(0.1, 0.1),
                       material=dc.Elastic(1.0e3))
    with pytest.raises(ValueError, match="K0 initial stress on beam 'beam': only solids carry initial stresses"):
        solve_stages(sc, [Stage("K0", add=[(beam, "beam")], initial_stress=[K0(beam, 0.5, 0.0)])])


# -- supports, loads and interfaces as stage items ----------------------------------------------------------
LC, P_TIP, Q_MID, Q_WEIGHT = 2.0, 0.3, 0.8, 0.25  # cantilever length; tip load, mid-span load, weight per length
E_C, SEC = 2.0e4, dc.Rectangle(0.1, 0.2)
EI_C = E_C * 0.1 * 0.2**3 / 12.0


def _cantilever(items: bool = True, n: int = 8):
    """A cantilever (clamped at x = 0, Bernoulli, section 0.1 × 0.2, geometrically linear) with a tip
    load P_TIP that exists from the start, and (``items``) as stage items a prop at the tip (uy), a load
    Q_MID at mid-span and its weight (Q_WEIGHT per length), all downwards; monitors at the tip and
    mid-span, the reaction at the tip."""
    x = np.linspace(0.0, LC, n + 1)
    tm = dc.io.mesh.from_arrays(np.column_stack([x, 0.0 * x]), np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                                "beam", point_groups={"base": np.array([0]), "mid": np.array([n // 2]),
                                                      "tip": np.array([n])}, comm=comm)
    sc = dc.Scene(large_rotations=False, linear_solver="direct")
    beam = sc.add_beam(tm, section=SEC, material=dc.Elastic(E_C, 0.3))
    sc.fix(beam, "base")
    sc.load(beam, "tip", force=(0.0, -P_TIP))
    if items:
        items = {"prop": sc.fix(beam, "tip", dofs=("uy",)),
                 "mid load": sc.load(beam, "mid", force=(0.0, -Q_MID)),
                 "weight": sc.gravity(beam, (0.0, -1.0), density=Q_WEIGHT / 0.02)}
    sc.monitor("tip", beam, "tip")
    sc.monitor("mid", beam, "mid")
    sc.monitor_reaction("prop", beam, "tip")
    return sc, beam, items


def _cantilever_deflections(tip: float = 0.0, mid: float = 0.0, q: float = 0.0) -> np.ndarray:
    """Downward deflections (at L/2, at L) of a cantilever of length LC under a tip force, a
    mid-span force and a uniform load q (Euler–Bernoulli, e.g. Roark's Formulas for Stress and
    Strain, table 8.1, cases 1a and 2a): w(x) = F x²(3a − x)/6EI for x ≤ a, F a²(3x − a)/6EI
    beyond, and q x²(6L² − 4Lx + x²)/24EI."""
    L, a = LC, LC / 2

    def point(F, load_at, x):
        return F * (x**2 * (3 * load_at - x) if x <= load_at else load_at**2 * (3 * x - load_at)) / (6 * EI_C)

    return np.array([point(tip, L, x) + point(mid, a, x) + q * x**2 * (6 * L**2 - 4 * L * x + x**2) / (24 * EI_C)
                     for x in (a, L)])


def test_supports_and_loads_added_and_removed_by_stages_follow_the_closed_forms():
    """A cantilever with its tip load P (geometrically linear; Bernoulli elements are nodally exact
    under nodal forces and the work-equivalent loads of a uniform weight):
    1. P alone: tip w₁ = PL³/3EI.
    2. a prop is added at the tip and a load Q at mid-span: the prop holds the tip where it is
       (not at zero) and the beam responds as a propped cantilever to Q: prop reaction 5Q/16,
       mid-span w₁(L/2) + 7QL³/768EI — half of that increment halfway through the stage.
    3. the beam's weight q is added: reaction 5Q/16 + 3qL/8.
    4. the prop is removed: its reaction is released over the stage (halfway, half of it still
       acts), and the beam ends as the cantilever under P, Q and q.
    5. Q and the weight are removed: back to w₁ along the beam.
    Every value to 1e-9 of the largest deflection (closed forms by superposition)."""
    sc, beam, items = _cantilever()
    stages = [Stage("P"),
              Stage("prop and Q", add=[items["prop"], items["mid load"]], driver=dc.LoadControl(steps=2)),
              Stage("weight", add=[items["weight"]]),
              Stage("prop removed", remove=[items["prop"]], driver=dc.LoadControl(steps=2)),
              Stage("Q and weight removed", remove=[items["mid load"], items["weight"]])]
    results = solve_stages(sc, stages, approach="I")
    rows = [r.history.rows for r in results]
    w = lambda row: -np.array([row["mid_uy"], row["tip_uy"]])  # noqa: E731 (downward deflections)
    L, q = LC, Q_WEIGHT
    unit = _cantilever_deflections(tip=1.0)  # a unit upward prop force lifts the beam by this
    w1 = _cantilever_deflections(tip=P_TIP)
    r_q, r_w = 3 * EI_C * _cantilever_deflections(mid=Q_MID)[1] / L**3, 3 * q * L / 8  # propped reactions
    assert r_q == pytest.approx(5 * Q_MID / 16, rel=1e-12)
    with_q = w1 + _cantilever_deflections(mid=Q_MID) - r_q * unit
    with_weight = with_q + _cantilever_deflections(q=q) - r_w * unit
    free = _cantilever_deflections(tip=P_TIP, mid=Q_MID, q=q)
    expected = [(rows[0][-1], w1), (rows[1][0], 0.5 * (w1 + with_q)), (rows[1][-1], with_q),
                (rows[2][-1], with_weight), (rows[3][0], free - 0.5 * (r_q + r_w) * unit), (rows[3][-1], free),
                (rows[4][-1], w1)]
    scale = free.max()
    for row, reference in expected:
        assert np.abs(w(row) - reference).max() < 1e-9 * scale, (row["stage"] if "stage" in row else row, reference)
    assert with_q[0] - w1[0] == pytest.approx(7 * Q_MID * L**3 / (768 * EI_C), rel=1e-12)  # (Roark 1e)
    assert rows[1][-1]["prop_Fy"] == pytest.approx(5 * Q_MID / 16, rel=1e-9)
    assert rows[2][-1]["prop_Fy"] == pytest.approx(5 * Q_MID / 16 + 3 * q * L / 8, rel=1e-9)
    assert rows[3][-1]["prop_Fy"] == pytest.approx(0.0, abs=1e-9 * P_TIP)


@pytest.mark.parametrize("kill", [("prop and Q", 1), ("prop removed", 1), ("Q and weight removed", 1)])
def test_a_run_with_staged_supports_and_loads_restarts_exactly(tmp_path, kill):
    """Killed in the stage that adds the prop and Q, in the one that removes the prop, or at the first
    step of the last one: the restart sets the supports and loads of each stage as the stages say
    (the prop holding the tip where the file has it), takes the stage's starting force from the file
    and reproduces the uninterrupted run (1e-12)."""
    sc, beam, items = _cantilever()

    def stages(items):
        return [Stage("P"), Stage("prop and Q", add=[items["prop"], items["mid load"]], driver=dc.LoadControl(steps=2)),
                Stage("prop removed", remove=[items["prop"]], driver=dc.LoadControl(steps=2)),
                Stage("Q and weight removed", remove=[items["mid load"], items["weight"]], driver=dc.LoadControl(steps=2))]

    full = solve_stages(sc, stages(items))
    path = comm.bcast(str(tmp_path / "staged.npz") if comm.rank == 0 else None, root=0)

    def die(stage, row):
        if (stage.name, row["step"]) == kill:
            raise Killed

    sc2, _, items2 = _cantilever()
    with pytest.raises(Killed):
        solve_stages(sc2, stages(items2), on_step=die, checkpoint=path)
    sc3, _, items3 = _cantilever()
    resumed = solve_stages(sc3, stages(items3), checkpoint=path, restart=path)
    for a, b in zip(full, resumed):
        for name in ("tip_uy", "mid_uy", "prop_Fy"):
            np.testing.assert_allclose(b.history.column(name), a.history.column(name), rtol=0, atol=1e-12)


def test_a_jack_removed_by_a_stage_releases_its_force():
    """The cantilever with its tip load P, its tip pushed up by a jack (a prescribed motion that the
    first stage adds: uy(λ, stage) = 0.05 λ, told the stage's name); the next stage removes the jack:
    the beam ends as the cantilever under P (w = PL³/3EI at the tip) and halfway through the stage
    the tip is midway (linear; 1e-9). The jack's reaction while it acts: 3EI (0.05 + w)/L³."""
    sc, beam, _ = _cantilever(items=False)
    stages_seen = set()

    def lift(lam, stage):
        stages_seen.add(stage)
        return 0.05 * lam

    jack = sc.prescribe(beam, "tip", uy=lift)
    results = solve_stages(sc, [Stage("jacked", add=[jack]),
                                Stage("jack removed", remove=[jack], driver=dc.LoadControl(steps=2))])
    assert stages_seen == {"jacked"}
    w1 = _cantilever_deflections(tip=P_TIP)
    jacked, midway, end = results[0].history.rows[-1], results[1].history.rows[0], results[1].history.rows[-1]
    assert jacked["tip_uy"] == pytest.approx(0.05, rel=1e-12)
    assert jacked["prop_Fy"] == pytest.approx(3 * EI_C * (0.05 + w1[1]) / LC**3, rel=1e-9)
    assert abs(end["tip_uy"] + w1[1]) < 1e-9 * w1[1]
    assert abs(end["mid_uy"] + w1[0]) < 1e-9 * w1[1]
    assert abs(midway["tip_uy"] - 0.5 * (0.05 - w1[1])) < 1e-9 * w1[1]


def test_bad_stage_items_are_named():
    """Something that is not a stage item, a support added while it exists, a load removed while it
    does not, and loads with an amplitude (each stage ramps its own loads) are refused by name,
    before anything is solved."""
    sc, beam, items = _cantilever()
    solved = []
    record = (lambda stage, row: solved.append(row))  # noqa: E731
    with pytest.raises(TypeError, match="stage 'one' add: 'tip' is none of a \\(part, cell group\\) pair, a "
                                        "support, motion or load"):
        solve_stages(sc, [Stage("one", add=["tip"])])
    with pytest.raises(ValueError, match="stage 'two' adds Condition\\(support on 'tip' of beam \\(uy\\)\\), "
                                         "which exists already"):
        solve_stages(sc, [Stage("one", add=[items["prop"]]), Stage("two", add=[items["prop"]])], on_step=record)
    with pytest.raises(ValueError, match="stage 'two' removes Condition\\(load on 'mid' of beam\\), which does "
                                         "not exist at that stage"):
        solve_stages(sc, [Stage("one", remove=[items["mid load"]]), Stage("two", remove=[items["mid load"]])],
                     on_step=record)
    sc.load(beam, "mid", force=(0.0, -1.0), amplitude=dc.Amplitude([(0.0, 0.0), (1.0, 1.0)]))
    with pytest.raises(ValueError, match="loads with an amplitude cannot be staged"):
        solve_stages(sc, [Stage("one")], on_step=record)
    assert not solved


def _block_with_walls(large: bool, right_wall: bool = True):
    """A soil block 4 × 2 (8 × 4 quadrilaterals) under its weight, clamped at its base, on rollers
    along its left side and (``right_wall``) along its right one; its top takes a traction
    (0.3, −1)·q as a stage item. Small strain, or SVK with q large enough for 5 % strains."""
    from dolfinx_corot.io.mesh import rectangles

    tm = rectangles({"soil": (0.0, 0.0, 4.0, 2.0, 8, 4)},
                    {"base": [("soil", "bottom")], "left": [("soil", "left")], "right": [("soil", "right")],
                     "top": [("soil", "top")]}, comm=comm)
    sc = dc.Scene(large_rotations=large, linear_solver="direct")
    material = dc.SaintVenantKirchhoff(E, NU, density=RHO) if large else dc.Elastic(E, NU, density=RHO)
    soil = sc.add_solid(tm, material=material, degree=1)
    sc.fix(soil, "base")
    sc.fix(soil, "left", dofs=("ux",))
    wall = sc.fix(soil, "right", dofs=("ux",)) if right_wall else None
    sc.gravity(soil, (0.0, -G))
    q = 400.0 if large else 40.0
    surcharge = sc.load(soil, "top", traction=(0.3 * q, -q))
    return sc, soil, wall, surcharge


@pytest.mark.parametrize("large", [False, True])
def test_a_surcharge_added_and_a_wall_removed_end_as_one_analysis_without_the_wall(large):
    """A block under its weight, held by rollers on both sides; a stage adds a surcharge (pushing
    towards the right wall too), the next removes the right wall over two steps. Elastic and
    conservative loads: the end state is the equilibrium of the block without the wall under weight
    and surcharge, whatever the path — node by node equal to one analysis of that block (1e-9 of
    the largest displacement at small strain, 1e-8 with SVK at 5 % strain). Small strain: the
    wall's reaction is released in proportion to λ, so halfway the block is midway between the
    states that end the two stages (1e-9)."""
    sc, soil, wall, surcharge = _block_with_walls(large)
    states = {}
    results = solve_stages(sc, [Stage("weight", driver=dc.LoadControl(steps=2)),
                                Stage("surcharge", add=[surcharge], driver=dc.LoadControl(steps=2)),
                                Stage("wall removed", remove=[wall], driver=dc.LoadControl(steps=2))],
                           on_step=lambda stage, row: states.__setitem__((stage.name, row["load_factor"]),
                                                                         _nodal(soil)))
    assert all(r.history.column("cuts").sum() == 0 for r in results)
    direct, direct_soil, _, _ = _block_with_walls(large, right_wall=False)
    dc.solve(direct, dc.LoadControl(steps=4))
    reference = _nodal(direct_soil)
    scale = max(np.abs(u).max() for u in reference.values())
    staged = states["wall removed", 1.0]
    assert max(np.abs(staged[p] - u).max() for p, u in reference.items()) < (1e-8 if large else 1e-9) * scale
    # the wall held the block: removing it moves the block by a good part of its displacement
    before, midway = states["surcharge", 1.0], states["wall removed", 0.5]
    assert max(np.abs(staged[p] - before[p]).max() for p in reference) > 0.1 * scale
    if not large:
        assert max(np.abs(midway[p] - 0.5 * (before[p] + staged[p])).max() for p in reference) < 1e-9 * scale


F_BEAM = 0.05  # load at the middle of the beam on the soil block


def _beam_on_block():
    """A beam (span 3, section 1 × 0.2, E 1e4; pinned at both ends) lying on a soft soil block
    (4 × 1, E 100) at zero gap, its nodes slaves of the block's top (penalty), a load F_BEAM at
    mid-span; small strain."""
    from dolfinx_corot.io.mesh import rectangles

    block = rectangles({"soil": (0.0, -1.0, 4.0, 1.0, 16, 4)}, {"soil_base": [("soil", "bottom")],
                                                                "soil_top": [("soil", "top")]}, comm=comm)
    xb = np.linspace(0.5, 3.5, 13)
    line = dc.io.mesh.from_arrays(np.column_stack([xb, np.full_like(xb, 0.1)]),
                                  np.column_stack([np.arange(12), np.arange(1, 13)]), "beam",
                                  point_groups={"left": np.array([0]), "right": np.array([12]),
                                                "mid": np.array([6])}, comm=comm)
    sc = dc.Scene(large_rotations=False, linear_solver="direct")
    soil = sc.add_solid(block, material=dc.Elastic(100.0, 0.3), degree=1)
    beam = sc.add_beam(line, section=dc.Rectangle(1.0, 0.2), material=dc.Elastic(1.0e4, 0.3))
    sc.fix(soil, "soil_base")
    sc.fix(beam, "left", dofs=("ux", "uy"))
    sc.fix(beam, "right", dofs=("uy",))
    sc.load(beam, "mid", force=(0.0, -F_BEAM))
    sc.monitor("mid", beam, "mid")
    pair = sc.contact(slaves=(beam, "beam"), masters=(soil, "soil_top"), law=dc.Penalty())
    sc.monitor_contact("contact", pair)
    return sc, soil, beam, pair


@pytest.mark.parametrize("approach", ["I", "II"])
def test_an_interface_removed_and_added_again_by_stages(approach):
    """A beam pinned at its ends lies on a soft block and is pressed at mid-span: the contact
    carries most of the load. A stage removes the interface: its forces are released over the
    stage (halfway, the state is midway: small strain, 1e-9) and the beam ends as the simply
    supported beam, w = FL³/48EI at mid-span (Roark table 8.1 case 1e; 1e-9), the block unloaded
    back at zero. The next stage adds the interface again, the beam now deep in the block:
    approach I takes every gap found as zero (seed §3.1.2), so nothing moves and the contact
    carries nothing (1e-9); approach II keeps the gaps, the overlap's forces push the beam out
    over the stage and it ends where the first stage ended (elastic, frictionless: one
    equilibrium; 1e-9)."""
    sc, soil, beam, pair = _beam_on_block()
    states = {}

    def record(stage, row):
        states[stage.name, row["load_factor"]] = {**_nodal(soil), **_nodal(beam)}

    results = solve_stages(sc, [Stage("loaded", driver=dc.LoadControl(steps=2)),
                                Stage("interface removed", remove=[pair], driver=dc.LoadControl(steps=2)),
                                Stage("interface added", add=[pair], driver=dc.LoadControl(steps=4))],
                           approach=approach, on_step=record)
    rows = [r.history.rows[-1] for r in results]
    assert rows[0]["contact_Fy"] > 0.5 * F_BEAM  # (the force on the beam, upwards)
    EI, span = 1.0e4 * 0.2**3 / 12, 3.0
    w = F_BEAM * span**3 / (48 * EI)
    assert rows[1]["mid_uy"] == pytest.approx(-w, rel=1e-9)
    loaded, free = states["loaded", 1.0], states["interface removed", 1.0]
    soil_nodes = _nodal(soil)
    assert max(np.abs(free[p]).max() for p in soil_nodes) < 1e-9 * w
    midway = states["interface removed", 0.5]
    assert max(np.abs(midway[p] - 0.5 * (loaded[p] + free[p])).max() for p in free) < 1e-9 * w
    end = states["interface added", 1.0]
    if approach == "I":
        assert max(np.abs(end[p] - free[p]).max() for p in free) < 1e-9 * w
        assert abs(rows[2]["contact_Fy"]) < 1e-9 * F_BEAM
    else:
        assert max(np.abs(end[p] - loaded[p]).max() for p in free) < 1e-9 * w

"""Staged construction (issue 14, first part): existence of solid cells per stage, stage loads,
strain-free activation. Reference: the layered fill of a laterally confined column, in closed form."""
import gmsh
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.mesh import from_gmsh
from dolfinx_corot.assembly import make_system
from dolfinx_corot.staging import Stage, solve_stages
from fd import tangent_and_fd

comm = MPI.COMM_WORLD
H, WIDTH, E, NU, RHO, G = 8.0, 1.0, 1.0e4, 0.25, 2.0, 10.0


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
        def group(dim, tags, tag, name):
            gmsh.model.addPhysicalGroup(dim, tags, tag)
            gmsh.model.setPhysicalName(dim, tag, name)

        for k, sf in enumerate(surfaces):
            group(2, [sf], k + 1, f"layer{k + 1}")
        group(1, [base], n + 1, "base")
        group(1, lefts + rights, n + 2, "sides")
        for k in range(1, n + 1):
            group(0, [left[k]], n + 2 + k, f"z{k}")
        gmsh.model.mesh.generate(2)
    tm = from_gmsh(gmsh.model, 2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


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
    """An unknown approach, a missing cell group and a part kind that cannot be staged yet each end
    in a clear error before anything is solved."""
    sc, soil = _column_scene(2, large=False)
    with pytest.raises(ValueError, match=r"approach = 'III' is not one of \('I', 'II'\)"):
        solve_stages(sc, [Stage("one", add=[(soil, "layer1")])], approach="III")
    with pytest.raises(dc.GroupNotFoundError, match="'layer9' not found"):
        solve_stages(sc, [Stage("one", add=[(soil, "layer9")])])
    from dolfinx_corot.io.gmsh_models import polyline
    sc2 = dc.Scene()
    beam = sc2.add_beam(polyline([[0.0, 0.0], [1.0, 0.0]], 2, line_name="beam"), "beam",
                        section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1.0e3))
    with pytest.raises(NotImplementedError, match="solve_stages: beam 'beam': staged construction: structural "
                                                  "parts are not staged yet, only solids"):
        solve_stages(sc2, [Stage("one", add=[(beam, "beam")])])


@pytest.mark.skipif(comm.size > 1, reason="dense finite differences of the assembled system: serial")
@pytest.mark.parametrize("approach", ["I", "II"])
def test_staged_tangent_matches_finite_differences(approach):
    """The tangent of a staged column at large strain — the top layer activated on the settled one,
    its shift s ≠ 0 (approach II: F = (I + ∇u)(I + ∇s)⁻¹ over X + s) — against central differences
    of the residual at a perturbed state, free dofs (1e-6 of its largest entry)."""
    sc, soil = _column_scene(2, large=True, modulus=1500.0)
    solve_stages(sc, [Stage(f"layer {k}", add=[(soil, f"layer{k}")]) for k in (1, 2)], approach=approach)
    model = soil.model
    assert np.abs(model.activation_shift.x.array).max() > 0.05  # the second layer's bottom had settled
    system = make_system(sc.model, solver="direct")
    try:
        rng = np.random.default_rng(5)
        model.state.x.array[:] += rng.uniform(-0.02, 0.02, model.state.x.array.shape)
        K, Kfd = tangent_and_fd(system, model.state.x.array, 1.0)
        fixed = np.concatenate([bc.dof_indices()[0] for bc in system.bcs])
    finally:
        system.destroy()
    free = np.setdiff1d(np.arange(len(K)), fixed)  # (constrained columns are eliminated from K)
    K, Kfd = K[np.ix_(free, free)], Kfd[np.ix_(free, free)]
    assert np.abs(K).max() > 100.0
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()

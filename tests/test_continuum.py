"""Large-deformation continua (UFL): exact homogeneous states, tangent, solver choice, loads, bad input."""
import gmsh
import numpy as np
import pytest
from petsc4py import PETSc
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.assembly import make_system
from dolfinx_corot.io.mesh import rectangles

comm = MPI.COMM_WORLD
L, H, E = 2.0, 1.0, 100.0


def _rectangle(nx, ny, quads):
    return rectangles({"block": (0.0, 0.0, L, H, nx, ny)},
                      {"left": [("block", "left")], "bottom": [("block", "bottom")],
                       "right": [("block", "right")], "top": [("block", "top")]}, comm=comm, quads=quads)


def _box(n, hexes):
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.occ.addBox(0, 0, 0, L, H, H)
        gmsh.model.occ.synchronize()
        for c in gmsh.model.getEntities(1):
            gmsh.model.mesh.setTransfiniteCurve(c[1], n + 1)
        for s in gmsh.model.getEntities(2):
            gmsh.model.mesh.setTransfiniteSurface(s[1])
            if hexes:
                gmsh.model.mesh.setRecombine(2, s[1])
        gmsh.model.mesh.setTransfiniteVolume(1)
        names = {}
        for _, s in gmsh.model.getEntities(2):
            c = gmsh.model.occ.getCenterOfMass(2, s)
            for k, axis in enumerate("xyz"):
                if abs(c[k]) < 1e-9:
                    names[s] = f"{axis}0"
                if axis == "x" and abs(c[0] - L) < 1e-9:
                    names[s] = "x1"
        gmsh.model.addPhysicalGroup(3, [1], 1)
        gmsh.model.setPhysicalName(3, 1, "block")
        for k, (s, name) in enumerate(sorted(names.items()), start=2):
            gmsh.model.addPhysicalGroup(2, [s], k)
            gmsh.model.setPhysicalName(2, k, name)
        gmsh.model.mesh.generate(3)
    tm = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=3, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _uniaxial_exact(material, s):
    """First Piola stress P_xx of uniaxial stretch s with free lateral faces (ν = 0: no lateral strain)."""
    if isinstance(material, dc.NeoHookean):
        return material.E / 2 * (s - 1 / s)
    return s * material.E * 0.5 * (s * s - 1)


@pytest.mark.parametrize("material", [dc.SaintVenantKirchhoff(E, 0.0), dc.NeoHookean(E, 0.0)],
                         ids=["svk", "neo-hookean"])
@pytest.mark.parametrize("quads,degree", [(False, 1), (False, 2), (True, 1), (True, 2)])
def test_uniaxial_stretch_reaction_is_exact_in_plane_strain(material, quads, degree):
    """Stretch by 25 %, sides free (ν = 0): the reaction is P_xx(s) H for any element."""
    tm = _rectangle(4, 2, quads)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=material, degree=degree)
    sc.fix(b, "left", dofs=("ux",))
    sc.fix(b, "bottom", dofs=("uy",))
    sc.prescribe(b, "right", ux=0.5)
    sc.monitor_reaction("right", b, "right")
    res = dc.solve(sc, dc.LoadControl(steps=2))
    exact = _uniaxial_exact(material, 1.25) * H
    assert abs(res.history.column("right_Fx")[-1] - exact) < 1e-8 * exact


@pytest.mark.parametrize("hexes", [False, True], ids=["tets", "hexes"])
def test_uniaxial_stretch_in_3d_with_poisson(hexes):
    """3D St Venant–Kirchhoff bar with ν = 0.3 stretched by 20 %, symmetry planes x0/y0/z0: the
    state is homogeneous (exact for P1 and P2). The lateral stretch t solves S_yy = 0, i.e.
    E_yy = −λ E_xx / (2(λ + μ)), t = √(1 + 2 E_yy); the reaction is the first Piola stress
    P_xx = F_xx S_xx = s·S_xx on the reference area H² (equal to the Cauchy stress s S_xx / t²
    on the current area t² H²)."""
    nu, s = 0.3, 1.2
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    Exx = 0.5 * (s * s - 1)
    Eyy = -lam * Exx / (2 * (lam + mu))          # S_yy = λ(Exx + 2Eyy) + 2μ Eyy = 0
    t = np.sqrt(1 + 2 * Eyy)
    Sxx = lam * (Exx + 2 * Eyy) + 2 * mu * Exx
    tm = _box(2, hexes)
    tm.add_point_group("corner", [(L, H, H)])
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, nu), degree=2)
    for face, dof in (("x0", "ux"), ("y0", "uy"), ("z0", "uz")):
        sc.fix(b, face, dofs=(dof,))
    sc.prescribe(b, "x1", ux=(s - 1) * L)
    sc.monitor_reaction("x1", b, "x1")
    sc.monitor("corner", b, "corner")
    res = dc.solve(sc, dc.LoadControl(steps=2))
    row = res.history.rows[-1]
    exact = s * Sxx * H * H
    # measured relative errors (tets/hexes, serial and 2 ranks): reaction ≤ 2.1e-10, lateral
    # contraction (t − 1) H of the free corner ≤ 3.3e-10 — Newton's stopping tolerance, not the
    # elements; the bound 2e-9 is 6–10 × that
    assert abs(row["x1_Fx"] - exact) < 2e-9 * exact, (row["x1_Fx"], exact)
    contraction = (t - 1) * H                    # −0.0683: the free faces move in by (1 − t) H
    for dof in ("uy", "uz"):
        assert abs(row[f"corner_{dof}"] - contraction) < 2e-9 * abs(contraction), (row[f"corner_{dof}"], contraction)
    assert "continuum (SaintVenantKirchhoff, 3D, degree 2" in sc.effects()[0]


@pytest.mark.skipif(comm.size > 1, reason="dense FD check of the element forms: serial")
@pytest.mark.parametrize("material", [dc.SaintVenantKirchhoff(E, 0.3), dc.NeoHookean(E, 0.3)],
                         ids=["svk", "neo-hookean"])
def test_tangent_matches_finite_differences_of_the_residual(material):
    tm = _rectangle(2, 2, True)
    sc = dc.Scene(linear_solver="direct")
    b = sc.add_solid(tm, material=material, degree=2)
    sc.fix(b, "left")
    system = make_system(sc.model, solver="direct")
    model = sc.model
    rng = np.random.default_rng(0)
    model.state.x.array[:] = 0.02 * rng.normal(size=model.state.x.array.size)  # |∇u| ≈ 0.1
    model.state.x.scatter_forward()
    system.residual(0.0)
    system.jacobian()
    K = system.A.convert("dense").getDenseArray()
    x0 = model.state.x.array.copy()
    n = x0.size
    Kfd = np.empty((n, n))
    h = 1e-6
    for j in range(n):
        for sign in (1, -1):
            model.state.x.array[:] = x0
            model.state.x.array[j] += sign * h
            system.residual(0.0)
            r = system.b.array.copy()  # λ f_ext − f_int (constrained rows: x̄ − x)
            if sign == 1:
                rp = r
        Kfd[:, j] = -(rp - r) / (2 * h)
    model.state.x.array[:] = x0
    free = np.setdiff1d(np.arange(n), np.concatenate([bc.dof_indices()[0] for bc in system.bcs]))
    sub = np.ix_(free, free)
    assert np.abs(K[sub] - Kfd[sub]).max() < 1e-6 * np.abs(K[sub]).max()
    system.destroy()


def test_linear_solver_is_chosen_by_the_scene():
    tm = _rectangle(2, 2, True)
    sc = dc.Scene()
    sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, 0.3), degree=1)
    s = make_system(sc.model)
    assert s.linear.ksp.getType() == "cg" and s.linear.ksp.getPC().getType() == "gamg"
    assert s.A.getType().endswith("aij") and s.A.getBlockSize() == 2 and s.iterative
    s.destroy()
    s = make_system(sc.model, solver="direct")
    assert s.linear.ksp.getPC().getFactorSolverType() == "mumps"
    s.destroy()


def _cantilever_block(n=(12, 2, 2), traction=200.0):
    """A cantilever block 6 × 1 × 1 under a dead end traction (200: a tip deflection of 0.23 L;
    1 000: its end turned by about 1.2 rad)."""
    tm = dc.io.mesh.box((6.0, 1.0, 1.0), n)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1e5, 0.3), degree=1)
    sc.fix(b, "x0")
    sc.load(b, "x1", traction=(0.0, -traction, 0.0))
    tm.add_point_group("tip", [(6.0, 0.0, 0.0)])
    sc.monitor("tip", b, "tip")
    return sc


def test_inexact_newton_reaches_the_direct_solution_with_fewer_krylov_iterations():
    """A cantilever block bent to a tip deflection of 0.23 L by a dead end traction: CG + AMG with
    Eisenstat–Walker tolerances and the AMG kept for a step ends on the direct solver's answer
    (the Newton tolerance decides, not the linear one) with fewer Krylov iterations than exact
    solves with a new AMG every iteration."""
    tips, krylov, its = {}, {}, {}
    for name, solver, newton in (
            ("direct", "direct", dc.NewtonOptions()),
            ("exact", "iterative", dc.NewtonOptions(forcing=False, preconditioner="iteration")),
            ("inexact", "iterative", dc.NewtonOptions())):
        sc = _cantilever_block()
        system = make_system(sc.model, solver=solver)
        res = dc.solve(sc, dc.LoadControl(steps=3, extrapolate=True, newton=newton), system=system)
        tips[name] = res.history.column("tip_uy")[-1]
        krylov[name] = system.krylov_iterations
        assert system.fallback_solves == 0
        its[name] = res.history.column("iterations")
        system.destroy()
    assert -tips["direct"] > 1.2  # 0.23 L
    for name in ("exact", "inexact"):
        assert abs(tips[name] - tips["direct"]) < 1e-7 * abs(tips["direct"])
    assert krylov["inexact"] < 0.8 * krylov["exact"]
    # inexact solves cost at most one extra Newton iteration per step
    assert all(i <= j + 1 for i, j in zip(its["inexact"], its["exact"])), its


def test_failed_krylov_solve_falls_back_to_lu():
    """Past the SVK limit of compression (stretch < 1/√3) the tangent is indefinite: CG + AMG
    breaks down, the system repeats the solve with MUMPS LU and returns the right correction;
    the AMG hierarchy that failed is not kept for the next step (none to co-rotate)."""
    sc = _cantilever_block((6, 2, 2))
    system = make_system(sc.model, solver="iterative")
    m = sc.model
    system.residual(1.0)
    system.jacobian()
    system.solve()  # at rest: the hierarchy is taken to be co-rotated at the next step
    assert system.fallback_solves == 0 and system.linear.prolongator is not None
    X = m.V.tabulate_dof_coordinates()
    u = m.state.x.array.reshape(-1, 3)
    u[:, 0] = -0.5 * X[: len(u), 0]        # uniform axial stretch 0.5
    u[:, 1] = 0.01 * X[: len(u), 0] ** 2   # and a little bending
    system.residual(1.0)
    system.jacobian()
    system.solve()
    assert system.fallback_solves == 1
    assert system.linear.prolongator is None
    check = system.b.duplicate()
    system.A.mult(system.dx, check)
    check.axpy(-1.0, system.b)
    assert check.norm() < 1e-8 * system.b.norm()
    system.destroy()


def test_self_weight_and_traction_reactions_small_strain():
    """Geometrically linear check of the loads: the support reaction balances ρ g V plus a
    traction on the top face times its length (per metre)."""
    tm = _rectangle(4, 2, False)
    sc = dc.Scene(large_rotations=False)
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, 0.2), degree=2)
    sc.fix(b, "bottom")
    sc.gravity(b, acceleration=(0.0, -9.81), density=2.0)
    sc.load(b, "top", traction=(0.0, -3.0))
    sc.monitor_reaction("base", b, "bottom")
    res = dc.solve(sc, dc.LoadControl(steps=1))
    expected = 2.0 * 9.81 * L * H + 3.0 * L
    assert abs(res.history.column("base_Fy")[-1] - expected) < 1e-9 * expected
    assert res.history.rows[-1]["iterations"] == 1
    assert sc.effects()[1] == "dead loads"


def test_bad_input_is_named():
    tm = _rectangle(2, 2, True)
    sc = dc.Scene()
    with pytest.raises(ValueError, match="degree 3"):
        sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, 0.3), degree=3)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, 0.3))
    with pytest.raises(ValueError, match="facets"):
        sc.load(b, "block", traction=(1.0, 0.0))
    with pytest.raises(ValueError, match="add_solid"):
        dc.Scene().add_beam(tm, "block", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(E))
    with pytest.raises(NotImplementedError, match="one law per solid"):
        sc.add_solid(tm, "block", material=dc.NeoHookean(E, 0.3))
    with pytest.raises(dc.GroupNotFoundError):
        sc.fix(b, "nowhere")


@pytest.mark.parametrize("large_rotations", [True, False], ids=["neo-hookean", "small strain"])
def test_reference_configuration_is_owned_by_the_solid(large_rotations):
    """A solid whose reference is the mesh moved by a field w (X' = X + w, here X' = 2X on the unit
    square) is the solid meshed at X' itself: the same displacements node by node (to round-off),
    under a traction per reference area and a body force per reference volume (Nanson's formula and
    det J₀ in the load forms)."""
    results = []
    for scale, shifted in ((1.0, True), (2.0, False)):
        tm = rectangles({"block": (0.0, 0.0, scale, scale, 3, 3)},
                        {"bottom": [("block", "bottom")], "left": [("block", "left")],
                         "right": [("block", "right")]}, comm=comm)
        sc = dc.Scene(large_rotations=large_rotations)
        b = sc.add_solid(tm, material=dc.NeoHookean(E, 0.3), degree=2)
        sc.fix(b, "bottom", dofs=("uy",))
        sc.fix(b, "left", dofs=("ux",))
        sc.load(b, "right", traction=(0.02 * E, 0.005 * E))
        sc.gravity(b, (0.0, -1.0), 0.01 * E)
        model = sc.model
        if shifted:
            model.capture_reference(model.V.tabulate_dof_coordinates()[:, :2].ravel())  # w = X
        dc.solve(sc, dc.LoadControl(steps=2))
        X, u = model.nodes()
        ref = X * (2.0 if shifted else 1.0)
        order = np.lexsort(np.round(ref, 9).T[::-1])
        results.append(u[order])
    assert np.abs(results[0]).max() > 1e-3
    np.testing.assert_allclose(results[0], results[1], atol=1e-10 * np.abs(results[1]).max())


def test_the_predictors_are_the_polynomials_through_the_converged_states():
    """LoadControl(extrapolate='quadratic') starts a step from the parabola through the last
    three converged states: a path x(λ) = λ² v is predicted exactly, the secant is off by
    (λ − λ₁)(λ − λ₂) v."""
    sc = _cantilever_block((4, 1, 1))
    system = make_system(sc.model, solver="direct")
    x = sc.model.state.x.array
    v = np.linspace(-1.0, 1.0, x.size)
    path = []
    for lam in (0.5, 1.0, 2.0):
        x[:] = lam**2 * v
        path.append((lam, system.checkpoint()))
    system.predict(path, 3.0)
    assert np.allclose(x, 9.0 * v, rtol=0.0, atol=1e-13)
    system.predict(path[1:], 3.0)
    assert np.allclose(x, (9.0 - (3.0 - 1.0) * (3.0 - 2.0)) * v, rtol=0.0, atol=1e-13)
    with pytest.raises(ValueError, match=r"extrapolate = 'cubic' is not one of"):
        dc.LoadControl(extrapolate="cubic")
    # on the bent block the parabola ends where the secant does
    tips = {}
    for how in ("secant", "quadratic"):
        sc = _cantilever_block()
        res = dc.solve(sc, dc.LoadControl(steps=4, extrapolate=how))
        tips[how] = res.history.column("tip_uy")[-1]
    assert tips["quadratic"] == pytest.approx(tips["secant"], rel=1e-7)
    system.destroy()


def _move_to(system, model, u):
    """The system's configuration to displacement u (local dofs, owned first), as a Newton
    update would make it."""
    m = system.dx.getLocalSize()
    system.dx.array[:] = (u - model.state.x.array)[:m]
    system.update()


def _deformed_block(cell, degree, material, n=(6, 2, 2)):
    tm = dc.io.mesh.box((3.0, 1.0, 1.0), n, cell=cell)
    sc = dc.Scene(linear_solver="direct")
    b = sc.add_solid(tm, material=material, degree=degree)
    sc.fix(b, "x0")
    sc.fix(b, "x1", dofs=("uz",))
    sc.load(b, "x1", traction=(0.0, -75.0, 0.0))
    return sc


@pytest.mark.parametrize("cell, degree, material", [
    ("hexahedron", 1, dc.SaintVenantKirchhoff(1e5, 0.3)), ("hexahedron", 2, dc.NeoHookean(1e5, 0.3)),
    ("tetrahedron", 1, dc.NeoHookean(1e5, 0.3)), ("tetrahedron", 2, dc.SaintVenantKirchhoff(1e5, 0.3))],
    ids=["hex-Q1", "hex-Q2", "tet-P1", "tet-P2"])
def test_compiled_assembly_is_dolfinx_assembly_bit_for_bit(monkeypatch, cell, degree, material):
    """A continuum's tangent is added into the AIJ matrix's values by a compiled loop
    (assembly.cells; on several ranks into the owned rows' diagonal and off-diagonal blocks, the
    rows of ghost nodes sent to their owners): at a deformed state, with supports of all and of
    one component, and with extra couplings in single rows, it is DOLFINx's assembly to the last
    bit (the same sums in the same order), and the direct solver sees the new values (MUMPS
    refactorizes: the matrix's state has changed). The places of the blocks kept from one tangent
    to the next are checked: a coupling added amid a node's first row moves them, and the loop
    finds them again. The diagonal the loop reads for the residual's round-off floor is PETSc's."""
    from dolfinx_corot.assembly import cells

    monkeypatch.setattr(cells, "MIN_CELLS", 0)
    sc = _deformed_block(cell, degree, material)
    system = make_system(sc.model, solver="direct")
    model = sc.model
    system.jacobian()  # the compiled loop's first (the pattern laid out from the form's)
    assert system._cells is not None
    if comm.size > 1:  # the ranks share nodes: some element matrices have rows of ghost nodes
        assert comm.allreduce(len(system._cells.ghost_cells), op=MPI.MIN) > 0
    rng = np.random.default_rng(1)
    for trial in range(3):
        if trial == 1:  # a coupling in one row of a node only (its rows' columns no longer alike)
            system.A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
            n = system.A.getSize()[0]
            system.A.setValue(4, n - 1, 0.0, addv=PETSc.InsertMode.ADD_VALUES)
            system.A.setValue(n - 2, 1, 0.0, addv=PETSc.InsertMode.ADD_VALUES)
            system.A.assemble()
        if trial == 2:  # a coupling amid a node's first row: the places kept from the last tangent move
            lo, hi = system.A.getOwnershipRange()
            row = lo + 3 * ((hi - lo) // 6)
            columns = system.A.getRow(row)[0]
            gap = np.setdiff1d(np.arange(columns[0], columns[-1]), columns)
            if len(gap):
                system.A.setValue(row, int(gap[len(gap) // 2]), 0.0, addv=PETSc.InsertMode.ADD_VALUES)
            system.A.assemble()
        _move_to(system, model, 0.01 * rng.normal(size=model.state.x.array.size))
        system.residual(0.5)
        system.jacobian()
        fast = system.A.getValuesCSR()[2].copy()
        x = system.A.createVecRight()
        system.solve(system.b, x)
        Ax = system.A.createVecLeft()
        system.A.mult(x, Ax)
        Ax.axpy(-1.0, system.b)
        assert Ax.norm() < 1e-9 * system.b.norm()  # solved with this tangent, not the last one
        diagonal = system._tangent_diagonal()  # read by the compiled loop
        saved, system._cells = system._cells, None
        assert np.array_equal(diagonal, system._tangent_diagonal())  # PETSc's MatGetDiagonal
        system._assemble_parts_matrix()
        assert np.array_equal(system.A.getValuesCSR()[2], fast)
        system._cells = saved
    system.destroy()


@pytest.mark.parametrize("cell, degree", [("hexahedron", 1), ("tetrahedron", 2)], ids=["hex-Q1", "tet-P2"])
def test_the_first_tangent_needs_no_dolfinx_assembly(monkeypatch, cell, degree):
    """Where the compiled loop assembles the tangent, A's pattern is laid out from the form's
    sparsity pattern (``_dolfinx.form_pattern``) and the loop assembles the first tangent too:
    pattern and values are those of DOLFINx's first assembly to the last bit, supports included."""
    from dolfinx_corot.assembly import cells

    monkeypatch.setattr(cells, "MIN_CELLS", 0)
    csr = []
    for dolfinx_first in (False, True):
        sc = _deformed_block(cell, degree, dc.SaintVenantKirchhoff(1e5, 0.3))
        system = make_system(sc.model, solver="direct")
        _move_to(system, sc.model, 0.01 * np.random.default_rng(2).normal(size=sc.model.state.x.array.size))
        if dolfinx_first:
            system._cells_checked = True  # DOLFINx's assembly, as before the pattern was laid out
        system.residual(0.5)
        system.jacobian()
        assert (system._cells is None) == dolfinx_first
        csr.append([a.copy() for a in system.A.getValuesCSR()])
        system.destroy()
    for ours, theirs in zip(*csr):
        assert np.array_equal(ours, theirs)


@pytest.mark.parametrize("n, degree", [((6, 2, 2), 1), ((3, 1, 1), 2), ((6, 3), 2)],
                         ids=["hex-Q1", "hex-Q2", "plane-Q2"])
def test_cg_reads_the_tangent_s_upper_triangle_in_nodal_blocks(n, degree):
    """The iterative solver's operator is the upper triangle of the AIJ tangent in nodal blocks
    (SBAIJ, 3 × 3 in 3D, 2 × 2 in plane strain; AMG is built from the AIJ matrix): at a deformed
    state with supports it holds the values PETSc's own conversion gives, to the last bit, and so
    acts as the AIJ tangent does; and it is copied again only when the tangent has changed."""
    from dolfinx_corot.assembly import petsc

    if len(n) == 3:
        sc = _deformed_block("hexahedron", degree, dc.SaintVenantKirchhoff(1e5, 0.3), n=n)
    else:
        sc = dc.Scene(linear_solver="iterative")
        b = sc.add_solid(_rectangle(*n, True), material=dc.NeoHookean(E, 0.3), degree=degree)
        sc.fix(b, "left")
        sc.load(b, "right", traction=(0.0, -1.0))
    system = make_system(sc.model, solver="iterative")
    assert system.A.getBlockSize() == len(n)
    rng = np.random.default_rng(3)
    _move_to(system, sc.model, 0.01 * rng.normal(size=sc.model.state.x.array.size))
    system.residual(0.5)
    system.jacobian()
    A = system.A
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    reference = A.convert("sbaij", PETSc.Mat())  # PETSc's MatConvert (slow, element by element)
    op = petsc.SymmetricBlockOperator(A)
    op.refresh()
    dense = [M.convert("dense", PETSc.Mat()) for M in (op.S, reference)]
    if MPI.COMM_WORLD.size == 1:
        assert np.array_equal(dense[0].getDenseArray(), dense[1].getDenseArray())
    else:  # PETSc's MPI conversion keeps a diagonal block's lower entries, ours its upper ones,
        # as on one rank: the two differ by the tangent's round-off asymmetry
        scale = np.abs(dense[1].getDenseArray()).max()
        assert np.abs(dense[0].getDenseArray() - dense[1].getDenseArray()).max() <= 1e-14 * scale
    x, y, z = A.createVecRight(), A.createVecLeft(), A.createVecLeft()
    x.setRandom()
    A.mult(x, y)
    op.S.mult(x, z)
    z.axpy(-1.0, y)
    assert z.norm() <= 1e-14 * y.norm()
    state = op.S.stateGet()
    op.refresh()
    assert op.S.stateGet() == state  # A unchanged: nothing copied
    _move_to(system, sc.model, 0.02 * rng.normal(size=sc.model.state.x.array.size))
    system.residual(0.5)
    system.jacobian()
    op.refresh()
    A.mult(x, y)
    op.S.mult(x, z)
    z.axpy(-1.0, y)
    assert z.norm() <= 1e-14 * y.norm()
    petsc.destroy(op, reference, *dense, x, y, z)
    system.destroy()



@pytest.mark.parametrize("n", [(6, 2, 2), (6, 3)], ids=["hex-Q1", "plane-Q2"])
def test_the_block_operator_s_compiled_product_is_petsc_s_to_the_last_bit(n):
    """The product of the SBAIJ operator (3 × 3 and 2 × 2 blocks) is a compiled loop installed as
    the matrix's MATOP_MULT (on several ranks: of its diagonal block, which PETSc's MPISBAIJ
    product calls), the operations of PETSc's in PETSc's order: at a deformed state with
    supports it gives PETSc's product of the same values (an operator made with
    ``-dc_sbaij_product false``, which keeps PETSc's) to the last bit, and the AIJ tangent's
    product to round-off, before and after a new tangent."""
    from dolfinx_corot.assembly import cells, petsc

    if len(n) == 3:
        sc = _deformed_block("hexahedron", 1, dc.SaintVenantKirchhoff(1e5, 0.3), n=n)
    else:
        sc = dc.Scene(linear_solver="iterative")
        b = sc.add_solid(_rectangle(*n, True), material=dc.NeoHookean(E, 0.3), degree=2)
        sc.fix(b, "left")
        sc.load(b, "right", traction=(0.0, -1.0))
    system = make_system(sc.model, solver="iterative")
    rng = np.random.default_rng(5)
    _move_to(system, sc.model, 0.01 * rng.normal(size=sc.model.state.x.array.size))
    system.residual(0.5)
    system.jacobian()
    A = system.A
    ops = {}
    for installed in (True, False):
        options = PETSc.Options()
        if not installed:
            options["dc_sbaij_product"] = "false"
        try:
            ops[installed] = petsc.SymmetricBlockOperator(A)
        finally:
            if not installed:
                del options["dc_sbaij_product"]
        ops[installed].refresh()
    ctypes, lib, _, _ = petsc._petsc_library()
    module = cells.compiled()
    ours = int(module.ffi.cast("uintptr_t", module.ffi.addressof(module.lib, "sbaij_mult")))

    def product_of(op):
        target = op.S if MPI.COMM_WORLD.size == 1 else op.S.getDiagonalBlock()
        f = ctypes.c_void_p()
        assert lib.MatGetOperation(ctypes.c_void_p(target.handle), petsc._MATOP_MULT, ctypes.byref(f)) == 0
        return f.value

    assert product_of(ops[True]) == ours
    assert product_of(ops[False]) != ours
    x, y, z, w = A.createVecRight(), A.createVecLeft(), A.createVecLeft(), A.createVecLeft()
    for k in range(3):
        x.setArray(rng.normal(size=x.getLocalSize()))
        ops[True].S.mult(x, y)
        ops[False].S.mult(x, w)
        assert np.array_equal(y.array_r, w.array_r)
        A.mult(x, z)
        assert np.linalg.norm(y.array_r - z.array_r) <= 1e-13 * np.linalg.norm(z.array_r)
    # a new tangent: the same values' address, the product follows them
    _move_to(system, sc.model, 0.02 * rng.normal(size=sc.model.state.x.array.size))
    system.residual(0.5)
    system.jacobian()
    for op in ops.values():
        op.refresh()
    ops[True].S.mult(x, y)
    ops[False].S.mult(x, w)
    assert np.array_equal(y.array_r, w.array_r)
    petsc.destroy(ops[True], ops[False], x, y, z, w)
    system.destroy()

def _true_linear_residuals(sc, system, steps=3):
    """Solve the bent block and return, for each inexact Newton solve, the true linear residual
    ‖b − K x‖ / ‖b‖ it left and the tolerance η the forcing term asked of it."""
    linear = system.linear
    seen = []
    solve = linear.solve

    def recording(rhs, out):
        solve(rhs, out)
        K = linear.ksp.getOperators()[0]
        r = rhs.duplicate()
        K.mult(out, r)
        r.aypx(-1.0, rhs)  # r = b − K x
        seen.append((r.norm() / rhs.norm(), linear.ksp.getTolerances()[0]))
        r.destroy()

    linear.solve = recording
    dc.solve(sc, dc.LoadControl(steps=steps), system=system, quiet=True)
    system.destroy()
    return np.array(seen)


def test_the_inexact_newton_bounds_the_true_residual_of_each_linear_solve():
    """Eisenstat & Walker's forcing term is a bound on the linear solve's true residual,
    ‖b − K s‖ ≤ η ‖b‖. CG measures it so (the unpreconditioned norm): every solve of the bent
    block meets it. With PETSc's default, the preconditioned norm, the same η leaves true
    residuals up to 10³ times above it (the test can fail: the old norm breaks the bound)."""
    sc = _cantilever_block()
    seen = _true_linear_residuals(sc, make_system(sc.model, solver="iterative"))
    assert len(seen) >= 6
    # (CG updates its residual by recursion: the true one differs from it at round-off)
    assert np.all(seen[:, 0] <= 1.01 * seen[:, 1]), seen
    sc, system = _block_system_with_option("dc_newton_forcing_true_residual", "false")
    old = _true_linear_residuals(sc, system)
    assert np.any(old[:, 0] > 2.0 * old[:, 1]), old


def _block_system_with_option(name: str, value: str):
    """The bent cantilever block and its iterative system made while the PETSc option ``name``
    is ``value`` (the option is removed afterwards)."""
    options = PETSc.Options()
    options[name] = value
    try:
        sc = _cantilever_block()
        return sc, make_system(sc.model, solver="iterative")
    finally:
        del options[name]


@pytest.mark.parametrize("n, degree", [((6, 2, 2), 1), ((3, 1, 1), 2), ((6, 3), 2)],
                         ids=["hex-Q1", "hex-Q2", "plane-Q2"])
def test_the_tangent_assembled_into_its_upper_block_triangle_alone_is_the_copied_one(monkeypatch, n, degree):
    """On one rank, with the compiled assembly and CG on the upper block triangle, a tangent goes
    into the SBAIJ operator alone (``CellAssembler.assemble_upper``: the node pairs on or above the
    diagonal). At a deformed state with supports of all components and of one, that operator is
    PETSc's conversion of the AIJ tangent the compiled loop assembles, to the last bit, and so is
    the diagonal the residual's round-off floor reads, which is written into A as well (the
    smoothers of a kept AMG hierarchy read it there); A's other values are made from S only when
    A is read (``System.A``), then the assembled AIJ tangent: its upper triangle to the last bit,
    its lower one to round-off (the mirror image of the upper). On several ranks the same, to
    round-off: the owned columns go into S's diagonal block, the higher ranks' columns and the
    rows of ghost nodes by PETSc's insertion (sums in another order than the AIJ assembly's)."""
    from dolfinx_corot.assembly import cells

    monkeypatch.setattr(cells, "MIN_CELLS", 0)
    if len(n) == 3:
        sc = _deformed_block("hexahedron", degree, dc.SaintVenantKirchhoff(1e5, 0.3), n=n)
    else:
        sc = dc.Scene(linear_solver="iterative")
        b = sc.add_solid(_rectangle(*n, True), material=dc.NeoHookean(E, 0.3), degree=degree)
        sc.fix(b, "left")
        sc.fix(b, "right", dofs=("uy",))
        sc.load(b, "right", traction=(1.0, 0.0))
    system = make_system(sc.model, solver="iterative")
    system.jacobian()  # the first tangent: into A
    assert system._cells is not None and system._upper_operator() is None
    system.linear.block_operator()  # made by the first solve, from A's pattern
    rng = np.random.default_rng(5)
    _move_to(system, sc.model, 0.01 * rng.normal(size=sc.model.state.x.array.size))
    system.residual(0.5)
    system.jacobian()
    op = system.linear.operator
    assert op.upper_newer and op.assembled

    def same(a, b):
        if comm.size == 1:
            return np.array_equal(a, b)
        return a.shape == b.shape and np.allclose(a, b, rtol=0.0, atol=1e-14 * max(np.abs(b).max(initial=0.0), 1e-300))

    state = system._A.stateGet()
    direct = op.S.convert("dense", PETSc.Mat()).getDenseArray().copy()
    diagonal = system._tangent_diagonal().copy()
    assert np.array_equal(diagonal, system._A.getDiagonal().array)  # A's diagonal follows (Jacobi smoothers)
    assert system._A.stateGet() == state  # nothing else read or written
    mirrored = system.A.getValuesCSR()  # A read: made from S
    assert not op.upper_newer and system._A.stateGet() != state
    mirrored = [a.copy() for a in mirrored]
    system._upper_assembly = False
    system.jacobian()  # the compiled loop into A, as on several ranks
    assert not op.upper_newer
    A = system.A
    indptr, indices, values = A.getValuesCSR()
    assert np.array_equal(indptr, mirrored[0]) and np.array_equal(indices, mirrored[1])
    rows = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
    bs = A.getBlockSize()
    rows += A.getOwnershipRange()[0]
    upper = (indices // bs > rows // bs) | ((indices // bs == rows // bs) & (indices >= rows))
    assert same(mirrored[2][upper], values[upper])
    assert np.allclose(mirrored[2], values, rtol=0.0, atol=1e-14 * np.abs(values).max())
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    reference = A.convert("sbaij", PETSc.Mat())
    assert same(direct, reference.convert("dense", PETSc.Mat()).getDenseArray())
    assert same(diagonal, A.getDiagonal().array)
    reference.destroy()
    system.destroy()


def test_the_newton_path_on_the_upper_block_triangle_alone_is_the_path_on_the_copied_one(monkeypatch):
    """The bent cantilever block (12 × 2 × 2, two steps, CG + AMG kept and co-rotated) with its
    tangents assembled into the upper block triangle alone (the default) and into the AIJ matrix
    then copied (``-dc_newton_upper_assembly false``): on one rank the same path to the last bit
    (tip, Newton and Krylov iterations: CG, its preconditioner's build and its kept smoothers see
    the same numbers), on several to round-off (the interface's sums in another order); the AIJ
    matrix is filled from the operator only where it is read: here for the inertia of each
    converged step's tangent (a model this small has its critical points tracked), and never in
    between."""
    from dolfinx_corot.assembly import cells, petsc

    monkeypatch.setattr(cells, "MIN_CELLS", 0)
    tips, newton, krylov, syncs = {}, {}, {}, {}
    op_class = petsc.SymmetricBlockOperator
    original = op_class.sync
    for name, value in (("upper", "true"), ("copied", "false")):
        sc, system = _block_system_with_option("dc_newton_upper_assembly", value)
        calls = []
        monkeypatch.setattr(op_class, "sync", lambda self: (calls.append(self.upper_newer), original(self))[1])
        res = dc.solve(sc, dc.LoadControl(steps=2, extrapolate=True), system=system)
        monkeypatch.setattr(op_class, "sync", original)
        assert system.linear.operator.assembled == (name == "upper")
        tips[name] = res.history.column("tip_uy")[-1]
        newton[name] = res.totals["newton_iterations"]
        krylov[name] = system.krylov_iterations
        syncs[name] = sum(calls)  # the syncs that made A from S
        system.destroy()
    if comm.size == 1:
        assert tips["upper"] == tips["copied"]
        assert krylov["upper"] == krylov["copied"]
    else:
        assert tips["upper"] == pytest.approx(tips["copied"], rel=1e-9)
        assert abs(krylov["upper"] - krylov["copied"]) <= 2
    assert newton["upper"] == newton["copied"]
    assert syncs["copied"] == 0 and syncs["upper"] == 2


def test_the_newton_path_on_the_block_operator_is_the_path_on_the_aij_tangent():
    """The bent cantilever block with CG on the tangent's upper triangle in nodal blocks (the
    default) and with CG on the AIJ tangent (``-dc_newton_block_operator false``): the same tip
    to 1e-8 in as many Krylov iterations (within 2: the products' round-off differs)."""
    tips, krylov = {}, {}
    for name, value in (("blocks", "true"), ("aij", "false")):
        sc, system = _block_system_with_option("dc_newton_block_operator", value)
        res = dc.solve(sc, dc.LoadControl(steps=2, extrapolate=True), system=system)
        assert (system.linear.operator is not None) == (name == "blocks")
        assert system.linear.ksp.getOperators()[0].getType().endswith("sbaij") == (name == "blocks")
        tips[name] = res.history.column("tip_uy")[-1]
        krylov[name] = system.krylov_iterations
        system.destroy()
    assert tips["blocks"] == pytest.approx(tips["aij"], rel=1e-8)
    assert abs(krylov["blocks"] - krylov["aij"]) <= 2


def test_the_amg_near_nullspace_is_the_current_configuration_s_rigid_motions():
    """A free block turned rigidly by 1.2 rad: its tangent (no stress: material stiffness only)
    annihilates the translations and the infinitesimal rotations of x = X + u, which the
    AMG gets as its near-nullspace; rotations about the reference X are far from free."""
    from dolfinx_corot.assembly import petsc

    tm = dc.io.mesh.box((2.0, 1.0, 1.0), (4, 2, 2))
    sc = dc.Scene(linear_solver="iterative")
    sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1e5, 0.3), degree=1)
    system = make_system(sc.model, solver="iterative")
    model = sc.model
    n = model.V.dofmap.index_map.size_local
    X = model.V.tabulate_dof_coordinates()[:, :3]
    c, s = np.cos(1.2), np.sin(1.2)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    _move_to(system, model, (X @ R.T - X).ravel())
    system.jacobian()
    scale = system.A.norm(PETSc.NormType.FROBENIUS)
    reference = model.near_nullspace_modes()
    model.state.x.array[:] = 0.0
    at_rest = model.near_nullspace_modes()  # X alone
    model.state.x.array[:] = (X @ R.T - X).ravel()
    v, y = system.A.createVecRight(), system.A.createVecLeft()

    def residual(mode):
        v.array[:] = mode[:n].ravel()
        system.A.mult(v, y)
        return y.norm() / (scale * v.norm())

    assert max(residual(m) for m in model.near_nullspace_modes()) < 1e-12
    assert min(residual(m) for m in at_rest[3:]) > 1e-3  # rotations of X: not free at this state
    assert all(np.array_equal(a, b) for a, b in zip(reference, model.near_nullspace_modes()))
    system.destroy()


def _rotation(axis, angle):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "numpy"])
def test_patch_rotations_recover_a_rigid_rotation_of_the_mesh(compiled, monkeypatch):
    """The rotation fitted to each node's patch of cells (Kabsch's least squares) is the rigid
    rotation that moved the mesh, to round-off, in 3D (2.5 rad about a skew axis, after a bend of
    the block) and in plane strain; under a general deformation it is a proper rotation."""
    from dolfinx_corot.assembly import amg

    if not compiled:
        monkeypatch.setattr(amg, "_compiled", lambda: None)
    tm = dc.io.mesh.box((3.0, 1.0, 1.0), (6, 2, 2))
    sc = dc.Scene()
    sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1e5, 0.3), degree=1)
    model = sc.model
    cells = model.V.dofmap.list.array.reshape(-1, model.nodes_per_cell)
    n = model.V.dofmap.index_map.size_local
    X = model.positions()
    bent = X + 0.1 * np.column_stack([np.zeros(len(X)), X[:, 0] ** 2, np.sin(X[:, 0])])
    R0 = _rotation((1.0, 2.0, -0.5), 2.5)
    moved = bent @ R0.T + np.array([0.3, -1.0, 2.0])
    assert np.abs(amg.patch_rotations(cells, bent, moved, n) - R0).max() < 1e-13
    rng = np.random.default_rng(0)
    R = amg.patch_rotations(cells, X, X + 0.3 * rng.normal(size=X.shape), n)
    assert np.abs(np.einsum("nij,nkj->nik", R, R) - np.eye(3)).max() < 1e-13
    assert np.allclose(np.linalg.det(R), 1.0)
    rect = _rectangle(6, 3, True)
    sc2 = dc.Scene()
    sc2.add_solid(rect, material=dc.NeoHookean(E, 0.3), degree=2)
    m2 = sc2.model
    cells2 = m2.V.dofmap.list.array.reshape(-1, m2.nodes_per_cell)
    Y = m2.positions()
    c, s = np.cos(-1.9), np.sin(-1.9)
    Q = np.array([[c, -s], [s, c]])
    R2 = amg.patch_rotations(cells2, Y, Y @ Q.T + 1.0, m2.V.dofmap.index_map.size_local)
    assert np.abs(R2 - Q).max() < 1e-13


def test_the_compiled_polar_iteration_is_the_svd_rotation_where_it_answers():
    """cells.polar3 (Newton's polar iteration) against the SVD's nearest proper rotation U Vᵀ on
    patch moments near and far from a rotation, of any scale: the same rotation to 1e-13 wherever
    det H > 0, and no answer (the SVD's turn then) where H reflects or is singular."""
    from dolfinx_corot.assembly import amg, cells

    module = cells.compiled()
    rng = np.random.default_rng(3)
    H = np.eye(3) + 0.3 * rng.normal(size=(2000, 3, 3))
    H[:200] = rng.normal(size=(200, 3, 3))  # far from a rotation: about half reflect
    H[200] = 0.0
    H[201] = np.diag([1.0, 1.0, 0.0])
    H[202] = np.diag([1.0, 1.0, -1e-3])
    H *= np.exp(rng.uniform(-8.0, 8.0, size=(len(H), 1, 1)))
    R = np.empty_like(H)
    ok = np.zeros(len(H), dtype=np.uint8)
    module.lib.polar3(len(H), amg._ptr(module, "double", H), amg._ptr(module, "double", R),
                      amg._ptr(module, "uint8_t", ok))
    det = np.linalg.det(H)
    assert np.array_equal(ok == 1, det > 1e-13 * np.linalg.norm(H, axis=(1, 2)) ** 3)
    assert 50 < np.sum(ok[:200] == 0) < 150 and not ok[200:203].any()
    # round-off grows with the condition number of H: measured where it is below 100
    s = np.linalg.svd(H, compute_uv=False)
    fair = (ok == 1) & (s[:, 0] < 100.0 * s[:, 2])
    assert fair.sum() > 1800
    assert np.abs(R[fair] - amg._nearest_rotations(H[fair])).max() < 1e-13


def _amg_solved(d: int, refined: int = 1, load: float = 0.0):
    """The cantilever block (d = 3, 12 × 2 × 2 cells times ``refined``) or plane-strain strip
    (d = 2, 24 × 4 times ``refined``) with its iterative system after one solve (a GAMG hierarchy
    built) at the load factor ``load``."""
    if d == 3:
        sc = _cantilever_block((12 * refined, 2 * refined, 2 * refined))
    else:
        sc = dc.Scene()
        b = sc.add_solid(_rectangle(24 * refined, 4 * refined, True), material=dc.NeoHookean(E, 0.3), degree=1)
        sc.fix(b, "left")
        sc.load(b, "right", traction=(0.0, -1.0))
    system = make_system(sc.model, solver="iterative")
    system.residual(load)
    system.jacobian()
    system.solve()
    return system


def _nodal_rotations(rng, n: int, d: int) -> np.ndarray:
    """n random rotations (n, d, d)."""
    if d == 2:
        angle = rng.uniform(-3.0, 3.0, size=n)
        return np.stack([np.stack([np.cos(angle), -np.sin(angle)], -1), np.stack([np.sin(angle), np.cos(angle)], -1)], 1)
    return np.array([_rotation(rng.normal(size=3), rng.uniform(0.0, 3.0)) for _ in range(n)])


@pytest.mark.parametrize("compiled, d", [(True, 3), (False, 3), (True, 2)], ids=["compiled", "numpy", "plane"])
def test_the_corotated_prolongator_is_the_built_one_turned_node_by_node(compiled, d, monkeypatch):
    """The finest prolongator of the block's GAMG hierarchy (3D, and plane strain), turned by a
    rotation a node, is diag(R_i) P⁰ to round-off, on one rank and several (the off-diagonal
    block too), and turned back by the identity it is P⁰ again, bit for bit: the rotation acts
    on the values kept."""
    from dolfinx_corot.assembly import amg

    if not compiled:
        monkeypatch.setattr(amg, "_compiled", lambda: None)
    system = _amg_solved(d)
    pc = system.linear.ksp.getPC()
    assert pc.getMGLevels() >= 2
    prolongator = amg.CorotatedProlongator(pc, d)
    P = prolongator.P
    P0 = P.convert("dense", PETSc.Mat()).getDenseArray().copy()
    n = system.A.getLocalSize()[0] // d
    rng = np.random.default_rng(comm.rank)
    R = _nodal_rotations(rng, n, d)
    prolongator.rotate(R)
    P1 = P.convert("dense", PETSc.Mat()).getDenseArray()
    expected = np.einsum("nab,nbk->nak", R, P0.reshape(n, d, -1)).reshape(P0.shape)
    assert np.abs(P1 - expected).max() <= 1e-14 * np.abs(P0).max()
    prolongator.rotate(np.tile(np.eye(d), (n, 1, 1)))
    assert np.array_equal(P.convert("dense", PETSc.Mat()).getDenseArray(), P0)
    assert prolongator.current(pc)
    system.destroy()



@pytest.mark.parametrize("d", [3, 2], ids=["block", "plane"])
def test_the_transfers_by_the_nodal_loops_are_petsc_s_products_to_the_last_bit(d):
    """The V-cycle's restriction Pᵀr and prolongation x + Pe with the kept finest prolongator are
    compiled loops over its nodes (the rows of a node share their columns; installed as the
    matrix's MATOP_MULT_TRANSPOSE and MATOP_MULT_ADD on one rank, PETSc's MPIAIJ products on
    several): PETSc's products (of a copy of P: its I-node product for the prolongation) to the
    last bit, the prolongation into another vector and in place, before and after the
    prolongator is turned, and PETSc's own again once restored (the system's own prolongator
    installed the loops on P before this second one did)."""
    from dolfinx_corot.assembly import amg, petsc

    system = _amg_solved(d)
    pc = system.linear.ksp.getPC()
    prolongator = amg.CorotatedProlongator(pc, d)
    P = prolongator.P
    products = prolongator.transfer_products
    assert sorted(p.kind for p in products) == ([2, 4] if comm.size == 1 else []) and all(p.installed for p in products)
    n = system.A.getLocalSize()[0] // d
    rng = np.random.default_rng(comm.rank + 7)
    r, ours, theirs = P.createVecLeft(), P.createVecRight(), P.createVecRight()
    e, fine_ours, fine_theirs = P.createVecRight(), P.createVecLeft(), P.createVecLeft()
    ctypes, lib, _, _ = petsc._petsc_library()

    def operation(product):
        f = ctypes.c_void_p()
        op, _ = petsc.CompiledProduct._FUNCTIONS[product.kind]
        assert lib.MatGetOperation(ctypes.c_void_p(product.handle), op, ctypes.byref(f)) == 0
        return f.value

    def same():
        copy = P.duplicate(copy=True)  # a new matrix: PETSc's products
        r.setArray(rng.normal(size=r.getLocalSize()))
        e.setArray(rng.normal(size=e.getLocalSize()))
        P.multTranspose(r, ours)
        copy.multTranspose(r, theirs)
        equal = [np.array_equal(ours.array_r, theirs.array_r)]
        P.multAdd(e, r, fine_ours)
        copy.multAdd(e, r, fine_theirs)
        equal.append(np.array_equal(fine_ours.array_r, fine_theirs.array_r))
        P.multAdd(e, fine_ours, fine_ours)  # (in place, as the V-cycle's interpolation)
        copy.multAdd(e, fine_theirs, fine_theirs)
        equal.append(np.array_equal(fine_ours.array_r, fine_theirs.array_r))
        copy.destroy()
        return all(equal)

    module = petsc._compiled_cells()
    for product in products:
        name = petsc.CompiledProduct._FUNCTIONS[product.kind][1]
        assert operation(product) == int(module.ffi.cast("uintptr_t", module.ffi.addressof(module.lib, name)))
    assert same()
    R = _nodal_rotations(rng, n, d)
    prolongator.rotate(R)
    assert same()
    for product in products:
        product.restore()
        f = operation(product)
        assert f == product.original and not product.installed
        # PETSc's own, although the system's prolongator had installed the loop on P first
        name = petsc.CompiledProduct._FUNCTIONS[product.kind][1]
        assert f != int(module.ffi.cast("uintptr_t", module.ffi.addressof(module.lib, name)))
    assert same()
    petsc.destroy(r, ours, theirs, e, fine_ours, fine_theirs)
    system.destroy()


def test_the_tangent_s_diagonal_is_the_kept_one_while_the_tangent_is_current():
    """Where the tangent is assembled into the solver's upper block triangle alone (the compiled
    assembly: 4 000 cells a rank at least), A's MATOP_GET_DIAGONAL (which the finest Jacobi smoother
    reads once a solve) hands back the diagonal the assembly kept: PETSc's own diagonal of A (of
    a duplicate) to the last bit after each new tangent; once A has changed otherwise, A's own
    operation (the changed entry); PETSc's operation back once restored. A second one on the
    same matrix is not installed."""
    from dolfinx_corot.assembly import cells, petsc

    system = make_system(_cantilever_block((64, 12, 12)).model, solver="iterative")  # (4 608 cells a rank on two)
    system.residual(0.5)
    system.jacobian()
    system.solve()
    operator = system._upper_operator()
    assert operator is not None
    kept = operator._kept
    A = system.A
    ctypes, lib, _, _ = petsc._petsc_library()
    module = cells.compiled()
    ours = int(module.ffi.cast("uintptr_t", module.ffi.addressof(module.lib, "kept_diagonal")))

    def operation():
        f = ctypes.c_void_p()
        assert lib.MatGetOperation(ctypes.c_void_p(A.handle), petsc._MATOP_GET_DIAGONAL, ctypes.byref(f)) == 0
        return f.value

    def petsc_diagonal():
        plain = A.duplicate(copy=True)  # (a new matrix: PETSc's operation)
        d = plain.getDiagonal()
        values = d.array_r.copy()
        petsc.destroy(plain, d)
        return values

    assert kept is not None and kept.installed and operation() == ours
    assert not petsc.KeptDiagonal(A).installed  # (a second one would call itself as A's own)
    for load in (0.5, 1.0):
        system.residual(load)
        system.jacobian()
        assert kept.values is not None and np.array_equal(kept.values, operator.diagonal())
        d = A.getDiagonal()
        assert np.array_equal(d.array_r, petsc_diagonal()) and np.all(d.array_r > 0.0)
        d.destroy()
        system.solve()
    first = A.getOwnershipRange()[0]
    A.setValue(first, first, 12345.0)
    A.assemble()
    d = A.getDiagonal()
    assert d.array_r[0] == 12345.0 and np.array_equal(d.array_r, petsc_diagonal())
    d.destroy()
    own = kept.own
    kept.restore()
    assert operation() == own != ours and not kept.installed
    system.destroy()


@pytest.mark.parametrize("d", [3, 2], ids=["block", "plane"])
def test_the_coarse_levels_multiply_by_nodal_block_copies_while_they_are_current(d):
    """AMG's operators between the finest and the coarsest level (AIJ with blocks of the
    rigid-body modes, 6 × 6 in 3D, 3 × 3 in the plane) multiply by an SBAIJ copy (the upper
    block triangle: CG's tangent is symmetric) installed as their MATOP_MULT: the AIJ product
    (of a duplicate: PETSc's own) to round-off; once the operator's state has changed, its own
    product to the last bit, and a new copy at the next solve's check; PETSc's own product back
    once restored. A linear solve ends on the solution of the hierarchy without copies
    (``-dc_amg_coarse_blocks false``) to its tolerance."""
    from dolfinx_corot.assembly import petsc

    def solved():  # (three levels at least)
        return _amg_solved(d, 2 if d == 3 else 4, load=1.0)

    system = solved()
    linear = system.linear
    pc = linear.ksp.getPC()
    copies = linear._coarse
    assert pc.getMGLevels() >= 3 and sorted(copies) == list(range(1, pc.getMGLevels() - 1))
    module = next(iter(copies.values())).module
    ours = int(module.ffi.cast("uintptr_t", module.ffi.addressof(module.lib, "copied_mult")))
    ctypes, lib, _, _ = petsc._petsc_library()

    def operation(A):
        f = ctypes.c_void_p()
        assert lib.MatGetOperation(ctypes.c_void_p(A.handle), petsc._MATOP_MULT, ctypes.byref(f)) == 0
        return f.value

    rng = np.random.default_rng(comm.rank + 3)

    def against_petsc(A, exact=False):
        """A's product against PETSc's own (of a duplicate) at a random x: to round-off, and not
        the same numbers (another order of the sums), or (``exact``) to the last bit."""
        plain = A.duplicate(copy=True)
        x, y, z = A.createVecRight(), A.createVecLeft(), A.createVecLeft()
        x.setArray(rng.normal(size=x.getLocalSize()))
        A.mult(x, y)
        plain.mult(x, z)
        if exact:
            assert np.array_equal(y.array_r, z.array_r)
        else:
            assert 0.0 < (y - z).norm() <= 1e-13 * z.norm()
        petsc.destroy(plain, x, y, z)

    sbaij = int(module.ffi.cast("uintptr_t", module.ffi.addressof(module.lib, "sbaij_mult")))
    for level, product in copies.items():
        A = pc.getMGSmoother(level).getOperators()[0]
        assert product.installed and product.current(A) and operation(A) == ours
        assert product.copy.getType() in ("seqsbaij", "mpisbaij") and product.copy.getBlockSize() == 3 * (d - 1)
        against_petsc(A)
        # the copy's product by the compiled loop (on several ranks its diagonal block's): PETSc's
        # SBAIJ product (MatMult_SeqSBAIJ_6 or _3) to the last bit
        compiled = product.compiled
        assert compiled is not None and compiled.installed and compiled.bs == 3 * (d - 1)
        target = product.copy if comm.size == 1 else product.copy.getDiagonalBlock()
        assert operation(target) == sbaij
        x, y, z = A.createVecRight(), A.createVecLeft(), A.createVecLeft()
        x.setArray(rng.normal(size=x.getLocalSize()))
        A.mult(x, y)
        compiled.restore()
        assert operation(target) == compiled.original != sbaij
        A.mult(x, z)
        assert np.array_equal(y.array_r, z.array_r)
        petsc.destroy(x, y, z)
        A.stateIncrease()  # as after a new Galerkin product into A
        assert not product.current(A)
        against_petsc(A, exact=True)
    renewed = petsc.coarse_copies(pc, True, dict(copies))
    assert sorted(renewed) == sorted(copies)
    for level, product in renewed.items():
        A = pc.getMGSmoother(level).getOperators()[0]
        assert product is not copies[level] and product.current(A) and not copies[level].installed
        own = product.own
        product.restore()
        assert operation(A) == own != ours and not product.installed
    # an unsymmetric solve's copies: BAIJ, the AIJ product to round-off
    for level, product in petsc.coarse_copies(pc, False, {}).items():
        A = pc.getMGSmoother(level).getOperators()[0]
        assert product.format == "baij" and product.copy.getType() in ("seqbaij", "mpibaij")
        against_petsc(A)
        product.restore()
    linear._coarse = {}
    system.destroy()

    solutions = {}
    for blocks in (True, False):
        options = PETSc.Options()
        if not blocks:
            options["dc_amg_coarse_blocks"] = "false"
        try:
            system = solved()
            assert bool(system.linear._coarse) == blocks
            # (on several ranks two meshes of one scene may be partitioned apart: global figures)
            solutions[blocks] = np.array([system.dx.norm(), system.dx.dot(system.b), system.dx.max()[1]])
            system.destroy()
        finally:
            if not blocks:
                del options["dc_amg_coarse_blocks"]
    assert np.all(np.abs(solutions[False]) > 0.0)
    assert np.all(np.abs(solutions[True] - solutions[False]) <= 1e-8 * np.abs(solutions[False]))


def test_the_amg_hierarchy_is_kept_from_step_to_step_co_rotated():
    """The cantilever block bent until its end has turned by about 1.2 rad, in 4 steps, CG + AMG:
    with the hierarchy of the first step kept and its finest prolongator co-rotated by the
    nodal rotations and its coarse operators kept, the tip is the one of new hierarchies every
    step (the Newton tolerance decides) in at most 1.25 times their CG iterations (measured: 1.14
    on one rank and on two), with no hierarchy built anew. Kept without the rotation, the
    prolongator spans the rigid modes of the first configuration: at least 1.1 times the
    co-rotated iterations (measured 1.56 and 1.71). Turned by random rotations, the hierarchy is useless, its CG iterations
    grow, and it is built anew (the safety net)."""
    from dolfinx_corot.assembly import amg

    runs = {}
    true_rotations = amg.patch_rotations
    rng = np.random.default_rng(comm.rank)

    def identity(cells, before, after, n):
        return np.tile(np.eye(3), (n, 1, 1))

    def random(cells, before, after, n):
        return np.array([_rotation(rng.normal(size=3), rng.uniform(0.5, 3.0)) for _ in range(n)])

    for name, rotations in (("anew", true_rotations), ("co-rotated", true_rotations), ("kept", identity),
                            ("random", random)):
        options = PETSc.Options()
        if name == "anew":
            options["dc_newton_amg_corotate"] = "false"
        amg.patch_rotations = rotations
        try:
            sc = _cantilever_block((24, 4, 4), traction=1000.0)
            system = make_system(sc.model, solver="iterative")
            res = dc.solve(sc, dc.LoadControl(steps=4, extrapolate=True), system=system)
        finally:
            amg.patch_rotations = true_rotations
            if name == "anew":
                del options["dc_newton_amg_corotate"]
        runs[name] = (res.history.column("tip_uy")[-1], system.krylov_iterations, system.amg_builds,
                      system.amg_corotations)
        system.destroy()
    tip, cg, builds, kept = runs["co-rotated"]
    assert runs["anew"][2] == 3 and runs["anew"][3] == 0
    assert builds == 0 and kept == 3
    assert tip == pytest.approx(runs["anew"][0], rel=1e-8)
    assert tip == pytest.approx(-3.8875, rel=1e-4)
    assert cg <= 1.25 * runs["anew"][1]
    assert runs["kept"][1] >= 1.1 * cg
    assert runs["random"][2] >= 1
    for name in ("kept", "random"):
        assert runs[name][0] == pytest.approx(tip, rel=1e-8)


# -- the C kernels of the hyperelastic laws (continuum.compiled) ---------------------------------
def _curved(cell):
    """A quarter of an annulus (2D, 6-node triangles or 9-node quadrilaterals) or of a thick
    cylinder (3D, 10-node tetrahedra) meshed by gmsh with second-order, curved cells; faces
    'inner' (r = 1) and 'cut' (y = 0)."""
    dim = 3 if cell == "tetrahedron" else 2
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        if dim == 2:
            ring = occ.cut([(2, occ.addDisk(0, 0, 0, 2, 2))], [(2, occ.addDisk(0, 0, 0, 1, 1))])[0]
        else:
            ring = occ.cut([(3, occ.addCylinder(0, 0, 0, 0, 0, 1, 2))], [(3, occ.addCylinder(0, 0, 0, 0, 0, 1, 1))])[0]
        quarter = occ.intersect(ring, [(dim, occ.addBox(0, 0, -1, 3, 3, 3) if dim == 3 else
                                       occ.addRectangle(0, 0, 0, 3, 3))])[0]
        occ.synchronize()
        gmsh.model.addPhysicalGroup(dim, [t for _, t in quarter], 1)
        gmsh.model.setPhysicalName(dim, 1, "body")
        for k, (name, test) in enumerate([("inner", lambda c: abs(np.hypot(c[0], c[1]) - 1.0) < 0.3),
                                          ("cut", lambda c: abs(c[1]) < 1e-9)], start=2):
            faces = [t for _, t in gmsh.model.getEntities(dim - 1)
                     if test(occ.getCenterOfMass(dim - 1, t)) and abs(occ.getMass(dim - 1, t)) > 1e-9]
            gmsh.model.addPhysicalGroup(dim - 1, faces, k)
            gmsh.model.setPhysicalName(dim - 1, k, name)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        if cell == "quadrilateral":
            gmsh.option.setNumber("Mesh.RecombineAll", 1)
            gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 1)  # quadrilaterals only
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
        gmsh.model.mesh.generate(dim)
        gmsh.model.mesh.setOrder(2)
    tm = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=dim, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _ufl_forms(solid, monkeypatch):
    """The solid's forms as FFCx compiles them from UFL (its C kernels switched off)."""
    with monkeypatch.context() as m:
        m.setattr(type(solid), "_compiled_forms", lambda self: None)
        solid._forms = None
        forms = solid.forms()
    solid._forms = None
    return forms


def _assembled(forms):
    import dolfinx.fem.petsc

    b = dolfinx.fem.petsc.assemble_vector(forms[0])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    A = dolfinx.fem.petsc.assemble_matrix(forms[1])
    A.assemble()
    return b, A


@pytest.mark.parametrize("material", [dc.SaintVenantKirchhoff(1e5, 0.3), dc.NeoHookean(1e5, 0.3)],
                         ids=["svk", "neo-hookean"])
@pytest.mark.parametrize("cell, degree", [("hexahedron", 1), ("hexahedron", 2), ("tetrahedron", 1),
                                          ("tetrahedron", 2), ("quadrilateral", 1), ("quadrilateral", 2),
                                          ("triangle", 1), ("triangle", 2), ("curved triangle", 2),
                                          ("curved quadrilateral", 2), ("curved tetrahedron", 2)])
def test_the_c_kernels_are_the_ufl_forms(monkeypatch, material, cell, degree):
    """The C kernels of the two laws (continuum.compiled: the isotropic structure of the tangent,
    the blocks b ≥ a, the points in vectors) give the residual and the tangent of the UFL forms
    that FFCx compiles, to rounding: on every cell and degree, on second-order curved cells, at a
    deformed state (|∇u| ≈ 0.1) with E and ν varying from cell to cell (measured: ≤ 1.4e-13 on 2
    ranks, the sums in another order; bound 1e-12)."""
    import dolfinx.cpp

    if cell.startswith("curved"):
        tm = _curved(cell.split()[1])
        assert tm.mesh.geometry.cmap.degree == 2
    elif cell in ("hexahedron", "tetrahedron"):
        tm = dc.io.mesh.box((3.0, 1.0, 1.0), (3, 2, 2), cell=cell)
    else:
        tm = _rectangle(3, 2, cell == "quadrilateral")
    sc = dc.Scene()
    b = sc.add_solid(tm, material=material, degree=degree)
    solid = sc.model
    rng = np.random.default_rng(comm.rank)
    solid.E.x.array[:] *= 1.0 + 0.5 * rng.random(solid.E.x.array.size)
    solid.nu.x.array[:] = 0.1 + 0.35 * rng.random(solid.nu.x.array.size)
    x = solid.V.tabulate_dof_coordinates()[:, : solid.gdim]
    u = 0.1 * np.sin(np.arange(1, solid.gdim + 1) * x.sum(axis=1, keepdims=True) + x[:, ::-1])
    solid.state.x.array[:] = u.ravel()
    forms = solid.forms()
    assert not hasattr(forms[1], "ufcx_form")  # the C kernels
    (bc, Ac), (bu, Au) = _assembled(forms), _assembled(_ufl_forms(solid, monkeypatch))
    assert hasattr(_ufl_forms(solid, monkeypatch)[1], "ufcx_form")
    db, dA = bc.copy(), Ac.copy()
    db.axpy(-1.0, bu)
    dA.axpy(-1.0, Au)
    assert db.norm() < 1e-12 * bu.norm() and dA.norm() < 1e-12 * Au.norm(), (db.norm() / bu.norm(),
                                                                                dA.norm() / Au.norm())
    assert bu.norm() > 1e-3 * Au.norm() * np.abs(u).max()  # a state with stresses, not the rest state
    # inverted cells (a reflection, J = −1): the neo-Hookean residual is not a number, as ln J of the UFL form
    if isinstance(material, dc.NeoHookean):
        reflection = np.zeros_like(x)
        reflection[:, 0] = -2.0 * x[:, 0]
        solid.state.x.array[:] = reflection.ravel()
        b = dolfinx.fem.petsc.assemble_vector(forms[0])
        assert not np.isfinite(comm.allreduce(b.norm(), op=MPI.MAX))
    for o in (bc, Ac, bu, Au, db, dA):
        o.destroy()


@pytest.mark.skipif(comm.size > 1, reason="dense FD check of the element forms: serial")
@pytest.mark.parametrize("material", [dc.SaintVenantKirchhoff(1e5, 0.3), dc.NeoHookean(1e5, 0.3)],
                         ids=["svk", "neo-hookean"])
@pytest.mark.parametrize("cell, degree", [("hexahedron", 1), ("tetrahedron", 2)])
def test_the_c_kernels_tangent_matches_finite_differences_of_their_residual(material, cell, degree):
    """The 3D C kernels' tangent is the derivative of their residual: central differences of step
    1e-7 at a deformed state with supports (the plane-strain Q2 case is
    ``test_tangent_matches_finite_differences_of_the_residual``)."""
    from fd import free_part, tangent_and_fd

    sc = _deformed_block(cell, degree, material, n=(2, 1, 1))
    system = make_system(sc.model, solver="direct")
    assert not hasattr(system.a, "ufcx_form")
    rng = np.random.default_rng(3)
    state = sc.model.state.x.array
    state[:] = 0.05 * rng.normal(size=state.size)
    K, Kfd = free_part(system, *tangent_and_fd(system, state, 0.5, h=1e-7))
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max(), np.abs(K - Kfd).max() / np.abs(K).max()
    system.destroy()


def test_scenes_use_the_c_kernels_only_where_they_cover_the_forms():
    """Plain hyperelastic continua take the C kernels; small strains, follower pressures, a captured
    reference and staged cells keep FFCx's kernels of the UFL forms."""
    def tangent(**scene):
        tm = _rectangle(2, 2, True)
        sc = dc.Scene(**scene.pop("scene", {}))
        b = sc.add_solid(tm, material=dc.NeoHookean(E, 0.3), degree=1)
        if scene.get("follower"):
            sc.pressure(b, "top", 1.0, follower=True)
        if scene.get("reference"):
            sc.model.capture_reference(np.full(sc.model.state.x.array.size, 0.01))
        if scene.get("staged"):
            sc.model.start_staging("II")
        return sc.model.forms()[1]

    assert not hasattr(tangent(), "ufcx_form")
    assert hasattr(tangent(scene={"large_rotations": False}), "ufcx_form")
    assert hasattr(tangent(follower=True), "ufcx_form")
    assert hasattr(tangent(reference=True), "ufcx_form")
    assert hasattr(tangent(staged=True), "ufcx_form")


@pytest.mark.parametrize("material", [dc.SaintVenantKirchhoff(1e5, 0.3), dc.NeoHookean(1e5, 0.3)],
                         ids=["svk", "neo-hookean"])
def test_the_c_kernels_keep_the_digits_of_tiny_strains(material):
    """Uniaxial strain ε = 1e-9 of a block 3 × 1 × 1 (u = ε X e_x): the nodal forces of the face
    x = 3 add up to P_xx times its area, P_xx = (1 + ε)(λ + 2μ)(ε + ε²/2) (St Venant–Kirchhoff) or
    μ ε(2 + ε)/(1 + ε) + λ ln(1 + ε)/(1 + ε) (neo-Hookean), to 1e-12. The kernels form the strains
    from ∇u (E = (H + Hᵀ + HᵀH)/2, ln J = log1p(J − 1) from the invariants of H; measured 1.7e-15
    and 1.4e-15). Made from FᵀF − I and ln det F, the differences of numbers near 1 keep about 7 of
    the 16 digits: FFCx's kernels of the UFL forms are off by 8.2e-8 and 8.3e-8 here, and a first
    version of the C kernels that did the same took up to 29 Newton iterations a step instead of 21
    in test_friction.py (a base 10⁴ times stiffer than the block on it)."""
    import dolfinx.fem.petsc

    tm = dc.io.mesh.box((3.0, 1.0, 1.0), (3, 2, 2))
    sc = dc.Scene()
    sc.add_solid(tm, material=material, degree=1)
    solid = sc.model
    eps = 1e-9
    x = solid.V.tabulate_dof_coordinates()
    u = np.zeros((len(x), 3))
    u[:, 0] = eps * x[:, 0]
    solid.state.x.array[:] = u.ravel()
    forms = solid.forms()
    assert not hasattr(forms[0], "ufcx_form")
    b = dolfinx.fem.petsc.assemble_vector(forms[0])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    owned = solid.V.dofmap.index_map.size_local
    face = np.isclose(x[:owned, 0], 3.0)
    force = comm.allreduce(float(b.array.reshape(-1, 3)[face, 0].sum()), op=MPI.SUM)
    lmbda, mu = dc.continuum.lame(material.E, material.nu)
    if isinstance(material, dc.NeoHookean):
        P = mu * eps * (2 + eps) / (1 + eps) + lmbda * np.log1p(eps) / (1 + eps)
    else:
        P = (1 + eps) * (lmbda + 2 * mu) * (eps + eps**2 / 2)
    assert abs(force - P) < 1e-12 * P, (force, P, force / P - 1)
    b.destroy()

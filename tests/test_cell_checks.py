"""Every solid, shell and membrane cell is checked when its part is created: a cell the elements
cannot use ends in a MeshError naming the cell (input index, group) and its midpoint; valid
meshes numbered either way round are accepted and give the closed-form answer."""
import gmsh
import numpy as np
import pytest
import ufl
from mpi4py import MPI

import dolfinx.mesh
import dolfinx_corot as dc
from dolfinx_corot.io.mesh import TaggedMesh, from_arrays, from_gmsh, name_groups

comm = MPI.COMM_WORLD
SQUARE = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]


def _solid(tm, degree=1):
    return dc.Scene().add_solid(tm, material=dc.SaintVenantKirchhoff(100.0, 0.3), degree=degree)


def _refused(tm, match, add=_solid):
    with pytest.raises(dc.MeshError, match=match) as err:
        add(tm)
    assert isinstance(err.value, ValueError)
    return str(err.value)


def _mesh_3d(points, cells, cell_name):
    """A TaggedMesh of tetrahedra or hexahedra (DOLFINx vertex order) whose cells form group 'block'."""
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.Cell(cell_name, geometric_dimension=3), 1))
    cells = np.asarray(cells, dtype=np.int64)
    if comm.rank == 0:
        msh = dolfinx.mesh.create_mesh(comm, cells, np.asarray(points, dtype=float), domain)
    else:
        msh = dolfinx.mesh.create_mesh(comm, np.empty((0, cells.shape[1]), dtype=np.int64), np.empty((0, 3)), domain)
    cmap = msh.topology.index_map(3)
    local = np.arange(cmap.size_local + cmap.num_ghosts, dtype=np.int32)
    tags = dolfinx.mesh.meshtags(msh, 3, local, np.ones(len(local), dtype=np.int32))
    return TaggedMesh(msh, tags, {"block": (3, 1)})


# -- solids in 2D ------------------------------------------------------------------------
def test_bow_tie_quadrilateral_is_refused():
    """Two unit squares, the second with its corners out of order (a self-intersecting bow tie):
    before the check it was solved and gave displacements with the wrong sign."""
    pts = SQUARE + [[2.0, 0.0], [2.0, 1.0]]
    tm = from_arrays(pts, [[0, 1, 2, 3], [1, 4, 2, 5]], "block", comm=comm)
    _refused(tm, r"solid mesh: 1 cell\(s\) self-intersecting \(a bow tie: its corners are not in order around "
                 r"it\); the first is cell 1 \(in input order\) of group 'block' at \(1\.5, 0\.5\)$")


def test_inverted_quadrilateral_is_refused():
    """A corner of the unit square pushed in past the diagonal of the other three, to (0.3, 0.3):
    the angle there exceeds 180° and the bilinear map folds over (det J < 0 at that corner)."""
    pts = [[0.0, 0.0], [1.0, 0.0], [0.3, 0.3], [0.0, 1.0]]
    tm = from_arrays(pts, [[0, 1, 2, 3]], "block", comm=comm)
    _refused(tm, r"1 cell\(s\) not convex \(an angle above 180°.*the first is cell 0 \(in input order\) of group "
                 r"'block' at \(0\.325, 0\.325\)$")


def test_inverted_triangle_is_refused():
    """A fan of four triangles about a centre node pushed below the bottom side: the bottom triangle
    turns over and overlaps its neighbours; it is named, not them (its orientation differs from
    that of the other three)."""
    pts = SQUARE + [[0.5, -0.3]]
    tm = from_arrays(pts, [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], "block", comm=comm)
    _refused(tm, r"1 cell\(s\) inverted: overlapping a neighbour \(both on the same side of their common side.*"
                 r"the first is cell 0 \(in input order\) of group 'block' at \(0\.5, -0\.1\)$")


def test_zero_area_triangle_in_a_solid_is_refused():
    pts = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 1.0], [3.0, 0.0]]
    tm = from_arrays(pts, [[0, 1, 3], [1, 2, 3], [1, 2, 4]], "block", comm=comm)
    _refused(tm, r"1 cell\(s\) of zero area \(flat: its corners on one line\); the first is cell 2 \(in input "
                 r"order\) of group 'block' at \(2, 0\)$")


# -- solids in 3D ------------------------------------------------------------------------
CUBE = [[x, y, z] for z in (0.0, 1.0) for y in (0.0, 1.0) for x in (0.0, 1.0)]  # DOLFINx hexahedron order


def _cube_fan(centre):
    """The unit cube as twelve tetrahedra coned from a centre node (index 8), each face split along
    a diagonal, all numbered with positive orientation as gmsh numbers them (for the centre
    (0.5, 0.5, 0.5)); faces in the order x0, x1, y0, y1, z0, z1."""
    faces = [(0, 2, 4, 6), (1, 3, 5, 7), (0, 1, 4, 5), (2, 3, 6, 7), (0, 1, 2, 3), (4, 5, 6, 7)]
    X = np.array(CUBE + [[0.5, 0.5, 0.5]])
    cells = []
    for a, b, c, d in faces:  # tensor-order face: triangles (a, b, d) and (a, d, c)
        for tet in ([a, b, d, 8], [a, d, c, 8]):
            if np.linalg.det(X[tet[1:]] - X[tet[0]]) < 0:
                tet[0], tet[1] = tet[1], tet[0]
            cells.append(tet)
    return CUBE + [list(centre)], cells


def _at(point) -> str:
    return r"\(" + r", ".join(f"{c:.6g}" for c in point).replace(".", r"\.") + r"\)"


def test_inverted_tetrahedron_is_refused():
    """The cube fan with its centre pushed out through the face x = 1: the two tetrahedra on that
    face turn over and overlap their neighbours; they are named (the first in input order)."""
    pts, cells = _cube_fan([1.4, 0.5, 0.5])
    tm = _mesh_3d(pts, cells, "tetrahedron")
    first = np.mean(np.array(pts)[cells[2]], axis=0)  # the first tetrahedron on face x1: (1, 3, 7, centre)
    _refused(tm, r"2 cell\(s\) inverted: overlapping a neighbour \(both on the same side of their common face.*"
                 rf"the first is cell 2 \(in input order\) of group 'block' at {_at(first)}$")


def test_inverted_hexahedron_is_refused():
    """A unit cube whose corner (1, 1, 1) is pushed through the cell to (0.2, 0.3, 0.4): the Jacobian
    changes sign inside the cell."""
    pts = [list(p) for p in CUBE]
    pts[7] = [0.2, 0.3, 0.4]
    tm = _mesh_3d(pts, [list(range(8))], "hexahedron")
    _refused(tm, r"1 cell\(s\) inverted inside \(the Jacobian of the cell changes sign.*the first is cell 0 "
                 rf"\(in input order\) of group 'block' at {_at(np.mean(pts, axis=0))}$")


def test_valid_tetrahedra_and_reflected_hexahedra_are_accepted():
    """The cube fan with its centre inside, and a hexahedron numbered as a mirror image (all
    corner Jacobians negative): valid cells, accepted."""
    _solid(_mesh_3d(*_cube_fan([0.5, 0.5, 0.5]), "tetrahedron"))
    _solid(_mesh_3d(CUBE, [[4, 5, 6, 7, 0, 1, 2, 3]], "hexahedron"))


# -- shells and membranes in space -------------------------------------------------------
def test_zero_area_shell_triangle_is_refused():
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0], [1, 1, 1]], dtype=float)
    tm = from_arrays(pts, [[0, 1, 2], [1, 3, 4], [0, 3, 1]], "roof", comm=comm)
    with pytest.raises(dc.MeshError, match=r"shell 'roof': 1 cell\(s\) of zero area \(its corners on one line\); "
                                           r"the first is cell 2 \(in input order\) at \(1, 0, 0\)$"):
        dc.Scene().add_shell(tm, "roof", thickness=0.01, material=dc.Elastic(1.0))


@pytest.mark.parametrize("corners, problem, at", [
    ([[0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 1, 0]], r"degenerate \(three corners on a line", r"\(1, 0\.25, 0\)"),
    ([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]], r"of zero area \(its corners on one line\)", r"\(1\.5, 0, 0\)"),
    ([[0, 0, 0], [1, 0, 0], [1, 1, 1], [0, 1, 0]], r"warped: the flat membrane works on the projection",
     r"\(0\.5, 0\.5, 0\.25\)"),
], ids=["three corners on a line", "zero area", "warped"])
def test_degenerate_membrane_quadrilaterals_are_refused(corners, problem, at):
    """One corner lifted by the side length warps the quadrilateral so much that its projection on
    the mean plane keeps 88 % of its area (below the 95 % the flat element accepts)."""
    tm = from_arrays(np.array(corners, dtype=float), [[0, 1, 2, 3]], "sail", comm=comm)
    with pytest.raises(dc.MeshError, match=rf"membrane 'sail': 1 cell\(s\) {problem}.*the first is cell 0 "
                                           rf"\(in input order\) at {at}$"):
        dc.Scene().add_membrane(tm, "sail", thickness=0.01, material=dc.Elastic(1.0))


def test_mildly_warped_membrane_quadrilateral_is_accepted():
    """A corner lifted by a tenth of the side: the projection keeps 99.8 % of the area."""
    tm = from_arrays(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.1], [0, 1, 0]], dtype=float), [[0, 1, 2, 3]], "sail",
                     comm=comm)
    dc.Scene().add_membrane(tm, "sail", thickness=0.01, material=dc.Elastic(1.0))


def test_zero_length_beam_is_refused_in_the_same_terms():
    tm = from_arrays(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), [[0, 1], [1, 2], [2, 3]], "beam",
                     comm=comm)
    with pytest.raises(dc.MeshError, match=r"beam 'beam': 1 element\(s\) of zero length, the first at \(1, 0\) "
                                           r"\(cell 1 in input order\)$"):
        dc.Scene().add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1.0))


# -- geometry degree -----------------------------------------------------------------------
def _quarter_disk(order, R=1.0, size=0.3):
    """A quarter disk of radius R meshed by gmsh with elements of ``order``; edge groups 'x_axis' and
    'y_axis' (the straight sides), cells 'disk'."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        c, a, b = g.addPoint(0, 0, 0, size), g.addPoint(R, 0, 0, size), g.addPoint(0, R, 0, size)
        lines = [g.addLine(c, a), g.addCircleArc(a, c, b), g.addLine(b, c)]
        surface = g.addPlaneSurface([g.addCurveLoop(lines)])
        g.synchronize()
        name_groups({"disk": (2, [surface]), "x_axis": (1, [lines[0]]), "y_axis": (1, [lines[2]])})
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(order)
    tm = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def _weight_reaction(tm):
    """Vertical support reaction of the quarter disk under its own weight (ρ g = 1), small strain,
    held on its lower side (x_axis) and by symmetry (ux = 0) on the other."""
    sc = dc.Scene(large_rotations=False)
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(100.0, 0.3), degree=2)
    sc.fix(b, "x_axis")
    sc.fix(b, "y_axis", dofs=("ux",))
    sc.gravity(b, acceleration=(0.0, -1.0), density=1.0)
    sc.monitor_reaction("base", b, "x_axis")
    return dc.solve(sc, dc.LoadControl(steps=1)).history.column("base_Fy")[-1]


def test_curved_second_order_geometry_works_for_quadratic_solids():
    """Quadratic solids take gmsh's second-order (curved) cells: the reaction to the weight of a
    quarter disk is ρ g π R²/4 to 3e-5 (measured −9.8e-6: the parabolic sides of the cells stray
    from the circle by O(h⁴)), where the straight-sided mesh of the same vertices misses the
    circular segments (−1.1 %)."""
    exact = np.pi / 4
    curved = _weight_reaction(_quarter_disk(2))
    straight = _weight_reaction(_quarter_disk(1))
    assert abs(curved - exact) < 3e-5 * exact, (curved, exact)
    assert abs(straight - exact) > 5e-3 * exact, (straight, exact)


def test_second_order_geometry_is_refused_where_only_first_order_is_supported():
    tm = _quarter_disk(2)
    with pytest.raises(dc.MeshError, match=r"solid of degree 1: the mesh has cells of geometry degree 2 \(6-node "
                                           r"triangles.*give degree=2, or mesh with first-order elements"):
        _solid(tm, degree=1)
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        a, b = g.addPoint(0, 0, 0), g.addPoint(1, 0, 0)
        line = g.addLine(a, b)
        g.synchronize()
        name_groups({"beam": (1, [line]), "base": (0, [a])})
        gmsh.model.mesh.generate(1)
        gmsh.model.mesh.setOrder(2)
    beam = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    with pytest.raises(dc.MeshError, match=r"beams, bars, shells and membranes: the mesh has cells of geometry "
                                           r"degree 2 \(3-node intervals.*mesh with first-order elements"):
        dc.Scene().add_beam(beam, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1.0))


# -- numbering direction is free --------------------------------------------------------------
@pytest.mark.parametrize("cell", ["triangle", "quadrilateral"])
@pytest.mark.parametrize("numbering", ["clockwise", "mixed"])
def test_clockwise_numbering_is_accepted_and_exact(cell, numbering):
    """A bar 2 × 1 in plane strain (small strain), stretched by δ with free sides: the reaction is
    E/(1 − ν²) δ/L H (σ_yy = 0, ε_zz = 0), with cells numbered clockwise (as gmsh may give a
    surface whose normal points down) or each cell either way."""
    L, H, E, nu, delta, nx, ny = 2.0, 1.0, 100.0, 0.3, 0.01, 4, 2
    X, Y = np.meshgrid(np.linspace(0, L, nx + 1), np.linspace(0, H, ny + 1))
    pts = np.column_stack([X.ravel(), Y.ravel()])
    node = np.arange(len(pts)).reshape(ny + 1, nx + 1)
    cells = []
    for j in range(ny):
        for i in range(nx):
            a, b, c, d = node[j, i], node[j, i + 1], node[j + 1, i + 1], node[j + 1, i]  # counter-clockwise
            cells += [[a, d, c, b]] if cell == "quadrilateral" else [[a, c, b], [a, d, c]]
    cells = np.array(cells)
    if numbering == "mixed":
        cells[::2] = cells[::2, ::-1]  # every other cell counter-clockwise again
    tm = from_arrays(pts, cells, "block", {"left": node[:, 0], "corner": [0], "right": node[:, -1]}, comm=comm)
    sc = dc.Scene(large_rotations=False)
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(E, nu), degree=1)
    sc.fix(b, "left", dofs=("ux",))
    sc.fix(b, "corner", dofs=("uy",))
    sc.prescribe(b, "right", ux=delta)
    sc.monitor_reaction("right", b, "right")
    reaction = dc.solve(sc, dc.LoadControl(steps=1)).history.column("right_Fx")[-1]
    exact = E / (1 - nu**2) * delta / L * H
    assert abs(reaction - exact) < 1e-9 * exact, (reaction, exact)


def test_a_boundary_group_off_the_mesh_is_named():
    """A line group whose lines are not edges of the triangles (an anchor meshed beside the soil,
    not embedded in it) cannot be a facet group of the soil's mesh: refused naming the group and
    where its first such node lies, on every rank (DOLFINx would abort)."""
    comm = MPI.COMM_WORLD
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("beside")
        soil = gmsh.model.occ.addRectangle(0.0, 0.0, 0.0, 1.0, 1.0)
        line = gmsh.model.occ.addLine(gmsh.model.occ.addPoint(2.0, 0.0, 0.0), gmsh.model.occ.addPoint(3.0, 0.0, 0.0))
        gmsh.model.occ.synchronize()
        gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [soil]), "soil")
        gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, [line]), "anchor")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(2)
    try:
        with pytest.raises(ValueError, match=r"group 'anchor' \(dimension 1\): \d+ of its nodes belong to no cell of "
                                             r"dimension 2 \(the first at \(2, 0, 0\)\)"):
            from_gmsh(gmsh.model, 2, comm=comm)
    finally:
        if comm.rank == 0:
            gmsh.finalize()

r"""Cell checks at set-up: a cell the elements cannot use is refused, naming it.

Every cell of a solid is checked when the solid is created, every cell of a
shell, membrane, beam or bar group when its elements are added; a cell that
fails is refused with a :class:`MeshError` that names the part or group, the
cell (its index in the input order: the row of the cell array given to
:func:`~dolfinx_corot.io.mesh.from_arrays`, the order of gmsh's cells) and its
midpoint. The checks are vectorized over the cells of each rank, and the
decision is collective: every rank raises the same message, that of the
offending cell with the smallest input index, whatever the partition.

With J the Jacobian of the map from the reference cell, d the dimension of
the cell and h its longest edge, the scaled Jacobian r = det J / h^d
(Knupp 2001, *Algebraic mesh quality metrics*, SIAM J. Sci. Comput. 23) is
evaluated at sample points of every solid cell (the corners of
quadrilaterals; the corners and the centre of hexahedra; corners, mid-sides
and centres of curved cells; once on straight simplices, where it is
constant). A solid cell is refused when

* it has zero size (h ≤ 10⁻¹⁰ of the mesh's extent) or zero area/volume
  (|r| ≤ 10⁻¹⁰ everywhere);
* J changes sign inside it or vanishes at a sample point: the map from the
  reference cell is not one-to-one, and the element integrates over a folded
  region (a self-intersecting "bow-tie" quadrilateral, whose corners are out
  of order; a corner pushed in past a diagonal; a hexahedron corner pushed
  through a face; a curved side crossing the cell);
* it overlaps a neighbour: both lie on the same side of their common side or
  face (a node pushed through the opposite side: the mesh folds over). Of the
  two, the cell whose orientation differs from that of most cells is named.

The direction in which a cell's nodes are numbered is free: clockwise or
counter-clockwise, even mixed within a mesh (as gmsh or hand-made arrays may
give them). The forms integrate with |det J| and pull gradients back with
J⁻¹, so a consistently reflected cell is a valid cell, and it gives the
same element matrices.

Shell and membrane triangles in space are refused at zero size or zero area;
membrane quadrilaterals also when self-intersecting, not convex, with three
corners on a line, or warped so much that the flat element, which works on
the projection of the quadrilateral on its mean plane (the plane normal to
d₁ × d₂, d₁, d₂ the diagonals), sees less than 95 % of its area.
"""
from __future__ import annotations

import basix
import numpy as np
from mpi4py import MPI

#: relative size below which a cell, a corner angle (its sine) or a scaled Jacobian counts as zero
ZERO = 1e-10
#: the smallest ratio of projected to true area of a membrane quadrilateral (its warp)
MIN_FLAT_AREA = 0.95

_SOLID_CELLS = {"triangle": basix.CellType.triangle, "quadrilateral": basix.CellType.quadrilateral,
                "tetrahedron": basix.CellType.tetrahedron, "hexahedron": basix.CellType.hexahedron}
_CHUNK = 400_000  # Jacobians (cells × points) evaluated at once


class MeshError(ValueError):
    """A mesh whose cells a part cannot use (inverted, self-intersecting, degenerate, or of a
    geometry degree the part does not support); the message names the first offending cell
    (input index, group) and its midpoint."""


def _format_point(p) -> str:
    return "(" + ", ".join(f"{c:.6g}" for c in p) + ")"


def local_cells(mesh) -> tuple[int, int]:
    """(owned, owned + ghost) numbers of cells of this rank."""
    cmap = mesh.topology.index_map(mesh.topology.dim)
    return cmap.size_local, cmap.size_local + cmap.num_ghosts


def midpoints(mesh, cells: np.ndarray) -> np.ndarray:
    """(len(cells), gdim) vertex means of local cells."""
    nv = _num_vertices(mesh)
    g = geometry_nodes(mesh)[np.asarray(cells, dtype=np.int64), :nv]
    return mesh.geometry.x[g, : mesh.geometry.dim].mean(axis=1)


def geometry_nodes(mesh) -> np.ndarray:
    """(owned + ghost cells, nodes per cell) geometry node indices of the local cells."""
    return mesh.geometry.dofmap.array.reshape(local_cells(mesh)[1], mesh.geometry.cmap.create_dof_layout().num_dofs)


def _num_vertices(mesh) -> int:
    return {"interval": 2, "triangle": 3, "quadrilateral": 4, "tetrahedron": 4,
            "hexahedron": 8}[mesh.topology.cell_name()]


def refuse(mesh, label: str, findings, error: type = MeshError, groups: np.ndarray | None = None) -> None:
    """Raise ``error`` on every rank for the first problem some rank found, or return.

    findings: [(problem, bad), …] in order of precedence, bad the local cells (owned or
    ghost; ghosts are counted by their owner) with that problem, problem a phrase that
    completes "n cell(s) …"; or [(message, bad)] with a message holding ``{n}`` (the number
    of bad cells) and ``{at}`` (the first cell's midpoint and input index). groups: the
    group name of every local cell (or None: the label names it). One collective call.
    """
    n_owned = local_cells(mesh)[0]
    original = np.asarray(mesh.topology.original_cell_index, dtype=np.int64)
    summary = []
    for _, bad in findings:
        bad = np.unique(np.asarray(bad, dtype=np.int64))
        bad = bad[bad < n_owned]
        if not len(bad):
            summary.append((0, None))
            continue
        k = int(np.argmin(original[bad]))
        cell = int(bad[k])
        group = None if groups is None else str(groups[cell])
        summary.append((len(bad), (int(original[cell]), midpoints(mesh, [cell])[0].tolist(), group)))
    found = mesh.comm.allgather(summary)
    for k, (problem, _) in enumerate(findings):
        total = sum(f[k][0] for f in found)
        if not total:
            continue
        index, point, group = min(f[k][1] for f in found if f[k][1] is not None)
        where = f"{_format_point(point)} (cell {index} in input order)"
        if "{at}" in problem:
            raise error(problem.format(n=total, at=where))
        of = f" of group '{group}'" if group else ""
        raise error(f"{label}: {total} cell(s) {problem}; the first is cell {index} (in input order){of} "
                    f"at {_format_point(point)}")


def mesh_extent(mesh) -> float:
    """The largest extent of the mesh along an axis (all ranks), at least 1e-300."""
    x = mesh.geometry.x[:, : mesh.geometry.dim]
    local = np.concatenate([-x.min(axis=0), x.max(axis=0)]) if len(x) else np.full(2 * x.shape[1], -np.inf)
    bounds = np.empty_like(local)
    mesh.comm.Allreduce(local, bounds, op=MPI.MAX)
    span = bounds[x.shape[1]:] + bounds[: x.shape[1]]
    return max(float(np.max(span)) if np.all(np.isfinite(span)) else 1.0, 1e-300)


# -- geometry degree -------------------------------------------------------------------
def check_geometry_degree(mesh, label: str, largest: int, advice: str) -> None:
    """Refuse a mesh whose geometry (node positions interpolated by the coordinate element) has a
    degree above ``largest`` (gmsh: ``Mesh.ElementOrder``, ``gmsh.model.mesh.setOrder``)."""
    degree = mesh.geometry.cmap.degree
    if degree > largest:
        nodes = mesh.geometry.cmap.create_dof_layout().num_dofs
        raise MeshError(f"{label}: the mesh has cells of geometry degree {degree} ({nodes}-node "
                        f"{mesh.topology.cell_name()}s, gmsh element order {degree}); {advice}")


# -- solids ---------------------------------------------------------------------------
def _sample_points(cell: basix.CellType, degree: int) -> np.ndarray:
    """Reference points where det J is evaluated."""
    simplex = cell in (basix.CellType.triangle, basix.CellType.tetrahedron)
    if simplex and degree == 1:
        return basix.geometry(cell).mean(axis=0, keepdims=True)  # det J is constant
    if cell == basix.CellType.quadrilateral and degree == 1:
        return basix.geometry(cell)  # det J is affine in (ξ, η): its extremes are at the corners
    if cell == basix.CellType.hexahedron and degree == 1:
        # the corners and the centre, as the Verdict library's hexahedron Jacobian (Stimpson et al. 2007)
        return np.vstack([basix.geometry(cell), [[0.5, 0.5, 0.5]]])
    # corners, mid-sides and centres (degree + 1 intervals per edge)
    return basix.create_lattice(cell, degree + 1, basix.LatticeType.equispaced, True)


def scaled_jacobians(mesh) -> tuple[np.ndarray, np.ndarray]:
    """(r (n_local, npts), h (n_local,)): det J / h^d at the sample points of every local cell
    and its longest edge."""
    cell = _SOLID_CELLS[mesh.topology.cell_name()]
    tdim, gdim = mesh.topology.dim, mesh.geometry.dim
    degree = mesh.geometry.cmap.degree
    element = basix.create_element(basix.ElementFamily.P, cell, degree, basix.LagrangeVariant.equispaced)
    n_local = local_cells(mesh)[1]
    g = geometry_nodes(mesh)
    x = mesh.geometry.x[:, :gdim]
    edges = np.asarray(basix.topology(cell)[1])
    pts = _sample_points(cell, degree)
    dphi = element.tabulate(1, pts)[1: tdim + 1, :, :, 0]  # (tdim, npts, nnodes)
    h = np.zeros(n_local)
    r = np.zeros((n_local, len(pts)))
    step = max(1, _CHUNK // len(pts))
    for start in range(0, n_local, step):
        X = x[g[start: start + step]]                               # (c, nnodes, gdim)
        h2 = np.zeros(len(X))
        for a, b in edges:
            d = X[:, b] - X[:, a]
            np.maximum(h2, np.einsum("ij,ij->i", d, d), out=h2)
        hc = np.sqrt(h2)
        J = np.ascontiguousarray(np.tensordot(X, dphi, axes=([1], [2])))  # (c, gdim, tdim, npts)
        h[start: start + step] = hc
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            r[start: start + step] = _det(J) / hc[:, None] ** tdim
    r[~np.isfinite(r)] = 0.0
    return r, h


def _det(J: np.ndarray) -> np.ndarray:
    """Determinants of J (..., d, d, p) over its two middle axes, d = 2 or 3."""
    if J.shape[-2] == 2:
        return J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
    return (J[:, 0, 0] * (J[:, 1, 1] * J[:, 2, 2] - J[:, 1, 2] * J[:, 2, 1])
            - J[:, 0, 1] * (J[:, 1, 0] * J[:, 2, 2] - J[:, 1, 2] * J[:, 2, 0])
            + J[:, 0, 2] * (J[:, 1, 0] * J[:, 2, 1] - J[:, 1, 1] * J[:, 2, 0]))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross products of (n, 3) arrays (np.cross is slower on long arrays)."""
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)


def _folds(mesh, orientation: np.ndarray, majority: float) -> np.ndarray:
    """Local cells that overlap a neighbour across a common facet (both on the same side of it);
    of each such pair the cell whose orientation differs from the majority (both if neither or
    both differ). The neighbours of owned cells are local cells in DOLFINx's default ghost mode
    (shared facet), so every pair is seen by the ranks that own its cells.

    orientation: (n_local,) sign of det J of every cell; majority: that of most cells."""
    cell = _SOLID_CELLS[mesh.topology.cell_name()]
    tdim, gdim = mesh.topology.dim, mesh.geometry.dim
    n_local = local_cells(mesh)[1]
    nv = _num_vertices(mesh)
    x = mesh.geometry.x[:, :gdim]
    gv = geometry_nodes(mesh)[:, :nv]
    facets = np.asarray(basix.topology(cell)[tdim - 1])             # (nf, nvf)
    nf, nvf = facets.shape
    F = gv[:, facets].reshape(-1, nvf)                               # incidences (cell·nf + local facet)
    ids = np.sort(F, axis=1).astype(np.int64)
    n = np.int64(len(x))
    keys = [ids[:, 0] * n + ids[:, 1]] + ([ids[:, 2] * n + (ids[:, 3] if nvf == 4 else 0)] if nvf > 2 else [])
    order = np.argsort(keys[0], kind="stable") if len(keys) == 1 else np.lexsort(keys[::-1])
    same = np.ones(max(len(order) - 1, 0), dtype=bool)
    for key in keys:
        k = key[order]
        same &= k[1:] == k[:-1]
    i, j = order[:-1][same], order[1:][same]
    if not len(i):
        return np.zeros(0, dtype=np.int64)
    ci, cj = i // nf, j // nf
    P = [x[F[i, a]] for a in range(nvf)]                            # the facet's corners, as ci sees them
    centre = sum(P) / nvf
    if tdim == 2:
        t = P[1] - P[0]
        normal = np.stack([t[:, 1], -t[:, 0]], axis=1)
    elif nvf == 3:
        normal = _cross(P[1] - P[0], P[2] - P[0])
    else:  # quadrilateral face, tensor-product order: diagonals (0, 3) and (1, 2)
        normal = _cross(P[3] - P[0], P[2] - P[1])
    mid = sum(x[gv[:, a]] for a in range(nv)) / nv
    si = np.einsum("ij,ij->i", mid[ci] - centre, normal)
    sj = np.einsum("ij,ij->i", mid[cj] - centre, normal)
    fold = si * sj > 0.0
    ci, cj = ci[fold], cj[fold]
    odd_i, odd_j = orientation[ci] != majority, orientation[cj] != majority
    name_i = odd_i | (odd_i == odd_j)
    name_j = odd_j | (odd_i == odd_j)
    return np.unique(np.concatenate([ci[name_i], cj[name_j]]))


def check_solid_cells(tmesh, label: str) -> None:
    """Refuse (MeshError, on every rank) a solid mesh with a cell of zero size, area or volume,
    whose Jacobian changes sign or vanishes inside it, or that overlaps a neighbour (see the
    module docstring); the message names the first such cell, its group and its midpoint."""
    mesh = tmesh.mesh
    n_owned, n_local = local_cells(mesh)
    r, h = scaled_jacobians(mesh)
    cell_name = mesh.topology.cell_name()
    extent = mesh_extent(mesh)
    rmax, rmin = r.max(axis=1, initial=-np.inf), r.min(axis=1, initial=np.inf)
    amax = np.abs(r).max(axis=1, initial=0.0)
    tiny = h <= ZERO * extent
    flat = ~tiny & (amax <= ZERO)
    crossed = ~tiny & ~flat & (rmax > ZERO) & (rmin < -ZERO)
    pinched = ~tiny & ~flat & ~crossed & (np.abs(r).min(axis=1, initial=np.inf) <= ZERO)
    measure = "area" if mesh.topology.dim == 2 else "volume"
    findings = [("of zero size (nodes at one point)", np.flatnonzero(tiny)),
                (f"of zero {measure} (flat: its corners on one {'line' if measure == 'area' else 'plane'})",
                 np.flatnonzero(flat))]
    if cell_name == "quadrilateral" and mesh.geometry.cmap.degree == 1:
        negative = np.sum(r < -ZERO, axis=1)
        bowtie = crossed & (negative == 2)
        findings += [("self-intersecting (a bow tie: its corners are not in order around it)", np.flatnonzero(bowtie)),
                     ("not convex (an angle above 180°: a corner pushed in past a diagonal)",
                      np.flatnonzero(crossed & ~bowtie))]
    else:
        findings.append(("inverted inside (the Jacobian of the cell changes sign: nodes out of order, a corner "
                         "pushed through a side or face, or a curved side crossing the cell)", np.flatnonzero(crossed)))
    findings.append(("degenerate (the Jacobian vanishes at a corner: an angle of 0° or 180°)",
                     np.flatnonzero(pinched)))
    # orientation of each cell, and of most cells (collective)
    orientation = np.sign(r.mean(axis=1))
    majority = float(np.sign(mesh.comm.allreduce(float(np.sum(orientation[:n_owned])), op=MPI.SUM)) or 1.0)
    findings.append(("inverted: overlapping a neighbour (both on the same side of their common "
                     f"{'side' if mesh.topology.dim == 2 else 'face'}: a node pushed through it, the mesh folds over)",
                     _folds(mesh, orientation, majority)))
    refuse(mesh, label, findings, groups=cell_groups(tmesh))


def cell_groups(tmesh) -> np.ndarray:
    """The name of the cell group (gmsh physical group) of every local cell ('' if none)."""
    mesh = tmesh.mesh
    tdim = mesh.topology.dim
    n_local = local_cells(mesh)[1]
    names = {tag: name for name, (dim, tag) in tmesh.groups.items() if dim == tdim and tag >= 0}
    out = np.full(n_local, "", dtype=object)
    if tmesh.cell_tags is not None and len(tmesh.cell_tags.values):
        tags, inverse = np.unique(tmesh.cell_tags.values, return_inverse=True)
        out[tmesh.cell_tags.indices] = np.array([names.get(int(t), "") for t in tags], dtype=object)[inverse]
    return out


# -- shells and membranes in space ----------------------------------------------------------
def triangle_problems(X: np.ndarray, extent: float) -> list[tuple[str, np.ndarray]]:
    """Zero-size and zero-area triangles among X (n, 3, 3): [(problem, bad indices), …]."""
    e = X[:, [1, 2, 0]] - X
    h = np.sqrt(np.max(np.sum(e * e, axis=2), axis=1, initial=0.0))
    area2 = np.linalg.norm(np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), axis=1)
    tiny = h <= ZERO * extent
    with np.errstate(divide="ignore", invalid="ignore"):
        flat = ~tiny & ~(area2 > ZERO * h * h)
    return [("of zero size (nodes at one point)", np.flatnonzero(tiny)),
            ("of zero area (its corners on one line)", np.flatnonzero(flat))]


def quadrilateral_problems(X: np.ndarray, extent: float) -> list[tuple[str, np.ndarray]]:
    """Bad quadrilaterals in space among X (n, 4, 3), corners counter-clockwise (or clockwise):
    zero size or area, self-intersecting, not convex, three corners on a line, warped (the
    projection on the mean plane keeps less than :data:`MIN_FLAT_AREA` of the area)."""
    e = np.roll(X, -1, axis=1) - X                                   # sides a → a+1
    h = np.sqrt(np.max(np.sum(e * e, axis=2), axis=1, initial=0.0))
    turn = np.cross(e, np.roll(e, -1, axis=1))                       # (n, 4, 3) at corners 1, 2, 3, 0
    size = np.linalg.norm(turn, axis=2)
    ref = turn[np.arange(len(X)), np.argmax(size, axis=1)] if len(X) else np.zeros((0, 3))
    with np.errstate(divide="ignore", invalid="ignore"):
        sine = np.einsum("nak,nk->na", turn, ref) / (np.linalg.norm(ref, axis=1)[:, None] * h[:, None] ** 2)
    sine[~np.isfinite(sine)] = 0.0
    tiny = h <= ZERO * extent
    flat = ~tiny & (np.abs(sine).max(axis=1, initial=0.0) <= ZERO)
    ok = ~tiny & ~flat
    negative = np.sum(sine < -ZERO, axis=1)
    bowtie = ok & (negative == 2)
    concave = ok & (negative % 2 == 1)
    pinched = ok & (negative == 0) & (np.abs(sine).min(axis=1, initial=np.inf) <= ZERO)
    good = ok & ~bowtie & ~concave & ~pinched
    projected = 0.5 * np.linalg.norm(np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 1]), axis=1)

    def tri(a, b, c):
        return 0.5 * np.linalg.norm(np.cross(X[:, b] - X[:, a], X[:, c] - X[:, a]), axis=1)

    true = 0.5 * (tri(0, 1, 2) + tri(0, 2, 3) + tri(0, 1, 3) + tri(1, 2, 3))
    with np.errstate(divide="ignore", invalid="ignore"):
        warped = good & (projected < MIN_FLAT_AREA * true)
    return [("of zero size (nodes at one point)", np.flatnonzero(tiny)),
            ("of zero area (its corners on one line)", np.flatnonzero(flat)),
            ("self-intersecting (a bow tie: its corners are not in order around it)", np.flatnonzero(bowtie)),
            ("not convex (an angle above 180°: a corner pushed in past a diagonal)", np.flatnonzero(concave)),
            ("degenerate (three corners on a line: an angle of 0° or 180°)", np.flatnonzero(pinched)),
            (f"warped: the flat membrane works on the projection on the mean plane, which keeps less than "
             f"{MIN_FLAT_AREA:.0%} of its area (refine the mesh, or use triangles)", np.flatnonzero(warped))]

"""gmsh models → DOLFINx meshes whose physical groups are addressed by name.

:func:`from_gmsh` reads the gmsh model on rank 0 (through
``dolfinx.io.gmshio.model_to_mesh``) and distributes it; physical-group
names travel with it so that supports, loads and monitors say
``where="tip"`` instead of a tag number. Groups of the highest dimension
become cell tags; groups of points (and, for 2D/3D meshes, of facets) are
located on every rank by the coordinates of their nodes, so that a node may
belong to several groups.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI

import dolfinx.mesh
from dolfinx.io import gmshio


class GroupNotFoundError(KeyError):
    """A physical-group name that the mesh does not have."""

    def __str__(self) -> str:  # KeyError would print the repr with quotes
        return str(self.args[0])


@dataclass
class TaggedMesh:
    """A DOLFINx mesh with named groups.

    mesh: the DOLFINx mesh; cell_tags: its cell MeshTags (gmsh physical tags);
    groups: name → (dim, physical tag); points: name → (n, 3) coordinates of
    the nodes of each group of dimension < tdim, the same on every rank;
    node_ids: name → input node numbers, which take precedence over the
    coordinates (nodes that share a position, as on the two sides of a slit).
    """

    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTagsMetaClass
    groups: dict[str, tuple[int, int]]
    points: dict[str, np.ndarray] = field(default_factory=dict)
    node_ids: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def tdim(self) -> int:
        return self.mesh.topology.dim

    def _check(self, name: str) -> tuple[int, int]:
        if name not in self.groups:
            known = ", ".join(f"'{n}' (dim {d})" for n, (d, _) in sorted(self.groups.items())) or "none"
            raise GroupNotFoundError(f"physical group '{name}' not found in the mesh; it has: {known}")
        return self.groups[name]

    def cells(self, name: str | None) -> np.ndarray:
        """Local cells (owned and ghost) of the cell group ``name``; all cells for None."""
        tdim = self.tdim
        cmap = self.mesh.topology.index_map(tdim)
        if name is None:
            return np.arange(cmap.size_local + cmap.num_ghosts, dtype=np.int32)
        dim, tag = self._check(name)
        if dim != tdim:
            raise ValueError(f"physical group '{name}' has dimension {dim}; a group of cells "
                             f"(dimension {tdim}) is needed here")
        return self.cell_tags.indices[self.cell_tags.values == tag]

    def vertices(self, name: str) -> np.ndarray:
        """Local vertex indices (owned and ghost) of the nodes of group ``name`` (any dim)."""
        dim, _ = self._check(name)
        if dim == self.tdim:
            self.mesh.topology.create_connectivity(self.tdim, 0)
            c2v = self.mesh.topology.connectivity(self.tdim, 0)
            cells = self.cells(name)
            counts = np.diff(c2v.offsets)[cells]
            idx = np.repeat(c2v.offsets[cells], counts) + _ramp(counts)
            return np.unique(c2v.array[idx]).astype(np.int32)
        if name in self.node_ids:
            return _vertices_of_input_nodes(self.mesh, self.node_ids[name])
        pts = self.points[name]
        return _locate_vertices(self.mesh, pts)


def _vertices_of_input_nodes(mesh: dolfinx.mesh.Mesh, ids: np.ndarray) -> np.ndarray:
    """Local vertices (owned and ghost) of the input nodes ``ids`` (P1 geometry: node = vertex)."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim, 0)
    c2v = mesh.topology.connectivity(tdim, 0).array
    gdofs = mesh.geometry.dofmap.array
    vertex_of_node = np.empty(len(mesh.geometry.x), dtype=np.int32)
    vertex_of_node[gdofs] = c2v
    inputs = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
    nodes = np.flatnonzero(np.isin(inputs, np.asarray(ids, dtype=np.int64)))
    return np.unique(vertex_of_node[nodes]).astype(np.int32)


def _ramp(counts: np.ndarray) -> np.ndarray:
    """0, 1, …, c−1 for each c in counts, concatenated."""
    total = int(np.sum(counts))
    starts = np.repeat(np.cumsum(counts) - counts, counts)
    return np.arange(total) - starts


def _locate_vertices(mesh: dolfinx.mesh.Mesh, pts: np.ndarray) -> np.ndarray:
    """Local vertices whose coordinates coincide with one of ``pts`` (n, 3)."""
    x = mesh.geometry.x
    scale = max(float(np.ptp(x, axis=0).max()) if len(x) else 1.0, 1e-300)
    tol = 1e-10 * scale
    from scipy.spatial import cKDTree
    tree = cKDTree(pts[:, : mesh.geometry.dim])

    def marker(xv):
        dist, _ = tree.query(xv[: mesh.geometry.dim].T, k=1)
        return dist <= tol

    return dolfinx.mesh.locate_entities(mesh, 0, marker)


def from_gmsh(model, gdim: int, comm: MPI.Comm = MPI.COMM_WORLD, rank: int = 0) -> TaggedMesh:
    """Distribute the meshed gmsh ``model`` (alive on ``rank``) as a :class:`TaggedMesh`.

    Every cell of the highest dimension must belong to exactly one physical
    group (gmsh exports a cell once per group it belongs to).
    """
    groups: dict[str, tuple[int, int]] = {}
    points: dict[str, np.ndarray] = {}
    error = None
    if comm.rank == rank:
        phys = model.getPhysicalGroups()
        if not phys:
            error = "the gmsh model has no physical groups: add at least one for the cells"
        tdim = max((d for d, _ in phys), default=0)
        seen: dict[int, str] = {}
        for dim, tag in phys:
            if dim != tdim or error:
                continue
            name = model.getPhysicalName(dim, tag) or f"{dim}:{tag}"
            for entity in model.getEntitiesForPhysicalGroup(dim, tag):
                for etags in model.mesh.getElements(dim, entity)[1]:
                    for e in etags[:1]:
                        if int(e) in seen and seen[int(e)] != name:
                            error = (f"cells belong to two physical groups, '{seen[int(e)]}' and '{name}': "
                                     "each cell must be in exactly one group of its dimension")
                        seen[int(e)] = name
        for dim, tag in phys:
            name = model.getPhysicalName(dim, tag) or f"{dim}:{tag}"
            if name in groups:
                error = f"physical group name '{name}' is used twice (dims {groups[name][0]} and {dim})"
            groups[name] = (dim, tag)
            if dim < tdim:
                nodes, coords = model.mesh.getNodesForPhysicalGroup(dim, tag)
                points[name] = np.asarray(coords, dtype=float).reshape(-1, 3)
    error = comm.bcast(error, root=rank)
    if error:
        raise ValueError(error)
    groups = comm.bcast(groups, root=rank)
    points = comm.bcast(points, root=rank)
    msh, cell_tags, _ = gmshio.model_to_mesh(model, comm, rank, gdim=gdim)
    tdim = msh.topology.dim
    ncells_local = msh.topology.index_map(tdim).size_local
    ncells = comm.allreduce(ncells_local, op=MPI.SUM)
    ntagged = comm.allreduce(int(np.sum(cell_tags.indices < ncells_local)), op=MPI.SUM)
    if ntagged != ncells:
        raise ValueError(f"{ncells - ntagged} of {ncells} cells have no physical group")
    return TaggedMesh(msh, cell_tags, groups, points)


def from_arrays(points: np.ndarray, cells: np.ndarray, cell_name: str = "all",
                point_groups: dict[str, np.ndarray] | None = None,
                comm: MPI.Comm = MPI.COMM_WORLD) -> TaggedMesh:
    """A :class:`TaggedMesh` built from arrays (frames, lattices and surfaces made in code).

    points: (n, gdim) node coordinates; cells: (m, 2) node indices (lines) or
    (m, 3) (triangles); all cells form the group ``cell_name``; point_groups:
    name → node indices. The arrays are read on rank 0 and distributed.
    """
    import ufl

    points = np.asarray(points, dtype=float)
    gdim = points.shape[1]
    cells = np.asarray(cells, dtype=np.int64)
    point_groups = point_groups or {}
    nv = cells.shape[1]
    if nv not in (2, 3):
        raise ValueError(f"from_arrays: cells must have 2 (lines) or 3 (triangles) nodes, got {nv}")
    cell = "interval" if nv == 2 else "triangle"
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.Cell(cell, geometric_dimension=gdim), 1))
    if comm.rank == 0:
        msh = dolfinx.mesh.create_mesh(comm, cells, points, domain)
    else:
        msh = dolfinx.mesh.create_mesh(comm, np.empty((0, nv), dtype=np.int64), np.empty((0, gdim)), domain)
    tdim = nv - 1
    cmap = msh.topology.index_map(tdim)
    local = np.arange(cmap.size_local + cmap.num_ghosts, dtype=np.int32)
    tags = dolfinx.mesh.meshtags(msh, tdim, local, np.ones(len(local), dtype=np.int32))
    pts, ids = {}, {}
    for name, idx in point_groups.items():
        idx = np.asarray(idx, dtype=np.int64)
        p = np.zeros((len(idx), 3))
        p[:, :gdim] = points[idx] if comm.rank == 0 else 0.0
        pts[name] = comm.bcast(p if comm.rank == 0 else None, root=0)
        ids[name] = comm.bcast(idx if comm.rank == 0 else None, root=0)
    groups = {cell_name: (tdim, 1), **{name: (0, 100 + k) for k, name in enumerate(point_groups)}}
    return TaggedMesh(msh, tags, groups, pts, ids)

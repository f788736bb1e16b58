"""gmsh models → DOLFINx meshes whose physical groups are addressed by name.

:func:`from_gmsh` reads the gmsh model on rank 0 (through
``dolfinx.io.gmshio.model_to_mesh``) and distributes it; physical-group
names travel with it so that supports, loads and monitors say
``where="tip"`` instead of a tag number. Groups of the highest dimension
become cell tags (and, one dimension lower, facet tags); every group of a
lower (or, for a mesh of lower dimension, higher) dimension also keeps the
gmsh node tags of its nodes, which are the mesh's input node numbers (tag − 1,
as ``gmshio.model_to_mesh`` numbers them). A group therefore addresses its
own nodes only, never a node of another body that shares its position (two
bodies meshed apart that start in contact), and a node may belong to several
groups. Only nodes that no cell of the mesh uses (a gmsh point not embedded
in the surface) and groups added with :meth:`TaggedMesh.add_point_group` are
located by their coordinates.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI

import dolfinx.mesh


class GroupNotFoundError(KeyError):
    """A physical-group name that the mesh does not have."""

    def __str__(self) -> str:  # KeyError would print the repr with quotes
        return str(self.args[0])


@dataclass
class TaggedMesh:
    """A DOLFINx mesh with named groups.

    mesh: the DOLFINx mesh; cell_tags: its cell MeshTags (gmsh physical tags);
    groups: name → (dim, physical tag). The nodes of a group of another
    dimension than the cells are its ``node_ids`` (name → input node numbers:
    the gmsh node tags − 1, or the indices given to :func:`from_arrays`) and its
    ``points`` (name → (n, 3) coordinates, the same on every rank) of nodes
    located by position (:meth:`add_point_group`; gmsh nodes that no cell
    uses). Input numbers tell apart nodes that share a position (the two
    sides of a slit, two bodies that touch).
    node_source: meshes with the same source number their nodes alike (the
    gmsh node tags of one meshed gmsh model, identified by its name and its
    nodes): parts on such meshes share the nodes they have in common (a beam
    stiffening a shell); meshes of different gmsh models or sessions never do.
    """

    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTagsMetaClass
    groups: dict[str, tuple[int, int]]
    points: dict[str, np.ndarray] = field(default_factory=dict)
    node_ids: dict[str, np.ndarray] = field(default_factory=dict)
    node_source: str = ""
    facet_tags: dolfinx.mesh.MeshTagsMetaClass | None = None
    extra_cells: dict[str, np.ndarray] = field(default_factory=dict)

    def add_cell_group(self, name: str, where) -> None:
        """A group of cells chosen by their midpoints: ``where(x)`` takes (3, n) coordinates and
        returns n booleans (e.g. the one element weakened as an imperfection). Cells may
        belong to it and to their gmsh group at once."""
        if name in self.groups:
            raise ValueError(f"group '{name}' exists already")
        tdim = self.tdim
        cmap = self.mesh.topology.index_map(tdim)
        cells = np.arange(cmap.size_local + cmap.num_ghosts, dtype=np.int32)
        mid = dolfinx.mesh.compute_midpoints(self.mesh, tdim, cells)
        picked = cells[np.asarray(where(mid.T), dtype=bool)]
        if self.mesh.comm.allreduce(int(np.sum(picked < cmap.size_local))) == 0:
            raise ValueError(f"cell group '{name}': no cell's midpoint satisfies the condition")
        self.extra_cells[name] = picked
        self.groups[name] = (tdim, -1)

    def add_point_group(self, name: str, points, within: str | None = None) -> None:
        """A group of the nodes at the coordinates ``points`` (n, gdim) (e.g. a loaded point), one
        node at each; ``within``: a group whose nodes alone are candidates (the body meant where
        two bodies have nodes at one position). The nodes are found now and addressed by their
        input numbers from then on."""
        if name in self.groups:
            raise ValueError(f"group '{name}' exists already")
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        gdim = self.mesh.geometry.dim
        if pts.ndim != 2 or not 1 <= pts.shape[1] <= 3 or not np.all(np.isfinite(pts)):
            raise ValueError(f"point group '{name}': give finite coordinates (n, {gdim}), got {pts.tolist()}")
        full = np.zeros((len(pts), 3))
        full[:, : pts.shape[1]] = pts
        vertices = _locate_vertices(self.mesh, full)
        if within is not None:
            vertices = np.intersect1d(vertices, self.vertices(within))
        owned = vertices[vertices < self.mesh.topology.index_map(0).size_local]
        from scipy.spatial import cKDTree
        x = dolfinx.mesh.compute_midpoints(self.mesh, 0, owned.astype(np.int32)) if len(owned) else np.zeros((0, 3))
        which = cKDTree(full[:, :gdim]).query(x[:, :gdim], k=1)[1] if len(owned) else np.zeros(0, dtype=int)
        count = self.mesh.comm.allreduce(np.bincount(which, minlength=len(full)))
        scope = f" among the nodes of '{within}'" if within is not None else ""
        if np.any(count == 0):
            raise ValueError(f"point group '{name}': no node{scope} at {pts[count == 0].tolist()}")
        if np.any(count > 1):
            raise ValueError(f"point group '{name}': {int(count.max())} nodes{scope} at {pts[count > 1][0].tolist()} "
                             "(bodies meshed apart share the position): give within=<a group of the body meant>")
        self.node_ids[name] = _input_nodes_of_vertices(self.mesh, vertices)
        self.groups[name] = (0, -1)

    @property
    def tdim(self) -> int:
        return self.mesh.topology.dim

    def _check(self, name: str) -> tuple[int, int]:
        if name not in self.groups:
            known = ", ".join(f"'{n}' (dim {d})" for n, (d, _) in sorted(self.groups.items())) or "none"
            raise GroupNotFoundError(f"physical group '{name}' not found in the mesh; it has: {known}")
        return self.groups[name]

    def group_dim(self, name: str) -> int:
        """The dimension of group ``name`` (refused with the groups there are if it is not one)."""
        return self._check(name)[0]

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
        if name in self.extra_cells:
            return self.extra_cells[name]
        return self.cell_tags.indices[self.cell_tags.values == tag]

    def facets(self, name: str) -> np.ndarray | None:
        """Local facets of group ``name`` if it is a group of facets with facet tags (else None)."""
        dim, tag = self._check(name)
        if dim != self.tdim - 1 or self.facet_tags is None or self.tdim < 2:
            return None
        return self.facet_tags.indices[self.facet_tags.values == tag]

    def pin_point_groups(self) -> None:
        """Address the nodes found by their coordinates by their input node numbers from now on
        (before the mesh nodes move, e.g. to a new reference configuration)."""
        for name in list(self.points):
            found = _input_nodes_of_vertices(self.mesh, _locate_vertices(self.mesh, self.points.pop(name)))
            self.node_ids[name] = np.union1d(self.node_ids.get(name, np.zeros(0, dtype=np.int64)), found)

    def vertices(self, name: str) -> np.ndarray:
        """Local vertex indices (owned and ghost) of the nodes of group ``name`` (any dim)."""
        dim, _ = self._check(name)
        if dim == self.tdim:
            return self._closure(self.tdim, self.cells(name))
        if name not in self.node_ids and name not in self.points and self.facets(name) is not None:
            return self._closure(self.tdim - 1, self.facets(name))  # a facet group known by its tags only
        found = [np.zeros(0, dtype=np.int32)]
        if name in self.node_ids:
            found.append(_vertices_of_input_nodes(self.mesh, self.node_ids[name]))
        if name in self.points:
            found.append(_locate_vertices(self.mesh, self.points[name]))
        return np.unique(np.concatenate(found)).astype(np.int32)

    def _closure(self, dim: int, entities: np.ndarray) -> np.ndarray:
        """The vertices of local entities of dimension ``dim``."""
        self.mesh.topology.create_connectivity(dim, 0)
        e2v = self.mesh.topology.connectivity(dim, 0)
        counts = np.diff(e2v.offsets)[entities]
        idx = np.repeat(e2v.offsets[entities], counts) + _ramp(counts)
        return np.unique(e2v.array[idx]).astype(np.int32)


def _vertex_geometry_nodes(mesh: dolfinx.mesh.Mesh) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, geometry nodes) of every local cell's corners, matched pairwise (the first
    geometry nodes of a cell are its vertices, in the same order, also for curved cells)."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim, 0)
    c2v = mesh.topology.connectivity(tdim, 0)
    ncells = len(c2v.offsets) - 1
    nv = len(c2v.array) // max(ncells, 1)
    gdofs = mesh.geometry.dofmap.array.reshape(ncells, -1)[:, :nv] if ncells else np.zeros(0, dtype=np.int32)
    return c2v.array, np.asarray(gdofs).ravel()


def _input_nodes_of_vertices(mesh: dolfinx.mesh.Mesh, vertices: np.ndarray) -> np.ndarray:
    """Input node numbers of local vertices, gathered from every rank."""
    verts, nodes = _vertex_geometry_nodes(mesh)
    node_of_vertex = np.empty(mesh.topology.index_map(0).size_local + mesh.topology.index_map(0).num_ghosts,
                              dtype=np.int64)
    node_of_vertex[verts] = nodes
    inputs = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
    local = inputs[node_of_vertex[np.asarray(vertices, dtype=np.int64)]]
    return np.unique(np.concatenate(mesh.comm.allgather(local))).astype(np.int64)


def _vertices_of_input_nodes(mesh: dolfinx.mesh.Mesh, ids: np.ndarray) -> np.ndarray:
    """Local vertices (owned and ghost) of the input nodes ``ids`` (nodes that are no vertex, such
    as the mid-side nodes of curved cells, are skipped)."""
    verts, nodes = _vertex_geometry_nodes(mesh)
    vertex_of_node = np.full(len(mesh.geometry.x), -1, dtype=np.int32)
    vertex_of_node[nodes] = verts
    inputs = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
    found = vertex_of_node[np.flatnonzero(np.isin(inputs, np.asarray(ids, dtype=np.int64)))]
    return np.unique(found[found >= 0]).astype(np.int32)


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


def from_gmsh(model, gdim: int, comm: MPI.Comm = MPI.COMM_WORLD, rank: int = 0,
              dim: int | None = None, cells: str | None = None) -> TaggedMesh:
    """Distribute the meshed gmsh ``model`` (alive on ``rank``) as a :class:`TaggedMesh`.

    dim: dimension of the cells (default: the highest dimension of the
    physical groups). A model that holds shells (triangles) and beams (lines)
    is read twice, ``from_gmsh(model, 3)`` and ``from_gmsh(model, 3, dim=1)``;
    both meshes keep the gmsh node numbers, so the beams and shells of a scene
    share the nodes they have in common. Every cell of dimension ``dim`` must
    belong to exactly one physical group (gmsh exports a cell once per group
    it belongs to).

    cells: ``"triangle"`` or ``"quadrilateral"``: the surface cells of that shape alone. A DOLFINx
    mesh holds one cell shape, so a surface meshed with both (gmsh's recombination where it
    succeeds) is read twice, ``from_gmsh(model, 3, cells="triangle")`` and ``cells="quadrilateral"``,
    and the shells added to both meshes share their common nodes. Point and line groups then
    become node groups of the nodes they have in that mesh.
    """
    groups: dict[str, tuple[int, int]] = {}
    points: dict[str, np.ndarray] = {}
    node_ids: dict[str, np.ndarray] = {}
    error = None
    if comm.rank == rank:
        phys = model.getPhysicalGroups()
        if not phys:
            error = "the gmsh model has no physical groups: add at least one for the cells"
        node_tags = np.sort(np.asarray(model.mesh.getNodes()[0], dtype=np.int64))
        if not error and not np.array_equal(node_tags, np.arange(1, len(node_tags) + 1)):
            error = ("the gmsh node tags are not 1..n (the mesh's input node numbers are the tags − 1): call "
                     "gmsh.model.mesh.renumberNodes() before from_gmsh")
        tdim = max((d for d, _ in phys), default=0) if dim is None else int(dim)
        if cells is not None:
            tdim = 2
        wanted = {None: None, "triangle": 2, "quadrilateral": 3}.get(cells, -1)
        if wanted == -1:
            error = f"cells = {cells!r} is not 'triangle' or 'quadrilateral'"
        if not error and not any(d == tdim for d, _ in phys):
            error = f"the gmsh model has no physical group of dimension {tdim} (cells to build a mesh of)"
        seen: dict[int, str] = {}
        for d, tag in phys:
            if d != tdim or error:
                continue
            name = model.getPhysicalName(d, tag) or f"{d}:{tag}"
            for entity in model.getEntitiesForPhysicalGroup(d, tag):
                for etags in model.mesh.getElements(d, entity)[1]:
                    for e in etags[:1]:
                        if int(e) in seen and seen[int(e)] != name:
                            error = (f"cells belong to two physical groups, '{seen[int(e)]}' and '{name}': "
                                     "each cell must be in exactly one group of its dimension")
                        seen[int(e)] = name
        # the nodes of the mesh: those of the cells (elements of the physical groups of dimension tdim)
        in_mesh = np.zeros(len(node_tags) + 1, dtype=bool)
        shapes = set()
        for d, tag in phys:
            if d == tdim and not error:
                for entity in model.getEntitiesForPhysicalGroup(d, tag):
                    etypes, _, enodes_all = model.mesh.getElements(d, entity)
                    for etype, enodes in zip(etypes, enodes_all):
                        shapes.add(int(etype))
                        if wanted is None or int(etype) == wanted:
                            in_mesh[np.asarray(enodes, dtype=np.int64)] = True
        if not error and tdim == 2 and cells is None and {2, 3} <= shapes:
            error = ("the surface mesh has both triangles and quadrilaterals; a DOLFINx mesh holds one cell shape: "
                     "read it as two meshes, from_gmsh(model, 3, cells='triangle') and from_gmsh(model, 3, "
                     "cells='quadrilateral'), and add the shells (or membranes) to both: they share their "
                     "common nodes")
        if not error and wanted is not None and wanted not in shapes:
            error = f"the gmsh model has no {cells} cells among its physical groups of dimension 2"
        # the mesh's facet tags come from the groups of dimension tdim − 1 (when tdim is the highest):
        # their elements must lie on the cells (DOLFINx cannot tag facets that are not the mesh's)
        if not error and tdim == max(d for d, _ in phys) and cells is None:
            for d, tag in phys:
                if d != tdim - 1 or error:
                    continue
                for entity in model.getEntitiesForPhysicalGroup(d, tag):
                    enodes = np.concatenate([np.asarray(n, dtype=np.int64)
                                             for n in model.mesh.getElements(d, entity)[2]] or [np.zeros(0, int)])
                    off = enodes[~in_mesh[enodes]]
                    if len(off):
                        at = model.mesh.getNode(int(off[0]))[0]
                        kind = {1: "lines", 2: "faces"}.get(d, "elements")
                        error = (f"physical group '{model.getPhysicalName(d, tag) or f'{d}:{tag}'}' (dimension {d}): "
                                 f"{len(np.unique(off))} of its nodes belong to no cell of dimension {tdim} (the "
                                 f"first at ({at[0]:.6g}, {at[1]:.6g}, {at[2]:.6g})): its {kind} are not on the "
                                 f"mesh of dimension {tdim}, whose boundary groups they would be. Embed them in "
                                 f"the cells before meshing (gmsh.model.mesh.embed({d}, tags, {tdim}, tag)), or "
                                 "build a structure apart from the solid in a gmsh model of its own")
                        break
        for d, tag in phys:
            name = model.getPhysicalName(d, tag) or f"{d}:{tag}"
            if name in groups:
                error = f"physical group name '{name}' is used twice (dims {groups[name][0]} and {d})"
            groups[name] = (d, tag)
            if d != tdim and not error:
                nodes, coords = model.mesh.getNodesForPhysicalGroup(d, tag)
                nodes = np.asarray(nodes, dtype=np.int64)
                used = in_mesh[nodes]
                node_ids[name] = np.unique(nodes[used] - 1)  # input node number = gmsh tag − 1
                if not np.all(used) and cells is None:  # e.g. a gmsh point not embedded in the surface: by position
                    points[name] = np.asarray(coords, dtype=float).reshape(-1, 3)[~used]
        # the model's name and a digest of all its nodes (tags and coordinates): reading one meshed
        # model twice (cells of two dimensions) gives one source; two meshes made in separate gmsh
        # sessions, whose tags both start at 1, never do, whatever their models are called
        tags, coords, _ = model.mesh.getNodes()
        digest = hashlib.sha1(np.asarray(tags, dtype=np.int64).tobytes() + np.asarray(coords, dtype=float).tobytes())
        source = f"gmsh:{model.getCurrent()}:{digest.hexdigest()[:16]}"
    else:
        source = None
        tdim = None
    error = comm.bcast(error, root=rank)
    if error:
        raise ValueError(error)
    groups = comm.bcast(groups, root=rank)
    points = comm.bcast(points, root=rank)
    node_ids = comm.bcast(node_ids, root=rank)
    source = comm.bcast(source, root=rank)
    tdim = comm.bcast(tdim, root=rank)
    top = max(d for d, _ in groups.values())
    facet_tags = None
    if tdim == top and cells is None:
        from dolfinx.io import gmshio  # (gmsh is imported when a gmsh model is read)

        msh, cell_tags, facet_tags = gmshio.model_to_mesh(model, comm, rank, gdim=gdim)
    else:
        msh, cell_tags = _lower_dimensional_mesh(model, comm, rank, gdim, tdim, cells)
    ncells_local = msh.topology.index_map(tdim).size_local
    ncells = comm.allreduce(ncells_local, op=MPI.SUM)
    ntagged = comm.allreduce(int(np.sum(cell_tags.indices < ncells_local)), op=MPI.SUM)
    if ntagged != ncells:
        raise ValueError(f"{ncells - ntagged} of {ncells} cells have no physical group")
    return TaggedMesh(msh, cell_tags, groups, points, node_ids, node_source=source, facet_tags=facet_tags)


def _lower_dimensional_mesh(model, comm: MPI.Comm, rank: int, gdim: int, tdim: int, shape: str | None = None):
    """The cells of dimension ``tdim`` < the model's highest (linear lines or triangles), or the
    surface cells of one ``shape`` ('triangle', 'quadrilateral'), as a mesh; its input node numbers
    are the gmsh node tags − 1, as for ``gmshio.model_to_mesh``."""
    import ufl

    cell_name, gmsh_type = {1: ("interval", 1), 2: ("triangle", 2)}[tdim]
    if shape == "quadrilateral":
        cell_name, gmsh_type = "quadrilateral", 3
    nv = {1: 2, 2: 3, 3: 4}[gmsh_type]
    if comm.rank == rank:
        tags, coords, _ = model.mesh.getNodes()
        order = np.argsort(tags)
        x = np.asarray(coords, dtype=float).reshape(-1, 3)[order]
        if not np.array_equal(np.asarray(tags)[order], np.arange(1, len(tags) + 1)):
            raise ValueError("gmsh node tags are not 1..n: call gmsh.model.mesh.renumberNodes()")
        cells, values = [], []
        for d, tag in model.getPhysicalGroups():
            if d != tdim:
                continue
            for entity in model.getEntitiesForPhysicalGroup(d, tag):
                types, _, nodes = model.mesh.getElements(d, entity)
                for t, n in zip(types, nodes):
                    if shape is not None and t in (2, 3) and t != gmsh_type:
                        continue  # the other shape of a mixed surface: a mesh of its own
                    if t != gmsh_type:
                        raise ValueError(f"physical group {tag} of dimension {d} has gmsh elements of type {t}; "
                                         f"only linear {cell_name}s (type {gmsh_type}) are read")
                    c = np.asarray(n, dtype=np.int64).reshape(-1, nv) - 1
                    if nv == 4:
                        c = c[:, [0, 1, 3, 2]]  # gmsh counter-clockwise → DOLFINx's tensor-product order
                    cells.append(c)
                    values.append(np.full(len(c), tag, dtype=np.int32))
        cells = np.concatenate(cells)
        values = np.concatenate(values)
    else:
        cells, values, x = np.empty((0, nv), dtype=np.int64), None, np.empty((0, 3))
    values = comm.bcast(values, root=rank)
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.Cell(cell_name, geometric_dimension=gdim), 1))
    msh = dolfinx.mesh.create_mesh(comm, cells, x[:, :gdim], domain)
    cmap = msh.topology.index_map(tdim)
    local = np.arange(cmap.size_local + cmap.num_ghosts, dtype=np.int32)
    original = np.asarray(msh.topology.original_cell_index, dtype=np.int64)
    tags = dolfinx.mesh.meshtags(msh, tdim, local, values[original[: len(local)]])
    return msh, tags


def from_arrays(points: np.ndarray, cells: np.ndarray, cell_name: str = "all",
                point_groups: dict[str, np.ndarray] | None = None,
                comm: MPI.Comm = MPI.COMM_WORLD, node_source: str | None = None) -> TaggedMesh:
    """A :class:`TaggedMesh` built from arrays (frames, lattices and surfaces made in code).

    points: (n, gdim) node coordinates; cells: (m, 2) node indices (lines),
    (m, 3) (triangles) or (m, 4) (quadrilaterals, nodes counter-clockwise); all
    cells form the group ``cell_name``; point_groups:
    name → node indices. The arrays are read on rank 0 and distributed.
    node_source: meshes built from one array of points with the same
    ``node_source`` share their common nodes when their parts meet in a scene
    (default: a mesh of its own).
    """
    import ufl

    points = np.asarray(points, dtype=float)
    gdim = points.shape[1]
    cells = np.asarray(cells, dtype=np.int64)
    point_groups = point_groups or {}
    nv = cells.shape[1]
    if nv not in (2, 3, 4):
        raise ValueError(f"from_arrays: cells must have 2 (lines), 3 (triangles) or 4 (quadrilaterals) "
                         f"nodes, got {nv}")
    cell = {2: "interval", 3: "triangle", 4: "quadrilateral"}[nv]
    if nv == 4:
        cells = cells[:, [0, 1, 3, 2]]  # counter-clockwise → DOLFINx's tensor-product vertex order
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.Cell(cell, geometric_dimension=gdim), 1))
    if comm.rank == 0:
        msh = dolfinx.mesh.create_mesh(comm, cells, points, domain)
    else:
        msh = dolfinx.mesh.create_mesh(comm, np.empty((0, nv), dtype=np.int64), np.empty((0, gdim)), domain)
    tdim = 1 if nv == 2 else 2
    cmap = msh.topology.index_map(tdim)
    local = np.arange(cmap.size_local + cmap.num_ghosts, dtype=np.int32)
    tags = dolfinx.mesh.meshtags(msh, tdim, local, np.ones(len(local), dtype=np.int32))
    ids = {}
    for name, idx in point_groups.items():
        idx = np.asarray(idx, dtype=np.int64).ravel()
        bad = comm.rank == 0 and bool(np.any(idx < 0) or np.any(idx >= len(points)))
        if comm.bcast(bad, root=0):
            raise ValueError(f"from_arrays: point group '{name}' has node indices outside 0..{len(points) - 1}")
        ids[name] = comm.bcast(np.unique(idx) if comm.rank == 0 else None, root=0)
    groups = {cell_name: (tdim, 1), **{name: (0, 100 + k) for k, name in enumerate(point_groups)}}
    if node_source is None:
        import uuid
        node_source = comm.bcast(f"arrays:{uuid.uuid4()}" if comm.rank == 0 else None, root=0)
    return TaggedMesh(msh, tags, groups, {}, ids, node_source=str(node_source))


def box(lengths, n, cell: str = "hexahedron", comm: MPI.Comm = MPI.COMM_WORLD) -> TaggedMesh:
    """A structured box [0, Lx] × [0, Ly] × [0, Lz] of ``n`` = (nx, ny, nz) hexahedra (or tetrahedra)
    whose cells form the group "box" and whose faces are the facet groups "x0", "x1", "y0",
    "y1", "z0", "z1"."""
    lengths = np.asarray(lengths, dtype=float)
    kind = {"hexahedron": dolfinx.mesh.CellType.hexahedron, "tetrahedron": dolfinx.mesh.CellType.tetrahedron}[cell]
    mesh = dolfinx.mesh.create_box(comm, [np.zeros(3), lengths], list(n), kind)
    cmap = mesh.topology.index_map(3)
    cells = np.arange(cmap.size_local + cmap.num_ghosts, dtype=np.int32)
    cell_tags = dolfinx.mesh.meshtags(mesh, 3, cells, np.ones(len(cells), dtype=np.int32))
    groups = {"box": (3, 1)}
    facets, values = [], []
    for k, axis in enumerate("xyz"):
        for side, value in (("0", 0.0), ("1", lengths[k])):
            tag = 2 + 2 * k + (side == "1")
            f = dolfinx.mesh.locate_entities_boundary(mesh, 2, lambda x, k=k, v=value: np.isclose(x[k], v))
            facets.append(f)
            values.append(np.full(len(f), tag, dtype=np.int32))
            groups[f"{axis}{side}"] = (2, tag)
    facets, values = np.concatenate(facets), np.concatenate(values)
    order = np.argsort(facets)
    facet_tags = dolfinx.mesh.meshtags(mesh, 2, facets[order], values[order])
    return TaggedMesh(mesh, cell_tags, groups, facet_tags=facet_tags)


def name_groups(groups: dict[str, tuple[int, list[int]]]) -> None:
    """Physical groups of the current gmsh model: name → (dim, entity tags)."""
    import gmsh

    for name, (dim, tags) in groups.items():
        tag = gmsh.model.addPhysicalGroup(dim, list(tags))
        gmsh.model.setPhysicalName(dim, tag, name)


def size_field(tag: int) -> None:
    """Make the gmsh mesh field ``tag`` the only source of element sizes of the current model:
    its background mesh, with the sizes that gmsh otherwise takes from the boundary, the points
    and the curvature switched off (they would override a graded field near the surfaces)."""
    import gmsh

    gmsh.model.mesh.field.setAsBackgroundMesh(tag)
    for option in ("MeshSizeExtendFromBoundary", "MeshSizeFromPoints", "MeshSizeFromCurvature"):
        gmsh.option.setNumber(f"Mesh.{option}", 0)


SIDES = ("bottom", "right", "top", "left")


def rectangles(blocks: dict[str, tuple], groups: dict[str, list[tuple[str, str]]] | None = None,
               comm: MPI.Comm = MPI.COMM_WORLD, quads: bool = True) -> TaggedMesh:
    """Structured quadrilateral blocks of one 2D mesh, not joined to each other: coincident edges
    keep separate nodes (bodies that may come into contact).

    blocks: name → (x0, y0, width, height, nx, ny); each block's cells form the group ``name``;
    groups: edge groups, name → [(block, side), …] with side "bottom", "right", "top" or "left"
    (a facet carries one tag: give each edge to one group at most); quads=False: triangles."""
    import gmsh

    taken = [m for members in (groups or {}).values() for m in members]
    if len(set(taken)) != len(taken):
        raise ValueError("rectangles: an edge is in two groups (a facet carries one tag)")
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        named, edges = {}, {}
        for name, (x0, y0, w, h, nx, ny) in blocks.items():
            pts = [g.addPoint(x, y, 0) for x, y in ((x0, y0), (x0 + w, y0), (x0 + w, y0 + h), (x0, y0 + h))]
            lines = [g.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
            surface = g.addPlaneSurface([g.addCurveLoop(lines)])
            for line, n in zip(lines, (nx, ny, nx, ny)):
                g.mesh.setTransfiniteCurve(line, n + 1)
            g.mesh.setTransfiniteSurface(surface)
            if quads:
                g.mesh.setRecombine(2, surface)
            named[name] = (2, [surface])
            for side, line in zip(SIDES, lines):
                edges[(name, side)] = line
        for name, members in (groups or {}).items():
            named[name] = (1, [edges[m] for m in members])
        g.synchronize()
        name_groups(named)
        gmsh.model.mesh.generate(2)
    tm = from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm

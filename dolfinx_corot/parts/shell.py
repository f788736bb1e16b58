"""Shells and membranes on surface meshes in space: co-rotational kernels wrapped as DOLFINx forms.

* :class:`Shell3D`: flat co-rotational shell triangles (OPT or CST membrane with drilling
  rotations, DKT bending) and membrane triangles on a triangle mesh;
* :class:`ShellQuad`: four-node co-rotational shells (incompatible-mode membrane with drilling
  rotations, MITC4 bending and transverse shear) and membranes on a quadrilateral mesh;
* :class:`MembraneQuad`: four-node co-rotational membranes (bilinear Q4) on a quadrilateral mesh
  that carries no shells.

Both have 6 dofs per node (u, spatial spins) with multiplicative rotations as 3D frames,
so that they share nodes with beams.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

import dolfinx.fem

from .. import _dolfinx
from ..elements import membrane_quad as quad_law
from ..elements import shell_quad as quad_shell_law
from ..elements import shell_triangle as shell_law
from ..elements import uniform_load
from ..conditions import Condition
from ..io.mesh import TaggedMesh
from ..kernels import CCW, RESULTANTS, OnFirstUse
from ..loads import FollowerLoad
from ..result import ElementResults
from ..sections import turned_stiffness
from .base import PartRef
from .cells import mesh_extent, quadrilateral_problems, refuse, triangle_problems
from .frame import Frame3D, LineFrame, Rotations3D
from .surface import Surface, SurfaceError, gather_surface


def _same_section(a: tuple, b: tuple) -> bool:
    """Whether two (section, material axis) pairs are the same."""
    (sa, xa), (sb, xb) = a, b
    if sa != sb or (xa is None) != (xb is None):
        return False
    if callable(xa) or callable(xb):
        return xa is xb
    return xa is None or bool(np.array_equal(np.asarray(xa, dtype=float), np.asarray(xb, dtype=float)))


def _cell_normals(X: np.ndarray) -> np.ndarray:
    """(n, 3) unit normals of cells X (n, 3 or 4, 3) by the right-hand rule over their nodes;
    quadrilaterals (DOLFINx's order (0, 0), (1, 0), (0, 1), (1, 1)): at the centre of the
    bilinear patch."""
    if X.shape[1] == 3:
        n = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    else:
        n = np.cross(X[:, 1] + X[:, 3] - X[:, 0] - X[:, 2], X[:, 2] + X[:, 3] - X[:, 0] - X[:, 1])
    return n / np.linalg.norm(n, axis=1)[:, None]


class Surface3D(Rotations3D, LineFrame):
    """What shells and quadrilateral membranes share: 6 dofs per node with multiplicative
    rotations as in :class:`Frame3D`, and per-cell constants (initial frame, local coordinates,
    local stiffness) computed once by the kernels' ``element_data_all``."""

    tdim = 2
    gdim = 3
    dof_names = Frame3D.dof_names
    translations = 3
    symmetric_tangent = False

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        LineFrame.__init__(self, tmesh, large_rotations)
        self._init_state()
        # dead loads per length on edges: ((cells, ends), q, amplitude, condition)
        self._edge_loads: list = []
        self._sections: dict = {}  # shells' label → (section, material axis)

    def _kernel_constants(self) -> list:
        """The kernels' per-cell constants of every cell with elements (DG0, computed once per
        change of existence) from the cell's reference: the mesh, or where it appeared (approach II)."""
        mesh = self.tmesh.mesh
        n = self.kernels.NEDATA
        Q = _dolfinx.function_space(mesh, "DG", 0, n)
        edata = dolfinx.fem.Function(Q, name="element_constants")
        X = mesh.geometry.x[mesh.geometry.dofmap.array.reshape(-1, self.nodes_per_cell)]
        X = X + self._activation_translations(np.arange(len(X)))
        props = self.cell_properties(np.arange(len(X)))
        out = np.zeros((len(X), n))
        self.kernels.element_data_all(X, props, self._linear_edge_flags(props), self._owner_of_cell != "", out)
        edata.x.array.reshape(-1, n)[Q.dofmap.list.array] = out
        return [edata]

    # -- edges where a drilling membrane meets a linear one ---------------------------
    # cell-local edges (as vertex pairs in DOLFINx's order) of triangles and quadrilaterals
    _EDGES = {3: ((0, 1), (1, 2), (2, 0)), 4: ((0, 1), (1, 3), (3, 2), (2, 0))}
    foreign_linear_edges: np.ndarray | None = None  # keys of other meshes' linear edges (set by Coupled)

    def set_foreign_linear_edges(self, keys: np.ndarray | None) -> None:
        """The keys of the linear membrane edges of the other meshes that share this one's nodes
        (see :meth:`Shell3D._linear_edge_flags`); forms made before are made again."""
        if self._forms is not None and not np.array_equal(keys, self.foreign_linear_edges):
            self._forms = None  # the element constants read the edges
        self.foreign_linear_edges = keys

    def _cell_keys(self) -> np.ndarray:
        """(cells, nodes) input (gmsh) node numbers of the local cells' vertices."""
        mesh = self.tmesh.mesh
        geo = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
        return geo[mesh.geometry.dofmap.array.reshape(-1, self.nodes_per_cell)]

    def _edge_keys(self) -> np.ndarray:
        """(cells, edges) a key per cell edge, the same in every mesh that shares the nodes."""
        ids = self._cell_keys()
        a = np.stack([ids[:, i] for i, _ in self._EDGES[self.nodes_per_cell]], axis=1)
        b = np.stack([ids[:, j] for _, j in self._EDGES[self.nodes_per_cell]], axis=1)
        return (np.minimum(a, b) << np.int64(32)) | np.maximum(a, b)

    def _has_linear_edges(self, props: np.ndarray) -> np.ndarray:
        """Per local cell: whether its element's membrane edges are linear (not the OPT's)."""
        return self._cells_active()

    def linear_edges(self) -> np.ndarray:
        """Keys of the edges of this part's existing cells whose membrane edges are linear (all
        ranks). Collective."""
        cmap = self.tmesh.mesh.topology.index_map(2)
        props = self.cell_properties(np.arange(cmap.size_local + cmap.num_ghosts))
        mine = self._has_linear_edges(props)[: cmap.size_local]
        keys = self._edge_keys()[: cmap.size_local][mine]
        return np.unique(np.concatenate(self.comm.allgather(keys.ravel())))

    def _linear_edge_flags(self, props: np.ndarray) -> np.ndarray:
        """(cells, edges) 1 where a cell's edge is also an edge of a cell with a linear membrane
        edge (see :class:`Shell3D`); zeros for parts without drilling membranes. Collective."""
        return np.zeros((len(props), len(self._EDGES[self.nodes_per_cell])))

    def surface(self, where: str, body: str | None = None) -> Surface:
        """The shells or membranes of cell group ``where`` as a two-sided contact surface: their
        mid-surface faces (triangles, or quadrilaterals with corners in cyclic order), met at half
        the thickness on either side along the current face normal — which turns with the
        element, so the contact faces follow the shell's rotations; a slave shell node meets
        other surfaces at its half thickness. Stiffness scale: the smallest E/(1 − ν²)."""
        n_owned = self.tmesh.mesh.topology.index_map(2).size_local
        cells = self.tmesh.cells(where)
        cells = cells[cells < n_owned]
        if self.comm.allreduce(int(np.any(self._owner_of_cell[cells] == "")), op=MPI.MAX):
            raise SurfaceError(f"contact surface '{where}': some of its cells carry no shell or membrane")
        order = CCW if self.nodes_per_cell == 4 else np.arange(3)
        blocks = np.array([self.V.dofmap.cell_dofs(c) for c in cells], dtype=np.int64).reshape(-1, self.nodes_per_cell)
        props = self.cell_properties(cells)
        E, nu, t = props[:, 0], props[:, 1], props[:, 2]
        modulus = self.comm.allreduce(float(np.min(E / (1.0 - nu**2), initial=np.inf)), op=MPI.MIN)
        return gather_surface(self, where, blocks[:, order], self.V.tabulate_dof_coordinates(), offsets=0.5 * t,
                              two_sided=True, modulus=modulus, cells=cells)


    def add_pressure(self, part: PartRef, where: str | None, p: float, follower: bool, amplitude=None,
                     condition: Condition | None = None) -> Condition:
        """A uniform pressure p on the shells or membranes of ``part`` (within cell group ``where``), along
        each cell's normal by the right-hand rule over its nodes (see ``Scene.pressure``)."""
        label = self._label(part)
        cells = self._loaded_cells(part, where, "pressure")
        condition = condition or Condition("load", f"pressure on {label}")
        kind = "triangle" if self.nodes_per_cell == 3 else "quad"
        if follower:
            self.followers.append(FollowerLoad(self, label, kind, cells, p, None, amplitude, condition))
            return condition

        def along_initial_normals(cells, X, p=p):
            return p * _cell_normals(X)
        self._distributed.append((label, where, along_initial_normals, amplitude, condition))
        return condition

    # -- loads on edges ------------------------------------------------------------
    def add_line_load(self, part: PartRef, where: str | None, q: np.ndarray, axes: str, follower: bool,
                      amplitude=None, condition: Condition | None = None) -> Condition:
        """A uniform dead load q per unit reference length, in global axes, on edges of the shells or
        membranes of ``part`` (see ``Scene.load``): the lines of a group of lines of the mesh, or
        the part's boundary edges between nodes of a group of nodes."""
        label = self._label(part)
        if where is None:
            raise ValueError(f"load per length on {label}: name the edges it acts on (a group of lines of the "
                             "mesh, or a group of nodes: the part's boundary edges between them)")
        if axes != "global" or follower:
            raise ValueError(f"load per length on the edges '{where}' of {label}: on shells and membranes it is "
                             "a dead load in global axes (axes='global', follower=False); a pressure that turns "
                             "with the surface is scene.pressure")
        edges = self._loaded_edges(label, where)
        if not self.comm.allreduce(len(edges[0])):
            dim = self.tmesh.groups[where][0]
            what = "lines" if dim == 1 else "boundary edges between its nodes"
            raise ValueError(f"load per length on {label}: group '{where}' has no {what} on its cells")
        condition = condition or Condition("load", f"per length on the edges '{where}' of {label}")
        self._edge_loads.append((edges, q, amplitude, condition))
        return condition

    def _loaded_edges(self, label: str, where: str) -> tuple[np.ndarray, np.ndarray]:
        """(cells (m,), ends (m, 2)) of the owned edges of group ``where`` on cells of ``label``: a
        group of lines gives its lines, a group of nodes the edges of one cell of ``label`` with
        both ends in it; ends: the positions of the edge's nodes in its cell, counter-clockwise."""
        dim = self.tmesh.group_dim(where)
        if dim == 2:
            raise ValueError(f"load per length on {label}: '{where}' is a group of cells; give a group of "
                             "lines or of nodes along the loaded edges")
        topology = self.tmesh.mesh.topology
        for a, b in ((1, 0), (1, 2), (2, 0)):
            topology.create_connectivity(a, b)
        f2v, f2c = topology.connectivity(1, 0), topology.connectivity(1, 2)
        c2v = topology.connectivity(2, 0)
        n_owned = topology.index_map(1).size_local
        mine = self._owner_of_cell == label
        facets = self.tmesh.facets(where) if dim == 1 else None
        if facets is None:  # a group of nodes: the edges with both ends in it
            ends = f2v.array.reshape(-1, 2)[:n_owned]
            facets = np.flatnonzero(np.isin(ends, self.tmesh.vertices(where)).all(axis=1))
        cyclic = CCW if self.nodes_per_cell == 4 else np.arange(3)
        cells, positions = [], []
        for e in facets[facets < n_owned]:
            on = [c for c in f2c.links(e) if mine[c]]
            if not on or (dim != 1 and len(on) != 1):
                continue
            around = list(c2v.links(on[0])[cyclic])
            i, j = (around.index(v) for v in f2v.links(e))
            if (j - i) % self.nodes_per_cell != 1:
                i, j = j, i
            cells.append(on[0])
            positions.append((cyclic[i], cyclic[j]))
        return np.array(cells, dtype=np.int32), np.array(positions, dtype=np.int64).reshape(-1, 2)

    def _edge_drilling(self, cells: np.ndarray) -> np.ndarray:
        """α_b of the drilling part of each cell's edge displacement (its edge loads' drilling
        moments, :func:`~dolfinx_corot.elements.uniform_load.edge_loads`): 0, linear edges."""
        return np.zeros(len(cells))

    def load_conditions(self) -> list:
        return super().load_conditions() + [(amp, cond) for *_, amp, cond in self._edge_loads]

    def _add_distributed_loads(self, b, amplitude) -> None:
        super()._add_distributed_loads(b, amplitude)
        terms = [(edges, q) for edges, q, amp, cond in self._edge_loads if amp is amplitude and cond.exists]
        if not terms:
            return
        loads = dolfinx.fem.Function(self.V)
        arr = loads.x.array.reshape(-1, self.ndof)
        cell_blocks = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)
        for (cells, ends), q in terms:
            if self._existing is not None:
                keep = self._existing[cells]
                cells, ends = cells[keep], ends[keep]
            rows = np.arange(len(cells))[:, None]
            Xc = self.reference[cell_blocks[cells]] + self._activation_translations(cells)
            normal = _cell_normals(Xc)
            drilling = self._edge_drilling(cells)
            forces, moments = uniform_load.edge_loads(Xc[rows, ends], normal, q, drilling)
            blocks = cell_blocks[cells][rows, ends]
            np.add.at(arr[:, :3], blocks, forces)
            np.add.at(arr[:, 3:6], blocks, moments)
        loads.x.scatter_reverse(dolfinx.la.ScatterMode.add)
        n = self.V.dofmap.index_map.size_local * self.ndof
        with b.localForm() as bl:
            bl.array[:n] += loads.x.array[:n]

    section_components = RESULTANTS

    def element_results(self, cells: np.ndarray | None = None, label: str = "",
                        gather: bool = True) -> ElementResults:
        """Stress resultants per unit length at the centre of every shell and membrane, in the
        element's current frame (triangles: e1 along side 1–2; quadrilaterals: e1 between the
        diagonals; e3 the normal by the right-hand rule over the nodes; the initial frame in a
        geometrically linear analysis): membrane forces Nxx, Nyy, Nxy, moments Mxx, Myy, Mxy
        (M = ∫σ z dz, z along e3), transverse shears Qx, Qy (from the moments' equilibrium), the
        stresses σ = N/t ± 6M/t² on the top (+e3) and bottom faces and their von Mises values.
        Membranes have no moments or shears. See :func:`dolfinx_corot.kernels.shell3d.resultants`."""
        cells = self._result_cells(cells)
        X, S = self._element_states(cells)
        values = np.empty((len(cells), len(self.section_components)))
        axes = np.empty((len(cells), 3, 3))
        self.kernels.resultants_all(np.ascontiguousarray(X), np.ascontiguousarray(S),
                                    np.ascontiguousarray(self.cell_properties(cells)), self.large_rotations,
                                    values, axes)
        centre = self._current_points(cells).mean(axis=1)[:, None, :]
        return self._gather_results("shell resultants", self.section_components, cells, centre, values[:, None, :],
                                    axes, label, gather)

    PLY_COMPONENTS = ("s11", "s22", "s12", "z", "ply")
    section_slots: tuple | None = None  # where a shell's A, B, D sit in its cells' properties

    def _remember_section(self, ref: PartRef, section, axis) -> PartRef:
        """Keep the section and material axis of the shells ``ref`` (for their ply stresses)."""
        self._sections[self._label(ref)] = (section, axis)
        return ref

    def ply_stresses(self, cells: np.ndarray | None = None, label: str = "") -> ElementResults:
        """Stresses in the plies of the shells' laminate at the centre of each cell, in each ply's
        own axes (1 along its fibres, 2 across, in the shell), at the bottom and the top face of
        every ply from the bottom of the laminate up (2 points per ply): classical lamination
        theory (Jones 1999, §4.2): the mid-surface strains and curvatures (ε, κ) =
        [A B; B D]⁻¹(N, M) of the cell's resultants (:meth:`element_results`), σ = Q̄ₖ(ε + zκ) in
        the element frame, turned to the ply's axes. Components s11, s22, s12, the height z
        above the mid-surface (along e3) and the ply's index; points at the centre moved by z e3.
        The cells must share one section."""
        cells = self._result_cells(cells)
        owners = sorted(set().union(*self.comm.allgather(set(self._owner_of_cell[cells]))))
        known = [o for o in owners if o in self._sections]
        if len(known) != len(owners) or not owners:
            raise ValueError(f"ply stresses of {label or 'the part'}: give shells (membranes carry N/t alone)")
        if any(not _same_section(self._sections[o], self._sections[owners[0]]) for o in owners):
            raise ValueError(f"ply stresses of {label or 'the part'}: its cells have different sections "
                             f"({', '.join(owners)}); ask for the cells of one of them")
        section, axis = self._sections[owners[0]]
        res = self.element_results(cells, label, gather=False)
        NM = res.values[:, 0, :6]
        props = self.cell_properties(cells)
        a0, b0, d0 = self.section_slots
        A, B, D = (props[:, k:k + 9].reshape(-1, 3, 3) for k in (a0, b0, d0))
        ABD = np.concatenate([np.concatenate([A, B], axis=2), np.concatenate([B, D], axis=2)], axis=1)
        strains = np.linalg.solve(ABD, NM[:, :, None])[:, :, 0] if len(cells) else np.zeros((0, 6))
        eps, kappa = strains[:, :3], strains[:, 3:]
        phi = np.zeros(len(cells)) if section.isotropic else self._material_angles(cells, axis, label)
        e3 = res.axes[:, 2] if len(cells) else np.zeros((0, 3))
        values, points = [], []
        z = -0.5 * section.thickness
        for k, ply in enumerate(section.plies):
            Q, _ = ply.stiffness()
            theta = phi + np.radians(ply.angle)
            Qbar = turned_stiffness(Q, theta)
            c, s = np.cos(theta), np.sin(theta)
            for height in (z, z + ply.thickness):
                sx, sy, sxy = np.einsum("nij,nj->in", Qbar, eps + height * kappa)
                values.append(np.stack([c * c * sx + s * s * sy + 2 * c * s * sxy,
                                        s * s * sx + c * c * sy - 2 * c * s * sxy,
                                        c * s * (sy - sx) + (c * c - s * s) * sxy,
                                        np.full(len(cells), height), np.full(len(cells), float(k))], axis=1))
                points.append(res.points[:, 0] + height * e3)
            z += ply.thickness
        return self._gather_results("ply stresses", self.PLY_COMPONENTS, cells, np.stack(points, axis=1),
                                    np.stack(values, axis=1), res.axes, label)

    def _drawn_sizes(self, cells: np.ndarray) -> np.ndarray:
        """The thickness."""
        return self.cell_properties(cells)[:, 2]

    membrane_A0: int = 0  # where a membrane's A sits in the cells' properties (set per kind)

    def add_membrane(self, where, section, axis=None):
        """Membranes on group ``where``: the section's membrane stiffness A alone (see
        :meth:`dolfinx_corot.Scene.add_membrane`); the kind's properties hold E, ν, t first."""
        E, nu = self._reference_modulus(section)
        head = np.zeros(self.nprops)
        head[:3] = E, nu, section.thickness
        rows = self._section_rows(head, section, axis, (self.membrane_A0, None, None, None), False)
        return self.add_elements(where, rows, False, "membrane", self._fingerprint(head, section, axis))

    def _check_geometry(self, cells, label, props):
        """Refuse cells of zero size or area; quadrilaterals also self-intersecting, not convex,
        with three corners on a line or strongly warped (MeshError naming the first; see
        :func:`dolfinx_corot.parts.cells.triangle_problems`, :func:`~.cells.quadrilateral_problems`)."""
        mesh = self.tmesh.mesh
        X = mesh.geometry.x[mesh.geometry.dofmap.array.reshape(-1, self.nodes_per_cell)[cells]]
        if self.nodes_per_cell == 4:
            problems = quadrilateral_problems(X[:, CCW], mesh_extent(mesh))
        else:
            problems = triangle_problems(X, mesh_extent(mesh))
        refuse(mesh, label, [(problem, cells[bad]) for problem, bad in problems])

    # -- sections: laminates and material axes ----------------------------------------------
    def _initial_axes(self, cells: np.ndarray):
        """(e1, e2, e3, centroid), each (n, 3): the initial element frames of local cells
        (triangles: e1 along side 1–2; quadrilaterals: e1 between the diagonals; e3 the normal by
        the right-hand rule over the nodes)."""
        mesh = self.tmesh.mesh
        X = mesh.geometry.x[mesh.geometry.dofmap.array.reshape(-1, self.nodes_per_cell)[cells]]
        if self.nodes_per_cell == 3:
            e1 = X[:, 1] - X[:, 0]
            n = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
        else:
            X = X[:, CCW]
            d1, d2 = X[:, 2] - X[:, 0], X[:, 3] - X[:, 1]
            n = np.cross(d1, d2)
            e1 = d1 / np.linalg.norm(d1, axis=1)[:, None] - d2 / np.linalg.norm(d2, axis=1)[:, None]
        e1 = e1 / np.linalg.norm(e1, axis=1)[:, None]
        e3 = n / np.linalg.norm(n, axis=1)[:, None]
        return e1, np.cross(e3, e1), e3, X.mean(axis=1)

    def _material_angles(self, cells: np.ndarray, axis, label: str) -> np.ndarray:
        """The angle (n,) of the material axis 1 from each cell's e1 about e3: ``axis`` (3,) or a
        function of the centroids (n, 3) → (n, 3), projected onto the cell's plane."""
        e1, e2, e3, centre = self._initial_axes(cells)
        if callable(axis):
            a = np.asarray(axis(centre), dtype=float)
        else:
            a = np.broadcast_to(np.asarray(axis, dtype=float), (len(cells), 3))
        if a.shape != (len(cells), 3) or not np.all(np.isfinite(a)):
            raise ValueError(f"{label}: the material axis must be 3 finite numbers, or a function of the points "
                             f"(n, 3) giving (n, 3) vectors; got shape {a.shape}")
        a1, a2 = np.einsum("ni,ni->n", a, e1), np.einsum("ni,ni->n", a, e2)
        bad = np.flatnonzero(np.hypot(a1, a2) <= 1e-6 * np.linalg.norm(a, axis=1))
        refuse(self.tmesh.mesh, label, [(f"{label}: the material axis is normal to {{n}} cell(s), the first at "
                                         "{at}: give an axis that lies in the shell", cells[bad])], ValueError)
        return np.arctan2(a2, a1)

    def _section_rows(self, head: np.ndarray, section, axis, slots: tuple, bending: bool):
        """A function of (cells, label) giving the cells' property rows: ``head`` then the
        section's A, B, D (and S when ``slots`` has four entries) at their slots, turned to each
        cell's initial frame (membranes: A alone)."""
        def rows(cells, label):
            angles = np.zeros(len(cells))
            if not section.isotropic:
                if axis is None:
                    raise ValueError(f"{label}: the section has orthotropic plies: give the material axis 1 "
                                     "(axis=(x, y, z), projected onto each cell, or a function of the points)")
                angles = self._material_angles(cells, axis, label)
            out = np.tile(head, (len(cells), 1))
            for slot, m in zip(slots, section.matrices(angles)):
                if slot is not None and (bending or slot == slots[0]):
                    size = m.shape[1] * m.shape[2]  # (a rank may hold none of the group's cells)
                    out[:, slot:slot + size] = m.reshape(len(cells), size)
            return out
        return rows

    @staticmethod
    def _reference_modulus(section) -> tuple[float, float]:
        """(E, ν) of the section's membrane stiffness along the material axis 1, from
        A = A(0): ν = A12/A22, E = (A11 A22 − A12²)/(A22 t) (an isotropic layer: its E and ν)."""
        A = section.matrices(0.0)[0][0]
        t = section.thickness
        return float((A[0, 0] * A[1, 1] - A[0, 1] ** 2) / (A[1, 1] * t)), float(A[0, 1] / A[1, 1])

    @staticmethod
    def _fingerprint(head, section, axis) -> list[float]:
        out = [float(v) for v in head]
        for p in section.plies:
            m = p.material
            out += [p.thickness, p.angle] + [float(v) if v is not None else -1.0 for v in vars(m).values()]
        if axis is not None and not callable(axis):
            out += [float(v) for v in np.asarray(axis, dtype=float)]
        return out


class Shell3D(Surface3D):
    """Flat co-rotational shell triangles on a triangle mesh in space; dofs (ux, uy, uz, rx, ry, rz)
    per node, rotations multiplicative as in :class:`Frame3D`."""

    nodes_per_cell = 3
    nprops = shell_law.NPROPS
    reads_linear_edges = True  # the OPT keeps its edges beside linear ones linear
    membrane_A0 = shell_law.A0
    section_slots = (shell_law.A0, shell_law.B0, shell_law.D0)
    kernels = OnFirstUse("shell3d")

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        if tmesh.mesh.topology.cell_name() != "triangle":
            raise NotImplementedError(f"shells are triangles; the mesh has {tmesh.mesh.topology.cell_name()} "
                                      "cells (set Mesh.RecombineAll = 0 in gmsh)")
        super().__init__(tmesh, large_rotations)

    def add_shell(self, where, section, drilling: float, membrane: str | None = None, kinematics: str = "kirchhoff",
                  axis=None, shallow: bool = False):
        label = f"shell '{where}'"
        if kinematics != "kirchhoff":
            raise ValueError(f"{label}: kinematics '{kinematics}': shell triangles bend as discrete Kirchhoff "
                             "triangles; Reissner–Mindlin shells ('mindlin', MITC4) need a quadrilateral mesh")
        if not (drilling > 0.0 and np.isfinite(drilling)):
            raise ValueError(f"{label}: the drilling factor {drilling} must be positive")
        membrane = "opt" if membrane is None else membrane
        if membrane not in ("opt", "cst"):
            raise ValueError(f"{label}: membrane '{membrane}' is not one of the triangles' ('opt', 'cst')")
        E, nu = self._reference_modulus(section)
        head = np.zeros(shell_law.NPROPS)
        head[:6] = E, nu, section.thickness, drilling, 1.0, 1.0 if membrane == "opt" else 0.0
        head[shell_law.SHALLOW] = 1.0 if shallow else 0.0
        rows = self._section_rows(head, section, axis, (shell_law.A0, shell_law.B0, shell_law.D0), True)
        return self._remember_section(self.add_elements(where, rows, True, "shell",
                                                        self._fingerprint(head, section, axis)), section, axis)

    def _has_linear_edges(self, props: np.ndarray) -> np.ndarray:
        return self._cells_active() & ~((props[:, shell_law.BENDING] != 0.0) & (props[:, shell_law.OPT] != 0.0))

    def _linear_edge_flags(self, props: np.ndarray) -> np.ndarray:
        """(cells, 3) 1 on the edges (nodes 1–2, 2–3, 3–1) of OPT triangles that are also edges of
        cells whose membrane edges are linear: constant-strain triangles, membranes and
        quadrilaterals of this mesh or of meshes that share its nodes. The OPT lumps a constant
        stress into drilling moments ∓α_b σ_nn l²/12 at an edge's ends (Allman's quadratic edge);
        a linear neighbour lumps none, so the two do not pass the patch test together. On those
        edges the OPT's edge stays linear (its basic stiffness without that edge's drilling
        moments; Felippa 2003, eq. 26, edge by edge). Collective."""
        opt = (props[:, shell_law.BENDING] != 0.0) & (props[:, shell_law.OPT] != 0.0)
        anywhere = self.comm.allreduce(int(np.any(opt)), op=MPI.MAX)
        flags = np.zeros((len(props), 3))
        if not anywhere:
            return flags
        linear = self.linear_edges()
        if self.foreign_linear_edges is not None:
            linear = np.union1d(linear, self.foreign_linear_edges)
        flags[:] = np.isin(self._edge_keys(), linear)
        flags[~opt] = 0.0
        return flags

    def _edge_drilling(self, cells: np.ndarray) -> np.ndarray:
        """α_b on OPT shells (the drilling part of their edges' displacement, Allman's), 0 on CST
        shells and membranes (linear edges)."""
        props = self.cell_properties(cells)
        return shell_law.ALPHA_B * (self._bending[cells] & (props[:, 5] != 0.0))


class ShellQuad(Surface3D):
    """Four-node co-rotational shells on a quadrilateral mesh in space (see
    :mod:`dolfinx_corot.kernels.shell_quad`); dofs (ux, uy, uz, rx, ry, rz) per node, rotations
    multiplicative as in :class:`Frame3D`. Membranes on the same mesh are the shell element's
    membrane alone (incompatible modes, no drilling, bending or shear stiffness); nodes carried by
    membranes alone have their rotations fixed."""

    nodes_per_cell = 4
    nprops = quad_shell_law.NPROPS
    section_slots = (quad_shell_law.A0, quad_shell_law.B0, quad_shell_law.D0)
    membrane_A0 = quad_shell_law.A0
    kernels = OnFirstUse("shell_quad")

    def add_shell(self, where, section, drilling: float, membrane: str | None = None, kinematics: str = "kirchhoff",
                  axis=None, shallow: bool = False):
        label = f"shell '{where}'"
        if kinematics not in ("kirchhoff", "mindlin"):
            raise ValueError(f"{label}: kinematics '{kinematics}' is not 'kirchhoff' (DKQ) or 'mindlin' (MITC4)")
        if not (drilling > 0.0 and np.isfinite(drilling)):
            raise ValueError(f"{label}: the drilling factor {drilling} must be positive")
        if membrane not in (None, "qm6"):
            raise ValueError(f"{label}: membrane '{membrane}' is for triangles; a quadrilateral shell's membrane is "
                             "'qm6' (bilinear with incompatible modes)")
        E, nu = self._reference_modulus(section)
        head = np.zeros(quad_shell_law.NPROPS)
        head[:4] = E, nu, section.thickness, drilling
        head[quad_shell_law.KIRCHHOFF] = 1.0 if kinematics == "kirchhoff" else 0.0
        head[quad_shell_law.SHALLOW] = 1.0 if shallow else 0.0
        slots = (quad_shell_law.A0, quad_shell_law.B0, quad_shell_law.D0, quad_shell_law.S0)
        rows = self._section_rows(head, section, axis, slots, True)
        return self._remember_section(self.add_elements(where, rows, True, "shell",
                                                        self._fingerprint(head, section, axis)), section, axis)


class MembraneQuad(Surface3D):
    """Four-node co-rotational membranes on a quadrilateral mesh in space; dofs (ux, uy, uz, rx,
    ry, rz) per node like shells (so that they may share nodes with shells and beams), the
    rotations of nodes carried by membranes alone fixed."""

    nodes_per_cell = 4
    nprops = quad_law.NPROPS
    membrane_A0 = quad_law.A0
    kernels = OnFirstUse("membrane_quad")

    def add_shell(self, where, section, drilling, membrane=None, kinematics="kirchhoff", axis=None,
                  shallow=False) -> PartRef:
        raise ValueError(f"shell '{where}': this quadrilateral mesh was given membranes first, which made it a "
                         "part of membranes alone (bilinear Q4); add its shells before its membranes, so that "
                         "the mesh carries four-node shells and its membranes are the shell's membrane")

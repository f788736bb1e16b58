"""What every part shares: nodes, dofs, supports, prescribed motion, loads, reactions, monitors,
checkpoint state and the reference configuration.

A part model lives on one DOLFINx mesh: the Newton corrections in a vector space
``V`` (one block of ``ndof`` dofs per node), the configuration in ``state``
(``state_size`` values per node: displacements, and rotations where they exist),
and its element forms. Subclasses say how a group of the mesh maps to dof
blocks (:meth:`Part._entities`), what their forms are, and how the state is
updated; everything below is written once here.

Prescribed motion is a :class:`Motion`: a value times the load factor, or times
an amplitude g(λ), or any function of (λ, stage).
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.la
import dolfinx.mesh

from .. import _dolfinx
from ..conditions import Condition
from ..io.mesh import TaggedMesh
from ..result import ElementResults
from .groups import NodeGroup, gather_group
from .surface import Surface, SurfaceError


@dataclass(frozen=True)
class PartRef:
    """Handle to a group of elements added to a model (returned by Scene.add_*)."""

    model: "Part"
    name: str
    kind: str


@dataclass(frozen=True)
class Motion:
    """A prescribed value of one dof: ``value`` × λ, × ``amplitude(λ)``, or ``function(λ, stage)``."""

    value: float = 0.0
    amplitude: object = None
    function: object = None

    def __call__(self, load_factor: float, stage: int | None = None) -> float:
        if self.function is not None:
            return float(self.function(load_factor, stage))
        return self.value * (load_factor if self.amplitude is None else self.amplitude(load_factor))

    @property
    def moves(self) -> bool:
        return self.function is not None or self.value != 0.0


def owned_dofs_of_vertices(V: dolfinx.fem.FunctionSpace, vertices: np.ndarray) -> np.ndarray:
    """Owned block indices (nodes) of V at the given local mesh vertices."""
    blocks = dolfinx.fem.locate_dofs_topological(V, 0, vertices)
    return blocks[blocks < V.dofmap.index_map.size_local]


def global_sum(comm: MPI.Comm, value: np.ndarray) -> np.ndarray:
    """Sum of an array over all ranks."""
    out = np.zeros_like(value)
    comm.Allreduce(np.ascontiguousarray(value), out, op=MPI.SUM)
    return out


def finite_vector(label: str, name: str, value, n: int) -> np.ndarray:
    """``value`` as n finite numbers, or a ValueError naming ``label`` and ``name``."""
    value = np.atleast_1d(np.asarray(value, dtype=float))
    if value.shape != (n,) or not np.all(np.isfinite(value)):
        raise ValueError(f"{label}: {name} must be {n} finite numbers, got {value.tolist()}")
    return value


class AdditiveState:
    """A state that is the dofs themselves (displacements; planar angles): updates add."""

    def update(self, dx: PETSc.Vec) -> None:
        """x ← x + dx (SO(2) rotations compose by adding angles)."""
        self.state.vector.axpy(1.0, dx)
        self.state.x.scatter_forward()

    def extrapolate(self, older: np.ndarray, newer: np.ndarray, factor: float) -> None:
        """x = newer + factor (newer − older)."""
        self.state.x.array[:] = newer + factor * (newer - older)

    def combine(self, states: list[np.ndarray], weights: list[float]) -> None:
        """x = Σ wᵢ xᵢ (weights summing to 1: a polynomial through converged states)."""
        x = self.state.x.array
        x[:] = weights[0] * states[0]
        for w, s in zip(weights[1:], states[1:]):
            x += w * s

    def displacement_vector(self) -> PETSc.Vec:
        return self.state.vector


class Part:
    """Base of every part model (see the module docstring).

    Subclasses set ``gdim``, ``tdim``, ``dof_names``, ``translations``, ``state_size``,
    ``V``, ``state``, ``tmesh``, ``large_rotations`` and call :meth:`_init_conditions`.
    """

    gdim: int
    tdim: int
    dof_names: tuple[str, ...]
    translations: int
    state_size: int
    state = None               # the configuration (a Function; made by each part)
    continuum = False          # a solid (UFL forms) rather than a structure
    coupled = False            # one mesh (Coupled: several)
    multiplicative_rotations = False  # 3D rotations composed multiplicatively (no polynomial predictor)
    _displacement_out = None   # output Functions, made on first use
    _rotation_out = None
    symmetric_tangent = True
    # a tangent that is not symmetric whose skew part vanishes at equilibrium (3D rotations): the
    # system may factorize its symmetric part (symmetrize_tangent; see System.symmetrize)
    symmetric_at_equilibrium = False
    kind_name = "part"
    followers: tuple = ()      # follower loads assembled as a contribution (structures)
    has_follower_loads = False  # follower loads in the part's own forms (solids)
    reads_linear_edges = False  # its elements need the linear membrane edges of the meshes it shares nodes with

    def linear_edges(self) -> np.ndarray | None:
        """Keys (see :meth:`dolfinx_corot.parts.shell.Surface3D.linear_edges`) of the edges of this
        part's cells whose membrane edges are linear; None for parts without membranes. Collective."""
        return None

    def set_foreign_linear_edges(self, keys: np.ndarray | None) -> None:
        """The linear membrane edges of the other meshes that share this one's nodes (read by
        parts whose :attr:`reads_linear_edges`)."""

    def _init_conditions(self) -> None:
        self.ndof = len(self.dof_names)
        self.parts: list[PartRef] = []
        # each support, motion and load with its Condition (whether it exists: staged construction)
        self._bcs: list[tuple[np.ndarray, tuple[int, ...], Condition]] = []
        self._prescribed: list[tuple[tuple[int, np.ndarray], int, Motion, Condition]] = []
        self._prescribed_values: list[tuple[dolfinx.fem.Function, np.ndarray, Motion]] = []
        self._point_loads: list[tuple[np.ndarray, np.ndarray, object, Condition]] = []
        self._mass: dict[tuple[str, str], tuple[float | None, float]] = {}
        self.lifting_bcs: list = []
        self._forms = None
        self.stage: int | None = None
        self.capture_reference()

    @property
    def comm(self):
        return self.V.mesh.comm

    # -- groups → dofs ----------------------------------------------------------------
    def _entities(self, where: str) -> tuple[int, np.ndarray]:
        """(dim, local entities) that locate the dofs of group ``where`` (its vertices by default)."""
        return 0, self.tmesh.vertices(where)

    def dof_blocks(self, where: str) -> np.ndarray:
        """Local blocks (nodes of V, owned and ghost) of group ``where``."""
        return dolfinx.fem.locate_dofs_topological(self.V, *self._entities(where))

    def owned_blocks(self, where: str) -> np.ndarray:
        blocks = self.dof_blocks(where)
        return blocks[blocks < self.V.dofmap.index_map.size_local]

    # -- reference configuration -----------------------------------------------------
    def capture_reference(self) -> None:
        """Take the nodes' current positions as the stress-free reference of the part's elements
        (at creation: the mesh; later, e.g. for a structure added in a deformed configuration)."""
        self.reference = self.V.tabulate_dof_coordinates()[:, : self.gdim].copy()

    # -- supports, prescribed motion, loads ------------------------------------------
    def fix(self, where: str, dofs: tuple[int, ...], condition: Condition | None = None) -> Condition:
        """Support of dofs ``dofs`` at the nodes of ``where``: zero, or where they are when it appears
        (a support a stage adds)."""
        condition = condition or Condition("support", f"'{where}'")
        self._bcs.append((self.dof_blocks(where), tuple(dofs), condition))
        return condition

    def prescribe(self, where: str, comp: int, value: float, amplitude=None, function=None,
                  condition: Condition | None = None) -> Condition:
        """Prescribed displacement of dof ``comp`` at the nodes of ``where``: ``value``·λ,
        ``value``·amplitude(λ), or ``function(λ, stage)``."""
        condition = condition or Condition("motion", f"'{where}'")
        self._prescribed.append((self._entities(where), comp, Motion(float(value), amplitude, function), condition))
        return condition

    def add_load(self, where: str, values: np.ndarray, amplitude=None, condition: Condition | None = None) -> Condition:
        """Dead nodal load at every node of group ``where``: λ·values, or amplitude(λ)·values."""
        condition = condition or Condition("load", f"'{where}'")
        self._point_loads.append((self.dof_blocks(where), np.asarray(values, dtype=float)[: self.ndof], amplitude,
                                  condition))
        return condition

    def load_conditions(self) -> list[tuple[object, Condition]]:
        """[(amplitude, condition)] of the part's loads (point loads here; distributed ones in
        subclasses)."""
        return [(amp, cond) for *_, amp, cond in self._point_loads]

    @property
    def amplitudes(self) -> list:
        """The distinct amplitudes of the loads (None: proportional to λ)."""
        out = []
        for amp, _ in self.load_conditions():
            if amp is not None and amp not in out:
                out.append(amp)
        return out

    @property
    def has_prescribed_motion(self) -> bool:
        return any(motion.moves for *_, motion, cond in self._prescribed if cond.exists)

    def set_load_factor(self, load_factor: float) -> None:
        """Set the prescribed displacements to their values at λ."""
        for g, dofs, motion in self._prescribed_values:
            g.x.array[dofs] = motion(load_factor, self.stage)

    def start_staging(self, approach: str) -> None:
        """Take part in staged construction (:mod:`dolfinx_corot.staging`): existence per element
        from now on. Parts that cannot be staged yet say so."""
        raise NotImplementedError(f"staged construction: {type(self).__name__} parts are not staged yet, only "
                                  "solids, beams, bars, shells and membranes")

    def is_staged(self) -> bool:
        """Whether the part has existence per element (staged construction)."""
        return False

    def held_blocks(self) -> np.ndarray:
        """Local blocks (owned and ghost) of nodes that no existing element touches (staged
        construction); none by default."""
        return np.zeros(0, dtype=np.int32)

    def touched_blocks(self, cells: np.ndarray) -> np.ndarray:
        """(local blocks, owned and ghost) whether a cell of the local mask ``cells`` on any rank
        touches the node."""
        touched = np.ones(self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts, dtype=bool)
        touched[self._untouched_blocks(np.flatnonzero(cells))] = False
        return touched

    def boundary_blocks(self) -> np.ndarray:
        """(local blocks, owned and ghost) whether the node lies on the mesh's exterior boundary."""
        mesh = self.V.mesh
        fdim = mesh.topology.dim - 1
        mesh.topology.create_connectivity(fdim, mesh.topology.dim)
        facets = dolfinx.mesh.exterior_facet_indices(mesh.topology)
        out = np.zeros(self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts, dtype=bool)
        out[dolfinx.fem.locate_dofs_topological(self.V, fdim, facets)] = True
        return out

    def _untouched_blocks(self, cells: np.ndarray) -> np.ndarray:
        """Local blocks (owned and ghost) that none of the local ``cells`` on any rank touches."""
        dofs = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)
        n_blocks = self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts
        touched = np.zeros(n_blocks, dtype=bool)
        touched[dofs[cells].ravel()] = True
        # a node touched by a cell on another rank only: ask the owners (reverse, sum)
        flag = dolfinx.la.vector(self.V.dofmap.index_map)
        flag.array[:] = touched
        flag.scatter_reverse(dolfinx.la.ScatterMode.add)
        flag.scatter_forward()
        return np.flatnonzero(flag.array[:n_blocks] == 0).astype(np.int32)

    #: a geostatic stage may discard this part's displacements and keep its strains
    #: (:meth:`reset_displacements`; staged solids)
    keeps_strains_without_displacements = False

    def can_reset_displacements(self) -> bool:
        """Whether a geostatic stage may discard this part's displacements now: it keeps its strains
        without them, or it is staged and none of its elements exists yet (nothing to keep)."""
        if self.keeps_strains_without_displacements:
            return True
        return self.is_staged() and not self.comm.allreduce(bool(self.cells_existing().any()), op=MPI.LOR)

    def reset_displacements(self) -> None:
        """Discard the displacements (a staged part none of whose elements exists yet: its nodes
        shared with a solid follow the solid's reset)."""
        if not self.can_reset_displacements():
            raise NotImplementedError(f"{type(self).__name__} parts cannot discard their displacements and keep "
                                      "their strains")
        self._reset_state()

    def _reset_state(self) -> None:
        """Displacements zero (and rotations the identity, where the state holds them)."""
        self.state.x.array[:] = 0.0

    def _fixed_blocks(self) -> np.ndarray:
        """Blocks whose non-translational dofs have no stiffness (fixed); none by default."""
        return np.zeros(0, dtype=np.int32)

    def dirichlet_bcs(self) -> list:
        """Supports (zero), dofs without stiffness (zero) and prescribed displacements (their
        values at λ, see :meth:`set_load_factor`)."""
        zero = PETSc.ScalarType(0.0)
        bcs = []
        holding = []  # dofs of supports added by a stage
        for blocks, comps, cond in self._bcs:
            if not cond.exists:
                continue
            for comp in comps:
                if cond.holds:
                    holding.append((blocks * self.ndof + comp, comp))
                else:
                    bcs.append(_dolfinx.dirichletbc(zero, blocks * self.ndof + comp, self.V, comp))
        free = self._fixed_blocks()
        for comp in range(self.translations, self.ndof):
            bcs.append(_dolfinx.dirichletbc(zero, free * self.ndof + comp, self.V, comp))
        held = self.held_blocks()
        n_held = len(held) if self.comm.size == 1 else self.comm.allreduce(len(held))
        if n_held or holding:  # nodes of no existing element (staged construction):
            # held where they are (the Function is made on every rank: its vector is collective)
            here = dolfinx.fem.Function(self.V)
            with self.displacement_vector().localForm() as x:
                here.x.array[:] = x.array
            if n_held:
                bcs.append(dolfinx.fem.dirichletbc(here, np.sort(held).astype(np.int32)))
            for dofs, comp in holding:  # supports added by a stage: where their nodes are
                Vi, parent = self.V.sub(comp).collapse()
                inside = np.full(len(here.x.array), -1, dtype=np.int32)
                inside[np.asarray(parent)] = np.arange(len(parent), dtype=np.int32)
                g = dolfinx.fem.Function(Vi)
                g.x.array[inside[dofs]] = here.x.array[dofs]
                bcs.append(_dolfinx.dirichletbc(g, [dofs.astype(np.int32), inside[dofs]], self.V, comp))
        self._prescribed_values = []
        self.lifting_bcs = []
        for entities, comp, motion, cond in self._prescribed:
            if not cond.exists:
                continue
            Vi, _ = self.V.sub(comp).collapse()
            g = dolfinx.fem.Function(Vi)
            dofs = dolfinx.fem.locate_dofs_topological((self.V.sub(comp), Vi), *entities)
            bc = _dolfinx.dirichletbc(g, dofs, self.V, comp)
            bcs.append(bc)
            self.lifting_bcs.append(bc)
            self._prescribed_values.append((g, dofs[1], motion))
        return bcs

    def constraint_dofs(self) -> list[tuple[np.ndarray, float, object]]:
        """[(local unrolled dofs of V, value, amplitude)] of the existing supports (value 0; None: held
        where they are, a support a stage added) and prescribed motion (value·λ or
        value·amplitude(λ); a general motion as value 1 and amplitude λ ↦ motion(λ))."""
        out = [(blocks * self.ndof + comp, None if cond.holds else 0.0, None)
               for blocks, comps, cond in self._bcs if cond.exists for comp in comps]
        for entities, comp, motion, cond in self._prescribed:
            if not cond.exists:
                continue
            blocks = dolfinx.fem.locate_dofs_topological(self.V, *entities)
            if motion.function is None:
                out.append((blocks * self.ndof + comp, motion.value, motion.amplitude))
            else:
                out.append((blocks * self.ndof + comp, 1.0, lambda lam, m=motion: m(lam, self.stage)))
        return out

    def external_force(self, b: PETSc.Vec, amplitude=None) -> None:
        """Add the loads with the given amplitude (None: those proportional to λ) at unit factor."""
        self._add_distributed_loads(b, amplitude)
        n_owned = self.V.dofmap.index_map.size_local
        # staged construction: a point load acts once an existing element of the part touches its node
        held = self.held_blocks() if self.is_staged() and self._point_loads else np.zeros(0, dtype=np.int32)
        with b.localForm() as bl:
            arr = bl.array.reshape(-1, self.ndof)
            for blocks, values, amp, cond in self._point_loads:
                if amp is amplitude and cond.exists:
                    blocks = blocks[(blocks < n_owned) & ~np.isin(blocks, held)]
                    arr[blocks, : len(values)] += values

    def _add_distributed_loads(self, b: PETSc.Vec, amplitude) -> None:
        """Tractions and body forces (solids); none by default."""

    # -- read-out -------------------------------------------------------------------
    def translations_of(self, blocks: np.ndarray) -> np.ndarray:
        """(len(blocks), gdim) displacements of the given local blocks."""
        return self.state.x.array.reshape(-1, self.state_size)[blocks, : self.gdim]

    @staticmethod
    def _dof_values(s: np.ndarray) -> np.ndarray:
        """The dof values (displacements, rotation vector) of one node's state."""
        return s

    def displacement_field(self) -> dolfinx.fem.Function:
        """The displacement as a Function with gdim components on the part's mesh (the state
        itself for solids; a P1 copy of the state's translations for structures)."""
        if self.state_size == self.gdim:
            return self.state
        if self._displacement_out is None:
            self._displacement_out = dolfinx.fem.Function(
                _dolfinx.function_space(self.V.mesh, "Lagrange", 1, self.gdim), name="displacement")
        out = self._displacement_out
        out.x.array.reshape(-1, self.gdim)[:] = self.state.x.array.reshape(-1, self.state_size)[:, : self.gdim]
        return out

    def rotation_field(self) -> dolfinx.fem.Function | None:
        """The nodal rotations as a P1 Function (2D: the angle θ_z; 3D: the rotation vector, norm ≤ π),
        or None for parts without rotations."""
        if self.ndof == self.translations:
            return None
        nr = self.ndof - self.translations
        if self._rotation_out is None:
            mesh = self.V.mesh
            space = _dolfinx.function_space(mesh, "Lagrange", 1, nr, scalar=nr == 1)
            self._rotation_out = dolfinx.fem.Function(space, name="rotation")
        self._rotation_out.x.array[:] = self._rotation_values().ravel()
        return self._rotation_out

    def _rotation_values(self) -> np.ndarray:
        """(blocks, ndof − translations) nodal rotations; a state that is the dofs holds them."""
        return self.state.x.array.reshape(-1, self.state_size)[:, self.translations: self.ndof]

    def reaction(self, where: str, values: np.ndarray) -> np.ndarray:
        """Sum over the nodes of ``where`` of an assembled nodal vector given as local array of V (all ranks)."""
        blocks = self.owned_blocks(where)
        local = values.reshape(-1, self.ndof)[blocks].sum(axis=0) if len(blocks) else np.zeros(self.ndof)
        return global_sum(self.comm, np.asarray(local, dtype=float))

    def dof_values(self, blocks: np.ndarray) -> np.ndarray:
        """(len(blocks), ndof) dof values (displacements, rotations as monitored) of local blocks."""
        st = self.state.x.array.reshape(-1, self.state_size)[np.asarray(blocks, dtype=np.int32)]
        return np.array([self._dof_values(s) for s in st], dtype=float).reshape(len(st), self.ndof)

    def node_group(self, where: str) -> NodeGroup:
        """The nodes of group ``where`` (those its supports and loads act on), gathered on every rank
        in a partition-independent order, with the lines of the group (a chain for profiles)."""
        group = gather_group(self, where, self.owned_blocks(where), self._group_lines(where))
        if len(group) == 0:
            raise ValueError(f"group '{where}' has no node")
        return group

    def _group_lines(self, where: str) -> np.ndarray | None:
        """(m, 2) local blocks of the end nodes of the group's lines that this rank adds (the owned
        cells of a group of lines of a mesh of lines; the owned facets of a group of facets that
        are lines), or None: the group is not made of lines."""
        mesh = self.tmesh.mesh
        dim = self.tmesh.groups[where][0]
        if dim != 1 or self.tdim not in (1, 2):
            return None
        if self.tdim == 1:
            entities = self.tmesh.cells(where)
        else:
            entities = self.tmesh.facets(where)
            if entities is None:
                return None
        entities = entities[entities < mesh.topology.index_map(1).size_local]
        tdim = self.tdim
        mesh.topology.create_connectivity(1, 0)
        mesh.topology.create_connectivity(tdim, 0)
        c2v = mesh.topology.connectivity(tdim, 0)
        ncells = len(c2v.offsets) - 1
        nv = len(c2v.array) // max(ncells, 1)
        vertex_block = np.full(mesh.topology.index_map(0).size_local + mesh.topology.index_map(0).num_ghosts, -1,
                               dtype=np.int64)
        if ncells:  # the first dofs of a Lagrange cell are at its vertices, in the cell's vertex order
            vertex_block[c2v.array] = self.V.dofmap.list.array.reshape(ncells, -1)[:, :nv].ravel()
        f2v = mesh.topology.connectivity(1, 0)
        ends = np.array([f2v.links(e) for e in entities], dtype=np.int64).reshape(-1, 2)
        return vertex_block[ends]

    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """(X (n, gdim) initial positions, state (n, state_size)) of all nodes, on every rank."""
        n_owned = self.V.dofmap.index_map.size_local
        X = self.V.tabulate_dof_coordinates()[:n_owned, : self.gdim]
        state = self.state.x.array.reshape(-1, self.state_size)[:n_owned]
        return np.concatenate(self.comm.allgather(X)), np.concatenate(self.comm.allgather(state))

    def _cells_active(self) -> np.ndarray:
        """Local cells (owned and ghost) with elements of this model (all by default)."""
        cmap = self.V.mesh.topology.index_map(self.V.mesh.topology.dim)
        return np.ones(cmap.size_local + cmap.num_ghosts, dtype=bool)

    def cell_shapes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For drawing: (X (cells, vertices, gdim) the initial positions of the vertices of every
        owned cell, u (cells, vertices, gdim) their displacement, exists (cells,) whether the cell
        has an existing element), on every rank, rank by rank. Quadrilateral vertices in the
        order of their outline (hexahedra: each face's)."""
        X, u, exists, _ = self._owned_cell_drawing()
        gather = (lambda a: np.concatenate(self.comm.allgather(a)))
        return gather(X), gather(u), gather(exists)

    def _owned_cell_drawing(self) -> tuple:
        """(X, u, exists, blocks) of the owned cells (see :meth:`cell_shapes`), blocks
        (cells, vertices) their vertices' blocks."""
        mesh = self.V.mesh
        tdim = mesh.topology.dim
        nv = {"interval": 2, "triangle": 3, "quadrilateral": 4, "tetrahedron": 4,
              "hexahedron": 8}[mesh.topology.cell_name()]
        n_owned = mesh.topology.index_map(tdim).size_local
        blocks = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)[:n_owned, :nv]
        if mesh.topology.cell_type == dolfinx.mesh.CellType.quadrilateral:
            blocks = blocks[:, [0, 1, 3, 2]]
        elif mesh.topology.cell_type == dolfinx.mesh.CellType.hexahedron:  # VTK's order: each face's outline
            blocks = blocks[:, [0, 1, 3, 2, 4, 5, 7, 6]]
        X = self.V.tabulate_dof_coordinates()[:, : self.gdim][blocks]
        u = self.state.x.array.reshape(-1, self.state_size)[:, : self.gdim][blocks]
        exists = (self.cells_existing() if self.is_staged() else self._cells_active())[:n_owned]
        return X, u, exists, blocks

    def drawing(self, root: int = 0) -> dict | None:
        """What a picture of the part needs (:mod:`dolfinx_corot.plot`), gathered on rank ``root``
        (None on the other ranks): ``cell`` (the cell name), ``gdim``, ``X`` (cells, vertices, gdim)
        the initial positions of the vertices of every cell, ``u`` their displacements, ``exists``
        (cells,), ``rotation`` (cells, vertices) the magnitude of the nodal rotations (None for a
        part without rotations), ``size`` (cells,) the drawn size of each cell (a beam's radius, a
        shell's thickness; None for solids), ``mises`` (cells,) their von Mises stress (None for
        beams) and ``keys`` (cells, vertices) the vertices' global node numbers. Collective."""
        X, u, exists, blocks = self._owned_cell_drawing()
        rotation = None
        if self.ndof > self.translations:
            values = self._rotation_values()
            rotation = np.linalg.norm(values.reshape(len(values), -1), axis=1)[blocks]
        n_owned = len(X)
        size = self._drawn_sizes(np.arange(n_owned, dtype=np.int32))
        mises = self._drawn_mises(n_owned)
        keys = self.V.dofmap.index_map.local_to_global(blocks.ravel().astype(np.int32)).reshape(blocks.shape)
        parts = self.comm.gather((X, u, exists, rotation, size, mises, keys), root=root)
        if parts is None:
            return None
        join = (lambda k: None if parts[0][k] is None else np.concatenate([p[k] for p in parts]))
        return {"cell": self.V.mesh.topology.cell_name(), "gdim": self.gdim, "X": join(0), "u": join(1),
                "exists": join(2), "rotation": join(3), "size": join(4), "mises": join(5), "keys": join(6),
                "kind": self.kind_name}

    def _drawn_mises(self, n_owned: int) -> np.ndarray | None:
        """(n_owned,) the von Mises stress of the owned cells for pictures (solids: at the centre;
        shells and membranes: the larger of the faces'; 0 where no element exists); None for parts
        without it."""
        components = getattr(self, "section_components", ())
        names = [c for c in ("mises", "mises_top", "mises_bottom") if c in components]
        if not names:
            return None
        local = self.element_results(gather=False)
        out = np.zeros(n_owned)
        out[local.cells] = np.max([local[c].max(axis=1) for c in names], axis=0)
        return out

    # -- element results ------------------------------------------------------------
    def element_results(self, cells: np.ndarray | None = None, label: str = "",
                        gather: bool = True) -> ElementResults:
        """Results per element at the current state (:class:`~dolfinx_corot.result.ElementResults`)
        of the given local cells (None: every cell with an existing element), gathered on every
        rank (collective); gather=False: this rank's owned cells only, by their local index."""
        raise ValueError(f"{self.kind_name} parts have no element results")

    def _result_cells(self, cells: np.ndarray | None) -> np.ndarray:
        """The owned cells among ``cells`` (None: all) that carry an existing element."""
        n_owned = self.V.mesh.topology.index_map(self.tdim).size_local
        active = self._cells_active() & (self.cells_existing() if self.is_staged() else True)
        keep = np.zeros(n_owned, dtype=bool)
        if cells is None:
            keep[:] = True
        else:
            cells = np.asarray(cells, dtype=np.int64)
            keep[cells[cells < n_owned]] = True
        return np.flatnonzero(keep & active[:n_owned]).astype(np.int32)

    def _gather_results(self, kind: str, components, cells: np.ndarray, points: np.ndarray, values: np.ndarray,
                        axes: np.ndarray | None, label: str, gather: bool = True) -> ElementResults:
        """The owned cells' results of every rank, ordered by the cells' input index (gather=False:
        this rank's, by local index)."""
        if not gather:
            return ElementResults(kind, components, cells, points, values, axes, label)
        index = np.asarray(self.V.mesh.topology.original_cell_index, dtype=np.int64)[cells]
        found = self.comm.allgather((index, points, values, axes))
        join = (lambda k: np.concatenate([f[k] for f in found]))
        index = join(0)
        order = np.argsort(index, kind="stable")
        return ElementResults(kind, components, index[order], join(1)[order], join(2)[order],
                              None if axes is None else join(3)[order], label)

    def _drawn_sizes(self, cells: np.ndarray) -> np.ndarray | None:
        """The drawn size of the given owned cells (see :meth:`drawing`); None: none."""
        return None

    def surface(self, where: str, body: str | None = None) -> Surface:
        """The contact surface of group ``where`` (parts that have none refuse); ``body``: the
        region whose face it is, where the group's lines separate two regions of one mesh."""
        raise SurfaceError(f"contact surface '{where}': {self.kind_name} parts in {self.gdim}D are not supported "
                           "as contact surfaces so far (solids, 2D beams, 3D beams as slaves, shells and membranes are)")

    # -- state ----------------------------------------------------------------------
    def checkpoint(self) -> np.ndarray:
        return self.state.x.array.copy()

    def restore(self, cp: np.ndarray) -> None:
        self.state.x.array[:] = cp

    def node_keys(self) -> np.ndarray:
        """Input (gmsh) node number of every local block of V (owned and ghost): nodes of meshes
        with the same ``node_source`` and the same key are one node of a coupled system."""
        mesh = self.V.mesh
        ids = np.empty(self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts, dtype=np.int64)
        geo = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
        ids[self.V.dofmap.list.array] = geo[mesh.geometry.dofmap.array]
        return ids

    def _key_ranks(self) -> np.ndarray:
        """Rank of every local block's (owned and ghost) node key among the keys of all the
        mesh's nodes: a partition-independent numbering 0…n−1 (a mesh of lines read from a gmsh
        model holds only some of its nodes, whose input numbers have gaps)."""
        keys = self.node_keys()
        owned = keys[: self.V.dofmap.index_map.size_local]
        return np.searchsorted(np.unique(np.concatenate(self.comm.allgather(owned))), keys)

    def _global_index(self) -> np.ndarray:
        """Position of each owned block in the partition-independent order of checkpoint files."""
        return self._key_ranks()[: self.V.dofmap.index_map.size_local]

    def to_global(self, local: np.ndarray) -> np.ndarray | None:
        """Gather a local nodal array (blocks, k) to rank 0, in the order of :meth:`_global_index`."""
        n_owned = self.V.dofmap.index_map.size_local
        nblocks = n_owned + self.V.dofmap.index_map.num_ghosts
        local = np.asarray(local).reshape(nblocks, -1)
        ids = self.comm.gather(self._global_index(), root=0)
        vals = self.comm.gather(local[:n_owned], root=0)
        if self.comm.rank != 0:
            return None
        out = np.empty((sum(len(i) for i in ids), local.shape[1]))
        for i, v in zip(ids, vals):
            out[i] = v
        return out

    def from_global(self, values: np.ndarray) -> np.ndarray:
        """Local flat array (owned and ghost blocks) from a node-ordered global (n, k) array."""
        if values.shape[0] != self.V.dofmap.index_map.size_global:
            raise ValueError(f"the checkpoint holds {values.shape[0]} nodes; this model has "
                             f"{self.V.dofmap.index_map.size_global}: it was written for another mesh")
        return values[self._key_ranks()].ravel()

    # -- staged state in checkpoint files --------------------------------------------------
    def staging_arrays(self) -> dict:
        """The state staged construction keeps per element (activation shifts, references) as
        partition-independent arrays on rank 0 (None elsewhere); {} for parts without it.
        Existence itself is rebuilt from the stages at a restart."""
        return {}

    def set_staging_arrays(self, arrays: dict) -> None:
        """Restore :meth:`staging_arrays`' output (every rank holds the arrays)."""

    def _cells_to_global(self, blocks: np.ndarray, values: np.ndarray) -> dict:
        """Per-cell nodal values in a partition-independent order, on rank 0 (``cell_*`` arrays;
        {} elsewhere): ``blocks`` (local cells, n) the local blocks of each cell's nodes,
        ``values`` (local cells, n, k). Cells are ordered by their input index, the nodes of each
        cell by their input number."""
        n_owned = self.V.mesh.topology.index_map(self.tdim).size_local
        cells = np.asarray(self.V.mesh.topology.original_cell_index, dtype=np.int64)[:n_owned]
        keys = self.node_keys()[blocks[:n_owned]]
        order = np.argsort(keys, axis=1)
        keys = np.take_along_axis(keys, order, axis=1)
        values = np.take_along_axis(np.asarray(values)[:n_owned], order[:, :, None], axis=1)
        found = self.comm.gather((cells, keys, values), root=0)
        if self.comm.rank != 0:
            return {}
        cells, keys, values = (np.concatenate(a) for a in zip(*found))
        first = np.argsort(cells)
        return {"cell_cells": cells[first], "cell_nodes": keys[first], "cell_values": values[first]}

    def _cells_from_global(self, blocks: np.ndarray, arrays: dict) -> np.ndarray:
        """The per-cell nodal values of :meth:`_cells_to_global` (in ``arrays``) for the local
        cells (owned and ghost) whose nodes are ``blocks``, (local cells, n, k); a file of another
        mesh is refused."""
        saved = {k[len("cell_"):]: v for k, v in arrays.items() if k.startswith("cell_")}
        label = f"staged {self.kind_name} part '{self.parts[0].name if self.parts else ''}'"
        cells = np.asarray(self.V.mesh.topology.original_cell_index, dtype=np.int64)[: len(blocks)]
        pos = np.searchsorted(saved["cells"], cells)
        keys = self.node_keys()[blocks]
        order = np.argsort(keys, axis=1)
        ok = len(saved["cells"]) == self.V.mesh.topology.index_map(self.tdim).size_global and \
            np.all(pos < len(saved["cells"]))
        if ok:
            ok = np.array_equal(saved["cells"][pos], cells) and \
                np.array_equal(saved["nodes"][pos], np.take_along_axis(keys, order, axis=1))
        if not self.comm.allreduce(bool(ok), op=MPI.LAND):
            raise ValueError(f"{label}: the checkpoint's cells are not those of this mesh")
        out = np.empty((len(blocks),) + saved["values"].shape[1:])
        np.put_along_axis(out, order[:, :, None], saved["values"][pos], axis=1)
        return out

    # -- description ------------------------------------------------------------------
    def _geometry_hash(self) -> str:
        """SHA-256 of the mesh's node coordinates in input order (the same for any partition)."""
        geo = self.V.mesh.geometry
        ids = np.asarray(geo.input_global_indices, dtype=np.int64)
        nodes = self.comm.gather((ids, geo.x[: len(ids), : self.gdim]), root=0)
        digest = None
        if self.comm.rank == 0:
            allids = np.concatenate([i for i, _ in nodes])
            allx = np.concatenate([x for _, x in nodes])
            order = np.unique(allids, return_index=True)[1]
            digest = hashlib.sha256(np.ascontiguousarray(allx[order]).tobytes()).hexdigest()
        return self.comm.bcast(digest, root=0)

    def _materials(self) -> list:
        """What the part's elements are made of (for the fingerprint); subclasses add to it."""
        return [(p.kind, p.name) for p in self.parts]

    def describe(self) -> dict:
        """What defines the part: kind, mesh sizes and geometry, groups, elements and materials."""
        imap = self.V.dofmap.index_map
        cells = self.tmesh.mesh.topology.index_map(self.tdim).size_global
        return {"kind": type(self).__name__, "gdim": self.gdim, "nodes": imap.size_global, "cells": cells,
                "geometry": self._geometry_hash(), "groups": sorted(self.tmesh.groups),
                "elements": self._materials(), "large_rotations": self.large_rotations}

    # -- building (scene-facing); parts that cannot carry an element kind refuse it ---------
    def _refuse_kind(self, kind: str, where, need: str, hint: str = "") -> None:
        cell = self.tmesh.mesh.topology.cell_name()
        raise ValueError(f"{kind} '{where}': {need}; this mesh has {cell}s in {self.gdim}D{hint}")

    def add_beam(self, where, section, material, kinematics, orientation, plane_strain=False) -> PartRef:
        self._refuse_kind("beam", where, "beams need a mesh of lines", " (for beams on shells read the lines "
                          "as a mesh of their own: from_gmsh(model, 3, dim=1))")

    def add_truss(self, where, area, material, prestress_force) -> PartRef:
        self._refuse_kind("truss", where, "bars need a mesh of lines")

    def add_shell(self, where, section, drilling, membrane=None, kinematics="kirchhoff", axis=None,
                  shallow=False) -> PartRef:
        self._refuse_kind("shell", where, "shells need a triangle or quadrilateral mesh in 3D "
                          "(from_gmsh(model, gdim=3))")

    def add_membrane(self, where, section, axis=None) -> PartRef:
        self._refuse_kind("membrane", where, "membranes need a triangle or quadrilateral mesh in 3D "
                          "(from_gmsh(model, gdim=3))")

    def add_line_load(self, part: PartRef, where, q, axes, follower, amplitude=None, condition=None) -> Condition:
        self._refuse_kind("load per length on", where, "it acts on beams, bars and the edges of shells and membranes")

    def add_pressure(self, part: PartRef, where, p, follower, amplitude=None, condition=None) -> Condition:
        self._refuse_kind("pressure on", where, "it acts on shells, membranes and the faces of solids")

    def set_follower_factor(self, load_factor: float) -> None:
        """The load factor of the residual about to be assembled (follower loads in the part's forms)."""

    def follower_form(self):
        """The linear form of the part's own follower loads at the current configuration (external
        forces, assembled with the loads), or None."""
        return None

    def add_traction(self, where: str, traction: np.ndarray, amplitude=None, condition=None) -> Condition:
        raise ValueError(f"load '{where}': tractions act on solids; structures take forces and moments")

    def set_mass(self, part: PartRef, density: float | None, measure: float) -> None:
        """The density ρ of the material of ``part`` (None: not given) and the measure of its
        cross-section that makes ρ a mass per element size: the area A of beams and bars (mass
        per unit length), the thickness t of shells and membranes (mass per unit area)."""
        self._mass[(part.kind, part.name)] = (density, float(measure))

    def add_gravity(self, part: PartRef, acceleration: np.ndarray, density: float | None, where: str | None,
                    amplitude=None, condition: Condition | None = None) -> Condition:
        """Self-weight of ``part`` under the gravitational acceleration g (gdim,), dead and scaled
        like the other loads; ``density`` None: the material's."""
        raise NotImplementedError(f"gravity on {part.kind} '{part.name}': not available for {self.kind_name} parts")

    def load_values(self, where: str, force, moment) -> np.ndarray:
        """The nodal load vector of a force and a moment (checked), in the part's dof order."""
        raise NotImplementedError

    def effect(self) -> str:
        """What the part assembles, in words (Scene.effects)."""
        return self.kind_name

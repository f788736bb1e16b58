"""Structural models on DOLFINx meshes.

:class:`Frame2D` holds the beams and bars that live on one 1D mesh in the
plane: one space with (u_x, u_y, θ_z) per node, the configuration as a
DOLFINx Function (displacements and *total* nodal angles), per-cell section
properties as a DG0 Function, and the element kernels of
:mod:`dolfinx_corot.kernels.line2d` wrapped as DOLFINx forms.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.la

from . import assembly
from .elements import line2d as law
from .io.mesh import TaggedMesh
from .kernels import line2d as kernels


@dataclass(frozen=True)
class PartRef:
    """Handle to a group of elements added to a model (returned by Scene.add_*)."""

    model: "Frame2D"
    name: str
    kind: str


class Frame2D:
    """Beams and bars on one 1D mesh with gdim = 2; dofs (ux, uy, rz) per node."""

    dof_names = ("ux", "uy", "rz")

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        mesh = tmesh.mesh
        if mesh.topology.dim != 1 or mesh.geometry.dim != 2:
            raise ValueError(f"a 2D frame needs a mesh of lines in the plane (tdim 1, gdim 2); got "
                             f"tdim {mesh.topology.dim}, gdim {mesh.geometry.dim}: read the gmsh model "
                             "with from_gmsh(model, gdim=2)")
        self.tmesh = tmesh
        self.large_rotations = bool(large_rotations)
        self.V = dolfinx.fem.VectorFunctionSpace(mesh, ("Lagrange", 1), dim=3)
        self.state = dolfinx.fem.Function(self.V, name="state")
        Q = dolfinx.fem.VectorFunctionSpace(mesh, ("DG", 0), dim=law.NPROPS)
        self.props = dolfinx.fem.Function(Q, name="section")
        self._prop_blocks = Q.dofmap.list.array  # DG0: one block per cell
        cmap = mesh.topology.index_map(1)
        self._owner_of_cell = np.full(cmap.size_local + cmap.num_ghosts, "", dtype=object)
        self._bending = np.zeros(cmap.size_local + cmap.num_ghosts, dtype=bool)
        self.parts: list[PartRef] = []
        self._bcs: list[tuple[np.ndarray, tuple[int, ...]]] = []
        self._loads: list[tuple[np.ndarray, np.ndarray]] = []
        self._prescribed: list[tuple[np.ndarray, int, float]] = []
        self._prescribed_values: list[tuple[dolfinx.fem.Function, np.ndarray, float]] = []
        self._forms = None

    # -- building -----------------------------------------------------------
    def add_elements(self, where: str | None, EA: float, EI: float, GAs: float, N0: float, kind: str) -> PartRef:
        label = f"{kind} '{where or 'all cells'}'"
        law.check_props(EA, EI, GAs, label)
        cells = self.tmesh.cells(where)
        taken = self._owner_of_cell[cells]
        clash = taken[taken != ""]
        if len(clash):
            raise ValueError(f"{label}: its cells already belong to {clash[0]}")
        self._check_lengths(cells, label)
        self._owner_of_cell[cells] = label
        self._bending[cells] = EI > 0.0
        values = self.props.x.array.reshape(-1, law.NPROPS)
        values[self._prop_blocks[cells]] = (EA, EI, GAs, N0)
        self.props.x.scatter_forward()
        ref = PartRef(self, where or "", kind)
        self.parts.append(ref)
        self._forms = None
        return ref

    def _check_lengths(self, cells: np.ndarray, label: str) -> None:
        x = self.tmesh.mesh.geometry.x
        gdofs = self.tmesh.mesh.geometry.dofmap.array.reshape(-1, 2)[cells]
        lengths = np.linalg.norm(x[gdofs[:, 1]] - x[gdofs[:, 0]], axis=1)
        scale = max(float(np.ptp(x, axis=0).max()), 1e-300)
        bad = np.flatnonzero(lengths <= 1e-10 * scale)
        if len(bad):
            p = x[gdofs[bad[0], 0]]
            raise ValueError(f"{label}: {len(bad)} element(s) of zero length, the first at "
                             f"({p[0]:.6g}, {p[1]:.6g})")

    def fix(self, where: str, dofs: tuple[int, ...]) -> None:
        self._bcs.append((self.tmesh.vertices(where), dofs))

    def prescribe(self, where: str, comp: int, value: float) -> None:
        """Prescribed displacement ``value``·λ of dof ``comp`` at the nodes of ``where``."""
        self._prescribed.append((self.tmesh.vertices(where), comp, float(value)))

    def add_load(self, where: str, values: np.ndarray) -> None:
        """Nodal load (fx, fy, mz) at every node of group ``where`` (scaled by the load factor)."""
        self._loads.append((self.tmesh.vertices(where), np.asarray(values, dtype=float)))

    # -- Model protocol (assembly.System) ------------------------------------
    def forms(self):
        if self._forms is None:
            cmap = self.tmesh.mesh.topology.index_map(1)
            owned = np.flatnonzero(self._owner_of_cell[: cmap.size_local] != "").astype(np.int32)
            all_owned = self.V.mesh.comm.allreduce(len(owned) == cmap.size_local)
            cells = None if all_owned else owned
            self._flag = dolfinx.fem.Constant(self.V.mesh, PETSc.ScalarType(1.0 if self.large_rotations else 0.0))
            coeffs = [self.state, self.props]
            L = assembly.kernel_form(self.V, kernels.vector_kernel.address, 1, coeffs, [self._flag], cells)
            a = assembly.kernel_form(self.V, kernels.matrix_kernel.address, 2, coeffs, [self._flag], cells)
            self._forms = (L, a)
        return self._forms

    def dirichlet_bcs(self) -> list:
        """Supports (zero) and prescribed displacements (λ-scaled values, see :meth:`set_load_factor`)."""
        zero = PETSc.ScalarType(0.0)
        bcs = []
        for vertices, comps in self._bcs + [(self._rotation_free_vertices(), (2,))]:
            for comp in comps:
                dofs = dolfinx.fem.locate_dofs_topological(self.V.sub(comp), 0, vertices)
                bcs.append(dolfinx.fem.dirichletbc(zero, dofs, self.V.sub(comp)))
        self._prescribed_values = []
        for vertices, comp, value in self._prescribed:
            Vi, _ = self.V.sub(comp).collapse()
            g = dolfinx.fem.Function(Vi)
            dofs = dolfinx.fem.locate_dofs_topological((self.V.sub(comp), Vi), 0, vertices)
            bcs.append(dolfinx.fem.dirichletbc(g, dofs, self.V.sub(comp)))
            self._prescribed_values.append((g, dofs[1], value))
        return bcs

    @property
    def has_prescribed_motion(self) -> bool:
        return any(value != 0.0 for _, _, value in self._prescribed)

    def set_load_factor(self, load_factor: float) -> None:
        """Set the prescribed displacements to λ times their values."""
        for g, dofs, value in self._prescribed_values:
            g.x.array[dofs] = load_factor * value

    def reaction(self, where: str, fint: PETSc.Vec) -> np.ndarray:
        """Sum over the nodes of ``where`` of the assembled internal force (fx, fy, mz) (all ranks)."""
        blocks = assembly.owned_dofs_of_vertices(self.V, self.tmesh.vertices(where))
        with fint.localForm() as f:
            local = f.array.reshape(-1, 3)[blocks].sum(axis=0) if len(blocks) else np.zeros(3)
        return assembly.global_sum(self.V.mesh.comm, np.asarray(local, dtype=float))

    def _rotation_free_vertices(self) -> np.ndarray:
        """Vertices touched by no bending element: their rotation has no stiffness and is fixed."""
        mesh = self.tmesh.mesh
        mesh.topology.create_connectivity(0, 1)
        v2c = mesh.topology.connectivity(0, 1)
        vmap = mesh.topology.index_map(0)
        nv = vmap.size_local + vmap.num_ghosts
        counts = np.add.reduceat(self._bending[v2c.array].astype(np.int32), v2c.offsets[:-1][:nv])
        bending = counts > 0
        # a vertex may see its bending cell only on another rank: reduce over owners
        flag = dolfinx.fem.Function(dolfinx.fem.FunctionSpace(mesh, ("Lagrange", 1)))
        vert_to_dof = dolfinx.fem.locate_dofs_topological(flag.function_space, 0, np.arange(nv, dtype=np.int32))
        flag.x.array[vert_to_dof] = bending.astype(float)
        flag.x.scatter_reverse(dolfinx.la.ScatterMode.add)
        flag.x.scatter_forward()
        return np.flatnonzero(flag.x.array[vert_to_dof] == 0.0).astype(np.int32)

    def external_force(self, b: PETSc.Vec) -> None:
        n_owned = self.V.dofmap.index_map.size_local
        with b.localForm() as bl:
            arr = bl.array.reshape(-1, 3)
            for vertices, values in self._loads:
                blocks = assembly.owned_dofs_of_vertices(self.V, vertices)
                arr[blocks[blocks < n_owned]] += values

    def update(self, dx: PETSc.Vec) -> None:
        """Displacements add; planar rotations compose, which for SO(2) is exact addition of angles."""
        self.state.vector.axpy(1.0, dx)
        self.state.x.scatter_forward()

    def extrapolate(self, older: np.ndarray, newer: np.ndarray, factor: float) -> None:
        """x = newer + factor (newer − older): angles of SO(2) extrapolate linearly."""
        self.state.x.array[:] = newer + factor * (newer - older)

    def checkpoint(self) -> np.ndarray:
        return self.state.x.array.copy()

    def restore(self, cp: np.ndarray) -> None:
        self.state.x.array[:] = cp

    # -- restart: node-ordered global arrays ------------------------------------
    def _input_ids(self) -> np.ndarray:
        """Input (gmsh) node number of every local block of V (owned and ghost)."""
        mesh = self.V.mesh
        ids = np.empty(self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts, dtype=np.int64)
        geo = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
        ids[self.V.dofmap.list.array] = geo[mesh.geometry.dofmap.array]
        return ids

    def to_global(self, local: np.ndarray) -> np.ndarray | None:
        """Gather a local (blocks, 3) array to rank 0, ordered by input node number (None elsewhere)."""
        n_owned = self.V.dofmap.index_map.size_local
        comm = self.V.mesh.comm
        ids = comm.gather(self._input_ids()[:n_owned], root=0)
        vals = comm.gather(np.asarray(local).reshape(-1, 3)[:n_owned], root=0)
        if comm.rank != 0:
            return None
        out = np.empty((sum(len(i) for i in ids), 3))
        for i, v in zip(ids, vals):
            out[i] = v
        return out

    def from_global(self, values: np.ndarray) -> np.ndarray:
        """Local (blocks·3,) array (owned and ghost) from a node-ordered global (n, 3) array."""
        ids = self._input_ids()
        if values.shape != (self.V.dofmap.index_map.size_global, 3):
            raise ValueError(f"the checkpoint holds {values.shape[0]} nodes; this model has "
                             f"{self.V.dofmap.index_map.size_global}: it was written for another mesh")
        return values[ids].ravel()

    # -- read-out -------------------------------------------------------------
    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """(X (n, 2) initial positions, state (n, 3) = ux, uy, rz) of all nodes, on every rank."""
        n_owned = self.V.dofmap.index_map.size_local
        X = self.V.tabulate_dof_coordinates()[:n_owned, :2]
        state = self.state.x.array.reshape(-1, 3)[:n_owned]
        comm = self.V.mesh.comm
        return np.concatenate(comm.allgather(X)), np.concatenate(comm.allgather(state))

    def nodal_values(self, where: str) -> np.ndarray:
        """(ux, uy, rz) of the first node of group ``where``, identical on every rank."""
        blocks = assembly.owned_dofs_of_vertices(self.V, self.tmesh.vertices(where))
        comm = self.V.mesh.comm
        local = np.zeros(4)
        if len(blocks):
            local[:3] = self.state.x.array.reshape(-1, 3)[blocks[0]]
            local[3] = 1.0
        # the group's first node is owned by exactly one rank; take the lowest such rank
        owners = comm.allgather(local)
        for v in owners:
            if v[3] == 1.0:
                return v[:3].copy()
        raise ValueError(f"group '{where}' has no node")

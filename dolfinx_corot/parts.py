"""Structural models on DOLFINx meshes.

A model holds the beams and bars that live on one 1D mesh: the space of the
Newton corrections (one block of dofs per node), the configuration as a
DOLFINx Function, per-cell section properties as a DG0 Function, and the
element kernels wrapped as DOLFINx forms.

* :class:`Frame2D` (gdim 2): dofs (u_x, u_y, θ_z); the state holds the
  displacements and the *total* nodal angles (SO(2) updates are additions).
* :class:`Frame3D` (gdim 3): dofs (u_x, u_y, u_z, w_x, w_y, w_z), w spatial
  spins; the state holds the displacements and a unit quaternion per node,
  updated multiplicatively, q ← exp(w)∘q.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
from mpi4py import MPI
import numpy as np
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.la

from . import assembly, rotations
from .elements import beam3d as law3d
from .elements import line2d as law2d
from .elements import shell_triangle as shell_law
from .io.mesh import TaggedMesh
from .kernels import beam3d as kernels3d
from .kernels import line2d as kernels2d
from .kernels import membrane_quad as kernels_mq
from .kernels import shell3d as kernels_shell
from .elements import membrane_quad as quad_law


@dataclass(frozen=True)
class PartRef:
    """Handle to a group of elements added to a model (returned by Scene.add_*)."""

    model: "LineFrame"
    name: str
    kind: str


class PrescribedMotion:
    """Prescribed displacements scaled by λ or amplitude(λ), shared by structures and solids:
    ``_prescribed`` holds (where, comp, value, amplitude), ``_prescribed_values`` the BC
    functions (g, dofs, value, amplitude) made by ``dirichlet_bcs``."""

    _prescribed: list
    _prescribed_values: list

    @property
    def has_prescribed_motion(self) -> bool:
        return any(value != 0.0 for _, _, value, _ in self._prescribed)

    def set_load_factor(self, load_factor: float) -> None:
        """Set the prescribed displacements to λ (or amplitude(λ)) times their values."""
        for g, dofs, value, amplitude in self._prescribed_values:
            g.x.array[dofs] = (load_factor if amplitude is None else amplitude(load_factor)) * value


class LineFrame(PrescribedMotion):
    """What 2D and 3D frames and shells share: cells, properties, supports, loads, forms, read-out."""

    tdim = 1
    nodes_per_cell = 2
    gdim: int
    dof_names: tuple[str, ...]
    translations: int           # number of translational dofs per node
    state_size: int             # entries of the nodal state
    nprops: int
    kernels = None

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        mesh = tmesh.mesh
        if mesh.topology.dim != self.tdim or mesh.geometry.dim != self.gdim:
            raise ValueError(f"{type(self).__name__} needs a mesh of tdim {self.tdim} in gdim {self.gdim}; got "
                             f"tdim {mesh.topology.dim}, gdim {mesh.geometry.dim}: read the gmsh model "
                             f"with from_gmsh(model, gdim={self.gdim})")
        self.tmesh = tmesh
        self.large_rotations = bool(large_rotations)
        self.ndof = len(self.dof_names)
        self.V = dolfinx.fem.VectorFunctionSpace(mesh, ("Lagrange", 1), dim=self.ndof)
        Q = dolfinx.fem.VectorFunctionSpace(mesh, ("DG", 0), dim=self.nprops)
        self.props = dolfinx.fem.Function(Q, name="section")
        self._prop_blocks = Q.dofmap.list.array  # DG0: one block per cell
        cmap = mesh.topology.index_map(self.tdim)
        self._owner_of_cell = np.full(cmap.size_local + cmap.num_ghosts, "", dtype=object)
        self._bending = np.zeros(cmap.size_local + cmap.num_ghosts, dtype=bool)
        self.parts: list[PartRef] = []
        self._bcs: list[tuple[np.ndarray, tuple[int, ...]]] = []
        self._loads: list[tuple[np.ndarray, np.ndarray, object]] = []
        self._prescribed: list[tuple[np.ndarray, int, float, object]] = []
        self._prescribed_values: list[tuple[dolfinx.fem.Function, np.ndarray, float, object]] = []
        self._forms = None

    @property
    def comm(self):
        return self.V.mesh.comm

    # -- building -----------------------------------------------------------
    def add_elements(self, where: str | None, props: np.ndarray, bending: bool, kind: str) -> PartRef:
        label = f"{kind} '{where or 'all cells'}'"
        cells = self.tmesh.cells(where)
        taken = self._owner_of_cell[cells]
        clash = taken[taken != ""]
        if len(clash):
            raise ValueError(f"{label}: its cells already belong to {clash[0]}")
        self._check_geometry(cells, label, props)
        self._owner_of_cell[cells] = label
        self._bending[cells] = bending
        values = self.props.x.array.reshape(-1, self.nprops)
        values[self._prop_blocks[cells]] = props
        self.props.x.scatter_forward()
        ref = PartRef(self, where or "", kind)
        self.parts.append(ref)
        self._forms = None
        return ref

    def _element_vectors(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = self.tmesh.mesh.geometry.x
        gdofs = self.tmesh.mesh.geometry.dofmap.array.reshape(-1, 2)[cells]
        return x[gdofs[:, 0]], x[gdofs[:, 1]] - x[gdofs[:, 0]]

    def _refuse(self, cells: np.ndarray, bad: np.ndarray, points: np.ndarray, message: str) -> None:
        """Raise ValueError(message) on every rank if any rank found bad cells.

        cells: the local cells checked; bad: indices into cells of the bad ones;
        points: (len(cells), ≥gdim) a point of each cell for the message, which
        may use {n} (number of bad cells, owned ones counted once) and {at}.
        """
        owned = cells[bad] < self.tmesh.mesh.topology.index_map(self.tdim).size_local
        first = points[bad[0], : self.gdim].tolist() if len(bad) else None
        found = self.comm.allgather((int(np.sum(owned)), first))
        total = sum(n for n, _ in found)
        if total or any(f is not None for _, f in found):
            at = next(f for _, f in found if f is not None)
            raise ValueError(message.format(n=max(total, 1), at="(" + ", ".join(f"{c:.6g}" for c in at) + ")"))

    def _check_geometry(self, cells: np.ndarray, label: str, props: np.ndarray) -> None:
        start, d = self._element_vectors(cells)
        lengths = np.linalg.norm(d, axis=1)
        x = self.tmesh.mesh.geometry.x
        scale = max(float(np.ptp(x, axis=0).max()) if len(x) else 1.0, 1e-300)
        bad = np.flatnonzero(lengths <= 1e-10 * scale)
        self._refuse(cells, bad, start, f"{label}: {{n}} element(s) of zero length, the first at {{at}}")

    def fix(self, where: str, dofs: tuple[int, ...]) -> None:
        self._bcs.append((self.tmesh.vertices(where), dofs))

    def prescribe(self, where: str, comp: int, value: float, amplitude=None) -> None:
        """Prescribed displacement ``value``·λ (or ·amplitude(λ)) of dof ``comp`` at the nodes of ``where``."""
        if comp >= self.translations and self.gdim == 3 and value != 0.0:
            raise NotImplementedError(f"prescribe '{where}': non-zero rotations ({self.dof_names[comp]}) "
                                      "cannot be prescribed in 3D; prescribe displacements or apply a moment")
        self._prescribed.append((self.tmesh.vertices(where), comp, float(value), amplitude))

    def add_load(self, where: str, values: np.ndarray, amplitude=None) -> None:
        """Nodal load (forces, moments) at every node of group ``where``: λ·values, or amplitude(λ)·values."""
        self._loads.append((self.tmesh.vertices(where), np.asarray(values, dtype=float), amplitude))

    @property
    def amplitudes(self) -> list:
        """The distinct amplitudes of the loads (None: proportional to λ)."""
        out = []
        for _, _, amp in self._loads:
            if amp is not None and amp not in out:
                out.append(amp)
        return out

    # -- Model protocol (assembly.System) ------------------------------------
    symmetric_tangent = True

    def forms(self):
        if self._forms is None:
            cmap = self.tmesh.mesh.topology.index_map(self.tdim)
            owned = np.flatnonzero(self._owner_of_cell[: cmap.size_local] != "").astype(np.int32)
            all_owned = self.V.mesh.comm.allreduce(bool(len(owned) == cmap.size_local), op=MPI.LAND)
            cells = None if all_owned else owned
            self._flag = dolfinx.fem.Constant(self.V.mesh, PETSc.ScalarType(1.0 if self.large_rotations else 0.0))
            coeffs = [self.state, self.props, *self._element_constants()]
            L = assembly.kernel_form(self.V, self.kernels.vector_kernel.address, 1, coeffs, [self._flag], cells)
            a = assembly.kernel_form(self.V, self.kernels.matrix_kernel.address, 2, coeffs, [self._flag], cells)
            self._forms = (L, a)
        return self._forms

    def _element_constants(self) -> list:
        """Extra per-cell coefficients the kernels read after the properties (none by default)."""
        return []

    def dirichlet_bcs(self) -> list:
        """Supports (zero) and prescribed displacements (λ-scaled values, see :meth:`set_load_factor`)."""
        zero = PETSc.ScalarType(0.0)
        bcs = []
        for vertices, comps in self._bcs:
            for comp in comps:
                dofs = dolfinx.fem.locate_dofs_topological(self.V.sub(comp), 0, vertices)
                bcs.append(dolfinx.fem.dirichletbc(zero, dofs, self.V.sub(comp)))
        free = self._rotation_free_blocks()
        for comp in range(self.translations, self.ndof):
            bcs.append(dolfinx.fem.dirichletbc(zero, free * self.ndof + comp, self.V.sub(comp)))
        self._prescribed_values = []
        for vertices, comp, value, amplitude in self._prescribed:
            Vi, _ = self.V.sub(comp).collapse()
            g = dolfinx.fem.Function(Vi)
            dofs = dolfinx.fem.locate_dofs_topological((self.V.sub(comp), Vi), 0, vertices)
            bcs.append(dolfinx.fem.dirichletbc(g, dofs, self.V.sub(comp)))
            self._prescribed_values.append((g, dofs[1], value, amplitude))
        self.lifting_bcs = bcs[len(bcs) - len(self._prescribed):]
        return bcs

    def bending_blocks(self) -> np.ndarray:
        """Local blocks (owned and ghost) that a bending element on this rank touches."""
        nblocks = self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts
        flags = np.zeros(nblocks, dtype=bool)
        dofs = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)
        flags[dofs[self._bending[: len(dofs)]].ravel()] = True
        return flags

    def _rotation_free_blocks(self) -> np.ndarray:
        """Blocks touched by no bending element (on any rank): their rotation has no stiffness."""
        flag = dolfinx.fem.Function(self.V)
        flag.x.array.reshape(-1, self.ndof)[:, 0] = self.bending_blocks()
        flag.x.scatter_reverse(dolfinx.la.ScatterMode.add)
        flag.x.scatter_forward()
        return np.flatnonzero(flag.x.array.reshape(-1, self.ndof)[:, 0] == 0.0).astype(np.int32)

    def constraint_dofs(self) -> list[tuple[np.ndarray, float, object]]:
        """[(local unrolled dofs of V, value, amplitude)]: supports (value 0) and prescribed motion
        (value·λ or value·amplitude(λ)); rotations without stiffness are not included."""
        out = []
        for vertices, comps in self._bcs:
            blocks = dolfinx.fem.locate_dofs_topological(self.V, 0, vertices)
            for comp in comps:
                out.append((blocks * self.ndof + comp, 0.0, None))
        for vertices, comp, value, amplitude in self._prescribed:
            blocks = dolfinx.fem.locate_dofs_topological(self.V, 0, vertices)
            out.append((blocks * self.ndof + comp, value, amplitude))
        return out

    def external_force(self, b: PETSc.Vec, amplitude=None) -> None:
        """Add the loads with the given amplitude (None: those proportional to λ) at unit factor."""
        n_owned = self.V.dofmap.index_map.size_local
        with b.localForm() as bl:
            arr = bl.array.reshape(-1, self.ndof)
            for vertices, values, amp in self._loads:
                if amp is not amplitude:
                    continue
                blocks = assembly.owned_dofs_of_vertices(self.V, vertices)
                arr[blocks[blocks < n_owned]] += values

    def reaction(self, where: str, values: np.ndarray) -> np.ndarray:
        """Sum over the nodes of ``where`` of an assembled nodal vector given as local array of V (all ranks)."""
        blocks = assembly.owned_dofs_of_vertices(self.V, self.tmesh.vertices(where))
        local = values.reshape(-1, self.ndof)[blocks].sum(axis=0) if len(blocks) else np.zeros(self.ndof)
        return assembly.global_sum(self.V.mesh.comm, np.asarray(local, dtype=float))

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
        """Gather a local nodal array (blocks, k) to rank 0, ordered by input node number."""
        n_owned = self.V.dofmap.index_map.size_local
        nblocks = n_owned + self.V.dofmap.index_map.num_ghosts
        comm = self.V.mesh.comm
        local = np.asarray(local).reshape(nblocks, -1)
        ids = comm.gather(self._input_ids()[:n_owned], root=0)
        vals = comm.gather(local[:n_owned], root=0)
        if comm.rank != 0:
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
        return values[self._input_ids()].ravel()

    # -- read-out -------------------------------------------------------------
    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """(X (n, gdim) initial positions, state (n, state_size)) of all nodes, on every rank."""
        n_owned = self.V.dofmap.index_map.size_local
        X = self.V.tabulate_dof_coordinates()[:n_owned, : self.gdim]
        state = self.state.x.array.reshape(-1, self.state_size)[:n_owned]
        comm = self.V.mesh.comm
        return np.concatenate(comm.allgather(X)), np.concatenate(comm.allgather(state))

    def nodal_values(self, where: str) -> np.ndarray:
        """Values of the dofs of the first node of group ``where``, identical on every rank."""
        blocks = assembly.owned_dofs_of_vertices(self.V, self.tmesh.vertices(where))
        comm = self.V.mesh.comm
        local = np.zeros(self.ndof + 1)
        if len(blocks):
            local[: self.ndof] = self._dof_values(self.state.x.array.reshape(-1, self.state_size)[blocks[0]])
            local[self.ndof] = 1.0
        for v in comm.allgather(local):
            if v[self.ndof] == 1.0:
                return v[: self.ndof].copy()
        raise ValueError(f"group '{where}' has no node")


class Frame2D(LineFrame):
    """Beams and bars on one 1D mesh with gdim = 2; dofs (ux, uy, rz) per node."""

    gdim = 2
    dof_names = ("ux", "uy", "rz")
    translations = 2
    state_size = 3
    nprops = law2d.NPROPS
    kernels = kernels2d

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        super().__init__(tmesh, large_rotations)
        self.state = dolfinx.fem.Function(self.V, name="state")  # state and corrections share V

    def add_beam(self, where, EA, EI, GAs, N0, kind):
        law2d.check_props(EA, EI, GAs, f"{kind} '{where}'")
        return self.add_elements(where, np.array([EA, EI, GAs, N0]), EI > 0.0, kind)

    def update(self, dx: PETSc.Vec) -> None:
        """Displacements add; planar rotations compose, which for SO(2) is exact addition of angles."""
        self.state.vector.axpy(1.0, dx)
        self.state.x.scatter_forward()

    def extrapolate(self, older: np.ndarray, newer: np.ndarray, factor: float) -> None:
        """x = newer + factor (newer − older): angles of SO(2) extrapolate linearly."""
        self.state.x.array[:] = newer + factor * (newer - older)

    def displacement_vector(self) -> PETSc.Vec:
        return self.state.vector

    @staticmethod
    def _dof_values(s: np.ndarray) -> np.ndarray:
        return s


@numba.njit(cache=True)
def _update_quaternions(state, dx, n):
    """state (n, 7) ← (u + du, exp(dw)∘q) for the first n nodes; dx (n, 6)."""
    for i in range(n):
        for k in range(3):
            state[i, k] += dx[i, k]
        state[i, 3:7] = rotations.quat_update(state[i, 3:7], dx[i, 3:6].copy())


class Frame3D(LineFrame):
    """Beams and bars on one 1D mesh with gdim = 3; dofs (ux, uy, uz, rx, ry, rz) per node,
    the rotational ones spatial spins composed multiplicatively with the nodal rotations."""

    gdim = 3
    dof_names = ("ux", "uy", "uz", "rx", "ry", "rz")
    translations = 3
    state_size = kernels3d.NSTATE
    nprops = law3d.NPROPS
    kernels = kernels3d
    symmetric_tangent = False  # spatial spins: K is symmetric only at equilibrium under conservative loads

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        super().__init__(tmesh, large_rotations)
        S = dolfinx.fem.VectorFunctionSpace(tmesh.mesh, ("Lagrange", 1), dim=kernels3d.NSTATE)
        self.state = dolfinx.fem.Function(S, name="state")
        self.state.x.array.reshape(-1, kernels3d.NSTATE)[:, 3] = 1.0  # identity rotations
        self._disp = dolfinx.fem.Function(self.V, name="displacement")

    def add_beam(self, where, values: dict, orientation, N0: float, kind: str):
        label = f"{kind} '{where}'"
        law3d.check_props(values, label)
        v = np.asarray(orientation, dtype=float)
        if v.shape != (3,) or not np.all(np.isfinite(v)) or np.linalg.norm(v) == 0.0:
            raise ValueError(f"{label}: orientation must be a non-zero 3-vector, got {orientation}")
        props = np.array([values["EA"], values["GJ"], values["EIy"], values["EIz"], values["GAy"], values["GAz"],
                          N0, *v])
        bending = values["EIy"] > 0.0 or values["EIz"] > 0.0
        return self.add_elements(where, props, bending, kind)

    def _check_geometry(self, cells, label, props):
        super()._check_geometry(cells, label, props)
        _, d = self._element_vectors(cells)
        v = props[-3:]
        c = np.abs(d @ v) / (np.linalg.norm(d, axis=1) * np.linalg.norm(v))
        bad = np.flatnonzero(c > 1.0 - 1e-8)
        start, _ = self._element_vectors(cells)
        self._refuse(cells, bad, start, f"{label}: the orientation vector {v.tolist()} is parallel to {{n}} "
                     "element(s), the first at {at}; choose one that fixes the local y axis")

    def update(self, dx: PETSc.Vec) -> None:
        """u ← u + du; q ← exp(dw)∘q (multiplicative, spatial) on owned nodes; ghosts from their owners."""
        n_owned = self.V.dofmap.index_map.size_local
        st = self.state.x.array.reshape(-1, kernels3d.NSTATE)
        _update_quaternions(st, dx.array_r.reshape(-1, 6), n_owned)
        self.state.x.scatter_forward()

    def extrapolate(self, older, newer, factor):
        raise NotImplementedError("the secant predictor is not available for 3D rotations; "
                                  "use LoadControl(extrapolate=False)")

    def displacement_vector(self) -> PETSc.Vec:
        """Displacements in the layout of the corrections (rotational entries 0), for constraints."""
        arr = self._disp.x.array.reshape(-1, 6)
        arr[:, :3] = self.state.x.array.reshape(-1, kernels3d.NSTATE)[:, :3]
        return self._disp.vector

    @staticmethod
    def _dof_values(s: np.ndarray) -> np.ndarray:
        return np.concatenate([s[:3], rotations.rotvec_from_quat(s[3:7].copy())])


class Surface3D(LineFrame):
    """What shells and quadrilateral membranes share: 6 dofs per node with multiplicative
    rotations as in :class:`Frame3D`, and per-cell constants (initial frame, local coordinates,
    local stiffness) computed once by the kernels' ``element_data_all``."""

    tdim = 2
    gdim = 3
    dof_names = Frame3D.dof_names
    translations = 3
    state_size = kernels3d.NSTATE
    symmetric_tangent = False
    update = Frame3D.update
    extrapolate = Frame3D.extrapolate
    displacement_vector = Frame3D.displacement_vector
    _dof_values = staticmethod(Frame3D._dof_values)

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        super().__init__(tmesh, large_rotations)
        S = dolfinx.fem.VectorFunctionSpace(tmesh.mesh, ("Lagrange", 1), dim=kernels3d.NSTATE)
        self.state = dolfinx.fem.Function(S, name="state")
        self.state.x.array.reshape(-1, kernels3d.NSTATE)[:, 3] = 1.0
        self._disp = dolfinx.fem.Function(self.V, name="displacement")

    def _element_constants(self) -> list:
        """The kernels' per-cell constants of every cell with elements (DG0, computed once)."""
        mesh = self.tmesh.mesh
        n = self.kernels.NEDATA
        Q = dolfinx.fem.VectorFunctionSpace(mesh, ("DG", 0), dim=n)
        edata = dolfinx.fem.Function(Q, name="element_constants")
        X = mesh.geometry.x[mesh.geometry.dofmap.array.reshape(-1, self.nodes_per_cell)]
        props = self.props.x.array.reshape(-1, self.nprops)[self._prop_blocks]
        out = np.zeros((len(X), n))
        self.kernels.element_data_all(X, props, self._owner_of_cell != "", out)
        edata.x.array.reshape(-1, n)[Q.dofmap.list.array] = out
        return [edata]


class Shell3D(Surface3D):
    """Flat co-rotational shell triangles on a triangle mesh in space; dofs (ux, uy, uz, rx, ry, rz)
    per node, rotations multiplicative as in :class:`Frame3D`."""

    nodes_per_cell = 3
    nprops = shell_law.NPROPS
    kernels = kernels_shell

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        if tmesh.mesh.topology.cell_name() != "triangle":
            raise NotImplementedError(f"shells are triangles; the mesh has {tmesh.mesh.topology.cell_name()} "
                                      "cells (set Mesh.RecombineAll = 0 in gmsh)")
        super().__init__(tmesh, large_rotations)

    def add_shell(self, where, E: float, nu: float, thickness: float, drilling: float, membrane: str = "opt"):
        label = f"shell '{where}'"
        if not (thickness > 0.0 and np.isfinite(thickness)):
            raise ValueError(f"{label}: thickness = {thickness} must be positive")
        if not drilling > 0.0:
            raise ValueError(f"{label}: the drilling factor {drilling} must be positive")
        if membrane not in ("opt", "cst"):
            raise ValueError(f"{label}: membrane '{membrane}' is not one of ('opt', 'cst')")
        opt = 1.0 if membrane == "opt" else 0.0
        return self.add_elements(where, np.array([E, nu, thickness, drilling, 1.0, opt]), True, "shell")

    def add_membrane(self, where, E: float, nu: float, thickness: float):
        if not (thickness > 0.0 and np.isfinite(thickness)):
            raise ValueError(f"membrane '{where}': thickness = {thickness} must be positive")
        return self.add_elements(where, np.array([E, nu, thickness, 0.0, 0.0, 0.0]), False, "membrane")

    def _check_geometry(self, cells, label, props):
        x = self.tmesh.mesh.geometry.x
        g = self.tmesh.mesh.geometry.dofmap.array.reshape(-1, 3)[cells]
        area = 0.5 * np.linalg.norm(np.cross(x[g[:, 1]] - x[g[:, 0]], x[g[:, 2]] - x[g[:, 0]]), axis=1)
        scale = max(float(np.ptp(x, axis=0).max()) if len(x) else 1.0, 1e-300)
        bad = np.flatnonzero(area <= 1e-10 * scale**2)
        self._refuse(cells, bad, x[g[:, 0]], f"{label}: {{n}} triangle(s) of zero area, the first at {{at}}")


class MembraneQuad(Surface3D):
    """Four-node co-rotational membranes on a quadrilateral mesh in space; dofs (ux, uy, uz, rx,
    ry, rz) per node like shells (so that they may share nodes with shells and beams), the
    rotations of nodes carried by membranes alone fixed."""

    nodes_per_cell = 4
    nprops = quad_law.NPROPS
    kernels = kernels_mq

    def add_membrane(self, where, E: float, nu: float, thickness: float):
        quad_law.check_props(E, nu, thickness, f"membrane '{where}'")
        return self.add_elements(where, np.array([E, nu, thickness]), False, "membrane")

    def _check_geometry(self, cells, label, props):
        x = self.tmesh.mesh.geometry.x
        g = self.tmesh.mesh.geometry.dofmap.array.reshape(-1, 4)[cells][:, kernels_mq.CCW]
        n = np.cross(x[g[:, 2]] - x[g[:, 0]], x[g[:, 3]] - x[g[:, 1]])
        # convexity: each corner turns the same way about the element normal
        ok = np.ones(len(g), dtype=bool)
        for a in range(4):
            e0 = x[g[:, (a + 1) % 4]] - x[g[:, a]]
            e1 = x[g[:, (a + 2) % 4]] - x[g[:, (a + 1) % 4]]
            ok &= np.einsum("ij,ij->i", np.cross(e0, e1), n) > 0.0
        self._refuse(cells, np.flatnonzero(~ok), x[g[:, 0]], f"{label}: {{n}} quadrilateral(s) not convex, of zero "
                     "area or with nodes out of order, the first at {at}")


class Coupled:
    """Structural models on several meshes, solved as one system (:class:`assembly.CoupledSystem`).

    Meshes of one node source (one gmsh model) share their common nodes: a
    beam along a shell's edge or across its surface moves with it, dofs for
    dofs. Models that share no node are still solved together (they interact
    through supports, loads or, later, contact).
    """

    def __init__(self, models: list[LineFrame]):
        self.models = list(models)
        self.large_rotations = self.models[0].large_rotations

    @property
    def comm(self):
        return self.models[0].comm

    @property
    def symmetric_tangent(self) -> bool:
        return all(m.symmetric_tangent for m in self.models)

    @property
    def has_prescribed_motion(self) -> bool:
        return any(m.has_prescribed_motion for m in self.models)

    @property
    def amplitudes(self) -> list:
        out = []
        for m in self.models:
            out += [a for a in m.amplitudes if a not in out]
        return out

    def extrapolate(self, older, newer, factor: float) -> None:
        for m, o, n in zip(self.models, older, newer):
            m.extrapolate(o, n, factor)

    def checkpoint(self):
        return tuple(m.checkpoint() for m in self.models)

    def restore(self, cp) -> None:
        for m, c in zip(self.models, cp):
            m.restore(c)

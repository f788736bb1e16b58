"""Large-deformation continuum parts: total-Lagrangian UFL forms on a DOLFINx mesh.

A :class:`Solid` holds the continuum on one mesh (plane strain in 2D, 3D):
the displacement in a vector Lagrange space of degree 1 or 2 (triangles,
quadrilaterals, tetrahedra, hexahedra), the Lamé constants per cell (DG0,
so that one region or one element can be weakened as an imperfection), and
the forms

    f_int(u; v) = ∫ P(F) : ∇v dX,     K = ∂f_int/∂u   (UFL derivative),

with P the first Piola–Kirchhoff stress of the law (``continuum.laws``), or
the small-strain stress when the scene has ``large_rotations=False``.
External loads are dead: tractions per reference area on facet groups,
body forces per reference volume, point forces at nodes. It presents the
same model protocol to :class:`dolfinx_corot.assembly.System` as the
structural parts.
"""
from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.la

from ..io.mesh import TaggedMesh
from ..parts import PartRef, PrescribedMotion
from ..materials import Elastic
from .kinematics import deformation_gradient
from .laws import first_piola, lame

CELLS = ("triangle", "quadrilateral", "tetrahedron", "hexahedron")


class Solid(PrescribedMotion):
    """A large-deformation continuum on one mesh (see the module docstring)."""

    symmetric_tangent = True  # hyperelastic, dead loads

    def __init__(self, tmesh: TaggedMesh, degree: int, large_rotations: bool):
        mesh = tmesh.mesh
        cell = mesh.topology.cell_name()
        if cell not in CELLS or mesh.topology.dim != mesh.geometry.dim:
            raise ValueError(f"solids need a mesh of {CELLS} filling its space (tdim = gdim); got {cell} with "
                             f"tdim {mesh.topology.dim}, gdim {mesh.geometry.dim}: read the gmsh model with "
                             f"from_gmsh(model, gdim={mesh.topology.dim})")
        if degree not in (1, 2):
            raise ValueError(f"solid: degree {degree} is not 1 or 2")
        self.tmesh = tmesh
        self.degree = degree
        self.large_rotations = bool(large_rotations)
        self.gdim = self.tdim = mesh.geometry.dim
        self.dof_names = ("ux", "uy", "uz")[: self.gdim]
        self.ndof = self.translations = self.gdim
        # Gauss rule: 2p on simplices, 2p + 1 on quadrilaterals/hexahedra ((p + 1)^d points)
        self.quadrature = 2 * degree + (0 if cell in ("triangle", "tetrahedron") else 1)
        self.V = dolfinx.fem.VectorFunctionSpace(mesh, ("Lagrange", degree))
        self.nodes_per_cell = self.V.dofmap.dof_layout.num_dofs  # dof blocks per cell
        self.state = dolfinx.fem.Function(self.V, name="displacement")
        Q = dolfinx.fem.FunctionSpace(mesh, ("DG", 0))
        self.E = dolfinx.fem.Function(Q, name="E")
        self.nu = dolfinx.fem.Function(Q, name="nu")
        self._cell_dof = Q.dofmap.list.array
        cmap = mesh.topology.index_map(self.tdim)
        self._owner_of_cell = np.full(cmap.size_local + cmap.num_ghosts, "", dtype=object)
        self.law: type | None = None
        self.parts: list = []
        self._bcs: list[tuple[np.ndarray, tuple[int, ...]]] = []
        self._prescribed: list[tuple[np.ndarray, int, float, object]] = []
        self._prescribed_values: list = []
        self._tractions: list[tuple[str, np.ndarray, object]] = []
        self._body: list[tuple[str | None, np.ndarray, object]] = []
        self._point_loads: list[tuple[np.ndarray, np.ndarray, object]] = []
        self._forms = None
        self.lifting_bcs: list = []

    @property
    def comm(self):
        return self.V.mesh.comm

    # -- building -------------------------------------------------------------
    def add_region(self, where: str | None, material: Elastic):
        label = f"solid '{where or 'all cells'}'"
        kind = type(material)
        if self.law is not None and kind is not self.law:
            raise NotImplementedError(f"{label}: one law per solid mesh ({self.law.__name__} already); "
                                      f"{kind.__name__} regions need a mesh of their own")
        cells = self.tmesh.cells(where)
        taken = self._owner_of_cell[cells]
        clash = taken[(taken != "") & (taken != label)]
        if len(clash) and where is None:
            raise ValueError(f"{label}: its cells already belong to {clash[0]}")
        # a named region may re-assign cells of the 'all cells' region (an imperfection)
        self._owner_of_cell[cells] = label
        self.E.x.array[self._cell_dof[cells]] = material.E
        self.nu.x.array[self._cell_dof[cells]] = material.nu
        self.law = kind
        ref = PartRef(self, where or "", "solid")
        self.parts.append(ref)
        self._forms = None
        return ref

    def _entities(self, where: str) -> tuple[int, np.ndarray]:
        """(dim, local entities) that locate the dofs of group ``where``: its facets when it is a
        facet group with tags (mid-side dofs included), else its vertices."""
        facets = self.tmesh.facets(where)
        if facets is not None:
            return self.tdim - 1, facets
        if self.degree > 1 and self.tmesh.groups[where][0] == self.tdim - 1:
            raise ValueError(f"group '{where}' has no facet tags (a mesh from arrays?): quadratic solids locate "
                             "boundary dofs by facets; read the mesh with from_gmsh")
        return 0, self.tmesh.vertices(where)

    def _dof_blocks(self, where: str) -> np.ndarray:
        """Local blocks (nodes of V, owned and ghost) of group ``where``."""
        return dolfinx.fem.locate_dofs_topological(self.V, *self._entities(where))

    def fix(self, where: str, dofs: tuple[int, ...]) -> None:
        self._bcs.append((self._dof_blocks(where), dofs))

    def prescribe(self, where: str, comp: int, value: float, amplitude=None) -> None:
        self._prescribed.append((where, comp, float(value), amplitude))

    def add_load(self, where: str, values: np.ndarray, amplitude=None) -> None:
        """Point forces at every node of group ``where`` (values: gdim components)."""
        self._point_loads.append((self._dof_blocks(where), np.asarray(values, dtype=float)[: self.gdim], amplitude))

    def add_traction(self, where: str, traction: np.ndarray, amplitude=None) -> None:
        if self.tmesh.facets(where) is None:
            raise ValueError(f"traction on '{where}': a group of facets (dimension {self.tdim - 1}) read with "
                             "from_gmsh is needed")
        self._tractions.append((where, np.asarray(traction, dtype=float), amplitude))

    def add_body_force(self, where: str | None, force: np.ndarray, amplitude=None) -> None:
        if where is not None:
            self.tmesh.cells(where)  # fails early for a missing group
        self._body.append((where, np.asarray(force, dtype=float), amplitude))

    @property
    def amplitudes(self) -> list:
        out = []
        for *_, amp in self._tractions + self._body + self._point_loads:
            if amp is not None and amp not in out:
                out.append(amp)
        return out

    # -- forms -----------------------------------------------------------------
    def stress(self, u):
        """First Piola–Kirchhoff stress (large rotations) or small-strain stress of u."""
        lmbda, mu = lame(self.E, self.nu)
        if not self.large_rotations:
            eps = ufl.sym(ufl.grad(u))
            return lmbda * ufl.tr(eps) * ufl.Identity(self.gdim) + 2.0 * mu * eps
        return first_piola(self.law, deformation_gradient(u), lmbda, mu)

    def _check_complete(self) -> None:
        cmap = self.tmesh.mesh.topology.index_map(self.tdim)
        missing = self.comm.allreduce(int(np.sum(self._owner_of_cell[: cmap.size_local] == "")), op=MPI.SUM)
        if missing:
            raise ValueError(f"{missing} cell(s) of the solid mesh have no material: give every cell a region "
                             "(add_solid without 'where' covers all)")
        if np.any(self.nu.x.array >= 0.5) or np.any(self.E.x.array <= 0.0):
            raise ValueError("solid: E must be positive and nu below 0.5 in every cell")

    def forms(self):
        if self._forms is None:
            self._check_complete()
            u, v, du = self.state, ufl.TestFunction(self.V), ufl.TrialFunction(self.V)
            residual = ufl.inner(self.stress(u), ufl.grad(v)) * ufl.dx(metadata={"quadrature_degree": self.quadrature})
            jacobian = ufl.derivative(residual, u, du)
            self._forms = (dolfinx.fem.form(residual), dolfinx.fem.form(jacobian))
        return self._forms

    def _load_form(self, amplitude):
        """Linear form of the tractions and body forces of one amplitude at unit factor (or None)."""
        v = ufl.TestFunction(self.V)
        terms = []
        if any(a is amplitude for *_, a in self._tractions):
            ds = ufl.Measure("ds", domain=self.V.mesh, subdomain_data=self.tmesh.facet_tags)
            for where, t, amp in self._tractions:
                if amp is amplitude:
                    tag = self.tmesh.groups[where][1]
                    terms.append(ufl.inner(ufl.as_vector([float(c) for c in t]), v) * ds(tag))
        dx = ufl.Measure("dx", domain=self.V.mesh, subdomain_data=self.tmesh.cell_tags)
        for where, b, amp in self._body:
            if amp is amplitude:
                measure = dx if where is None else dx(self.tmesh.groups[where][1])
                terms.append(ufl.inner(ufl.as_vector([float(c) for c in b]), v) * measure)
        if not terms:
            return None
        return dolfinx.fem.form(sum(terms[1:], terms[0]))

    def external_force(self, b: PETSc.Vec, amplitude=None) -> None:
        """Add the dead loads of one amplitude (None: proportional to λ) at unit factor."""
        form = self._load_form(amplitude)
        if form is not None:
            tmp = b.duplicate()
            with tmp.localForm() as t:
                t.set(0.0)
            dolfinx.fem.petsc.assemble_vector(tmp, form)
            tmp.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            b.axpy(1.0, tmp)
            tmp.destroy()
        n_owned = self.V.dofmap.index_map.size_local
        with b.localForm() as bl:
            arr = bl.array.reshape(-1, self.ndof)
            for blocks, values, amp in self._point_loads:
                if amp is amplitude:
                    arr[blocks[blocks < n_owned]] += values

    # -- constraints -------------------------------------------------------------
    def dirichlet_bcs(self) -> list:
        zero = PETSc.ScalarType(0.0)
        bcs = []
        for blocks, comps in self._bcs:
            for comp in comps:
                bcs.append(dolfinx.fem.dirichletbc(zero, blocks * self.ndof + comp, self.V.sub(comp)))
        self._prescribed_values = []
        self.lifting_bcs = []
        for where, comp, value, amplitude in self._prescribed:
            Vi, _ = self.V.sub(comp).collapse()
            g = dolfinx.fem.Function(Vi)
            dofs = dolfinx.fem.locate_dofs_topological((self.V.sub(comp), Vi), *self._entities(where))
            bc = dolfinx.fem.dirichletbc(g, dofs, self.V.sub(comp))
            bcs.append(bc)
            self.lifting_bcs.append(bc)
            self._prescribed_values.append((g, dofs[1], value, amplitude))
        return bcs

    def constraint_dofs(self) -> list:
        out = [(blocks * self.ndof + comp, 0.0, None) for blocks, comps in self._bcs for comp in comps]
        out += [(self._dof_blocks(where) * self.ndof + comp, value, amp) for where, comp, value, amp in self._prescribed]
        return out

    def bending_blocks(self) -> np.ndarray:
        return np.zeros(self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts, dtype=bool)

    # -- linear solver -------------------------------------------------------------
    def near_nullspace(self) -> PETSc.NullSpace:
        """Rigid-body modes (3 in 2D, 6 in 3D) of V, for algebraic multigrid."""
        x = self.V.tabulate_dof_coordinates()
        n_owned = self.V.dofmap.index_map.size_local
        x = x[:n_owned]
        d = self.gdim
        modes = []
        for k in range(d):
            m = np.zeros((n_owned, d))
            m[:, k] = 1.0
            modes.append(m)
        rots = [(0, 1)] if d == 2 else [(0, 1), (1, 2), (2, 0)]
        for i, j in rots:
            m = np.zeros((n_owned, d))
            m[:, i] = -x[:, j]
            m[:, j] = x[:, i]
            modes.append(m)
        vecs = []
        for m in modes:
            vec = dolfinx.la.create_petsc_vector(self.V.dofmap.index_map, d)
            vec.array[:] = m.ravel()
            vecs.append(vec)
        dolfinx.la.orthonormalize(vecs)
        return PETSc.NullSpace().create(vectors=vecs, comm=self.comm)

    # -- state ---------------------------------------------------------------------
    def update(self, dx: PETSc.Vec) -> None:
        self.state.vector.axpy(1.0, dx)
        self.state.x.scatter_forward()

    def extrapolate(self, older: np.ndarray, newer: np.ndarray, factor: float) -> None:
        self.state.x.array[:] = newer + factor * (newer - older)

    def displacement_vector(self) -> PETSc.Vec:
        return self.state.vector

    def _input_ids(self) -> np.ndarray:
        """A key per local dof block (owned and ghost) for :class:`~dolfinx_corot.assembly.DofLayout`:
        the input (gmsh) node number on linear meshes, so that structures read from the same gmsh
        model share the solid's nodes; quadratic solids number their blocks apart (never shared)."""
        imap = self.V.dofmap.index_map
        n = imap.size_local + imap.num_ghosts
        if self.degree == 1:
            mesh = self.V.mesh
            ids = np.empty(n, dtype=np.int64)
            geo = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
            ids[self.V.dofmap.list.array] = geo[mesh.geometry.dofmap.array]
            return ids
        return imap.local_to_global(np.arange(n, dtype=np.int32)).astype(np.int64) + (np.int64(1) << 32)

    def checkpoint(self) -> np.ndarray:
        return self.state.x.array.copy()

    def restore(self, cp: np.ndarray) -> None:
        self.state.x.array[:] = cp

    def _global_order(self) -> tuple[np.ndarray, np.ndarray]:
        """(coordinates of owned blocks, their rank in a partition-independent ordering) on every rank."""
        n_owned = self.V.dofmap.index_map.size_local
        x = self.V.tabulate_dof_coordinates()[:n_owned]
        allx = np.concatenate(self.comm.allgather(x))
        order = np.lexsort(allx.T[::-1].round(12))
        rank_of = np.empty(len(allx), dtype=np.int64)
        rank_of[order] = np.arange(len(allx))
        offset = sum(self.comm.allgather(n_owned)[: self.comm.rank])
        return x, rank_of[offset: offset + n_owned]

    def to_global(self, local: np.ndarray) -> np.ndarray | None:
        n_owned = self.V.dofmap.index_map.size_local
        _, idx = self._global_order()
        vals = self.comm.gather((idx, np.asarray(local).reshape(-1, self.ndof)[:n_owned]), root=0)
        if self.comm.rank != 0:
            return None
        out = np.empty((sum(len(i) for i, _ in vals), self.ndof))
        for i, v in vals:
            out[i] = v
        return out

    def from_global(self, values: np.ndarray) -> np.ndarray:
        _, idx = self._global_order()
        n_owned = self.V.dofmap.index_map.size_local
        out = np.zeros((n_owned + self.V.dofmap.index_map.num_ghosts, self.ndof))
        out[:n_owned] = values[idx]
        f = dolfinx.fem.Function(self.V)
        f.x.array[:] = out.ravel()
        f.x.scatter_forward()
        return f.x.array.copy()

    # -- read-out ------------------------------------------------------------------
    def reaction(self, where: str, values: np.ndarray) -> np.ndarray:
        """Sum over the dofs of group ``where`` (owned, all ranks) of a nodal vector (local array of V)."""
        blocks = self._dof_blocks(where)
        blocks = blocks[blocks < self.V.dofmap.index_map.size_local]
        local = values.reshape(-1, self.ndof)[blocks].sum(axis=0) if len(blocks) else np.zeros(self.ndof)
        out = np.zeros(self.ndof)
        self.comm.Allreduce(np.ascontiguousarray(local, dtype=float), out, op=MPI.SUM)
        return out

    def nodal_values(self, where: str) -> np.ndarray:
        """Displacement at the (first) vertex node of group ``where``, the same on every rank."""
        blocks = dolfinx.fem.locate_dofs_topological(self.V, 0, self.tmesh.vertices(where))
        blocks = blocks[blocks < self.V.dofmap.index_map.size_local]
        local = np.zeros(self.ndof + 1)
        if len(blocks):
            local[: self.ndof] = self.state.x.array.reshape(-1, self.ndof)[blocks[0]]
            local[self.ndof] = 1.0
        for v in self.comm.allgather(local):
            if v[self.ndof] == 1.0:
                return v[: self.ndof].copy()
        raise ValueError(f"group '{where}' has no node")

    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        n_owned = self.V.dofmap.index_map.size_local
        X = self.V.tabulate_dof_coordinates()[:n_owned, : self.gdim]
        u = self.state.x.array.reshape(-1, self.ndof)[:n_owned]
        return np.concatenate(self.comm.allgather(X)), np.concatenate(self.comm.allgather(u))

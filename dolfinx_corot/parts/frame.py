"""Beams and bars on 1D meshes: co-rotational kernels wrapped as DOLFINx forms.

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

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.la

from .. import _dolfinx
from ..conditions import Condition
from ..elements import line_properties
from ..elements import follower as follower_kernels
from ..elements import uniform_load
from ..io.mesh import TaggedMesh
from ..loads import FollowerLoad
from ..kernels import NSTATE, SYMMETRIZED, OnFirstUse, compiled
from ..result import ElementResults
from .base import AdditiveState, Part, PartRef
from .cells import MeshError, check_geometry_degree, mesh_extent, refuse
from .surface import Surface, SurfaceError, gather_surface


class LineFrame(Part):
    """What 2D and 3D frames and shells share: cells, section properties, forms."""

    tdim = 1
    nodes_per_cell = 2
    gdim: int
    nprops: int
    kernels = None
    kind_name = "structural"

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        mesh = tmesh.mesh
        if mesh.topology.dim != self.tdim or mesh.geometry.dim != self.gdim:
            raise ValueError(f"{type(self).__name__} needs a mesh of tdim {self.tdim} in gdim {self.gdim}; got "
                             f"tdim {mesh.topology.dim}, gdim {mesh.geometry.dim}: read the gmsh model "
                             f"with from_gmsh(model, gdim={self.gdim})")
        check_geometry_degree(mesh, "beams, bars, shells and membranes", 1,
                              "co-rotational beams, bars, shells and membranes are straight or flat elements on "
                              "the corner nodes: mesh with first-order elements (gmsh.model.mesh.setOrder(1), the "
                              "default), finer where the structure curves")
        self.tmesh = tmesh
        self.large_rotations = bool(large_rotations)
        self.V = _dolfinx.function_space(mesh, "Lagrange", 1, len(self.dof_names))
        Q = _dolfinx.function_space(mesh, "DG", 0, self.nprops)
        self.props = dolfinx.fem.Function(Q, name="section")
        self._prop_blocks = Q.dofmap.list.array  # DG0: one block per cell
        cmap = mesh.topology.index_map(self.tdim)
        self._owner_of_cell = np.full(cmap.size_local + cmap.num_ghosts, "", dtype=object)
        self._bending = np.zeros(cmap.size_local + cmap.num_ghosts, dtype=bool)
        self._element_props: list[tuple[str, list[float]]] = []
        # uniform dead loads on elements: (label, where, q or q(cells, X), amplitude, condition) — weights,
        # loads per length, dead pressures
        self._distributed: list[tuple[str, str | None, object, object, Condition]] = []
        self.followers: list[FollowerLoad] = []
        self._init_conditions()

    # -- building -----------------------------------------------------------
    def add_elements(self, where: str | None, props, bending: bool, kind: str,
                     fingerprint: list[float] | None = None) -> PartRef:
        """Elements of ``kind`` on the cells of group ``where``: ``props`` one row of properties
        for all of them, or a function of the local cells giving one row per cell (then
        ``fingerprint``: the numbers that describe them, the same on every rank)."""
        label = f"{kind} '{where or 'all cells'}'"
        cells = self.tmesh.cells(where)
        taken = self._owner_of_cell[cells]
        clash = taken[taken != ""]
        if len(clash):
            raise ValueError(f"{label}: its cells already belong to {clash[0]}")
        if callable(props):  # rows from the cells' geometry, once it is checked
            self._check_geometry(cells, label, None)
            rows = props(cells, label)
        else:
            rows = props
            self._check_geometry(cells, label, rows)
        self._owner_of_cell[cells] = label
        self._bending[cells] = bending
        values = self.props.x.array.reshape(-1, self.nprops)
        values[self._prop_blocks[cells]] = rows
        self.props.x.scatter_forward()
        ref = PartRef(self, where or "", kind)
        self.parts.append(ref)
        self._element_props.append((label, [float(v) for v in (props if fingerprint is None else fingerprint)]))
        self._forms = None
        return ref

    def _materials(self) -> list:
        return self._element_props

    def cell_properties(self, cells: np.ndarray) -> np.ndarray:
        """(len(cells), nprops) section properties of local cells."""
        return self.props.x.array.reshape(-1, self.nprops)[self._prop_blocks[cells]]

    def _element_vectors(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = self.tmesh.mesh.geometry.x
        gdofs = self.tmesh.mesh.geometry.dofmap.array.reshape(-1, 2)[cells]
        return x[gdofs[:, 0]], x[gdofs[:, 1]] - x[gdofs[:, 0]]

    def _refuse(self, cells: np.ndarray, bad: np.ndarray, message: str, error: type = MeshError) -> None:
        """Raise ``error(message)`` on every rank if any rank found bad cells.

        cells: the local cells checked; bad: indices into cells of the bad ones; the
        message may use {n} (number of bad cells, owned ones counted once) and {at} (the
        midpoint and input index of the bad cell that comes first in input order).
        """
        refuse(self.tmesh.mesh, "", [(message, cells[bad])], error)

    def _check_geometry(self, cells: np.ndarray, label: str, props: np.ndarray) -> None:
        _, d = self._element_vectors(cells)
        lengths = np.linalg.norm(d, axis=1)
        bad = np.flatnonzero(lengths <= 1e-10 * mesh_extent(self.tmesh.mesh))
        self._refuse(cells, bad, f"{label}: {{n}} element(s) of zero length, the first at {{at}}")

    def capture_reference(self) -> None:
        """Take the current configuration as the stress-free reference of the elements: the part's
        mesh nodes move to their current positions, displacements restart from zero and nodal
        rotations from the identity, and the element frames and per-cell constants follow from
        the new positions (the forms are rebuilt). A structure added in a deformed configuration
        (seed §3.1.2, approach II) is captured so; its displacements then measure U − U_os.
        At creation the reference is the mesh itself."""
        if self.state is None:
            return Part.capture_reference(self)
        self.tmesh.pin_point_groups()  # groups found by position: by node number from now on
        geo = self.tmesh.mesh.geometry
        node = np.empty(len(geo.x), dtype=np.int64)  # the block of V at each geometry node
        node[geo.dofmap.array] = self.V.dofmap.list.array
        geo.x[:, : self.gdim] += self.translations_of(node)
        self._reset_state()
        self._forms = None
        Part.capture_reference(self)

    def add_truss(self, where, area, material, prestress_force) -> PartRef:
        return self.add_bars(where, material.E * area, float(prestress_force))

    # -- self-weight --------------------------------------------------------------
    @staticmethod
    def _label(part: PartRef) -> str:
        return f"{part.kind} '{part.name or 'all cells'}'"

    def _weight_cells(self, label: str, where: str | None) -> np.ndarray:
        """Owned cells of the elements ``label``, within group ``where`` if given."""
        n_owned = self.tmesh.mesh.topology.index_map(self.tdim).size_local
        mine = self._owner_of_cell[:n_owned] == label
        if self._existing is not None:
            mine &= self._existing[:n_owned]
        cells = np.flatnonzero(mine).astype(np.int32)
        if where is not None:
            cells = np.intersect1d(cells, self.tmesh.cells(where))
        return cells

    def add_gravity(self, part: PartRef, acceleration: np.ndarray, density: float | None, where: str | None,
                    amplitude=None, condition: Condition | None = None) -> Condition:
        """Self-weight ρ·A·g per unit reference length of beams and bars, ρ·t·g per unit reference
        area of shells and membranes, of the elements of ``part`` (within group ``where`` if given),
        as dead work-equivalent nodal loads (:mod:`dolfinx_corot.elements.uniform_load`)."""
        label = self._label(part)
        stored, measure = self._mass.get((part.kind, part.name), (None, None))
        density = stored if density is None else density
        if density is None:
            raise ValueError(f"gravity on {label}: its material has no density; give it one "
                             "(dc.Elastic(E, nu, density=ρ)) or pass density= to scene.gravity")
        if measure is None:
            raise ValueError(f"gravity on {label}: its cross-section is unknown (add it with Scene.add_*)")
        if where is not None and not self.comm.allreduce(len(self._weight_cells(label, where))):
            raise ValueError(f"gravity on {label}: group '{where}' holds none of its elements")
        q = float(density) * measure * np.asarray(acceleration, dtype=float)
        condition = condition or Condition("gravity", f"on {label}")
        self._distributed.append((label, where, q, amplitude, condition))
        return condition

    def _loaded_cells(self, part: PartRef, where: str | None, what: str) -> np.ndarray:
        """Owned cells of ``part`` (within group ``where``), refused if there are none."""
        label = self._label(part)
        cells = self._weight_cells(label, where)
        if not self.comm.allreduce(len(cells)):
            raise ValueError(f"{what} on {label}: group '{where}' holds none of its elements")
        return cells

    def add_line_load(self, part: PartRef, where: str | None, q: np.ndarray, axes: str, follower: bool,
                      amplitude=None, condition: Condition | None = None) -> Condition:
        """A uniform load per unit length on the beams or bars of ``part`` (see ``Scene.load``)."""
        label = self._label(part)
        cells = self._loaded_cells(part, where, "load per length")
        condition = condition or Condition("load", f"per length on {label}")
        if follower:
            if axes != "element":
                raise ValueError(f"follower load per length on {label}: a follower load turns with the elements, "
                                 "so give it in element axes (axes='element': along the element, normal to it)")
            kind = "line2d" if self.gdim == 2 else "line3d"
            self.followers.append(FollowerLoad(self, label, kind, cells, q, self._bending[cells], amplitude,
                                               condition))
            return condition
        if axes == "global":
            self._distributed.append((label, where, q, amplitude, condition))
            return condition

        def in_element_axes(cells, X, q=q):
            axes = self._initial_axes(cells, X)
            return np.einsum("i,nij->nj", q, axes[:, : len(q)])
        self._distributed.append((label, where, in_element_axes, amplitude, condition))
        return condition

    def _initial_axes(self, cells: np.ndarray, X: np.ndarray) -> np.ndarray:
        """(n, gdim, gdim) the rows of each element's axes in its reference configuration: along the
        element, then normal to it (2D: e_z × t)."""
        t = X[:, 1] - X[:, 0]
        t /= np.linalg.norm(t, axis=1)[:, None]
        return np.stack([t, t @ follower_kernels.R90.T], axis=1)

    def add_pressure(self, part: PartRef, where: str | None, p: float, follower: bool, amplitude=None,
                     condition: Condition | None = None) -> Condition:
        raise ValueError(f"pressure on {self._label(part)}: a pressure acts on surfaces (shells, membranes, the "
                         "faces of solids); on beams and bars give a load per length (scene.load(..., per_length=))")

    def load_conditions(self) -> list:
        return [(amp, cond) for *_, amp, cond in self._point_loads + self._distributed] + \
            [(f.amplitude, f.condition) for f in self.followers]

    def _add_distributed_loads(self, b: PETSc.Vec, amplitude) -> None:
        """Add the uniform dead loads (weights, loads per length, dead pressures) of one amplitude (None:
        proportional to λ) at unit factor, from the reference positions of the nodes."""
        terms = [(label, where, q) for label, where, q, amp, cond in self._distributed
                 if amp is amplitude and cond.exists]
        if not terms:
            return
        g = self.gdim
        loads = dolfinx.fem.Function(self.V)
        arr = loads.x.array.reshape(-1, self.ndof)
        cell_blocks = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)
        for label, where, q in terms:
            cells = self._weight_cells(label, where)
            blocks = cell_blocks[cells]
            X = self.reference[blocks] + self._activation_translations(cells)
            if callable(q):  # one load per element, from its reference geometry
                q = q(cells, X)
            if self.tdim == 1:
                forces, moments = uniform_load.line_loads(X, q, self._bending[cells])
                np.add.at(arr[:, g:], blocks, moments.reshape(len(cells), 2, self.ndof - g))
            elif self.nodes_per_cell == 3:
                forces = uniform_load.triangle_loads(X, q)
            else:
                forces = uniform_load.quad_loads(X, q)
            np.add.at(arr[:, :g], blocks, forces)
        loads.x.scatter_reverse(dolfinx.la.ScatterMode.add)
        n = self.V.dofmap.index_map.size_local * self.ndof
        with b.localForm() as bl:
            bl.array[:n] += loads.x.array[:n]

    # -- Model protocol (assembly.System) ------------------------------------
    def forms(self):
        if self._forms is None:
            cmap = self.tmesh.mesh.topology.index_map(self.tdim)
            active = self._cells_active()[: cmap.size_local]
            owned = np.flatnonzero(active).astype(np.int32)
            all_owned = self.comm.allreduce(bool(len(owned) == cmap.size_local), op=MPI.LAND)
            cells = None if all_owned else owned
            self._flag = dolfinx.fem.Constant(self.V.mesh, PETSc.ScalarType(self._kernel_mode()))
            coeffs = [self.state, self.props, *self._element_constants()]
            vector_kernel, matrix_kernel = self._kernel_pair()
            L = _dolfinx.kernel_form(self.V, vector_kernel.address, 1, coeffs, [self._flag], cells)
            a = _dolfinx.kernel_form(self.V, matrix_kernel.address, 2, coeffs, [self._flag], cells)
            self._forms = (L, a)
        return self._forms

    _flag = None  # the kernels' constant c[0] (made with the forms)

    def _kernel_mode(self) -> float:
        """The kernels' c[0]: 0 geometrically linear, 1 co-rotational."""
        return 1.0 if self.large_rotations else 0.0

    def _element_constants(self) -> list:
        """Per-cell coefficients the kernels read after the properties: the kernels' own
        (:meth:`_kernel_constants`), then the nodes' states at activation of staged elements
        (approach II)."""
        return self._kernel_constants() + ([self.activation] if self._staged_shift() else [])

    def _kernel_constants(self) -> list:
        """Per-cell constants of the kernels (none by default)."""
        return []

    #: the function of :mod:`dolfinx_corot.kernels.compiled` that gives the part's C kernels (the
    #: numba kernels' numbers without loading numba); None: the numba kernels of ``kernels``
    compiled_kernels: str | None = None

    def _kernel_pair(self):
        """(vector kernel, matrix kernel) of the elements (approach II: of elements added undeformed,
        numba's)."""
        if self._staged_shift():
            return self.kernels.staged_kernels()
        if self.compiled_kernels is not None:
            return getattr(compiled, self.compiled_kernels)()
        return self.kernels.vector_kernel, self.kernels.matrix_kernel

    # -- staged construction (dolfinx_corot.staging) ---------------------------------
    _existing: np.ndarray | None = None  # which local cells exist (None: all)
    activation: dolfinx.fem.Function | None = None  # approach II: the nodes' states when each cell appeared

    def start_staging(self, approach: str) -> None:
        """Existence per element from now on (none until :meth:`set_existing`). Approach II
        (seed §3.1.2): an element appears undeformed in the configuration of that moment — the
        state of its nodes then, U_os (with their rotations), is memorized per element and its
        deformation is U − U_os (rotations R R_osᵀ), its reference the positions X + U_os.
        Approach I: the mesh is the reference and U the deformation (fit for small construction
        deformations, or nodes at rest until then)."""
        if not hasattr(self.kernels, "staged_kernels"):
            raise NotImplementedError(f"staged construction: {type(self).__name__} parts are not staged yet, only "
                                      "solids, beams, bars, shells and membranes")
        if self._existing is None:
            self._existing = np.zeros(len(self._owner_of_cell), dtype=bool)
            Q = _dolfinx.function_space(self.tmesh.mesh, "DG", 0, self.nodes_per_cell * self.state_size)
            self.activation = dolfinx.fem.Function(Q, name="activation")
        self.approach = approach
        self._forms = None

    def is_staged(self) -> bool:
        return self._existing is not None

    def cells_existing(self) -> np.ndarray:
        """(local cells, owned and ghost) whether each exists."""
        return self._existing.copy()

    def _activation_values(self) -> np.ndarray:
        """(local cells, nodes, state_size) view of the memorized states, cell by cell."""
        return self.activation.x.array.reshape(-1, self.nodes_per_cell, self.state_size)

    def set_existing(self, exists: np.ndarray) -> None:
        """Which local cells exist; with approach II the new ones memorize their nodes' state."""
        new = exists & ~self._existing
        if self.approach == "II" and new.any():
            blocks = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)[new]
            act = self._activation_values()
            act[self.activation.function_space.dofmap.list.array[new]] = \
                self.state.x.array.reshape(-1, self.state_size)[blocks]
        self._existing = np.asarray(exists, dtype=bool).copy()
        self._forms = None

    def staging_arrays(self) -> dict:
        """The state U_os of every element's nodes when it appeared (staged structures)."""
        if self.activation is None:
            return {}
        act = self._activation_values()[self.activation.function_space.dofmap.list.array]
        return self._cells_to_global(self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell), act)

    def set_staging_arrays(self, arrays: dict) -> None:
        if self.activation is None:
            return
        values = self._cells_from_global(self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell), arrays)
        self._activation_values()[self.activation.function_space.dofmap.list.array] = values
        self._forms = None

    def held_blocks(self) -> np.ndarray:
        """Nodes that no (existing) element of the part touches — also without stages: a mesh of
        lines read from a model with solids may hold nodes that no element of the part uses."""
        return self._untouched_blocks(self._cells_active())

    def _staged_shift(self) -> bool:
        return self.activation is not None and self.approach == "II"

    def _cells_active(self) -> np.ndarray:
        """Local cells (owned and ghost) with elements that exist."""
        active = self._owner_of_cell != ""
        return active if self._existing is None else active & self._existing

    def _activations(self, cells: np.ndarray) -> np.ndarray:
        """(cells, nodes, state_size) state of the cells' nodes when they appeared (approach II)."""
        return self._activation_values()[self.activation.function_space.dofmap.list.array[cells]]

    def _activation_translations(self, cells: np.ndarray) -> np.ndarray | float:
        """(cells, nodes, gdim) translation of the elements' reference from the mesh (elements
        added undeformed in a deformed configuration, approach II); 0 otherwise."""
        return self._activations(cells)[:, :, : self.gdim] if self._staged_shift() else 0.0

    def _element_states(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(X (cells, nodes, 3), S (cells, nodes, state_size)): the reference positions of the
        elements' nodes and their states since the elements appeared (approach II: reference
        X + U_os, states U − U_os with rotations R R_osᵀ), as the kernels read them."""
        blocks = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)[cells]
        X = np.zeros(blocks.shape + (3,))
        X[:, :, : self.gdim] = self.reference[blocks]
        S = self.state.x.array.reshape(-1, self.state_size)[blocks]
        if self._staged_shift():
            A = self._activations(cells)
            if self.state_size == 7:  # multiplicative rotations
                from ..kernels.spatial import since_activation_all  # (loaded with the first kernels)

                Xa, Sa = np.empty_like(X), np.empty_like(S)
                since_activation_all(X, S, A, Xa, Sa)
                return Xa, Sa
            X[:, :, : self.gdim] += A[:, :, : self.gdim]
            S = S - A
        return X, S

    _load_factor = 0.0  # of the residual last assembled (the converged state's, after a solve)

    def set_follower_factor(self, load_factor: float) -> None:
        self._load_factor = float(load_factor)

    def _span_loads(self, cells: np.ndarray) -> np.ndarray:
        """(cells, 2, ndof) the nodal forces and moments (global axes) by which the uniform loads
        on the given line elements — weights, dead loads per length, 2D follower loads — act on
        their nodes at the current load factor (in a staged run at full value: the state at a
        stage's end). The element's end forces less these are the forces its neighbours exert on
        it: the section forces of a loaded span (its fixed-end forces included)."""
        g, nd = self.gdim, self.ndof
        out = np.zeros((len(cells), 2, nd))
        if not len(cells):
            return out
        lam, staged = self._load_factor, self.is_staged()
        blocks_of = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)
        for label, where, q, amplitude, condition in self._distributed:
            hit = np.isin(cells, self._weight_cells(label, where)) if condition.exists else np.zeros(0, bool)
            if not hit.any():
                continue
            c = 1.0 if staged else (lam if amplitude is None else float(amplitude(lam)))
            sub = cells[hit]
            X = self.reference[blocks_of[sub]] + self._activation_translations(sub)
            forces, moments = uniform_load.line_loads(X, q(sub, X) if callable(q) else q, self._bending[sub])
            out[hit, :, :g] += c * forces
            out[hit, :, g:] += c * moments.reshape(len(sub), 2, nd - g)
        for load in self.followers:
            if load.condition is not None and not load.condition.exists:
                continue
            where = {int(cell): k for k, cell in enumerate(load.cells)}
            hit = np.array([int(cell) in where for cell in cells], dtype=bool)
            if hit.any():
                c = 1.0 if staged else load.factor(lam)
                f, _ = load.evaluate()
                out[hit] += c * f[[where[int(cell)] for cell in cells[hit]]].reshape(-1, 2, nd)
        return out

    def _current_points(self, cells: np.ndarray) -> np.ndarray:
        """(cells, nodes, gdim) the current positions of the elements' nodes."""
        blocks = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)[cells]
        return self.reference[blocks] + self.state.x.array.reshape(-1, self.state_size)[blocks][:, :, : self.gdim]

    def bending_blocks(self) -> np.ndarray:
        """Local blocks (owned and ghost) that a bending element on this rank touches."""
        nblocks = self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts
        flags = np.zeros(nblocks, dtype=bool)
        dofs = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)
        flags[dofs[(self._bending & self._cells_active())[: len(dofs)]].ravel()] = True
        return flags

    def _fixed_blocks(self) -> np.ndarray:
        """Blocks touched by no bending element (on any rank): their rotation has no stiffness."""
        flag = dolfinx.fem.Function(self.V)
        flag.x.array.reshape(-1, self.ndof)[:, 0] = self.bending_blocks()
        flag.x.scatter_reverse(dolfinx.la.ScatterMode.add)
        flag.x.scatter_forward()
        return np.flatnonzero(flag.x.array.reshape(-1, self.ndof)[:, 0] == 0.0).astype(np.int32)

    def load_values(self, where: str, force, moment) -> np.ndarray:
        g = self.gdim
        nm = 1 if g == 2 else 3
        force = np.zeros(g) if force is None else np.atleast_1d(np.asarray(force, dtype=float))
        moment = np.zeros(nm) if moment is None else np.atleast_1d(np.asarray(moment, dtype=float))
        if force.shape != (g,) or moment.shape != (nm,) or not (np.all(np.isfinite(force))
                                                             and np.all(np.isfinite(moment))):
            raise ValueError(f"load '{where}': in {g}D give force as {g} finite numbers and moment as "
                             f"{'a number' if nm == 1 else '3 numbers'}; got force={force.tolist()}, "
                             f"moment={moment.tolist()}")
        return np.concatenate([force, moment])

    def effect(self) -> str:
        kinds = sorted({p.kind for p in self.parts})
        frame = "co-rotational" if self.large_rotations else "geometrically linear"
        return f"{' and '.join(kinds)} elements ({frame}, {self.gdim}D)"


class Frame2D(AdditiveState, LineFrame):
    """Beams and bars on one 1D mesh with gdim = 2; dofs (ux, uy, rz) per node."""

    gdim = 2
    dof_names = ("ux", "uy", "rz")
    translations = 2
    state_size = 3
    nprops = line_properties.NPROPS_2D
    kernels = OnFirstUse("line2d")
    compiled_kernels = "line2d_kernels"

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        super().__init__(tmesh, large_rotations)
        self.state = dolfinx.fem.Function(self.V, name="state")  # state and corrections share V

    def add_beam(self, where, section, material, kinematics, orientation, plane_strain=False) -> PartRef:
        """plane_strain: the beam is a plate strip of unit width bending in plane strain; axial
        and bending stiffness take the plate modulus E/(1 − ν²), the shear stiffness G·As."""
        E = material.E / (1.0 - material.nu**2) if plane_strain else material.E
        GAs = material.G * section.As if kinematics == "timoshenko" else 0.0
        return self._add(where, E * section.A, E * section.I, GAs, 0.0, "beam")

    def add_bars(self, where, EA: float, N0: float) -> PartRef:
        return self._add(where, EA, 0.0, 0.0, N0, "truss")

    def _add(self, where, EA, EI, GAs, N0, kind):
        line_properties.check_props_2d(EA, EI, GAs, f"{kind} '{where}'")
        return self.add_elements(where, np.array([EA, EI, GAs, N0]), EI > 0.0, kind)

    def _drawn_sizes(self, cells: np.ndarray) -> np.ndarray:
        """Half the section's depth √(12 EI/EA)/2 (exact for rectangles; 0 for bars)."""
        props = self.cell_properties(cells)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(props[:, 0] > 0.0, 0.5 * np.sqrt(12.0 * props[:, 1] / props[:, 0]), 0.0)

    def element_forces(self) -> tuple[np.ndarray, np.ndarray]:
        """(cells, forces): the owned cells with existing elements and their end forces and
        moments (n, 6) in global axes, (Fx, Fy, M) at node 1 then node 2 — the forces the element
        exerts on its nodes' equilibrium, f_int."""
        cells = self._result_cells(None)
        return cells, self._end_forces(cells)[0]

    def _end_forces(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(F (n, 6) the elements' nodal forces in global axes, X (n, 2, 2) their reference nodes)."""
        X, S = self._element_states(cells)
        X = np.ascontiguousarray(X[:, :, :2])
        F = np.zeros((len(cells), 6))
        K = np.zeros((len(cells), 6, 6))
        compiled.evaluate_all_2d(X, np.ascontiguousarray(S.reshape(-1, 6)),
                                 np.ascontiguousarray(self.cell_properties(cells)), self.large_rotations, F, K)
        return F, X

    section_components = ("N", "V", "M")

    def element_results(self, cells: np.ndarray | None = None, label: str = "",
                        gather: bool = True) -> ElementResults:
        """Section forces (N, V, M) at both ends of every beam and bar, in the element's axes — e1
        along the current chord (the initial one in a geometrically linear analysis), e2 = e1
        turned by +90° — as the resultants on the face whose outward normal is +e1: −f₁ at end 1
        and +f₂ at end 2 of the nodal forces f the element exerts (seed §1: the engineering
        quantities of the rotated element frame). N > 0 in tension; M > 0 bends the element
        concave towards +e2 (the −e2 fibres in tension), M = EIκ; dM/ds = −V (as Mz and Vy in
        3D). An element under a uniform load (weight, load per length) reports the forces its
        neighbours exert on it, its nodal share of the load taken off: the ends of a loaded span,
        fixed-end forces included (a linear beam's are then exact at the nodes)."""
        cells = self._result_cells(cells)
        F, X = self._end_forces(cells)
        F = F - self._span_loads(cells).reshape(len(cells), 6)
        x = self._current_points(cells) if self.large_rotations else X
        chord = x[:, 1] - x[:, 0]
        e1 = chord / np.linalg.norm(chord, axis=1)[:, None]
        e2 = np.stack([-e1[:, 1], e1[:, 0]], axis=1)
        values = np.empty((len(cells), 2, 3))
        for end, sign in ((0, -1.0), (1, 1.0)):
            f = F[:, 3 * end: 3 * end + 2]
            values[:, end, 0] = sign * np.einsum("ij,ij->i", f, e1)
            values[:, end, 1] = sign * np.einsum("ij,ij->i", f, e2)
            values[:, end, 2] = sign * F[:, 3 * end + 2]
        return self._gather_results("section forces", self.section_components, cells, self._current_points(cells),
                                    values, np.stack([e1, e2], axis=1), label, gather)

    def surface(self, where: str, body: str | None = None) -> Surface:
        """The beams of line group ``where`` as a two-sided contact surface: the axis offset by half
        the section's depth √(12 EI/EA)/2 on either side (exact for rectangles; 0 for bars)."""
        cells = self.tmesh.cells(where)
        cells = cells[cells < self.tmesh.mesh.topology.index_map(1).size_local]
        seg_blocks = np.array([self.V.dofmap.cell_dofs(c) for c in cells], dtype=np.int64).reshape(-1, 2)
        props = self.cell_properties(cells)
        EA, EI = props[:, 0], props[:, 1]
        half = 0.5 * np.sqrt(12.0 * EI / np.where(EA > 0.0, EA, 1.0)) * (EA > 0.0)
        return gather_surface(self, where, seg_blocks, self.V.tabulate_dof_coordinates(), offsets=half,
                              two_sided=True, modulus=None, cells=cells)


class Rotations3D:
    """Nodal state (u, q) with multiplicative rotation updates, shared by 3D frames and surfaces."""

    state_size = NSTATE
    multiplicative_rotations = True
    _owned_blocks = None  # owned nodes of the part's mesh (found at the first update)
    # The consistent tangent with respect to spatial spins is not symmetric: its skew part is
    # −½ spin(m_a) on each node's rotations, m_a the node's unbalanced moment sum (the bracket
    # of the rotation group; Simo & Vu-Quoc 1986, Nour-Omid & Rankin 1991, Crisfield 1997
    # §17.2). At equilibrium it vanishes on the free rotations wherever no moment is applied
    # and no node has exactly one of its three rotations held (whose reaction would couple the
    # other two): there ½(K + Kᵀ) keeps Newton's quadratic convergence and is factorized by
    # LDLᵀ, which also counts the negative eigenvalues (see System.symmetrize)
    symmetric_at_equilibrium = True
    _symmetrized = False

    def symmetrize_tangent(self, on: bool) -> None:
        """The kernels return ½(K + Kᵀ) (``on``, co-rotational analyses) or K."""
        self._symmetrized = bool(on) and self.large_rotations
        if self._flag is not None:
            self._flag.value = self._kernel_mode()

    def _kernel_mode(self) -> float:
        if not self.large_rotations:
            return 0.0
        return SYMMETRIZED if self._symmetrized else 1.0

    def _init_state(self) -> None:
        S = _dolfinx.function_space(self.tmesh.mesh, "Lagrange", 1, NSTATE)
        self.state = dolfinx.fem.Function(S, name="state")
        self._reset_state()
        self._disp = dolfinx.fem.Function(self.V, name="displacement")

    def _reset_state(self) -> None:
        self.state.x.array[:] = 0.0
        self.state.x.array.reshape(-1, NSTATE)[:, 3] = 1.0  # identity rotations

    def update(self, dx: PETSc.Vec) -> None:
        """u ← u + du; q ← exp(dw)∘q (multiplicative, spatial) on owned nodes; ghosts from their owners."""
        if self._owned_blocks is None:  # (DOLFINx makes a new DofMap wrapper at every .dofmap)
            self._owned_blocks = self.V.dofmap.index_map.size_local
        st = self.state.x.array.reshape(-1, NSTATE)
        compiled.update_quaternions(st, dx.array_r.reshape(-1, 6), self._owned_blocks)
        self.state.x.scatter_forward()

    def extrapolate(self, older, newer, factor):
        raise NotImplementedError("states on the secant between two configurations are not formed for 3D rotations")

    def combine(self, states, weights):
        """The secant predictor on the rotation group: u = u₁ + f (u₁ − u₀) and, per node,
        q = exp(f log(q₁∘q₀⁻¹))∘q₁ (the last converged increment of each nodal rotation, scaled
        and applied again), with f = −w₀ of the weights (−f, 1 + f)."""
        if len(states) != 2:
            raise NotImplementedError("LoadControl(extrapolate='quadratic') is not available for 3D rotations; "
                                      "use extrapolate=True (the secant on the rotation group)")
        older, newer = (np.asarray(s).reshape(-1, NSTATE) for s in states)
        from ..kernels.spatial import secant_quaternions

        secant_quaternions(self.state.x.array.reshape(-1, NSTATE), older, newer, -weights[0])

    def displacement_vector(self) -> PETSc.Vec:
        """Displacements in the layout of the corrections (rotational entries 0), for constraints."""
        arr = self._disp.x.array.reshape(-1, 6)
        arr[:, :3] = self.state.x.array.reshape(-1, NSTATE)[:, :3]
        return self._disp.vector

    @staticmethod
    def _dof_values(s: np.ndarray) -> np.ndarray:
        return np.concatenate([s[:3], compiled.rotvecs_from_quats(s[None, 3:7])[0]])

    def dof_values(self, blocks: np.ndarray) -> np.ndarray:
        """(len(blocks), 6) displacements and rotation vectors of local blocks (all nodes at once)."""
        st = self.state.x.array.reshape(-1, NSTATE)[np.asarray(blocks, dtype=np.int32)]
        out = np.empty((len(st), 6))
        out[:, :3] = st[:, :3]
        out[:, 3:] = compiled.rotvecs_from_quats(st[:, 3:7])
        return out

    def _rotation_values(self) -> np.ndarray:
        """Rotation vectors (blocks, 3) of the nodal quaternions (norm ≤ π)."""
        st = self.state.x.array.reshape(-1, NSTATE)
        return compiled.rotvecs_from_quats(st[:, 3:7])

    def prescribe(self, where: str, comp: int, value: float, amplitude=None, function=None,
                  condition: Condition | None = None) -> Condition:
        if comp >= self.translations and (value != 0.0 or function is not None):
            raise NotImplementedError(f"prescribe '{where}': non-zero rotations ({self.dof_names[comp]}) "
                                      "cannot be prescribed in 3D; prescribe displacements or apply a moment")
        return Part.prescribe(self, where, comp, value, amplitude, function, condition)


class Frame3D(Rotations3D, LineFrame):
    """Beams and bars on one 1D mesh with gdim = 3; dofs (ux, uy, uz, rx, ry, rz) per node,
    the rotational ones spatial spins composed multiplicatively with the nodal rotations."""

    gdim = 3
    dof_names = ("ux", "uy", "uz", "rx", "ry", "rz")
    translations = 3
    nprops = line_properties.NPROPS_3D
    kernels = OnFirstUse("beam3d")
    compiled_kernels = "beam3d_kernels"
    symmetric_tangent = False  # spatial spins: K is symmetric only at equilibrium under conservative loads

    def __init__(self, tmesh: TaggedMesh, large_rotations: bool):
        LineFrame.__init__(self, tmesh, large_rotations)
        self._init_state()
        # the distance from the axis at which each cell's section meets a contact surface
        self._contact_radius = np.zeros(len(self._owner_of_cell))

    def add_beam(self, where, section, material, kinematics, orientation, plane_strain=False) -> PartRef:
        if plane_strain:
            raise ValueError(f"beam '{where}': plane_strain is for 2D beams (a plate strip of unit width); "
                             "a beam in 3D has its own section")
        GAs = material.G * section.As if kinematics == "timoshenko" else 0.0
        self._contact_radius[self.tmesh.cells(where)] = section.contact_radius
        return self._add(where, {"EA": material.E * section.A, "GJ": material.G * section.torsion_constant,
                                 "EIy": material.E * section.second_moment_y, "EIz": material.E * section.I,
                                 "GAy": GAs, "GAz": GAs}, orientation, 0.0, "beam")

    def add_bars(self, where, EA: float, N0: float) -> PartRef:
        _, d = self._element_vectors(self.tmesh.cells(where))
        # any vector not parallel to the bars orients their (unused) local axes
        v = np.array([0.0, 0.0, 1.0]) if np.all(np.abs(d[:, 2]) < 0.9 * np.linalg.norm(d, axis=1)) \
            else np.array([1.0, 0.0, 0.0])
        return self._add(where, {"EA": EA, "GJ": 0.0, "EIy": 0.0, "EIz": 0.0, "GAy": 0.0, "GAz": 0.0}, v, N0,
                         "truss")

    def _add(self, where, values: dict, orientation, N0: float, kind: str):
        label = f"{kind} '{where}'"
        line_properties.check_props_3d(values, label)
        v = np.asarray(orientation, dtype=float)
        if v.shape != (3,) or not np.all(np.isfinite(v)) or np.linalg.norm(v) == 0.0:
            raise ValueError(f"{label}: orientation must be a non-zero 3-vector, got {orientation}")
        props = np.array([values["EA"], values["GJ"], values["EIy"], values["EIz"], values["GAy"], values["GAz"],
                          N0, *v])
        bending = values["EIy"] > 0.0 or values["EIz"] > 0.0
        return self.add_elements(where, props, bending, kind)

    section_components = ("N", "Vy", "Vz", "T", "My", "Mz")

    def element_results(self, cells: np.ndarray | None = None, label: str = "",
                        gather: bool = True) -> ElementResults:
        """Section forces (N, Vy, Vz, T, My, Mz) at both ends of every beam and bar, in the
        element's current axes (e1 along the chord, e2 from the nodal rotations of the section's
        y axis; the initial axes in a geometrically linear analysis): the resultant force and
        moment on the face whose outward normal is +e1 (−f₁ at end 1, +f₂ at end 2 of the nodal
        forces the element exerts, less its nodal share of a uniform load on it, as in 2D). N > 0
        in tension, T the torque; My > 0 puts the +e3 fibres in tension, Mz > 0 the −e2 fibres;
        dMy/ds = Vz, dMz/ds = −Vy."""
        cells = self._result_cells(cells)
        X, S = self._element_states(cells)
        values = np.empty((len(cells), 2, 6))
        axes = np.empty((len(cells), 3, 3))
        compiled.section_forces_all(np.ascontiguousarray(X), np.ascontiguousarray(S),
                                    np.ascontiguousarray(self.cell_properties(cells)), self.large_rotations,
                                    values, axes)
        span = self._span_loads(cells)  # less the span loads' nodal share, in the element's axes
        for end, sign in ((0, -1.0), (1, 1.0)):
            values[:, end, :3] -= sign * np.einsum("nij,nj->ni", axes, span[:, end, :3])
            values[:, end, 3:] -= sign * np.einsum("nij,nj->ni", axes, span[:, end, 3:])
        return self._gather_results("section forces", self.section_components, cells, self._current_points(cells),
                                    values, axes, label, gather)

    def surface(self, where: str, body: str | None = None) -> Surface:
        """The nodes of the beams of line group ``where`` as contact slaves: each meets a surface at
        its section's contact radius (``Section.outer``: a pipe's or a circle's outer radius, a
        rectangle's half depth) from the axis, on any side; the segments give each node its share of
        the beam's length."""
        cells = self.tmesh.cells(where)
        cells = cells[cells < self.tmesh.mesh.topology.index_map(1).size_local]
        seg_blocks = np.array([self.V.dofmap.cell_dofs(c) for c in cells], dtype=np.int64).reshape(-1, 2)
        if self.comm.allreduce(int(np.any(self._owner_of_cell[cells] == "")), op=MPI.MAX):
            raise SurfaceError(f"contact surface '{where}': some of its lines carry no beam")
        return gather_surface(self, where, seg_blocks, self.V.tabulate_dof_coordinates(),
                              offsets=self._contact_radius[cells], two_sided=True, modulus=None, cells=cells)

    def _drawn_sizes(self, cells: np.ndarray) -> np.ndarray:
        """The section's contact radius (a pipe's or a circle's outer radius, a rectangle's half depth)."""
        return self._contact_radius[cells]

    def _initial_axes(self, cells: np.ndarray, X: np.ndarray) -> np.ndarray:
        """(n, 3, 3) each element's reference axes: x along it, y the orientation vector's part
        normal to x, z = x × y (the beam's local axes)."""
        x = X[:, 1] - X[:, 0]
        x /= np.linalg.norm(x, axis=1)[:, None]
        v = self.cell_properties(cells)[:, -3:]
        y = v - np.einsum("ni,ni->n", v, x)[:, None] * x
        y /= np.linalg.norm(y, axis=1)[:, None]
        return np.stack([x, y, np.cross(x, y)], axis=1)

    def _check_geometry(self, cells, label, props):
        super()._check_geometry(cells, label, props)
        _, d = self._element_vectors(cells)
        v = props[-3:]
        c = np.abs(d @ v) / (np.linalg.norm(d, axis=1) * np.linalg.norm(v))
        bad = np.flatnonzero(c > 1.0 - 1e-8)
        self._refuse(cells, bad, f"{label}: the orientation vector {v.tolist()} is parallel to {{n}} "
                     "element(s), the first at {at}; choose one that fixes the local y axis", ValueError)

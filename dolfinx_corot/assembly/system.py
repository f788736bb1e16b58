r"""The nonlinear system that the solvers see: a sum of the parts' forms and of contributions.

:math:`\mathbf r(\mathbf x, \lambda) = \lambda\mathbf f_{ext} + \sum_g g(\lambda)\mathbf f_g
- \mathbf f_{int}(\mathbf x)`, with f_int the parts' internal forces (their forms,
assembled by DOLFINx) plus the forces of every
:class:`~dolfinx_corot.assembly.contribution.Contribution` (contact today).
The tangent is the parts' matrix plus the contributions' blocks, gathered in a
matrix over the union of their declared couplings (built once per change of
couplings). The system also relays Newton's hooks to the contributions and
holds their state with the parts' for step cutting and checkpoint files.

:class:`System` is one part model on one mesh (DOLFINx's own layout);
:class:`CoupledSystem` stacks models on several meshes with a
:class:`~dolfinx_corot.assembly.layout.DofLayout`. Newton increments are
homogeneous on supported dofs. The system knows nothing about beams or contact.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from typing import Protocol, Sequence

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc

from .. import _dolfinx, validate
from . import petsc
from .contribution import Contribution
from .layout import DofLayout

logger = logging.getLogger(__name__)
_EPS = float(np.finfo(float).eps)


class Model(Protocol):
    """What :class:`System` and the drivers need from the assembled part(s)."""

    V: dolfinx.fem.FunctionSpace                              # space of the Newton corrections
    state: dolfinx.fem.Function                               # the configuration (kernels' coefficient)
    symmetric_tangent: bool                                   # LDLᵀ allowed
    symmetric_at_equilibrium: bool                            # its symmetric part may stand for K
    has_prescribed_motion: bool
    amplitudes: list                                          # distinct load amplitudes (None: ∝ λ)
    large_rotations: bool
    continuum: bool                                           # a continuum alone (AMG may solve it)
    coupled: bool                                             # parts on several meshes (``models``)
    lifting_bcs: list                                         # the bcs of prescribed motion

    def forms(self) -> tuple[object, object]: ...            # (vector form, matrix form)
    def dirichlet_bcs(self) -> list: ...                        # supports and prescribed motion
    def set_load_factor(self, load_factor: float) -> None: ...  # prescribed values at λ
    def set_follower_factor(self, load_factor: float) -> None: ...  # follower loads' factor at λ
    def follower_form(self): ...                               # follower loads (a linear form) or None
    def external_force(self, b: PETSc.Vec, amplitude=None) -> None: ...  # unit loads of one amplitude
    def displacement_vector(self) -> PETSc.Vec: ...             # x in the layout of V (constraints)
    def update(self, dx: PETSc.Vec) -> None: ...                # x ← x ⊕ dx
    def extrapolate(self, older: object, newer: object, factor: float) -> None: ...
    def combine(self, states: list, weights: list[float]) -> None: ...   # x = Σ wᵢ xᵢ
    def checkpoint(self) -> object: ...
    def restore(self, cp: object) -> None: ...
    def to_global(self, local: np.ndarray) -> np.ndarray | None: ...   # for checkpoint files
    def from_global(self, values: np.ndarray) -> np.ndarray: ...


@dataclass
class Timings:
    """Accumulated wall time (s) of the phases of the Newton iterations; ``contributions``:
    the part of assembly spent in contributions (search, kernels, their matrix)."""

    assembly: float = 0.0
    solve: float = 0.0
    update: float = 0.0
    contributions: float = 0.0

    def copy(self) -> "Timings":
        return Timings(self.assembly, self.solve, self.update, self.contributions)


class System:
    """Nonlinear system r(x, λ) = λ f_ext − f_int(x) = 0 of one model plus contributions.

    solver: 'direct' (MUMPS LDLᵀ when ``symmetric``, else LU) or 'iterative'
    (CG + AMG with the rigid-body near-nullspace, on a block matrix; see
    :class:`~dolfinx_corot.assembly.petsc.LinearSolver`).
    contributions: :class:`~dolfinx_corot.assembly.contribution.Contribution` objects
    (e.g. the scene's contact) summed into the residual and tangent.
    tangent: 'consistent' (K = ∂f/∂x as the parts give it), 'symmetrized' (½(K + Kᵀ) for parts
    whose tangent is symmetric at equilibrium: 3D beams, shells, membranes), or 'auto' (the
    symmetric part where its skew part vanishes at equilibrium; see :meth:`symmetrize`).
    """

    _cells = None  # the compiled assembly of the parts' tangent (assembly.cells), where it serves
    linear = None

    @property
    def A(self) -> PETSc.Mat:
        """The tangent as an AIJ matrix. Where the iterative solver's symmetric block operator
        alone was assembled (:meth:`_assemble_parts_matrix`), A's values are made from it first."""
        if self.linear is not None:
            self.linear.sync_aij()
        return self._A

    def __init__(self, model: Model, options_prefix: str = "dc_newton_", symmetric: bool | None = None,
                 solver: str = "direct", contributions: Sequence[Contribution] = (), tangent: str = "auto"):
        validate.choice("System", "tangent", tangent, validate.TANGENTS)
        self.model = model
        self.comm = model.comm
        self._mat_type = None  # AIJ (with the nodal block size): what MUMPS and AMG read
        self._build()
        self.fint, self.dx, self.step_dx, self.lift, self.fext_total, self._rhs = petsc.duplicate(self.b, 6)
        self.has_prescribed_motion = bool(model.has_prescribed_motion)
        self.load_factor = 0.0
        self.fext = self._external_force(None)
        self.reference_load_norm = self.fext.norm()
        # loads with their own amplitudes g(λ)
        self.amplitude_loads = [(amp, self._external_force(amp)) for amp in model.amplitudes]
        self.timings = Timings()
        self.contributions = list(contributions)
        if self.contributions and solver == "iterative":
            raise NotImplementedError(f"{self.contributions[0].name} needs the direct solver "
                                      "(linear_solver='direct' or 'auto')")
        for c in self.contributions:
            c.bind(self)
        # contributions that are loads following the configuration add to the external forces
        self._load_contributions = [c for c in self.contributions if c.follows_configuration]
        self._force_contributions = [c for c in self.contributions if not c.follows_configuration]
        # the parts' own follower loads (a solid's pressure): linear forms at the current configuration
        self._follower_forms = [m.follower_form() for m in self.models]
        has_forms = any(f is not None for f in self._follower_forms)
        self.fload = petsc.duplicate(self.b) if (self._load_contributions or has_forms) else None
        self._version = 0          # counts changes of the configuration
        self._residual_at = None   # (configuration, load factor) of the last residual
        self._tangent_version = -1  # the configuration of a tangent assembled ahead (tangent_at)
        self.C: PETSc.Mat | None = None   # the contributions' matrix over their declared couplings
        self._merged = False
        self.pattern_builds = 0
        self.engaged = False
        self.tangent = tangent if symmetric is None else "consistent"  # a factorization asked for: K as it is
        self.symmetrized = False
        self._resymmetrize = False
        self.consistent_retries = 0  # steps taken again with the consistent tangent
        if symmetric is None:
            symmetric = model.symmetric_tangent
        self._symmetric = symmetric
        # a contribution whose tangent is not symmetric (mortar contact) makes the direct solver
        # factorize by LU while it is engaged, by LDLᵀ otherwise: an idle one changes nothing
        self._unsymmetric = any(not c.symmetric_tangent for c in self.contributions)
        self.iterative = solver == "iterative"
        nullspace = None
        if self.iterative:
            nullspace = petsc.near_nullspace(self.comm, model.V.dofmap.index_map, model.V.dofmap.index_map_bs,
                                             model.near_nullspace_modes())
        prolongator = None
        if self.iterative and model.large_rotations and hasattr(model, "patch_rotations"):
            from .amg import CorotatedProlongator as prolongator
        # the tangent assembled into the iterative solver's upper block triangle alone where it
        # can be (:meth:`_upper_operator`; ``-<prefix>upper_assembly false``: into A, then copied)
        self._upper_assembly = PETSc.Options().getBool(options_prefix + "upper_assembly", True)
        self.linear = petsc.LinearSolver(self.comm, self._A, self.iterative, symmetric, options_prefix, nullspace,
                                         fixed_rtol=not model.large_rotations, prolongator=prolongator)
        self._current_modes = self.iterative and model.large_rotations
        self._modes_version = self._version
        # the AMG hierarchy: the positions it was built at, and whether the configuration has
        # changed since its last set-up (see reuse_preconditioner)
        self._amg_stale = False
        self._amg_built_at = model.positions().copy() if self._current_modes and hasattr(model, "positions") else None
        self._amg_period = (0, 0)  # (Krylov iterations, solves) when the last set-up was decided
        self._amg_reference = None  # CG iterations a solve in the first period after a build
        self.amg_builds = 0  # hierarchies built anew at a new configuration (the first one not counted)
        self.amg_corotations = 0  # hierarchies kept and co-rotated
        self._fields_setup()
        self._choose_tangent()

    # -- layout (one mesh: DOLFINx's own) -------------------------------------------
    def _build(self) -> None:
        self.L, self.a = self.model.forms()
        self._test_space = self.a.function_spaces[0]
        self.bcs = self.model.dirichlet_bcs()
        self._A = petsc.form_matrix(self.a, self._mat_type)
        self.b = petsc.form_vector(self.L)
        # a large continuum's tangent is assembled into A's values by a compiled loop
        # (:mod:`.cells`), A's pattern laid out from the form's sparsity before the first
        self._cells = None
        self._cells_checked = False

    def _external_force(self, amplitude) -> PETSc.Vec:
        """Assembled unit external load of one amplitude (None: the loads proportional to λ)."""
        v = petsc.duplicate(self.b)
        with v.localForm() as f:
            f.set(0.0)
        self.model.external_force(v, amplitude)
        v.assemble()
        return v

    def _assemble_parts(self) -> None:
        with self.fint.localForm() as f:
            f.set(0.0)
            _dolfinx.assemble_vector_into(f.array_w, self.L)
        self.fint.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)

    def _assemble_follower_forms(self) -> None:
        """fload = the parts' follower loads at the current configuration and load factor."""
        with self.fload.localForm() as f:
            f.set(0.0)
        if self._follower_forms[0] is not None:
            dolfinx.fem.petsc.assemble_vector(self.fload, self._follower_forms[0])
        self.fload.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)

    def _assemble_fint(self) -> None:
        self._assemble_parts()
        if self.fload is not None:
            self._assemble_follower_forms()
        if self.contributions:
            t = time.perf_counter()
            self._add_blocks(self.fint, lambda c, add: c.add_residual(add), self._force_contributions)
            if self._load_contributions:
                self._add_blocks(self.fload, lambda c, add: c.add_residual(add), self._load_contributions)
            # something is near: the contributions' matrix and Newton's safeguards are needed
            self.engaged = bool(self._reduce(any(c.engaged() for c in self.contributions), MPI.LOR))
            self.timings.contributions += time.perf_counter() - t

    def _add_blocks(self, vec: PETSc.Vec, call, contributions=None) -> None:
        """vec += the blocks each contribution (of ``contributions``; default: all) adds through
        ``call(contribution, add)`` (global dofs)."""
        def add(dofs, values):
            d = np.asarray(dofs).ravel().astype(PETSc.IntType)
            v = np.asarray(values, dtype=float).ravel()
            free = d >= 0  # (a vector, unlike a matrix, does not skip negative indices)
            vec.setValues(d[free], v[free], addv=PETSc.InsertMode.ADD_VALUES)

        for c in (self.contributions if contributions is None else contributions):
            call(c, add)
        vec.assemblyBegin()
        vec.assemblyEnd()

    def _constrain_residual(self, load_factor: float) -> None:
        x = self.model.displacement_vector()
        if self.has_prescribed_motion:
            self.model.set_load_factor(load_factor)
            with self.lift.localForm() as f:
                f.set(0.0)
            # supports never move (x = 0 there): only prescribed motion has a lifting
            lifting_bcs = self.model.lifting_bcs
            dolfinx.fem.petsc.apply_lifting(self.lift, [self.a], bcs=[lifting_bcs], x0=[x], scale=1.0)
            self.lift.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            self.b.axpy(1.0, self.lift)
        dolfinx.fem.petsc.set_bc(self.b, self.bcs, x, 1.0)

    def model_array(self, model, vec: PETSc.Vec) -> np.ndarray:
        """Local values (owned and ghost) of ``vec`` in the layout of ``model.V``."""
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with vec.localForm() as f:
            return f.array.copy()

    @property
    def models(self) -> list:
        """The part models of the system."""
        return [self.model]

    # -- checkpoint files: node-ordered arrays -------------------------------------
    def global_arrays(self, vectors: dict) -> dict:
        """Configuration, contribution states and vectors as node-ordered arrays on rank 0."""
        arrays = {}
        for i, m in enumerate(self.models):
            arrays[f"state{i}"] = m.to_global(m.state.x.array)
            for name, vec in vectors.items():
                arrays[f"{name}{i}"] = m.to_global(self.model_array(m, vec))
        for i, c in enumerate(self.contributions):
            for key, value in c.state_arrays().items():
                arrays[f"contribution{i}_{key}"] = value
        return arrays

    def set_global_arrays(self, arrays: dict) -> None:
        """Restore configuration and contribution states from :meth:`global_arrays`' output."""
        self._version += 1
        for i, m in enumerate(self.models):
            m.state.x.array[:] = m.from_global(arrays[f"state{i}"])
        for i, c in enumerate(self.contributions):
            prefix = f"contribution{i}_"
            c.set_state_arrays({k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)})

    def global_to_vector(self, arrays: dict, name: str, vec: PETSc.Vec) -> None:
        """Fill ``vec`` (owned and ghost) from the arrays of :meth:`global_arrays` (entry ``name``)."""
        with vec.localForm() as v:
            v.array[:] = self.model.from_global(arrays[f"{name}0"])

    # -- residual -----------------------------------------------------------
    def residual(self, load_factor: float) -> tuple[float, float]:
        """Assemble b = λ f_ext + Σ g(λ) f_g − f_int; on constrained dofs b = ū(λ) − x (0 on supports).

        With prescribed displacements the columns of constrained dofs are
        lifted, b_f −= K_fc (ū − x)_c, so that one Newton correction honours
        them exactly. Returns (‖b‖, reference force norm) where the
        reference is the larger of the external load's norm and ‖f_int‖ over
        all dofs (reactions included).
        """
        t = time.perf_counter()
        self.load_factor = load_factor
        for m in self.models:
            m.set_follower_factor(load_factor)
        self._assemble_fint()
        self.fext.copy(self.fext_total)
        self.fext_total.scale(load_factor)
        for amp, v in self.amplitude_loads:
            self.fext_total.axpy(amp(load_factor), v)
        if self.fload is not None:  # follower loads at this configuration and load factor
            self.fext_total.axpy(1.0, self.fload)
        self.fext_total.copy(self.b)
        self.b.axpy(-1.0, self.fint)
        self._constrain_residual(load_factor)
        squares = self._reduce(self._field_squares((self.b, self.fext_total, self.fint)), MPI.SUM)
        norm = math.sqrt(squares[0] + squares[1])
        ref = max(math.sqrt(squares[2] + squares[3]), math.sqrt(squares[4] + squares[5]))
        # per field (forces; moments on rotational dofs), each against its own scale
        ref_f = max(math.sqrt(squares[2]), math.sqrt(squares[4]))
        self.fields = {"force": (math.sqrt(squares[0]), ref_f)}
        if self.has_rotations:
            ref_m = max(math.sqrt(squares[3]), math.sqrt(squares[5]))
            ell = self.element_length
            self.fields = {"force": (math.sqrt(squares[0]), max(ref_f, ref_m / ell if ell > 0.0 else 0.0)),
                           "moment": (math.sqrt(squares[1]), max(ref_m, ell * ref_f))}
        self.timings.assembly += time.perf_counter() - t
        self._residual_at = (self._version, load_factor)
        return norm, ref

    def _field_squares(self, vectors) -> np.ndarray:
        """Σ a² over the owned entries of each vector, per field: [v₀ force, v₀ moment, v₁ force, …]."""
        A = self._squares_buffer[: len(vectors)]
        for k, v in enumerate(vectors):
            A[k] = v.array_r
        if A.size and not np.abs(A).max() < 1e150:
            with np.errstate(over="ignore"):  # loads beyond floating point: an infinite norm, reported
                return np.concatenate([np.bincount(self._field, a * a, 2) for a in A])
        return ((A * A) @ self._membership).ravel()  # (one product for all: small systems)

    def _reduce(self, value, op):
        """``comm.allreduce`` of the Newton loop's small values; on one rank the value itself
        (mpi4py's pickling allreduce costs 40 µs a call even then)."""
        return value if self.comm.size == 1 else self.comm.allreduce(value, op=op)

    # -- convergence measures: fields and the round-off floor -------------------------
    def _rotation_mask(self) -> np.ndarray:
        """Owned entries of the system's vectors that are rotations (True) or translations."""
        m = self.model
        mask = np.zeros((self.b.getLocalSize() // m.ndof, m.ndof), dtype=bool)
        mask[:, m.translations:] = True
        return mask.ravel()

    def _fields_setup(self) -> None:
        """Which dofs carry moments; the model's length and coordinate scales (round-off floor)."""
        self._rot = self._rotation_mask()
        self._field = self._rot.astype(np.intp)  # 0: force, 1: moment
        self._membership = np.stack([~self._rot, self._rot], axis=1).astype(float)  # (owned, 2)
        self._squares_buffer = np.empty((3, len(self._rot)))
        self.has_rotations = bool(self._reduce(int(self._rot.any()), MPI.MAX))
        lo, hi = [], []
        for m in self.models:
            X = m.V.mesh.geometry.x[:, : m.gdim]
            if len(X):
                lo.append(X.min(axis=0))
                hi.append(X.max(axis=0))
        gd = self.models[0].gdim
        lo_all, hi_all = np.empty(gd), np.empty(gd)
        self.comm.Allreduce(np.min(lo, axis=0) if lo else np.full(gd, np.inf), lo_all, op=MPI.MIN)
        self.comm.Allreduce(np.max(hi, axis=0) if hi else np.full(gd, -np.inf), hi_all, op=MPI.MAX)
        lo, hi = lo_all, hi_all
        self.length_scale = float(np.linalg.norm(hi - lo))
        # the mean element side of the parts with rotations: nodal forces that balance moments M
        # in an element of side h are of order M/h
        total = np.zeros(2)
        for m in self.models:
            if m.ndof == m.translations:
                continue
            geometry = m.V.mesh.geometry
            n_owned = m.V.mesh.topology.index_map(m.V.mesh.topology.dim).size_local
            if n_owned == 0:  # a rank without cells of this part
                continue
            cells = geometry.dofmap.array.reshape(-1, geometry.dofmap.offsets[1])
            x = geometry.x[cells[:n_owned]]
            sides = np.linalg.norm(x - np.roll(x, 1, axis=1), axis=2)
            total += (sides.sum(), sides.size)
        total = self._reduce(total, MPI.SUM)
        self.element_length = float(total[0] / total[1]) if total[1] else self.length_scale
        self._coordinates = self._dof_coordinates()
        self._coordinates[self._rot] = 1.0
        self.floors = {"force": 0.0, "moment": 0.0}
        self._diagonal = None

    def _dof_coordinates(self) -> np.ndarray:
        """Owned entries: the distance of each dof's node from the origin (reference)."""
        m = self.model
        n = self.b.getLocalSize() // m.ndof
        X = m.V.tabulate_dof_coordinates()[:n, : m.gdim]
        return np.repeat(np.linalg.norm(X, axis=1), m.ndof)

    def _update_floor(self) -> None:
        """The residual's round-off floor per field, from the tangent just assembled: an internal
        force computed from coordinates of size c_i carries errors of about ε K_ii c_i on dof i
        (ε K_ii on a rotation, angles of order one), so no residual below
        ε ‖diag(K) c‖ can be told from zero."""
        dc = self._tangent_diagonal() * self._coordinates  # (rotations: coordinate 1)
        dc *= dc
        sq = self._reduce(dc @ self._membership, MPI.SUM)
        self.floors = {"force": _EPS * math.sqrt(sq[0]), "moment": _EPS * math.sqrt(sq[1])}

    def _tangent_diagonal(self) -> np.ndarray:
        """The owned diagonal of A: read by the compiled loop where it assembles A (bisection in
        each row; PETSc's MatGetDiagonal scans rows from their start, 14 ms on the 116 k-dof
        block against 1 ms), else PETSc's."""
        operator = self._upper_operator()
        if operator is not None and operator.upper_newer:
            return operator.diagonal()
        if self._cells is not None and self._A.getType() in ("seqaij", "mpiaij"):
            from . import cells

            if self.comm.size == 1:
                with petsc.SeqAIJArrays(self._A, write=False) as (indptr, indices, values):
                    return cells.diagonal(indptr, indices, values)
            with petsc.MPIAIJArrays(self._A, write=False) as ((indptr, indices, values), _, _):
                return cells.diagonal(indptr, indices, values)
        if self._diagonal is None:
            self._diagonal = self._A.createVecLeft()
        self._A.getDiagonal(self._diagonal)
        return self._diagonal.array_r

    def correction_norms(self) -> dict[str, tuple[float, float]]:
        """Per field: (‖dx‖, ‖Σ corrections of the step‖) — translations, rotations."""
        sq = np.sqrt(self._reduce(self._field_squares((self.dx, self.step_dx)), MPI.SUM))
        out = {"force": (sq[0], sq[2])}
        if self.has_rotations:
            out["moment"] = (sq[1], sq[3])
        return out

    def _upper_operator(self):
        """The iterative solver's symmetric block operator where the tangent is assembled into it
        alone (the compiled assembly, CG on the upper block triangle; the solver has no
        contributions), else None. The AIJ matrix A is then filled from it only where it is read:
        the AMG's set-up (once on the SVK block of benchmarks/block3d.py, whose hierarchy is kept
        and co-rotated), a fallback LU, the stability checks (:attr:`A`). The first tangent goes
        into A, whose copy the first solve makes the operator from: the AMG's set-up reads A then
        (the copy costs less than A's mirror image from the operator would)."""
        if self._cells is None or not self.iterative or self.contributions or not self._upper_assembly:
            return None
        operator = self.linear.operator
        return operator if operator is not None and operator.direct else None

    def _assemble_parts_matrix(self) -> None:
        if self._cells is not None:
            operator = self._upper_operator()
            if operator is not None:
                operator.assemble_upper(self._cells.assemble_upper)
                return
            if self.comm.size == 1:
                with petsc.SeqAIJArrays(self._A) as (indptr, indices, values):
                    values[:] = 0.0
                    self._cells.assemble(indptr, indices, values)
                return
            with petsc.MPIAIJArrays(self._A) as ((indptr, indices, values), (ip, ix, v), colmap):
                values[:] = 0.0
                v[:] = 0.0
                rows, columns, ghost = self._cells.assemble(indptr, indices, values, (ip, ix, v, colmap))
            if len(rows):  # the rows of ghost nodes, to their owners
                self._A.setValuesBlockedLocalRCV(rows, columns, ghost, addv=PETSc.InsertMode.ADD_VALUES)
            self._A.assemble()
            return
        if not self._cells_checked:
            self._cells_checked = True
            self._cells = self._cell_assembler()
            if self._cells is not None:
                # A's pattern laid out from the form's sparsity, so that the compiled loop assembles
                # the first tangent too (DOLFINx's insertion of it took 0.4–0.8 s on the 116 k-dof block, this 0.2 s)
                from . import cells

                petsc.lay_out(self._A, *cells.expand_blocks(*_dolfinx.form_sparsity(self.a), self._A.getBlockSize()))
                self._assemble_parts_matrix()
                return
        self._A.zeroEntries()
        _dolfinx.assemble_matrix_with_bcs(self._A, self.a, self.bcs, self._test_space)
        self._A.assemble()

    def _cell_assembler(self):
        """The compiled assembly of the parts' tangent (:mod:`.cells`), or None where DOLFINx's
        stays: forms other than FFCx forms of cell integrals, small meshes, int64 indices (the
        same choice on every rank: both assemblies communicate the rows of ghost nodes, each in
        its own calls). Contributions (contact) merge their couplings into A's pattern, so that a
        node's rows may differ in their columns: the loop checks each row's layout."""
        from . import cells

        parts = None
        try:
            if self._A.getType() in ("seqaij", "mpiaij") and np.dtype(PETSc.IntType) == np.int32:
                parts = _dolfinx.cell_integrals(self.a, self.bcs)
            ok = parts is not None and sum(len(c) for _, c, _ in parts[0]) >= cells.MIN_CELLS
            if ok:
                cells.compiled()
        except Exception as err:  # e.g. no compiler or no writable cache: DOLFINx's assembly stays
            logger.warning("the compiled tangent assembly is not available (%s); DOLFINx assembles it", err)
            ok = False
        space = self.a.function_spaces[0]
        im, bs = space.dofmap.index_map, space.dofmap.index_map_bs
        if self.comm.size > 1:
            ok = bool(self.comm.allreduce(int(ok), op=MPI.MIN))
        if not ok:
            return None
        return cells.CellAssembler(*parts, size=(im.size_local + im.num_ghosts) * bs, owned=im.size_local,
                                   ghosts=np.asarray(im.ghosts, dtype=np.int64) * bs)

    def jacobian(self) -> None:
        """Assemble the tangent K = ∂f_int/∂x (parts and contributions), identity rows/columns on
        supports; a tangent that :meth:`tangent_at` assembled at this very configuration is kept
        (parts alone: it depends on the configuration only)."""
        if self._tangent_version == self._version and self.tangent_reusable:
            self._tangent_version = -1
            return
        t = time.perf_counter()
        self._assemble_parts_matrix()
        self._add_contribution_tangents()
        self._constrain_matrix()
        self._update_floor()
        self.timings.assembly += time.perf_counter() - t

    def _constrain_matrix(self) -> None:
        """Constrained rows and columns (DOLFINx's assembly did them for one mesh)."""

    def _add_contribution_tangents(self) -> None:
        """A += C, the contributions' tangent blocks in a matrix over their declared couplings
        (nothing while no contribution is engaged: bodies far apart cost a search, no matrix work)."""
        if not self.engaged:
            return
        t = time.perf_counter()
        A = self._A
        if self.C is None or any(c.couplings_changed for c in self.contributions):
            self._build_couplings(A)
        C = self.C
        C.zeroEntries()

        def add(dofs, K):
            d = np.asarray(dofs).astype(PETSc.IntType)
            if d.shape[0] == 0:  # a rank with none of the contribution's dofs (PETSc divides by the row count)
                return
            C.setValuesRCV(d, d, K, addv=PETSc.InsertMode.ADD_VALUES)

        for c in self.contributions:
            c.add_tangent(add)
        C.assemble()
        lgmap = A.getLGMap()
        A.axpy(1.0, C, PETSc.Mat.Structure.SUBSET if self._merged else PETSc.Mat.Structure.DIFFERENT)
        if not self._merged:
            A.setLGMap(*lgmap)  # a new pattern replaces the matrix's internals
            self._merged = True
        self.timings.contributions += time.perf_counter() - t

    def _build_couplings(self, A: PETSc.Mat) -> None:
        """C's pattern: the dense blocks every contribution of every rank declares."""
        # each entry (row, column) as one key row × size + column: sorting and merging keys is
        # several times faster than rows of pairs (a smoothed 3D master's pair couples ~50 dofs)
        size = np.int64(A.getSize()[0])
        keys = []
        for c in self.contributions:
            dofs = c.couplings().astype(np.int64)
            if dofs.size:
                n = dofs.shape[1]
                r, q = np.repeat(dofs, n, axis=1).ravel(), np.tile(dofs, (1, n)).ravel()
                keep = (r >= 0) & (q >= 0)
                keys.append(np.unique(r[keep] * size + q[keep]))
        local = np.unique(np.concatenate(keys)) if keys else np.zeros(0, dtype=np.int64)
        allkeys = np.unique(np.concatenate(self.comm.allgather(local)))
        allentries = np.column_stack([allkeys // size, allkeys % size])
        petsc.destroy(self.C)
        self.C = petsc.coupling_matrix(self.comm, A.getSizes(), self.ownership_range(), allentries)
        self._merged = False
        self.pattern_builds += 1
        for c in self.contributions:
            c.couplings_changed = False

    # -- linear solves ------------------------------------------------------------
    def solve(self, rhs: PETSc.Vec | None = None, out: PETSc.Vec | None = None) -> float:
        """Solve K out = rhs (default K dx = b) with the last tangent; return ‖out‖."""
        rhs = self.b if rhs is None else rhs
        out = self.dx if out is None else out
        t = time.perf_counter()
        try:
            self._choose_factorization()
            if self._amg_stale:
                self._refresh_amg()
            self.linear.solve(rhs, out)
        finally:
            self.timings.solve += time.perf_counter() - t
        return out.norm()

    def _choose_factorization(self) -> None:
        self.linear.set_symmetric(self._symmetric and not (self._unsymmetric and self.engaged))

    # -- the symmetric part of a tangent that is symmetric at equilibrium -------------------
    def skew_at_equilibrium(self) -> list[str]:
        """Why the skew part of the parts' tangent may not vanish at equilibrium (empty: it
        does). The tangent of 3D rotations with respect to spatial spins has the skew part
        −½ spin(m) on each node's rotations, m the node's moment sum, which equilibrium makes zero
        on the free rotations unless a moment is applied there, or a node has exactly one of its
        three rotations held (its reaction couples the two free ones); follower loads and
        contributions (contact, stabilising springs) add load stiffnesses of their own. A
        geometrically linear analysis has K = B₀ᵀ K̄ B₀, symmetric as it is: only follower
        loads count there."""
        if not self.model.large_rotations:
            return ["follower loads"] if self.fload is not None else []
        reasons = []
        if self._force_contributions:
            names = sorted({type(c).__name__ for c in self._force_contributions})
            reasons.append("contributions (" + ", ".join(names) + ")")
        if self.fload is not None:
            reasons.append("follower loads")
        rot = self._rot
        loads = [self.fext] + [v for _, v in self.amplitude_loads]
        if self._reduce(bool(any(np.any(v.array_r[rot] != 0.0) for v in loads)), MPI.LOR):
            reasons.append("applied moments")
        if self._reduce(bool(self._one_rotation_held()), MPI.LOR):
            reasons.append("nodes with one of their three rotations held")
        return reasons

    def _one_rotation_held(self) -> bool:
        """Whether a local node of a model with 3D rotations has exactly one rotation constrained."""
        held = np.zeros(self._local_size(), dtype=bool)
        for bc in self.bcs:
            held[bc.dof_indices()[0]] = True
        m = self.model
        if m.ndof != 6:
            return False
        return bool(np.any(held.reshape(-1, 6)[:, 3:].sum(axis=1) == 1))

    def _local_size(self) -> int:
        with self.b.localForm() as f:
            return f.getSize()

    def _choose_tangent(self) -> None:
        """Symmetrize the tangent (and factorize it by LDLᵀ) as ``tangent`` asks: always for
        'symmetrized', for 'auto' where :meth:`skew_at_equilibrium` finds nothing."""
        model = self.model
        if self.tangent == "consistent" or self.iterative or model.symmetric_tangent \
                or not model.symmetric_at_equilibrium:
            if self.tangent == "symmetrized" and not model.symmetric_tangent and not self.iterative:
                raise ValueError("tangent='symmetrized' is for 3D beams, shells and membranes (their tangent "
                                 "is symmetric at equilibrium); this model's is not (a pressure on an open "
                                 "surface of a solid?)")
            return
        if self.tangent == "auto" and self.linear.dense is not None:
            # a small serial system goes to LAPACK, whose LU and separate inertia count beat
            # MUMPS's LDLᵀ there (the 45° bend, 54 dofs: 85–97 against 100 ms for 100 iterations)
            return
        reasons = self.skew_at_equilibrium()
        if self.tangent == "symmetrized":
            hard = [r for r in reasons if r == "follower loads"] + (["unsymmetric contributions"] if self._unsymmetric else [])
            if hard:
                raise ValueError(f"tangent='symmetrized' with {' and '.join(hard)}: their load stiffness is not "
                                 "symmetric even at equilibrium; use tangent='consistent' or 'auto'")
            self.symmetrize(True)
        else:
            self.symmetrize(not reasons)
            if reasons:
                logger.info("tangent: the consistent one (LU); its skew part does not vanish at equilibrium: %s",
                            "; ".join(reasons))
            else:
                logger.info("tangent: its symmetric part (LDLᵀ); the skew part vanishes at equilibrium")

    def symmetrize(self, on: bool) -> None:
        """The parts' kernels hand over ½(K + Kᵀ), factorized by LDLᵀ (``on``), or K (LU).

        Where the skew part of K vanishes at equilibrium, it is of the order of the residual, so
        Newton with the symmetric part still converges quadratically, and the symmetric part is
        what stability is judged by: LDLᵀ takes about two thirds of LU's time and counts the
        negative eigenvalues with it (the pull-out of an open cylinder, 5 550 dofs: the same
        Newton iterations within one, the same answer to 1e-14, a Newton solve 24 against 38 ms,
        and no separate LDLᵀ of the symmetric part per step). In a geometrically linear analysis
        the kernels' K is symmetric already and only the factorization changes."""
        self.model.symmetrize_tangent(on)
        self.symmetrized = bool(on)
        self._symmetric = bool(on) or self.model.symmetric_tangent
        self._choose_factorization()

    def set_forcing(self, eta: float | None) -> None:
        self.linear.set_forcing(eta)

    def reuse_preconditioner(self, reuse: bool) -> None:
        """Keep (True) or set up anew (False) the iterative solver's preconditioner for the
        next solves. For a large-deformation continuum at a new configuration the AMG follows
        the rigid-body modes of the current configuration (a total-Lagrangian tangent is nearly
        singular for infinitesimal rotations of x = X + u, not of X; the 116 k-dof SVK block: a
        third fewer CG iterations): its hierarchy co-rotated or built anew at the next solve
        (:meth:`_refresh_amg`)."""
        if not reuse and self._current_modes and self._modes_version != self._version:
            self._modes_version = self._version
            self._amg_stale = True  # decided at the next solve
        self.linear.reuse_preconditioner(reuse)

    def _refresh_amg(self) -> None:
        """The AMG hierarchy for a new configuration, before the solve that sets it up: kept
        and co-rotated (:mod:`dolfinx_corot.assembly.amg`: its finest prolongator turned by
        the nodal rotations since it was built, its coarse operators kept), or built anew with the rigid-body modes of the current configuration. Anew
        when there is none to keep, and when its CG iterations a solve since the last decision
        exceed 1.5 times (+ 2) those of the first period after its build: the co-rotation follows
        the material's rotation, not the change of its strain and stress."""
        self._amg_stale = False
        model, linear = self.model, self.linear
        its, solves = linear.krylov_iterations, linear.solves
        period = ((its - self._amg_period[0]) / (solves - self._amg_period[1])
                  if solves > self._amg_period[1] else None)
        self._amg_period = (its, solves)
        if self._amg_reference is None:
            self._amg_reference = period
        grown = (period is not None and self._amg_reference is not None
                 and period > 1.5 * self._amg_reference + 2.0)
        kept = linear.prolongator is not None and linear.prolongator.current(linear.ksp.getPC())
        if (self._amg_built_at is not None and not grown and self.comm.allreduce(kept, op=MPI.LAND)
                and linear.corotate(model.patch_rotations(self._amg_built_at))):
            self.amg_corotations += 1
            return
        if grown:
            logger.debug("AMG built anew: %.1f CG iterations a solve against %.1f after its last build",
                         period, self._amg_reference)
        linear.set_near_nullspace(petsc.near_nullspace(
            self.comm, model.V.dofmap.index_map, model.V.dofmap.index_map_bs, model.near_nullspace_modes()))
        if self._amg_built_at is not None:
            self._amg_built_at = model.positions().copy()
        self._amg_reference = None
        self.amg_builds += 1

    def negative_eigenvalues(self) -> int | None:
        return self.linear.negative_eigenvalues()

    # -- stability of the tangent -----------------------------------------------------
    @property
    def counts_inertia(self) -> bool:
        """Whether every factorization of the Newton solver counts negative eigenvalues (LDLᵀ)."""
        return self.linear.ldlt

    def take_inertia(self) -> tuple[list[int], list[int]]:
        """(negative-eigenvalue counts, determinant signs) of the tangents factorized since the
        last call (LDLᵀ gives counts, LU signs)."""
        return self.linear.take_inertia()

    @property
    def tangent_reusable(self) -> bool:
        # contributions may change their pairs when a solve begins; prescribed motion of coupled
        # parts is lifted while the tangent is constrained
        return not self.contributions and not (self.model.coupled and self.has_prescribed_motion)

    @property
    def smooth(self) -> bool:
        """Whether the equilibrium path is smooth in the unknowns: no contribution whose active set
        may change along it (a gap that closes, a stick that slips), so that a stable step that goes
        far beyond its tangent's prediction has leapt (:mod:`dolfinx_corot.solvers.control`)."""
        return not self.contributions

    def tangent_at(self, load_factor: float, factorize: bool = True) -> None:
        """Assemble (and, with a direct solver, factorize) the tangent at the current configuration,
        its contributions evaluated there; the next Newton solve from here uses it as it is."""
        self._tangent_version = -1
        if self.contributions or self._residual_at != (self._version, load_factor):
            self.residual(load_factor)  # (parts alone: the last residual, at this very state, will do)
        self.jacobian()
        self._tangent_version = self._version
        if factorize:
            t = time.perf_counter()
            self._choose_factorization()
            self.linear.factorize()
            self.timings.solve += time.perf_counter() - t

    def inertia(self) -> int:
        """Negative eigenvalues of the symmetric part of the last assembled tangent (an LDLᵀ
        factorization of its own; −1: singular)."""
        t = time.perf_counter()
        try:
            return self.linear.inertia()
        finally:
            self.timings.solve += time.perf_counter() - t

    def smallest_eigenvalue(self) -> float:
        """Eigenvalue closest to zero of the (symmetric part of the) last assembled tangent, the
        constrained dofs taken out."""
        return self.linear.smallest_eigenvalue(self.constrained_global_dofs())

    def softest_motions(self, count: int) -> tuple[list, list[float]]:
        """The ``count`` softest motions of the last assembled tangent (its null space if singular),
        orthonormal, softest first, and their quotients ‖K v‖/max|diag K|."""
        vectors = [self.new_vector() for _ in range(count)]
        q = self.linear.null_space(self.constrained_global_dofs(), vectors)
        for v in vectors:
            v.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        return vectors, q

    def set_model_array(self, model, values: np.ndarray, vec: PETSc.Vec) -> None:
        """vec = ``values`` (local array in the layout of ``model.V``) on the model's dofs, 0 elsewhere."""
        with vec.localForm() as f:
            f.set(0.0)
            f.array[:] = values

    @property
    def krylov_iterations(self) -> int:
        return self.linear.krylov_iterations

    @property
    def fallback_solves(self) -> int:
        return self.linear.fallback_solves

    def reference_load(self, out: PETSc.Vec) -> None:
        """out = f_ext with zero rows on constrained dofs (right-hand side of K dx_t = f_ext)."""
        self.fext.copy(out)
        dolfinx.fem.petsc.set_bc(out, self.bcs, None, 0.0)

    def evaluate_internal_force(self) -> np.ndarray:
        """f_int of the parts and the contributions (contact) at the current configuration, owned
        entries."""
        self._assemble_fint()
        return self.fint.array.copy()

    def start_stage(self, approach: str) -> None:
        """Tell the contributions that a construction stage starts (approach "I" or "II")."""
        for c in self.contributions:
            c.start_stage(approach)

    def ramp_loads_from(self, previous: np.ndarray | None) -> np.ndarray:
        """Stage loads: f_ext(λ) = F_prev + λ (F − F_prev), with F the external force assembled
        for this system and F_prev (owned entries) where the stage starts (None: F_prev = 0).
        Returns F (owned entries)."""
        target = self.fext.array.copy()
        if previous is not None:
            self.fext.array[:] -= previous
            held = self.new_vector()
            held.array[:] = previous
            self.amplitude_loads.append((_constant_one, held))  # destroyed with the system
            self._choose_tangent()  # the held loads may carry moments
        return target

    def new_vector(self) -> PETSc.Vec:
        """A vector laid out like the solution (ghosted)."""
        return petsc.duplicate(self.b)

    def update(self, scale: float = 1.0) -> None:
        """x ← x ⊕ scale·dx through the model's update rule (multiplicative for rotations)."""
        t = time.perf_counter()
        self._version += 1
        if scale != 1.0:
            self.dx.scale(scale)
        self.model.update(self.dx)
        self.step_dx.axpy(scale, self.dx)
        if scale != 1.0:
            self.dx.scale(1.0 / scale)
        self.timings.update += time.perf_counter() - t

    def directional_residual(self) -> float:
        """dx·r at the last residual: minus the derivative of the energy along dx."""
        return self.dx.dot(self.b)

    # -- Newton hooks, relayed to the contributions ---------------------------------
    def before_step(self) -> None:
        """A load step (or its retry) starts: the contributions' hook, and the sum of its corrections
        from 0 (see :meth:`step_increment_norm`)."""
        self._residual_at = None  # (a stage's change of the elements does not count as a new configuration)
        for c in self.contributions:
            c.before_step()
        with self.step_dx.localForm() as s:
            s.set(0.0)

    def another_start(self) -> bool:
        """A step failed: whether some contribution offers another start for it (every one is
        asked; see Contribution.another_start), or, for a tangent that 'auto' symmetrized, the
        same step again with the consistent tangent (far from equilibrium, in a step that turns
        the structure hard, the skew part is of the order of the unbalanced moments)."""
        if any([c.another_start() for c in self.contributions]):
            return True
        if self.symmetrized and self.tangent == "auto":
            logger.info("the step failed with the symmetric part of the tangent: again with the consistent tangent")
            self.symmetrize(False)
            self._resymmetrize = True
            self.consistent_retries += 1
            return True
        return False

    def begin_step(self) -> None:
        """A Newton solve starts (the step's first, or one after a contribution's update at the
        converged load factor): the contributions' hook."""
        for c in self.contributions:
            c.before_solve()

    def correction_rhs(self) -> PETSc.Vec:
        """The right-hand side of the next correction: b, less the forces the contributions ask
        to take out of it (see Contribution.correction_rhs)."""
        extra = {}
        for c in self.contributions:
            blocks = c.correction_rhs()
            if blocks is not None:
                extra[id(c)] = blocks
        if not self._reduce(bool(extra), MPI.LOR):
            return self.b
        self.b.copy(self._rhs)

        def subtract(c, add):
            if id(c) in extra:
                dofs, forces = extra[id(c)]
                add(dofs, -np.asarray(forces))

        self._add_blocks(self._rhs, subtract)
        return self._rhs

    def limit_correction(self) -> float:
        """The smallest factor the contributions allow for the correction dx (≤ 1)."""
        return min([c.limit_correction(self.dx) for c in self.contributions], default=1.0)

    def needs_line_search(self) -> bool:
        return any(c.needs_line_search() for c in self.contributions)

    def after_iteration(self, residuals: list[float]) -> None:
        for c in self.contributions:
            c.after_iteration(residuals)

    def on_converged(self) -> bool:
        """Every contribution's update after a converged solve; True if any asks for another.
        A step that needed the consistent tangent (:meth:`another_start`) hands the next ones
        back to the symmetric part."""
        if self._resymmetrize:
            self._resymmetrize = False
            self.symmetrize(True)
        return any([c.on_converged() for c in self.contributions])

    def history(self, report) -> dict:
        row = {}
        for c in self.contributions:
            row.update(c.history(report))
        return row

    def commit(self) -> None:
        for c in self.contributions:
            c.commit()

    # -- state ----------------------------------------------------------------------
    def step_increment_norm(self) -> float:
        """‖Σ corrections‖ since :meth:`before_step`: the load step's increment, over all its Newton
        solves (Newton's ``xtol`` is relative to it; a solve after a contribution's update at the
        converged load factor may move the configuration by little)."""
        return self.step_dx.norm()

    def extrapolate(self, older, newer, factor: float) -> None:
        """Set x to newer ⊕ factor·(newer ⊖ older) (a secant predictor; configurations of
        :meth:`checkpoint`)."""
        self._version += 1
        self.model.extrapolate(older[0], newer[0], factor)

    def predict(self, path: list, load_factor: float) -> None:
        """Set x to the polynomial through the converged states ``path`` [(λ, configuration of
        :meth:`checkpoint`), …], oldest first, at ``load_factor`` (Lagrange; two states: the
        secant, three: the parabola)."""
        lams = [lam for lam, _ in path]
        weights = []
        for i, li in enumerate(lams):
            w = 1.0
            for j, lj in enumerate(lams):
                if j != i:
                    w *= (load_factor - lj) / (li - lj)
            weights.append(w)
        self._version += 1
        self.model.combine([cp[0] for _, cp in path], weights)

    def translation_difference(self, cp_a, cp_b) -> float:
        """The largest difference of nodal translations between two configurations of
        :meth:`checkpoint` (on every rank); the current configuration is left at ``cp_b``."""
        values = []
        for cp in (cp_a, cp_b):
            self.restore(cp)
            values.append(np.concatenate([m.translations_of(np.arange(m.V.dofmap.index_map.size_local)).ravel()
                                          for m in self.models]))
        local = float(np.max(np.abs(values[1] - values[0]), initial=0.0))
        return self.comm.allreduce(local, op=MPI.MAX)

    def checkpoint(self):
        """The configuration and every contribution's history state (in memory)."""
        return (self.model.checkpoint(), [c.checkpoint() for c in self.contributions])

    def restore(self, cp) -> None:
        self._version += 1
        self.model.restore(cp[0])
        for c, state in zip(self.contributions, cp[1]):
            c.restore(state)

    # -- numbering ------------------------------------------------------------------
    def global_dofs(self, model, local_dofs: np.ndarray) -> np.ndarray:
        """Global system dofs of ``model``'s local unrolled dofs."""
        return self._A.getLGMap()[0].apply(np.asarray(local_dofs, dtype=PETSc.IntType)).astype(np.int64)

    def touched_by_others(self, model) -> np.ndarray:
        """(local blocks of ``model``) whether an existing element of another model touches the
        node: never, with one model."""
        return np.zeros(len(model.bending_blocks()), dtype=bool)

    def constrained_global_dofs(self) -> np.ndarray:
        """All constrained dofs (supports and prescribed motion), global numbering, on every rank."""
        own = [self.global_dofs(self.model, bc.dof_indices()[0][: bc.dof_indices()[1]]) for bc in self.bcs]
        own = np.concatenate(own) if own else np.zeros(0, dtype=np.int64)
        return np.unique(own if self.comm.size == 1 else np.concatenate(self.comm.allgather(own)))

    def ownership_range(self) -> tuple[int, int]:
        return self._A.getOwnershipRange()

    def internal_force(self) -> PETSc.Vec:
        """f_int at the last residual, all dofs: on supported dofs it is the reaction."""
        return self.fint

    def destroy(self) -> None:
        for c in self.contributions:
            c.destroy()
        self.linear.destroy()
        petsc.destroy(self.fload, self.C, self._A, self.b, self.fint, self.dx, self.step_dx, self.lift, self.fext,
                      self.fext_total, self._rhs, *(v for _, v in self.amplitude_loads))


class CoupledSystem(System):
    """:class:`System` of parts on several meshes (``model.models``), stacked by a :class:`DofLayout`.

    Each model's kernels are assembled by DOLFINx into one PETSc matrix
    whose pattern is the union of the models' cell patterns: the matrix's
    local-to-global map is switched to each model's dofs in turn, so shared
    nodes sum their contributions. Supports and prescribed motion act on the
    system's dofs (MatZeroRowsColumns with the lifting of prescribed values);
    rotations without bending stiffness in every model are fixed.
    """

    def _build(self) -> None:
        models = self.model.models
        self.layout = lay = DofLayout(models)
        comm = self.comm
        blocks = []
        for m, loc in zip(models, lay.local):
            cells = m.V.dofmap.list.array.reshape(-1, m.nodes_per_cell)
            blocks.append(loc[(cells[:, :, None] * m.ndof + np.arange(m.ndof)).reshape(len(cells), -1)])
        self._A = petsc.layout_matrix(comm, lay.imap, blocks, lay.n_owned)
        self.b = petsc.layout_vector(lay.imap)
        self._diagonal_kept = False
        self._model_forms = [m.forms() for m in models]
        self._lgmaps = [petsc.lgmap(comm, gd) for gd in lay.gdofs]
        self._mvec = [petsc.form_vector(L) for L, _ in self._model_forms]
        self._xglobal = petsc.duplicate(self.b)
        self._constraints, self._fixed = self._gather_constraints()
        self._lift_pending = False

    @property
    def models(self) -> list:
        return self.model.models

    # -- moving values between the models' layouts and the system's ---------------
    def _add_from_models(self, vec: PETSc.Vec, arrays: Sequence[np.ndarray]) -> None:
        """vec = Σ over models of their local arrays (owned and ghost entries), summed on the owners."""
        with vec.localForm() as f:
            f.set(0.0)
            for loc, arr in zip(self.layout.local, arrays):
                f.array[loc] += arr
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)

    def touched_by_others(self, model) -> np.ndarray:
        """(local blocks of ``model``) whether an existing element of another model touches the node."""
        i = self.model.models.index(model)
        arrays = []
        for k, m in enumerate(self.model.models):
            a = np.zeros((len(m.bending_blocks()), m.ndof))
            if k != i:
                a[:] = 1.0
                a[m.held_blocks()] = 0.0
            arrays.append(a.ravel())
        self._add_from_models(self._xglobal, arrays)
        touched = self.model_array(model, self._xglobal) > 0.0
        return touched.reshape(-1, model.ndof).any(axis=1)

    def model_array(self, model, vec: PETSc.Vec) -> np.ndarray:
        i = self.model.models.index(model)
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with vec.localForm() as f:
            return f.array[self.layout.local[i]].copy()

    def set_model_array(self, model, values: np.ndarray, vec: PETSc.Vec) -> None:
        with vec.localForm() as f:
            f.set(0.0)
            f.array[self.layout.local[self.model.models.index(model)]] = values

    def _one_rotation_held(self) -> bool:
        v = self.new_vector()
        v.array[self._fixed] = 1.0
        v.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with v.localForm() as f:
            held = f.array > 0.0
        v.destroy()
        return any(np.any(held[loc].reshape(-1, 6)[:, 3:].sum(axis=1) == 1)
                   for m, loc in zip(self.model.models, self.layout.local)
                   if m.ndof == 6 and m.symmetric_at_equilibrium)

    def _rotation_mask(self) -> np.ndarray:
        arrays = []
        for m, loc in zip(self.model.models, self.layout.local):
            r = np.zeros((len(loc) // m.ndof, m.ndof))
            r[:, m.translations:] = 1.0
            arrays.append(r.ravel())
        return self._owned_indicator(arrays) > 0

    def _dof_coordinates(self) -> np.ndarray:
        arrays, ones = [], []
        for m, loc in zip(self.model.models, self.layout.local):
            X = m.V.tabulate_dof_coordinates()[: len(loc) // m.ndof, : m.gdim]
            arrays.append(np.repeat(np.linalg.norm(X, axis=1), m.ndof))
            ones.append(np.ones(len(loc)))
        # a node held by several models or ranks: the mean of the equal values
        return self._owned_indicator(arrays) / np.maximum(self._owned_indicator(ones), 1.0)

    def _owned_indicator(self, arrays: Sequence[np.ndarray]) -> np.ndarray:
        """Owned entries of Σ models' local arrays (a reduction over ranks)."""
        self._add_from_models(self._xglobal, arrays)
        return self._xglobal.array.copy()

    def _gather_constraints(self):
        """[(owned local rows, value, amplitude)] of supports and prescribed motion; and all fixed rows."""
        models = self.model.models
        groups = []
        for i, m in enumerate(models):
            for dofs, value, amp in m.constraint_dofs():
                arrays = [np.zeros(len(loc)) for loc in self.layout.local]
                arrays[i][dofs] = 1.0
                groups.append((np.flatnonzero(self._owned_indicator(arrays) > 0).astype(np.int32), value, amp))
        # rotations that no model gives bending stiffness
        rot, bend = [], []
        for m in models:
            r = np.zeros((len(m.bending_blocks()), m.ndof))
            r[:, m.translations:] = 1.0
            rot.append(r.ravel())
            bend.append((r * m.bending_blocks()[:, None]).ravel())
        free = (self._owned_indicator(rot) > 0) & (self._owned_indicator(bend) == 0)
        groups.append((np.flatnonzero(free).astype(np.int32), 0.0, None))
        # staged construction: dofs that no existing element of any model touches are held
        active = []
        for m in models:
            a = np.ones((len(m.bending_blocks()), m.ndof))
            a[m.held_blocks()] = 0.0
            active.append(a.ravel())
        held = np.flatnonzero(self._owned_indicator(active) == 0).astype(np.int32)
        if len(held):
            groups.append((held, None, None))  # held where they are
        fixed = np.unique(np.concatenate([g[0] for g in groups])).astype(np.int32)
        return groups, fixed

    # -- System hooks --------------------------------------------------------------
    def _external_force(self, amplitude) -> PETSc.Vec:
        arrays = []
        for m, v in zip(self.model.models, self._mvec):
            with v.localForm() as f:
                f.set(0.0)
            m.external_force(v, amplitude)
            with v.localForm() as f:
                arrays.append(f.array.copy())
        out = petsc.duplicate(self.b)
        self._add_from_models(out, arrays)
        return out

    def _assemble_parts(self) -> None:
        arrays = []
        for (L, _), v in zip(self._model_forms, self._mvec):
            with v.localForm() as f:
                f.set(0.0)
            dolfinx.fem.petsc.assemble_vector(v, L)
            with v.localForm() as f:
                arrays.append(f.array.copy())
        self._add_from_models(self.fint, arrays)

    def _assemble_follower_forms(self) -> None:
        arrays = []
        for form, v in zip(self._follower_forms, self._mvec):
            with v.localForm() as f:
                f.set(0.0)
            if form is not None:
                dolfinx.fem.petsc.assemble_vector(v, form)
            with v.localForm() as f:
                arrays.append(f.array.copy())
        self._add_from_models(self.fload, arrays)

    def _displacements(self) -> np.ndarray:
        """Owned entries of the displacement vector (rotational entries 0). An owned dof may be held
        by models on other ranks only (a solid's node owned here, the beam sharing it elsewhere):
        the holders' values reach the owner (they agree, so inserting is summing once)."""
        with self._xglobal.localForm() as f:
            f.set(0.0)
            for m, loc in zip(self.model.models, self.layout.local):
                with m.displacement_vector().localForm() as x:
                    f.array[loc] = x.array
        self._xglobal.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.REVERSE)
        return self._xglobal.array

    def _constrain_residual(self, load_factor: float) -> None:
        x = self._displacements()
        with self.lift.localForm() as f:
            f.set(0.0)
        lift = self.lift.array
        for rows, value, amp in self._constraints:
            if value is None:  # held where they are (staged construction)
                lift[rows] = 0.0
                continue
            target = value * (load_factor if amp is None else amp(load_factor))
            lift[rows] = target - x[rows]
        self.b.array[self._fixed] = lift[self._fixed]
        self._lift_pending = True

    def _assemble_parts_matrix(self) -> None:
        A = self._A
        A.zeroEntries()
        lg0 = A.getLGMap()
        for (_, a), lg in zip(self._model_forms, self._lgmaps):
            A.setLGMap(lg, lg)
            _dolfinx.assemble_matrix_into(A, a)
        A.setLGMap(*lg0)
        if not self._diagonal_kept:
            # explicit zeros on the diagonal before the first assembly fixes the pattern: rows that no
            # element reaches (nodes of cells without elements, or of elements that do not exist
            # yet) keep their diagonal, to be constrained
            n = self.layout.n_owned
            A.setValuesCSR(np.arange(n + 1, dtype=PETSc.IntType),
                           np.arange(self.layout.start, self.layout.start + n, dtype=PETSc.IntType),
                           np.zeros(n), addv=PETSc.InsertMode.ADD_VALUES)
            self._diagonal_kept = True
        A.assemble()

    def _constrain_matrix(self) -> None:
        rows = (self._fixed + self.layout.start).astype(PETSc.IntType)
        if self._lift_pending and self.has_prescribed_motion:
            self._A.zeroRowsColumns(rows, 1.0, self.lift, self.b)
        else:
            self._A.zeroRowsColumns(rows, 1.0)
        self._lift_pending = False

    def reference_load(self, out: PETSc.Vec) -> None:
        self.fext.copy(out)
        out.array[self._fixed] = 0.0

    def update(self, scale: float = 1.0) -> None:
        t = time.perf_counter()
        self._version += 1
        self.dx.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with self.dx.localForm() as f:
            dxl = f.array
            for m, loc, v in zip(self.model.models, self.layout.local, self._mvec):
                n = m.V.dofmap.index_map.size_local * m.ndof
                v.array[:] = scale * dxl[loc[:n]]
                m.update(v)
        self.step_dx.axpy(scale, self.dx)
        self.timings.update += time.perf_counter() - t

    def global_dofs(self, model, local_dofs: np.ndarray) -> np.ndarray:
        return self.layout.gdofs[self.model.models.index(model)][np.asarray(local_dofs)].astype(np.int64)

    def constrained_global_dofs(self) -> np.ndarray:
        own = (self._fixed + self.layout.start).astype(np.int64)
        return np.unique(own if self.comm.size == 1 else np.concatenate(self.comm.allgather(own)))

    def ownership_range(self) -> tuple[int, int]:
        return self.layout.start, self.layout.start + self.layout.n_owned

    def global_to_vector(self, arrays: dict, name: str, vec: PETSc.Vec) -> None:
        with vec.localForm() as f:
            for i, (m, loc) in enumerate(zip(self.model.models, self.layout.local)):
                f.array[loc] = m.from_global(arrays[f"{name}{i}"])
        # a dof this rank owns may be held by no model's nodes here (a beam's rotation at a node
        # owned through the solid): its value comes from the rank whose model holds it (a ghost)
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.REVERSE)
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def destroy(self) -> None:
        super().destroy()
        petsc.destroy(*self._mvec, self._xglobal, *self._lgmaps)


def make_system(model, solver: str = "auto", contributions: Sequence[Contribution] = (), **kwargs) -> System:
    """The :class:`System` of a model: DOLFINx's layout for one mesh, a :class:`CoupledSystem` for several.

    solver: 'direct' (MUMPS), 'iterative' (CG + AMG with the rigid-body near-nullspace) or
    'auto': iterative for a continuum alone without contributions, direct otherwise.
    contributions: added to the parts' residual and tangent (e.g. ``scene.contributions()``).
    """
    continuum = model.continuum
    if solver == "auto":
        solver = "iterative" if continuum and not contributions else "direct"
    if solver == "iterative" and not continuum:
        raise NotImplementedError("the iterative solver (CG + GAMG) is for continua alone; structures and coupled "
                                  "parts use the direct solver")
    cls = CoupledSystem if model.coupled else System
    return cls(model, solver=solver, contributions=contributions, **kwargs)


def _constant_one(load_factor: float) -> float:
    return 1.0

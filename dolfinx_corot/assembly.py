"""Residual and Jacobian assembly into PETSc through DOLFINx.

This is the only module that touches DOLFINx's C++ layer: a numba ``cfunc``
element kernel (ufcx ``tabulate_tensor`` signature) becomes a
``dolfinx.cpp.fem.Form_float64`` on the part's function space, so DOLFINx
handles dofmaps, ghosts, sparsity and Dirichlet rows (dolfinx-0.5 notes §2).

:class:`System` is what the solvers see: a residual
:math:`\\mathbf r(\\mathbf x, \\lambda) = \\lambda\\mathbf f_{ext} - \\mathbf f_{int}(\\mathbf x)`,
its Jacobian, a linear solve and an update rule; it knows nothing about
beams. Newton increments are homogeneous on supported dofs.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Protocol, Sequence

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.cpp
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.mesh

logger = logging.getLogger(__name__)


def kernel_form(V: dolfinx.fem.FunctionSpace, kernel_address: int, rank: int,
                coefficients: Sequence[dolfinx.fem.Function], constants: Sequence[dolfinx.fem.Constant],
                cells: np.ndarray | None = None):
    """A DOLFINx form whose cell integral is a compiled kernel.

    V: the argument space (test, and trial for rank 2); kernel_address: the
    address of a numba cfunc; coefficients are packed into ``w`` in order,
    constants into ``c``; cells: owned cells to integrate over (all if None).
    """
    mesh = V.mesh
    if cells is None:
        integrals = {dolfinx.cpp.fem.IntegralType.cell: ([(-1, kernel_address)], None)}
    else:
        tdim = mesh.topology.dim
        cells = np.unique(np.asarray(cells, dtype=np.int32))
        tags = dolfinx.mesh.meshtags(mesh, tdim, cells, np.ones(len(cells), dtype=np.int32))
        integrals = {dolfinx.cpp.fem.IntegralType.cell: ([(1, kernel_address)], tags)}
    spaces = [V._cpp_object] * rank
    return dolfinx.cpp.fem.Form_float64(spaces, integrals, [c._cpp_object for c in coefficients],
                                        [c._cpp_object for c in constants], False)


class Model(Protocol):
    """What :class:`System` and the drivers need from the assembled part(s)."""

    V: dolfinx.fem.FunctionSpace                              # space of the Newton corrections
    state: dolfinx.fem.Function                               # the configuration (kernels' coefficient)
    symmetric_tangent: bool                                   # LDLᵀ allowed
    has_prescribed_motion: bool
    amplitudes: list                                          # distinct load amplitudes (None: ∝ λ)

    def forms(self) -> tuple[object, object]: ...            # (vector form, matrix form)
    def dirichlet_bcs(self) -> list: ...                        # supports and prescribed motion
    def set_load_factor(self, load_factor: float) -> None: ...  # prescribed values at λ
    def external_force(self, b: PETSc.Vec, amplitude=None) -> None: ...  # unit loads of one amplitude
    def displacement_vector(self) -> PETSc.Vec: ...             # x in the layout of V (constraints)
    def update(self, dx: PETSc.Vec) -> None: ...                # x ← x ⊕ dx
    def extrapolate(self, older: object, newer: object, factor: float) -> None: ...
    def checkpoint(self) -> object: ...
    def restore(self, cp: object) -> None: ...
    def to_global(self, local: np.ndarray) -> np.ndarray | None: ...   # for checkpoint files
    def from_global(self, values: np.ndarray) -> np.ndarray: ...


@dataclass
class Timings:
    """Accumulated wall time (s) of the phases of the Newton iterations."""

    assembly: float = 0.0
    solve: float = 0.0
    update: float = 0.0

    def copy(self) -> "Timings":
        return Timings(self.assembly, self.solve, self.update)


class System:
    """Nonlinear system r(x, λ) = λ f_ext − f_int(x) = 0 of one model.

    The direct solver is MUMPS: LDLᵀ (``symmetric=True``, the tangent of
    conservative elastic structures) whose count of negative pivots is the
    number of negative eigenvalues of K (Sylvester's law; used to pass limit
    points), or LU. The iterative solver (continua) is CG preconditioned by
    smoothed-aggregation AMG with the rigid-body near-nullspace, on a
    block (BAIJ) matrix; Newton chooses its tolerances (inexact Newton) and
    when the AMG hierarchy is rebuilt (:class:`~dolfinx_corot.solvers.NewtonOptions`),
    and a failed Krylov solve (indefinite tangent) is repeated with MUMPS LU.
    PETSc options with the prefix ``dc_newton_`` override all of it
    (e.g. ``-dc_newton_pc_type lu``, ``-dc_newton_pc_type gamg``).
    """

    def __init__(self, model: Model, options_prefix: str = "dc_newton_", symmetric: bool | None = None,
                 solver: str = "direct", contacts: Sequence = ()):
        self.model = model
        self.comm = model.comm
        # block-compressed rows for AMG on continua: nodal blocks are inserted and multiplied
        # several times faster than in AIJ; MUMPS gets AIJ
        self._mat_type = "baij" if solver == "iterative" else None
        self._build()
        self.fint = self.b.duplicate()
        self.dx = self.b.duplicate()
        self.step_dx = self.b.duplicate()
        self.lift = self.b.duplicate()
        self._prescribed = bool(getattr(model, "has_prescribed_motion", False))
        self.load_factor = 0.0
        self.fext = self._external_force(None)
        self._fext_norm = self.fext.norm()
        # loads with their own amplitudes g(λ)
        self.amplitude_loads = [(amp, self._external_force(amp)) for amp in getattr(model, "amplitudes", [])]
        self.fext_total = self.b.duplicate()
        self.timings = Timings()
        self.contact = None
        if contacts:
            if solver == "iterative":
                raise NotImplementedError("contact needs the direct solver (linear_solver='direct' or 'auto')")
            from .contact.interface import ContactSet

            self.contact = ContactSet(contacts, self)

        if symmetric is None:
            symmetric = getattr(model, "symmetric_tangent", True)
        self.ksp = PETSc.KSP().create(self.comm)
        self.ksp.setOptionsPrefix(options_prefix)
        pc = self.ksp.getPC()
        self.iterative = solver == "iterative"
        self._fallback: PETSc.KSP | None = None
        self.fallback_solves = 0
        self.krylov_iterations = 0  # summed over iterative solves
        if self.iterative:
            # CG + smoothed-aggregation AMG with the rigid-body near-nullspace (continua): ML
            # (Trilinos) with Chebyshev–Jacobi smoothing where PETSc has it, else PETSc's GAMG
            self.ksp.setType("cg" if symmetric else "gmres")
            if PETSc.Sys.hasExternalPackage("ml"):
                pc.setType("ml")
                # aggregation across rank boundaries (MIS) pays on several ranks, not on one
                defaults = {"pc_ml_nullspace": "user", "mg_levels_ksp_type": "chebyshev",
                            "mg_levels_pc_type": "jacobi",
                            "pc_ml_CoarsenScheme": "MIS" if self.comm.size > 1 else "Uncoupled"}
                options = PETSc.Options()
                for key, value in defaults.items():
                    if not options.hasName(options_prefix + key):
                        options[options_prefix + key] = value
                # kept under our prefix: ML reads its level options at every set-up, not only now
            else:
                pc.setType("gamg")
            self.ksp.setTolerances(rtol=1e-10, atol=1e-50, max_it=500)
            self._nullspace = model.near_nullspace()
            self.A.setNearNullSpace(self._nullspace)
            # a tolerance given as a PETSc option is kept, and a linear problem is solved at
            # once: no adaptive forcing then
            self._fixed_rtol = PETSc.Options().hasName(options_prefix + "ksp_rtol") \
                or not getattr(model, "large_rotations", True)
        else:
            self.ksp.setType("preonly")
            pc.setType("cholesky" if symmetric else "lu")
            pc.setFactorSolverType("mumps")
        self.ksp.setFromOptions()
        # AMG needs AIJ: a converted copy of the block matrix builds the preconditioner
        self.P: PETSc.Mat | None = None
        self._reuse_pc = False
        self.ksp.setOperators(self.A)
        self._mumps = self.ksp.getType() == "preonly" and pc.getType() in ("lu", "cholesky") \
            and pc.getFactorSolverType() == "mumps"
        self._ldlt = self._mumps and pc.getType() == "cholesky"
        if self._mumps:
            # null-pivot detection (ICNTL 24): a singular tangent is reported, not solved
            pc.setFactorSetUpSolverType()
            pc.getFactorMatrix().setMumpsIcntl(24, 1)

    # -- layout (one mesh: DOLFINx's own) -------------------------------------------
    def _build(self) -> None:
        self.L, self.a = self.model.forms()
        self.bcs = self.model.dirichlet_bcs()
        self.A = dolfinx.fem.petsc.create_matrix(self.a, self._mat_type)
        self.b = dolfinx.fem.petsc.create_vector(self.L)

    def _external_force(self, amplitude) -> PETSc.Vec:
        """Assembled unit external load of one amplitude (None: the loads proportional to λ)."""
        v = self.b.duplicate()
        with v.localForm() as f:
            f.set(0.0)
        self.model.external_force(v, amplitude)
        v.assemble()
        return v

    def _assemble_fint(self) -> None:
        with self.fint.localForm() as f:
            f.set(0.0)
        dolfinx.fem.petsc.assemble_vector(self.fint, self.L)
        self.fint.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        if self.contact is not None:
            self.contact.add_force(self.fint)

    def _constrain_residual(self, load_factor: float) -> None:
        x = self.model.displacement_vector()
        if self._prescribed:
            self.model.set_load_factor(load_factor)
            with self.lift.localForm() as f:
                f.set(0.0)
            # supports never move (x = 0 there): only prescribed motion has a lifting
            lifting_bcs = getattr(self.model, "lifting_bcs", self.bcs)
            dolfinx.fem.petsc.apply_lifting(self.lift, [self.a], bcs=[lifting_bcs], x0=[x], scale=1.0)
            self.lift.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            self.b.axpy(1.0, self.lift)
        dolfinx.fem.petsc.set_bc(self.b, self.bcs, x, 1.0)

    def model_array(self, model, vec: PETSc.Vec) -> np.ndarray:
        """Local values (owned and ghost) of ``vec`` in the layout of ``model.V``."""
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with vec.localForm() as f:
            return f.array.copy()

    def global_arrays(self, vectors: dict) -> dict:
        """Configuration and vectors as node-ordered arrays on rank 0 (checkpoint files)."""
        model = self.model
        arrays = {"state": model.to_global(model.state.x.array)}
        for name, vec in vectors.items():
            with vec.localForm() as v:
                arrays[name] = model.to_global(v.array)
        return arrays

    def set_global_arrays(self, arrays: dict) -> None:
        """Restore the configuration from :meth:`global_arrays`' output (read on every rank)."""
        self.model.state.x.array[:] = self.model.from_global(arrays["state"])

    def global_to_vector(self, arrays: dict, name: str, vec: PETSc.Vec) -> None:
        """Fill ``vec`` (owned and ghost) from the arrays of :meth:`global_arrays` (entry ``name``)."""
        with vec.localForm() as v:
            v.array[:] = self.model.from_global(arrays[name])

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
        self._assemble_fint()
        self.fext.copy(self.fext_total)
        self.fext_total.scale(load_factor)
        for amp, v in self.amplitude_loads:
            self.fext_total.axpy(amp(load_factor), v)
        ref = max(self.fext_total.norm(), self.fint.norm())
        self.fext_total.copy(self.b)
        self.b.axpy(-1.0, self.fint)
        self._constrain_residual(load_factor)
        norm = self.b.norm()
        self.timings.assembly += time.perf_counter() - t
        return norm, ref

    def jacobian(self) -> None:
        """Assemble the tangent K = ∂f_int/∂x, identity rows/columns on supports."""
        t = time.perf_counter()
        self.A.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(self.A, self.a, bcs=self.bcs)
        self.A.assemble()
        if self.contact is not None:
            self.contact.add_tangent(self.A)
        if self._mat_type == "baij":
            # the AMG's finest level smooths with P: P follows A even when the hierarchy is kept
            if self.P is None:
                self.P = self.A.convert("aij", PETSc.Mat())  # a new matrix (out=None converts in place)
                self.P.setNearNullSpace(self._nullspace)
                self.ksp.setOperators(self.A, self.P)
            else:
                self.A.convert("aij", self.P)
        self.timings.assembly += time.perf_counter() - t

    def solve(self, rhs: PETSc.Vec | None = None, out: PETSc.Vec | None = None) -> float:
        """Solve K out = rhs (default K dx = b) with the last tangent; return ‖out‖."""
        rhs = self.b if rhs is None else rhs
        out = self.dx if out is None else out
        t = time.perf_counter()
        self.ksp.solve(rhs, out)
        reason = self.ksp.getConvergedReason()
        if self.iterative:
            self.krylov_iterations += self.ksp.getIterationNumber()
        if reason < 0 and self.iterative:
            # CG + GAMG fails on an indefinite tangent (past a bifurcation or a limit point):
            # this solve is repeated with a sparse LU (MUMPS); the next ones try CG again
            logger.warning("CG + GAMG failed (PETSc reason %d after %d iterations): solving with MUMPS LU",
                           reason, self.ksp.getIterationNumber())
            reason = self._direct_solve(rhs, out)
        self.timings.solve += time.perf_counter() - t
        if reason < 0:
            raise np.linalg.LinAlgError(f"linear solve failed (PETSc reason {reason}); "
                                        "the tangent may be singular (a missing support?)")
        if self._mumps:
            null_pivots = self.ksp.getPC().getFactorMatrix().getMumpsInfog(28)
            if null_pivots > 0:
                raise np.linalg.LinAlgError(
                    f"the tangent stiffness is singular ({null_pivots} zero pivot(s)): a missing support "
                    "(rigid-body motion), a mechanism, or a limit point under load control")
        return out.norm()

    def _direct_solve(self, rhs: PETSc.Vec, out: PETSc.Vec) -> int:
        if self._fallback is None:
            self._fallback = PETSc.KSP().create(self.comm)
            self._fallback.setType("preonly")
            pc = self._fallback.getPC()
            pc.setType("lu")
            pc.setFactorSolverType("mumps")
        self._fallback.setOperators(self.A)
        self._fallback.solve(rhs, out)
        self.fallback_solves += 1
        return self._fallback.getConvergedReason()

    def set_forcing(self, eta: float | None) -> None:
        """Relative tolerance of the next iterative solves (inexact Newton; None: back to 1e-10);
        ignored by direct solvers and when ``-<prefix>ksp_rtol`` was given."""
        if self.iterative and not self._fixed_rtol:
            self.ksp.setTolerances(rtol=1e-10 if eta is None else eta)

    def reuse_preconditioner(self, reuse: bool) -> None:
        """Keep the preconditioner of an earlier tangent for the next iterative solves (the matrix
        is still the current tangent: only the convergence rate of the Krylov solver changes)."""
        if self.iterative:
            self._reuse_pc = bool(reuse)
            self.ksp.getPC().setReusePreconditioner(self._reuse_pc)

    def negative_eigenvalues(self) -> int | None:
        """Number of negative eigenvalues of the last factorized tangent (LDLᵀ only; else None)."""
        if not self._ldlt:
            return None
        return int(self.ksp.getPC().getFactorMatrix().getMumpsInfog(12))

    def reference_load(self, out: PETSc.Vec) -> None:
        """out = f_ext with zero rows on constrained dofs (right-hand side of K dx_t = f_ext)."""
        self.fext.copy(out)
        dolfinx.fem.petsc.set_bc(out, self.bcs, None, 0.0)

    def new_vector(self) -> PETSc.Vec:
        """A vector laid out like the solution (ghosted)."""
        return self.b.duplicate()

    def update(self, scale: float = 1.0) -> None:
        """x ← x ⊕ scale·dx through the model's update rule (multiplicative for rotations)."""
        t = time.perf_counter()
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

    def begin_step(self) -> None:
        """Start summing the corrections of a new step (see :meth:`step_increment_norm`)."""
        if self.contact is not None:
            self.contact.begin_newton()
        with self.step_dx.localForm() as s:
            s.set(0.0)

    def step_increment_norm(self) -> float:
        """‖Σ corrections‖ since :meth:`begin_step`."""
        return self.step_dx.norm()

    def extrapolate(self, older, newer, factor: float) -> None:
        """Set x to newer ⊕ factor·(newer ⊖ older) (a secant predictor)."""
        if self.contact is not None:
            older, newer = older[0], newer[0]
        self.model.extrapolate(older, newer, factor)

    def checkpoint(self):
        """The model's state (and the contact multipliers, if any)."""
        if self.contact is not None:
            return (self.model.checkpoint(), self.contact.checkpoint())
        return self.model.checkpoint()

    def restore(self, cp) -> None:
        if self.contact is not None:
            self.model.restore(cp[0])
            self.contact.restore(cp[1])
            return
        self.model.restore(cp)

    # -- numbering (contact) -------------------------------------------------------
    def global_dofs(self, model, local_dofs: np.ndarray) -> np.ndarray:
        """Global system dofs of ``model``'s local unrolled dofs."""
        return self.A.getLGMap()[0].apply(np.asarray(local_dofs, dtype=PETSc.IntType)).astype(np.int64)

    def constrained_global_dofs(self) -> np.ndarray:
        """All constrained dofs (supports and prescribed motion), global numbering, on every rank."""
        own = [self.global_dofs(self.model, bc.dof_indices()[0][: bc.dof_indices()[1]]) for bc in self.bcs]
        own = np.concatenate(own) if own else np.zeros(0, dtype=np.int64)
        return np.unique(np.concatenate(self.comm.allgather(own)))

    def ownership_range(self) -> tuple[int, int]:
        return self.A.getOwnershipRange()

    def internal_force(self) -> PETSc.Vec:
        """f_int at the last residual, all dofs: on supported dofs it is the reaction."""
        return self.fint

    def destroy(self) -> None:
        if self._fallback is not None:
            self._fallback.destroy()
        if self.contact is not None:
            self.contact.destroy()
        if self.P is not None:
            self.P.destroy()
        for obj in (self.ksp, self.A, self.b, self.fint, self.dx, self.step_dx, self.lift, self.fext,
                    self.fext_total, *(v for _, v in self.amplitude_loads)):
            obj.destroy()


def owned_dofs_of_vertices(V: dolfinx.fem.FunctionSpace, vertices: np.ndarray) -> np.ndarray:
    """Owned block indices (nodes) of V at the given local mesh vertices."""
    blocks = dolfinx.fem.locate_dofs_topological(V, 0, vertices)
    return blocks[blocks < V.dofmap.index_map.size_local]


def global_sum(comm: MPI.Comm, value: np.ndarray) -> np.ndarray:
    """Sum of an array over all ranks."""
    out = np.zeros_like(value)
    comm.Allreduce(np.ascontiguousarray(value), out, op=MPI.SUM)
    return out


class DofLayout:
    """One global numbering for the dofs of models on different meshes.

    A node is identified by (node source, input node number): the meshes read
    from one gmsh model (or built from one array of points with the same
    ``node_source``) share the nodes they have in common, which become one
    node of the system with one set of dofs. A shared node is owned by the
    rank that owns it in the first model holding it; nodes are numbered rank
    by rank, so each rank owns a contiguous range of scalar dofs.

    imap: scalar IndexMap of the system (owned, then ghosts); gdofs[i]: global
    dof of every local unrolled dof (owned and ghost) of model i; local[i]:
    the same in the local numbering of ``imap``; n_owned, start: this rank's range.
    """

    def __init__(self, models: Sequence) -> None:
        comm = models[0].comm
        sources: list[str] = []
        keys = []
        for m in models:
            if m.tmesh.node_source not in sources:
                sources.append(m.tmesh.node_source)
            code = np.int64(sources.index(m.tmesh.node_source))
            keys.append((code << np.int64(40)) | m._input_ids())
        allk, allm, allr = [], [], []
        for i, (m, k) in enumerate(zip(models, keys)):
            for r, g in enumerate(comm.allgather(k[: m.V.dofmap.index_map.size_local])):
                allk.append(g)
                allm.append(np.full(len(g), i, dtype=np.int32))
                allr.append(np.full(len(g), r, dtype=np.int32))
        allk, allm, allr = np.concatenate(allk), np.concatenate(allm), np.concatenate(allr)
        order = np.lexsort((allm, allk))
        ks = allk[order]
        first = np.ones(len(order), dtype=bool)
        first[1:] = ks[1:] != ks[:-1]
        primary = order[first]
        ukeys, owner, pmodel = allk[primary], allr[primary], allm[primary]
        ncomp = np.array([m.ndof for m in models], dtype=np.int64)[pmodel]
        # every model holding a shared node must give it the same dofs
        for i, m in enumerate(models):
            idx = np.searchsorted(ukeys, keys[i])
            for j in np.unique(pmodel[idx]):
                if models[j].dof_names != m.dof_names:
                    raise ValueError(f"parts of kinds {[p.kind for p in m.parts]} and "
                                     f"{[p.kind for p in models[j].parts]} share nodes but have different dofs "
                                     f"({m.dof_names} and {models[j].dof_names})")
        gorder = np.lexsort((ukeys, owner))
        gnode = np.empty(len(ukeys), dtype=np.int64)
        gnode[gorder] = np.arange(len(ukeys))
        offsets_in_order = np.concatenate([[0], np.cumsum(ncomp[gorder])])
        offset = offsets_in_order[gnode]
        per_rank = np.bincount(owner, weights=ncomp, minlength=comm.size).astype(np.int64)
        self.start = int(per_rank[: comm.rank].sum())
        self.n_owned = int(per_rank[comm.rank])
        self.size_global = int(per_rank.sum())
        self.gdofs, owners = [], []
        for i, m in enumerate(models):
            idx = np.searchsorted(ukeys, keys[i])
            self.gdofs.append((offset[idx][:, None] + np.arange(m.ndof)).ravel())
            owners.append(np.repeat(owner[idx], m.ndof))
        alld, allo = np.concatenate(self.gdofs), np.concatenate(owners)
        outside = (alld < self.start) | (alld >= self.start + self.n_owned)
        ghosts, first_at = np.unique(alld[outside], return_index=True)
        ghost_owners = allo[outside][first_at].astype(np.int32)
        self.ghosts = ghosts
        self.imap = dolfinx.cpp.common.IndexMap(comm, self.n_owned, ghosts.astype(np.int64), ghost_owners)
        self.local = []
        for gd in self.gdofs:
            own = (gd >= self.start) & (gd < self.start + self.n_owned)
            self.local.append(np.where(own, gd - self.start,
                                       self.n_owned + np.searchsorted(ghosts, gd)).astype(np.int32))


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
        sp = dolfinx.cpp.la.SparsityPattern(comm, [lay.imap, lay.imap], [1, 1])
        for m, loc in zip(models, lay.local):
            cells = m.V.dofmap.list.array.reshape(-1, m.nodes_per_cell)
            dofs = loc[(cells[:, :, None] * m.ndof + np.arange(m.ndof)).reshape(len(cells), -1)]
            for row in dofs:
                sp.insert(row, row)
        sp.insert_diagonal(np.arange(lay.n_owned, dtype=np.int32))
        sp.assemble()
        self.A = dolfinx.cpp.la.petsc.create_matrix(comm, sp)
        self.b = dolfinx.cpp.la.petsc.create_vector(lay.imap, 1)
        self._model_forms = [m.forms() for m in models]
        self._lgmaps = [PETSc.LGMap().create(gd.astype(PETSc.IntType), comm=comm) for gd in lay.gdofs]
        self._mvec = [dolfinx.fem.petsc.create_vector(L) for L, _ in self._model_forms]
        self._xglobal = self.b.duplicate()
        self._constraints, self._fixed = self._gather_constraints()
        self._lift_pending = False

    # -- moving values between the models' layouts and the system's ---------------
    def _add_from_models(self, vec: PETSc.Vec, arrays: Sequence[np.ndarray]) -> None:
        """vec = Σ over models of their local arrays (owned and ghost entries), summed on the owners."""
        with vec.localForm() as f:
            f.set(0.0)
            for loc, arr in zip(self.layout.local, arrays):
                f.array[loc] += arr
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)

    def model_array(self, model, vec: PETSc.Vec) -> np.ndarray:
        i = self.model.models.index(model)
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with vec.localForm() as f:
            return f.array[self.layout.local[i]].copy()

    def _owned_indicator(self, arrays: Sequence[np.ndarray]) -> np.ndarray:
        """Owned entries of Σ models' local arrays (a reduction over ranks)."""
        v = self.b.duplicate()
        self._add_from_models(v, arrays)
        out = v.array.copy()
        v.destroy()
        return out

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
        out = self.b.duplicate()
        self._add_from_models(out, arrays)
        return out

    def _assemble_fint(self) -> None:
        arrays = []
        for (L, _), v in zip(self._model_forms, self._mvec):
            with v.localForm() as f:
                f.set(0.0)
            dolfinx.fem.petsc.assemble_vector(v, L)
            with v.localForm() as f:
                arrays.append(f.array.copy())
        self._add_from_models(self.fint, arrays)
        if self.contact is not None:
            self.contact.add_force(self.fint)

    def _displacements(self) -> np.ndarray:
        """Owned entries of the displacement vector (rotational entries 0)."""
        with self._xglobal.localForm() as f:
            for m, loc in zip(self.model.models, self.layout.local):
                with m.displacement_vector().localForm() as x:
                    f.array[loc] = x.array
        return self._xglobal.array

    def _constrain_residual(self, load_factor: float) -> None:
        x = self._displacements()
        with self.lift.localForm() as f:
            f.set(0.0)
        lift = self.lift.array
        for rows, value, amp in self._constraints:
            target = value * (load_factor if amp is None else amp(load_factor))
            lift[rows] = target - x[rows]
        self.b.array[self._fixed] = lift[self._fixed]
        self._lift_pending = True

    def jacobian(self) -> None:
        t = time.perf_counter()
        A = self.A
        A.zeroEntries()
        lg0 = A.getLGMap()
        for (_, a), lg in zip(self._model_forms, self._lgmaps):
            A.setLGMap(lg, lg)
            dolfinx.cpp.fem.petsc.assemble_matrix(A, a, dolfinx.fem.petsc._pack_constants(a),
                                                  dolfinx.fem.petsc._pack_coefficients(a), [], True)
        A.setLGMap(*lg0)
        A.assemble()
        if self.contact is not None:
            self.contact.add_tangent(A)
        rows = (self._fixed + self.layout.start).astype(PETSc.IntType)
        if self._lift_pending and self._prescribed:
            A.zeroRowsColumns(rows, 1.0, self.lift, self.b)
        else:
            A.zeroRowsColumns(rows, 1.0)
        self._lift_pending = False
        self.timings.assembly += time.perf_counter() - t

    def reference_load(self, out: PETSc.Vec) -> None:
        self.fext.copy(out)
        out.array[self._fixed] = 0.0

    def update(self, scale: float = 1.0) -> None:
        t = time.perf_counter()
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
        return np.unique(np.concatenate(self.comm.allgather(own)))

    def ownership_range(self) -> tuple[int, int]:
        return self.layout.start, self.layout.start + self.layout.n_owned

    # -- checkpoint files ------------------------------------------------------------
    def global_arrays(self, vectors: dict) -> dict:
        arrays = {}
        for i, m in enumerate(self.model.models):
            arrays[f"state{i}"] = m.to_global(m.state.x.array)
            for name, vec in vectors.items():
                arrays[f"{name}{i}"] = m.to_global(self.model_array(m, vec))
        return arrays

    def set_global_arrays(self, arrays: dict) -> None:
        for i, m in enumerate(self.model.models):
            m.state.x.array[:] = m.from_global(arrays[f"state{i}"])

    def global_to_vector(self, arrays: dict, name: str, vec: PETSc.Vec) -> None:
        with vec.localForm() as f:
            for i, (m, loc) in enumerate(zip(self.model.models, self.layout.local)):
                f.array[loc] = m.from_global(arrays[f"{name}{i}"])

    def destroy(self) -> None:
        super().destroy()
        for obj in (*self._mvec, self._xglobal, *self._lgmaps):
            obj.destroy()


def make_system(model, solver: str = "auto", **kwargs) -> System:
    """The :class:`System` of a model: DOLFINx's layout for one mesh, a :class:`CoupledSystem` for several.

    solver: 'direct' (MUMPS), 'iterative' (CG + GAMG with the rigid-body near-nullspace) or
    'auto': iterative for a continuum alone, direct for structures and coupled parts.
    """
    if solver == "auto":
        solver = "iterative" if hasattr(model, "near_nullspace") and not kwargs.get("contacts") else "direct"
    if solver == "iterative" and not hasattr(model, "near_nullspace"):
        raise NotImplementedError("the iterative solver (CG + GAMG) is for continua alone; structures and coupled "
                                  "parts use the direct solver")
    cls = CoupledSystem if hasattr(model, "models") else System
    return cls(model, solver=solver, **kwargs)

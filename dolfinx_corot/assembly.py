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

    The linear solver is MUMPS: LDLᵀ (``symmetric=True``, the tangent of
    conservative elastic structures) whose count of negative pivots is the
    number of negative eigenvalues of K (Sylvester's law; used to pass limit
    points), or LU. PETSc options with the prefix ``dc_newton_`` override it
    (e.g. ``-dc_newton_pc_type lu``).
    """

    def __init__(self, model: Model, options_prefix: str = "dc_newton_", symmetric: bool | None = None):
        self.model = model
        self.comm = model.V.mesh.comm
        self.L, self.a = model.forms()
        self.bcs = model.dirichlet_bcs()
        self.A = dolfinx.fem.petsc.create_matrix(self.a)
        self.b = dolfinx.fem.petsc.create_vector(self.L)
        self.fint = self.b.duplicate()
        self.dx = self.b.duplicate()
        self.step_dx = self.b.duplicate()
        self.lift = self.b.duplicate()
        self._prescribed = bool(getattr(model, "has_prescribed_motion", False))
        self.load_factor = 0.0
        self.fext = self.b.duplicate()
        with self.fext.localForm() as f:
            f.set(0.0)
        model.external_force(self.fext)
        self.fext.assemble()
        self._fext_norm = self.fext.norm()
        # loads with their own amplitudes g(λ)
        self.amplitude_loads = []
        for amp in getattr(model, "amplitudes", []):
            v = self.b.duplicate()
            with v.localForm() as f:
                f.set(0.0)
            model.external_force(v, amp)
            self.amplitude_loads.append((amp, v))
        self.fext_total = self.b.duplicate()
        self.timings = Timings()

        if symmetric is None:
            symmetric = getattr(model, "symmetric_tangent", True)
        self.ksp = PETSc.KSP().create(self.comm)
        self.ksp.setOptionsPrefix(options_prefix)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("cholesky" if symmetric else "lu")
        pc.setFactorSolverType("mumps")
        self.ksp.setFromOptions()
        self.ksp.setOperators(self.A)
        self._mumps = self.ksp.getType() == "preonly" and pc.getType() in ("lu", "cholesky") \
            and pc.getFactorSolverType() == "mumps"
        self._ldlt = self._mumps and pc.getType() == "cholesky"
        if self._mumps:
            # null-pivot detection (ICNTL 24): a singular tangent is reported, not solved
            pc.setFactorSetUpSolverType()
            pc.getFactorMatrix().setMumpsIcntl(24, 1)

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
        with self.fint.localForm() as f:
            f.set(0.0)
        dolfinx.fem.petsc.assemble_vector(self.fint, self.L)
        self.fint.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self.fext.copy(self.fext_total)
        self.fext_total.scale(load_factor)
        for amp, v in self.amplitude_loads:
            self.fext_total.axpy(amp(load_factor), v)
        ref = max(self.fext_total.norm(), self.fint.norm())
        self.fext_total.copy(self.b)
        self.b.axpy(-1.0, self.fint)
        x = self.model.displacement_vector()
        if self._prescribed:
            self.model.set_load_factor(load_factor)
            with self.lift.localForm() as f:
                f.set(0.0)
            dolfinx.fem.petsc.apply_lifting(self.lift, [self.a], bcs=[self.bcs], x0=[x], scale=1.0)
            self.lift.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            self.b.axpy(1.0, self.lift)
        dolfinx.fem.petsc.set_bc(self.b, self.bcs, x, 1.0)
        norm = self.b.norm()
        self.timings.assembly += time.perf_counter() - t
        return norm, ref

    def jacobian(self) -> None:
        """Assemble the tangent K = ∂f_int/∂x, identity rows/columns on supports."""
        t = time.perf_counter()
        self.A.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(self.A, self.a, bcs=self.bcs)
        self.A.assemble()
        self.timings.assembly += time.perf_counter() - t

    def solve(self, rhs: PETSc.Vec | None = None, out: PETSc.Vec | None = None) -> float:
        """Solve K out = rhs (default K dx = b) with the last tangent; return ‖out‖."""
        rhs = self.b if rhs is None else rhs
        out = self.dx if out is None else out
        t = time.perf_counter()
        self.ksp.solve(rhs, out)
        reason = self.ksp.getConvergedReason()
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
        with self.step_dx.localForm() as s:
            s.set(0.0)

    def step_increment_norm(self) -> float:
        """‖Σ corrections‖ since :meth:`begin_step`."""
        return self.step_dx.norm()

    def extrapolate(self, older, newer, factor: float) -> None:
        """Set x to newer ⊕ factor·(newer ⊖ older) (a secant predictor)."""
        self.model.extrapolate(older, newer, factor)

    def checkpoint(self):
        return self.model.checkpoint()

    def restore(self, cp) -> None:
        self.model.restore(cp)

    def internal_force(self) -> PETSc.Vec:
        """f_int at the last residual, all dofs: on supported dofs it is the reaction."""
        return self.fint

    def destroy(self) -> None:
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

"""The contribution protocol: what every addend of the nonlinear system provides.

The system (:class:`dolfinx_corot.assembly.system.System`) is the sum of the
parts' forms and of *contributions*: contact interfaces today, stage ties,
embedded beams and friction next. A contribution

* declares the dofs it couples (:meth:`Contribution.couplings`): the system
  builds the matrix of the union of all declared couplings once per change
  (``couplings_changed``) and never inserts outside it;
* adds its share to the internal forces and to the tangent through the
  ``add(dofs, values)`` callables the system hands it (global dofs, −1 for none),
  so that it never touches PETSc;
* takes part in Newton's iteration through hooks (:meth:`before_step`,
  :meth:`before_solve`, :meth:`correction_rhs`, :meth:`limit_correction`,
  :meth:`after_iteration`, :meth:`on_converged`), which every driver's Newton
  calls alike;
* owns its history state: :meth:`checkpoint`/:meth:`restore` in memory (step
  cutting restores the exact last converged state), :meth:`commit` when a
  step converges, and :meth:`state_arrays`/:meth:`set_state_arrays` for
  checkpoint files (partition-independent arrays).

Every method has a neutral default, so a contribution implements only what it needs.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

AddBlocks = Callable[[np.ndarray, np.ndarray], None]


class Contribution:
    """Base of the system's contributions (see the module docstring); every hook is a no-op."""

    name = "contribution"

    # -- binding and coupling ----------------------------------------------------
    def bind(self, system) -> None:
        """Learn the system's global numbering (``system.global_dofs``, ``system.ownership_range``,
        ``system.constrained_global_dofs``)."""

    couplings_changed = False
    symmetric_tangent = True  # whether its tangent blocks are symmetric (else the system solves by LU)
    # a load that follows the configuration (a pressure): add_residual adds external forces (counted
    # with the loads in the residual's scale), add_tangent still adds the derivative of −f
    follows_configuration = False

    def couplings(self) -> np.ndarray:
        """(k, n) global dofs, each row a dense block coupled by this contribution (−1: none)."""
        return np.zeros((0, 0), dtype=np.int64)

    def engaged(self) -> bool:
        """Whether this rank has anything to add now (the system asks all ranks)."""
        return False

    # -- assembly ----------------------------------------------------------------
    def add_residual(self, add: AddBlocks) -> None:
        """Evaluate at the current configuration and add internal forces: add(dofs (k, n), f (k, n))."""

    def add_tangent(self, add: AddBlocks) -> None:
        """Add the tangent of the last evaluation: add(dofs (k, n), K (k, n, n))."""

    def start_stage(self, approach: str) -> None:
        """A construction stage starts on this system (:mod:`dolfinx_corot.staging`, approach "I"
        or "II"), before its first residual."""

    # -- Newton hooks --------------------------------------------------------------
    def before_step(self) -> None:
        """A load step (or its retry after a cut) starts."""

    def before_solve(self) -> None:
        """A Newton solve starts (its first residual follows)."""

    def another_start(self) -> bool:
        """A step failed: True if this contribution offers another start for the same step (then
        tried again before it is cut; the next :meth:`before_step` uses it)."""
        return False

    def correction_rhs(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Forces (dofs (k, n), f (k, n)) to subtract from the right-hand side of the next
        correction only (the residual keeps the true law), or None."""
        return None

    def limit_correction(self, dx) -> float:
        """A factor ≤ 1 for the Newton correction ``dx`` (a ghosted PETSc vector; read only)."""
        return 1.0

    def needs_line_search(self) -> bool:
        """Whether Newton should search along its corrections now (see NewtonOptions.line_search)."""
        return False

    def after_iteration(self, residuals: list[float]) -> None:
        """A correction was applied; ``residuals`` are the residual norms of the solve so far."""

    def on_converged(self) -> bool:
        """Newton converged: update (e.g. Lagrange multipliers) and return True to solve again."""
        return False

    def history(self, report) -> dict:
        """Columns this contribution adds to the step's history row."""
        return {}

    # -- state ---------------------------------------------------------------------
    def commit(self) -> None:
        """The step converged: its state becomes the last converged state."""

    def checkpoint(self):
        """The history state, in memory (restored exactly by :meth:`restore`)."""
        return None

    def restore(self, state) -> None:
        """Back to a state from :meth:`checkpoint`."""

    def state_arrays(self) -> dict[str, np.ndarray]:
        """The history state as partition-independent arrays (the same on every rank) for files."""
        return {}

    def set_state_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore from :meth:`state_arrays` (read on every rank)."""

    def describe(self) -> dict:
        """What defines this contribution (for the scene's fingerprint)."""
        return {"name": self.name}

    def destroy(self) -> None:
        """Free what the contribution holds."""

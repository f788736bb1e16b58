"""Newton–Raphson iterations on a :class:`dolfinx_corot.assembly.System`.

Each iteration assembles r = λ f_ext − f_int(x) and K = ∂f_int/∂x, solves
K dx = r and updates x ← x ⊕ dx through the system's update rule
(multiplicative for rotations). Convergence: ‖r‖ ≤ rtol·ref + atol, with ref
the larger of ‖λ f_ext‖ and ‖f_int‖ (reactions included). Divergence
(NaN, growth of ‖r‖ by ``divergence_factor``, or ``max_iterations``) is
reported, never hidden: the driver then cuts the step and restores the last
converged state.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np

logger = logging.getLogger(__name__)


class ConvergenceError(RuntimeError):
    """A load step that could not be completed; ``result`` holds what was computed."""

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result


@dataclass(frozen=True)
class NewtonOptions:
    """rtol, atol: residual tolerances (relative, force units); xtol: relative size of a
    correction at round-off level; max_iterations per attempt;
    divergence_factor: ‖r‖ above this multiple of its initial value is divergence."""

    rtol: float = 1e-9
    atol: float = 1e-12
    xtol: float = 1e-13
    max_iterations: int = 25
    divergence_factor: float = 1e6


@dataclass
class NewtonReport:
    converged: bool
    iterations: int
    residuals: list[float] = field(default_factory=list)
    increments: list[float] = field(default_factory=list)
    reason: str = ""

    def rate(self) -> float:
        """Estimated order of convergence from the last three residuals (nan if too few)."""
        r = [x for x in self.residuals if x > 0]
        if len(r) < 3:
            return math.nan
        a, b, c = r[-3:]
        if a == b or b == c:
            return math.nan
        return math.log(c / b) / math.log(b / a)


def newton(system, load_factor: float, options: NewtonOptions = NewtonOptions()) -> NewtonReport:
    """Iterate to equilibrium at ``load_factor``; returns a report (does not raise on divergence)."""
    report = NewtonReport(False, 0)
    norm, ref = system.residual(load_factor)
    report.residuals.append(norm)
    first = norm
    floor_reached = False
    for it in range(1, options.max_iterations + 1):
        tol = options.rtol * ref + options.atol
        if norm <= tol or (floor_reached and norm <= np.sqrt(options.rtol) * ref + options.atol):
            report.converged = True
            break
        system.jacobian()
        try:
            report.increments.append(system.solve())
        except np.linalg.LinAlgError as err:
            report.reason = str(err)
            break
        floor_reached = report.increments[-1] <= options.xtol * system.state_norm()
        system.update()
        report.iterations = it
        norm, ref = system.residual(load_factor)
        report.residuals.append(norm)
        logger.debug("  Newton %2d: |r| = %.3e  |dx| = %.3e", it, norm, report.increments[-1])
        if not math.isfinite(norm) or norm > options.divergence_factor * max(first, tol):
            report.reason = f"diverged: |r| = {norm:.3e} after {it} iterations (initial {first:.3e})"
            break
    else:
        tol = options.rtol * ref + options.atol
        report.converged = norm <= tol
        if not report.converged:
            report.reason = (f"no convergence in {options.max_iterations} iterations: |r| = {norm:.3e} "
                             f"> tolerance {tol:.3e}")
    return report

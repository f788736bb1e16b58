"""Newton–Raphson iterations on a :class:`dolfinx_corot.assembly.System`.

Each iteration assembles r = λ f_ext − f_int(x) and K = ∂f_int/∂x, solves
K dx = r and updates x ← x ⊕ dx through the system's update rule
(multiplicative for rotations). Convergence: ‖r‖ ≤ rtol·ref + atol, with ref
the larger of ‖λ f_ext‖ and ‖f_int‖ (reactions included). Divergence
(NaN, growth of ‖r‖ by ``divergence_factor``, or ``max_iterations``) is
reported, never hidden: the driver then cuts the step and restores the last
converged state.

Line search (Crisfield 1991, §9.3.2): with g(s) = dx·r(x ⊕ s·dx), the energy
is stationary along dx where g = 0. The full step is kept when
|g(1)| ≤ ½ g(0); otherwise s is found by secant steps on g within
[0.1, 1]. This tames the first corrections of large-rotation steps in
finely meshed slender members, where a linear predictor stretches every
rotating element.
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
    """rtol, atol: residual tolerances (relative, force units); xtol: correction relative to
    the step's increment; max_iterations per attempt;
    divergence_factor: ‖r‖ above this multiple of max(initial ‖r‖, reference force) is divergence;
    line_search: scale the correction so that the energy is nearly stationary along it
    (at most ``line_search_trials`` extra residual evaluations per iteration; a correction that
    inverts an element is halved until the residual is finite); None (default): on while contact
    interfaces have candidate pairs (their active set and closest points change within a step),
    off otherwise;
    forcing: inexact Newton for iterative linear solvers (Eisenstat & Walker 1996, choice 2):
    the first solve of a step to ``forcing_initial``, then to
    η_k = γ (‖r_k‖/‖r_{k−1}‖)², kept below ``forcing_max`` and not below what the
    final tolerance needs; direct solvers ignore it;
    preconditioner: 'step' builds the iterative solver's preconditioner (AMG) from the first
    tangent of each step and keeps it for the step's later iterations, 'iteration' rebuilds it
    every iteration."""

    rtol: float = 1e-9
    atol: float = 0.0
    xtol: float = 1e-10
    max_iterations: int = 25
    divergence_factor: float = 1e10
    line_search: bool | None = None
    line_search_trials: int = 4
    line_search_tolerance: float = 0.5
    max_growth: int = 3
    forcing: bool = True
    forcing_initial: float = 1e-3
    forcing_max: float = 1e-2
    forcing_gamma: float = 0.9
    preconditioner: str = "step"


@dataclass
class NewtonReport:
    converged: bool
    iterations: int
    residuals: list[float] = field(default_factory=list)
    increments: list[float] = field(default_factory=list)
    reason: str = ""
    uzawa: int = 0  # augmented-Lagrangian updates (contact)

    def rate(self) -> float:
        """Estimated order of convergence from the last three residuals (nan if too few)."""
        r = [x for x in self.residuals if x > 0]
        if len(r) < 3:
            return math.nan
        a, b, c = r[-3:]
        if a == b or b == c:
            return math.nan
        return math.log(c / b) / math.log(b / a)


def converged(norm: float, ref: float, report: NewtonReport, system, options: NewtonOptions) -> bool:
    """Residual test, or a last correction below xtol of the step's summed corrections."""
    if norm <= options.rtol * ref + options.atol:
        return True
    return bool(report.increments) and report.increments[-1] <= options.xtol * system.step_increment_norm()


def newton(system, load_factor: float, options: NewtonOptions = NewtonOptions()) -> NewtonReport:
    """Iterate to equilibrium at ``load_factor``; returns a report (does not raise on divergence)."""
    report = NewtonReport(False, 0)
    contact = getattr(system, "contact", None)
    system.begin_step()  # before the first residual: contact chooses its pairs afresh
    norm, ref = system.residual(load_factor)
    report.residuals.append(norm)
    scale = max(norm, ref)
    growth = 0
    small_correction = False
    for it in range(1, options.max_iterations + 1):
        tol = options.rtol * ref + options.atol
        if norm <= tol or small_correction:
            report.converged = True
            break
        if getattr(system, "iterative", False):
            system.reuse_preconditioner(options.preconditioner == "step" and it > 1)
            if options.forcing:
                eta = forcing_term(options, norm, report.residuals[-2] if it > 1 else None,
                                   eta if it > 1 else None, tol)
                system.set_forcing(eta)
        if contact is not None:
            # after a rise of the residual, the positive part of the contact tangents
            contact.project = it > 1 and report.residuals[-1] > report.residuals[-2]
        system.jacobian()
        rhs = contact.newton_rhs(system.b) if contact is not None else None
        try:
            report.increments.append(system.solve(rhs))
        except np.linalg.LinAlgError as err:
            report.reason = str(err)
            break
        finally:
            if rhs is not None:
                rhs.destroy()
        if contact is not None:
            scale = contact.step_scale(system.dx)  # contact nodes move at most a search margin
            if scale < 1.0:
                system.dx.scale(scale)
        line_search = options.line_search
        if line_search is None:  # near contact: the active set and closest points change
            line_search = contact is not None and contact.engaged
        if line_search:
            norm, ref = _line_search(system, load_factor, options.line_search_trials,
                                     options.line_search_tolerance)
        else:
            system.update()
            norm, ref = system.residual(load_factor)
        report.iterations = it
        small_correction = report.increments[-1] <= options.xtol * system.step_increment_norm()
        report.residuals.append(norm)
        logger.debug("  Newton %2d: |r| = %.3e  |dx| = %.3e", it, norm, report.increments[-1])
        # the first corrections of a large-rotation step may raise |r| (a linear predictor
        # stretches rotating elements); divergence is growth three times running, or blow-up
        growth = growth + 1 if norm > report.residuals[-2] else 0
        if not math.isfinite(norm) or growth >= options.max_growth or norm > options.divergence_factor * scale:
            report.reason = (f"diverged: |r| = {norm:.3e} after {it} iterations "
                             f"(initial {report.residuals[0]:.3e})")
            break
    else:
        tol = options.rtol * ref + options.atol
        report.converged = norm <= tol or small_correction
        if not report.converged:
            report.reason = (f"no convergence in {options.max_iterations} iterations: |r| = {norm:.3e} "
                             f"> tolerance {tol:.3e}")
    if getattr(system, "iterative", False):
        system.set_forcing(None)
        system.reuse_preconditioner(False)
    return report


def forcing_term(options: NewtonOptions, norm: float, previous: float | None, eta_previous: float | None,
                 tol: float) -> float:
    """Relative tolerance of the linear solve at residual ``norm`` (Eisenstat–Walker, choice 2,
    with their safeguard against a sudden decrease of η); floored at half the remaining way
    to the Newton tolerance, so that the last solve does not over-solve."""
    if previous is None or not previous > 0.0:
        eta = options.forcing_initial
    else:
        eta = options.forcing_gamma * (norm / previous) ** 2
        if eta_previous is not None and options.forcing_gamma * eta_previous ** 2 > 0.1:
            eta = max(eta, options.forcing_gamma * eta_previous ** 2)
    eta = min(eta, options.forcing_max)
    if norm > 0.0:
        eta = max(eta, 0.5 * tol / norm)
    return float(min(max(eta, 1e-12), options.forcing_max))


def _line_search(system, load_factor: float, trials: int, tolerance: float) -> tuple[float, float]:
    """Apply s·dx with s from a secant search on g(s) = dx·r; returns the new (‖r‖, ref)."""
    g0 = system.directional_residual()
    base = system.checkpoint()
    s = 1.0
    system.update(s)
    norm, ref = system.residual(load_factor)
    while not math.isfinite(norm) and s > 1.0 / 64:
        s *= 0.5  # the full correction inverts an element: back off
        system.restore(base)
        system.update(s)
        norm, ref = system.residual(load_factor)
    if not (g0 > 0.0) or s < 1.0:
        return norm, ref
    g = system.directional_residual()
    best = (abs(g), 1.0, norm, ref)
    for _ in range(trials):
        if abs(g) <= tolerance * g0 or not math.isfinite(g):
            break
        s_new = s * g0 / (g0 - g) if g0 != g else s
        s_new = min(max(s_new, 0.1), 1.0)
        if abs(s_new - s) < 1e-3:
            break
        s = s_new
        system.restore(base)
        system.update(s)
        norm, ref = system.residual(load_factor)
        g = system.directional_residual()
        if abs(g) < best[0]:
            best = (abs(g), s, norm, ref)
    if best[1] != s:
        s, norm, ref = best[1], best[2], best[3]
        system.restore(base)
        system.update(s)
        norm, ref = system.residual(load_factor)
    return norm, ref

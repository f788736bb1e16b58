"""Newton–Raphson iterations on a :class:`dolfinx_corot.assembly.System`.

Each iteration assembles r = λ f_ext − f_int(x) and K = ∂f_int/∂x, solves
K dx = r and updates x ← x ⊕ dx through the system's update rule
(multiplicative for rotations).

Convergence is judged field by field — forces on the translations, moments
on the rotations — so that the test is homogeneous in each field's units
and a model in mm converges as the same model in m (a single norm would
add N to N·mm). A field converges when ‖r‖ ≤ rtol·ref + atol, with ref the
larger of ‖λ f_ext‖ and ‖f_int‖ over the field (reactions included; for
moments at least h·ref_forces, for forces at least ref_moments/h, with h
the mean element side of the parts with rotations: the nodal forces that
balance a moment M in an element are of order M/h), or when it has reached the
round-off floor of the residual and stopped falling there. The floor is
estimated from the assembled tangent: internal forces computed from
coordinates of size c carry errors of about ε K_ii c (ε K_ii on a
rotation), so ‖r‖ ≤ ε‖diag(K)·c‖ cannot be told from zero (a stiffness
10⁴ times too large, or loads 10⁸ times below the stiffness, put the
tolerance below that floor). The correction test ‖dx‖ ≤ xtol‖Δx‖ is
field by field as well. Divergence (NaN, growth of ‖r‖ above the floor
``max_growth`` times running or by ``divergence_factor``, or
``max_iterations``) is reported with the criterion that was not met and its
level, never hidden: the driver then cuts the step and restores the last
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

from .. import validate

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
    final tolerance needs, on the linear solve's true residual ‖b − Kx‖ (CG); direct
    solvers ignore it;
    preconditioner: 'step' builds the iterative solver's preconditioner (AMG) from the first
    tangent of each step and keeps it for the step's later iterations, 'iteration' rebuilds it
    every iteration;
    max_displacement: a converged state whose displacement exceeds this many times the model's
    size is absurd (loads or materials in the wrong units), and the run stops there."""

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
    forcing_initial: float = 1e-2
    forcing_max: float = 1e-1
    forcing_gamma: float = 0.9
    preconditioner: str = "step"
    max_displacement: float = 1e3

    def __post_init__(self):
        for name in ("rtol", "atol", "xtol"):
            validate.positive("NewtonOptions", name, getattr(self, name), allow_zero=True)
        if self.rtol == 0.0 and self.atol == 0.0:
            raise ValueError("NewtonOptions: rtol and atol are both 0: no residual can converge")
        validate.whole("NewtonOptions", "max_iterations", self.max_iterations, 1)
        validate.whole("NewtonOptions", "max_growth", self.max_growth, 1)
        validate.whole("NewtonOptions", "line_search_trials", self.line_search_trials, 0)
        validate.positive("NewtonOptions", "divergence_factor", self.divergence_factor)
        validate.positive("NewtonOptions", "max_displacement", self.max_displacement)
        if self.preconditioner not in ("step", "iteration"):
            raise ValueError(f"NewtonOptions: preconditioner = {self.preconditioner!r} is not 'step' or "
                             "'iteration'")


@dataclass
class NewtonReport:
    converged: bool
    iterations: int
    residuals: list[float] = field(default_factory=list)
    increments: list[float] = field(default_factory=list)
    reason: str = ""
    updates: int = 0  # contributions' state updates after convergence (augmented-Lagrangian: Uzawa)
    load_factor: float = math.nan  # where the solve ended
    singular_start: bool = False  # the first tangent of the solve could not be factorized

    def rate(self) -> float:
        """Estimated order of convergence from the last three residuals (nan if too few)."""
        r = [x for x in self.residuals if x > 0]
        if len(r) < 3:
            return math.nan
        a, b, c = r[-3:]
        if a == b or b == c:
            return math.nan
        return math.log(c / b) / math.log(b / a)


class Stepper:
    """How a Newton correction is made at a fixed load factor (load and displacement control):
    K dx = rhs. Arc-length supplies its own (:class:`~dolfinx_corot.solvers.control.ArcLengthStepper`),
    which also moves the load factor; the Newton loop and its hooks are the same."""

    check_growth = True  # a residual that grows ``max_growth`` times running is divergence

    def __init__(self, load_factor: float):
        self.load_factor = load_factor

    def correct(self, system, rhs) -> float:
        """Set ``system.dx`` to the correction; return its norm (raises LinAlgError)."""
        return system.solve(rhs)

    def scale(self, factor: float) -> None:
        """The correction was scaled by ``factor`` (a contribution's limit)."""

    def trial_load_factor(self, s: float) -> float:
        """The load factor after applying s·dx (line search)."""
        return self.load_factor

    def accept(self, system, s: float) -> None:
        """s·dx was applied."""


def newton(system, load_factor, options: NewtonOptions = NewtonOptions(), begin: bool = True) -> NewtonReport:
    """Iterate to equilibrium at ``load_factor`` (a number, or a :class:`Stepper` that makes the
    corrections); returns a report (does not raise on divergence).

    The system's contributions take part through hooks: ``before_solve`` before the first
    residual, ``correction_rhs`` for the right-hand side of each correction, ``limit_correction``
    to shorten it, ``needs_line_search`` (when ``options.line_search`` is None) and
    ``after_iteration``. begin: start the solve here (False: the driver did, before a predictor).
    """
    stepper = load_factor if isinstance(load_factor, Stepper) else Stepper(load_factor)
    report = NewtonReport(False, 0)
    if begin:
        system.begin_step()  # before the first residual: contributions' before_solve hooks
    norm, ref = system.residual(stepper.load_factor)
    report.residuals.append(norm)
    if not (math.isfinite(norm) and math.isfinite(ref)):
        # loads or a configuration beyond floating point: no tolerance can judge this residual
        report.reason = (f"the residual is not finite (|r| = {norm:.3e}, load and internal force norm "
                         f"{ref:.3e}): the loads or the configuration overflow")
        report.load_factor = stepper.load_factor
        return report
    scale = max(norm, ref)
    previous = None  # the fields' residuals one iteration back
    growth = 0
    small_correction = False
    eta = None
    for it in range(1, options.max_iterations + 1):
        tol = options.rtol * ref + options.atol
        if within_tolerance(system, options, previous) or small_correction:
            report.converged = True
            break
        if system.iterative:
            system.reuse_preconditioner(options.preconditioner == "step" and it > 1)
            if options.forcing:
                eta = forcing_term(options, norm, report.residuals[-2] if it > 1 else None,
                                   eta if it > 1 else None, tol)
                system.set_forcing(eta)
        fields = dict(system.fields)
        system.jacobian()
        try:
            report.increments.append(stepper.correct(system, system.correction_rhs()))
        except np.linalg.LinAlgError as err:
            report.reason = str(err)
            report.singular_start = it == 1
            break
        factor = system.limit_correction()  # e.g. contact nodes move at most a search margin
        if factor < 1.0:
            system.dx.scale(factor)
            stepper.scale(factor)
        line_search = options.line_search
        if line_search is None:  # on while a contribution asks for it (near contact)
            line_search = system.needs_line_search()
        if line_search:
            s, norm, ref = _line_search(system, stepper, options.line_search_trials, options.line_search_tolerance)
        else:
            s = 1.0
            system.update()
            norm, ref = system.residual(stepper.trial_load_factor(1.0))
        stepper.accept(system, s)
        report.iterations = it
        small_correction = all(d <= options.xtol * total for d, total in system.correction_norms().values())
        previous = fields
        report.residuals.append(norm)
        system.after_iteration(report.residuals)
        logger.debug("  Newton %2d: |r| = %.3e  |dx| = %.3e", it, norm, report.increments[-1])
        # the first corrections of a large-rotation step may raise |r| (a linear predictor
        # stretches rotating elements); divergence is growth three times running, or blow-up
        # (residuals at their round-off floor wander: no growth there)
        noise = all(r <= 2.0 * system.floors.get(name, 0.0) for name, (r, _) in system.fields.items())
        growth = growth + 1 if norm > report.residuals[-2] and not noise else 0
        if not math.isfinite(norm) or (stepper.check_growth and (growth >= options.max_growth
                                                                 or norm > options.divergence_factor * scale)):
            report.reason = (f"diverged: |r| = {norm:.3e} after {it} iterations "
                             f"(initial {report.residuals[0]:.3e})")
            break
    else:
        report.converged = within_tolerance(system, options, previous) or small_correction
        if not report.converged:
            report.reason = f"no convergence in {options.max_iterations} iterations: {stall(system, options, report)}"
    if system.iterative:
        system.set_forcing(None)
        system.reuse_preconditioner(False)
    report.load_factor = stepper.load_factor
    return report


def within_tolerance(system, options: NewtonOptions, previous: dict | None) -> bool:
    """Each field of the residual (forces; moments, when the model has rotations) within
    rtol × its own scale + atol, or at its round-off floor (``system.floors``) where it has
    stopped falling (above half its value one iteration back, ``previous``): residuals there
    are round-off, which no iteration removes. Every test is homogeneous in its units, so a
    model in mm converges as it does in m."""
    for name, (r, ref) in system.fields.items():
        if r <= options.rtol * ref + options.atol:
            continue
        if previous is not None and r <= system.floors.get(name, 0.0) and r > 0.5 * previous[name][0]:
            continue
        return False
    return True


def stall(system, options: NewtonOptions, report: NewtonReport) -> str:
    """Which criterion was not met, and at what level."""
    words = []
    for name, (r, ref) in system.fields.items():
        tol = options.rtol * ref + options.atol
        if r <= tol:
            continue
        floor = system.floors.get(name, 0.0)
        rel = f"{r / ref:.1e} of" if ref > 0.0 else "against"
        words.append(f"the {name} residual |r| = {r:.3e} ({rel} its scale {ref:.3e}) is above the tolerance "
                     f"{tol:.3e} (rtol {options.rtol:g}) and the round-off floor {floor:.1e} that the tangent's "
                     "stiffness sets")
    last = report.residuals[-4:]
    if len(last) >= 4 and min(last[1:]) > 0.1 * last[0]:
        words.append("it has stopped falling (" + ", ".join(f"{x:.2e}" for x in last) + "): a tangent that is "
                     "not consistent, a singular or nearly singular tangent, or data out of scale (loads far "
                     "below the stiffness)")
    return "; ".join(words) if words else f"|r| = {report.residuals[-1]:.3e}"


def solve_step(system, stepper, options: NewtonOptions, begin: bool = True) -> NewtonReport:
    """Newton to equilibrium, then, while a contribution updates its state after convergence
    (augmented-Lagrangian multipliers: Uzawa), Newton again at the converged load factor. The
    report sums the iterations; ``updates`` counts the updates."""
    report = newton(system, stepper, options, begin)
    while report.converged and system.on_converged():
        again = newton(system, report.load_factor, options)
        again.updates = report.updates + 1
        again.iterations += report.iterations
        again.residuals = report.residuals + again.residuals
        again.singular_start = False
        report = again
    if not report.converged and report.updates:
        report.reason = f"after {report.updates} contribution update(s): {report.reason}"
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


def _line_search(system, stepper: Stepper, trials: int, tolerance: float) -> tuple[float, float, float]:
    """Apply s·dx with s from a secant search on g(s) = dx·r; returns (s, ‖r‖, ref) after it."""
    g0 = system.directional_residual()
    base = system.checkpoint()
    s = 1.0
    system.update(s)
    norm, ref = system.residual(stepper.trial_load_factor(s))
    while not math.isfinite(norm) and s > 1.0 / 64:
        s *= 0.5  # the full correction inverts an element: back off
        system.restore(base)
        system.update(s)
        norm, ref = system.residual(stepper.trial_load_factor(s))
    if not (g0 > 0.0) or s < 1.0:
        return s, norm, ref
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
        norm, ref = system.residual(stepper.trial_load_factor(s))
        g = system.directional_residual()
        if abs(g) < best[0]:
            best = (abs(g), s, norm, ref)
    if best[1] != s:
        s, norm, ref = best[1], best[2], best[3]
        system.restore(base)
        system.update(s)
        norm, ref = system.residual(stepper.trial_load_factor(s))
    return s, norm, ref

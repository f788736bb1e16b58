"""Drivers: how the load path is followed.

* :class:`LoadControl` applies the load factors λ₁ < λ₂ < … in turn. With
  prescribed displacements (``Scene.prescribe``) the same driver is
  *displacement control*: λ scales the prescribed motion and the reactions
  are read with ``Scene.monitor_reaction``.
* :class:`ArcLength` follows the equilibrium path through limit points
  (snap-through and snap-back) by Crisfield's cylindrical arc-length method.

A step that fails is cut in half and retried from the exact last converged
state (configuration, rotations, history), up to ``max_cuts`` times in a row.
Before the first cut a contribution may offer another start for the same step
(frictional contact: the elastic predictor), tried once. After all cuts a
:class:`ConvergenceError` carries every converged step.
"""
from __future__ import annotations

import logging
import math
from dataclasses import asdict, dataclass, field
from typing import Callable, Sequence

import numpy as np

from .. import validate
from ..result import Result
from .newton import NewtonOptions, NewtonReport, Stepper, newton, solve_step
from .run import CheckpointError, Run
from .stability import (CriticalPoint, CriticalPointError, StabilityTracker, check_first_tangent,
                        singular_model)

STABILITY = ("auto", "on", "off")
# a step whose Newton iterates crossed states less stable than both its ends is followed again in
# halves; a leap across a limit point is declared where it persists at 1/2**LEAP_CUTS of the step
LEAP_CUTS = 4
# ... when the step's increment exceeds LEAP_RATIO times its first (tangent) correction
LEAP_RATIO = 2.0
# a step that goes FAR_LEAP_RATIO times as far as its tangent predicted is checked for a leap even where
# its iterates showed no less stable state (see :func:`_far_beyond_prediction`)
FAR_LEAP_RATIO = 10.0


def _far_beyond_prediction(system, tracker, report, before, after) -> bool:
    """Whether a step between stable states went more than FAR_LEAP_RATIO times as far as its
    tangent predicted, on a system whose factorizations give the determinant's sign alone (LU),
    which does not change where two eigenvalues cross zero together (a symmetric structure's
    double mode): a leap across a limit point that the signs miss. Systems with contact are
    left out: a gap that closes or a stick that slips makes such steps on a stable path."""
    return (system.smooth and before == 0 and after == 0
            and bool(report.increments)
            and system.step_increment_norm() > FAR_LEAP_RATIO * report.increments[0])

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class LoadControl:
    """Load factors ``load_factors`` in turn (they may decrease, to unload), or ``steps`` equal
    steps up to ``final``.

    max_cuts: successive halvings of a failing step before giving up;
    extrapolate: start each step from a prediction instead of the last converged state
    (exact rollback still restores the converged state): True or 'secant', the line through
    the last two converged states; 'quadratic', the parabola through the last three (the
    secant while there are two). With 3D rotations (beams, shells) the secant acts on the
    rotation group (each nodal rotation's last increment applied again, scaled); the parabola
    is not available there. Measured on the bent SVK
    block of ``benchmarks/block3d.py`` (100 × 10 × 10 hexahedra, 5 steps): 29 Newton
    iterations from the last state, 23 with the secant, 22 with the parabola (which saves one
    in its third step and loses its gain in the later ones).

    stability: count the negative eigenvalues of the tangent at every converged state
    ('auto': free with the LDLᵀ solver — with a predictor, from the step's last factorization —
    one extra LDLᵀ factorization per step otherwise for
    systems of up to 200 000 dofs — 20 000 for 3D continua on the iterative solver; 'on';
    'off'; see :mod:`~dolfinx_corot.solvers.stability`);
    at_critical_point: where the count changes (a bifurcation) or a step leaps across a limit
    point (its Newton iterates cross states less stable than both ends and it goes more than twice
    as far as its tangent predicted — or, without contact, more than ten times as far whatever
    its iterates' counts, which can skip the unstable states altogether — and it still does so
    when followed again in halves down to 1/16 of it; the history columns
    ``stability_checks`` and ``stability_iterations`` count such checks and the Newton iterations
    they took), the critical point is recorded (``result.critical_points``, with its load factor) and
    'stop' (default) ends the run at the last state before it with a
    :class:`~dolfinx_corot.solvers.stability.CriticalPointError`; 'continue' goes on (with a
    warning): load control past a critical point follows an unstable or a remote branch.
    """

    steps: int = 10
    final: float = 1.0
    load_factors: Sequence[float] | None = None
    max_cuts: int = 8
    extrapolate: bool | str = False
    newton: NewtonOptions = NewtonOptions()
    stability: str = "auto"
    at_critical_point: str = "stop"

    def __post_init__(self):
        validate.whole("LoadControl", "steps", self.steps, 1)
        validate.choice("LoadControl", "stability", self.stability, STABILITY)
        validate.choice("LoadControl", "at_critical_point", self.at_critical_point, ("stop", "continue"))
        validate.whole("LoadControl", "max_cuts", self.max_cuts, 0)
        if self.extrapolate not in (False, True, "secant", "quadratic"):
            raise ValueError(f"LoadControl: extrapolate = {self.extrapolate!r} is not one of False, True, "
                             "'secant', 'quadratic'")
        if self.load_factors is None and not (isinstance(self.final, (int, float)) and math.isfinite(self.final)
                                              and self.final != 0.0):
            raise ValueError(f"LoadControl: final = {self.final!r} must be a finite load factor other than 0 "
                             "(the start)")
        self.targets()

    def targets(self) -> np.ndarray:
        """The load factors to reach in turn (any order: they may decrease, to unload)."""
        if self.load_factors is not None:
            lf = np.asarray(self.load_factors, dtype=float)
        else:
            if self.steps < 1:
                raise ValueError(f"LoadControl: steps = {self.steps} must be at least 1")
            lf = np.linspace(0.0, self.final, self.steps + 1)[1:]
        if len(lf) == 0 or not np.all(np.isfinite(lf)):
            raise ValueError("LoadControl: load factors must be finite and not empty")
        return lf

    def describe(self) -> dict:
        return {"name": "LoadControl", "targets": self.targets().tolist(), "max_cuts": self.max_cuts,
                "extrapolate": self.extrapolate}

    def _restart_index(self, state: dict, lam: float, path: str) -> int:
        """Where a restart continues: at the checkpoint's next target when this driver's targets
        begin like those it had reached (the same driver, or one asking for more: a larger
        ``final`` with the same step, more ``load_factors``); else, for monotone targets, at the
        first one beyond the load factor reached (a smooth continuation with this driver's step);
        anything else is refused."""
        targets = self.targets()
        done = int(state["next_target"])
        old = np.asarray(state.get("targets", []), dtype=float)
        if len(old) >= done and len(targets) >= done and np.array_equal(targets[:done], old[:done]):
            return done
        steps = np.diff(np.concatenate([[0.0], targets]))
        if np.all(steps > 0.0) or np.all(steps < 0.0):
            beyond = np.flatnonzero(np.sign(steps[0]) * (targets - lam) > 1e-14 * max(1.0, abs(lam)))
            start = int(beyond[0]) if len(beyond) else len(targets)
            logger.info("restart from %s at load factor %.6g: this driver's targets differ from the "
                        "checkpoint's; continuing at %s", path, lam,
                        f"{targets[start]:.6g}" if start < len(targets) else "its end")
            return start
        raise CheckpointError(f"restart from {path}: the load factors of this LoadControl differ from those of "
                              "the checkpoint's and do not increase (or decrease) steadily, so where to go on "
                              "is ambiguous; restart with the same driver or one that extends it")

    def run(self, run: Run, restart: str | None = None) -> Result:
        system = run.system
        if self.extrapolate == "quadratic":
            models = system.model.models if system.model.coupled else [system.model]
            if any(m.multiplicative_rotations for m in models):
                raise NotImplementedError("LoadControl(extrapolate='quadratic') is not available for 3D rotations; "
                                          "use extrapolate=True (the secant on the rotation group)")
        targets = self.targets()
        start = 0
        if restart is not None:
            state, _ = run.load(restart, "LoadControl")
            start = self._restart_index(state, run.load_factor, restart)
        lam = run.load_factor
        previous = older = None
        tracker = StabilityTracker(system, self.stability)
        if run.history.rows and "negative_eigenvalues" in run.history.rows[-1]:
            tracker.negative = int(run.history.rows[-1]["negative_eigenvalues"])
        run.expect(len(targets), start)
        for index in range(start, len(targets)):
            target = targets[index]
            origin = lam
            cuts = 0
            retried = check_iterations = 0
            while abs(target - lam) > 1e-14 * max(1.0, abs(target)):
                trial = target if cuts == 0 else lam + (target - lam) / 2**cuts
                cp = system.checkpoint()
                started = run.begin()
                if self.extrapolate and previous is not None and lam != previous[0]:
                    # a polynomial through the last converged states: the parabola through three
                    # while the path goes on in one direction, else the secant through two
                    path = [previous, (lam, cp)]
                    onward = older is not None and (older[0] - previous[0]) * (previous[0] - lam) > 0.0 \
                        and (previous[0] - lam) * (lam - trial) > 0.0
                    if self.extrapolate == "quadratic" and onward:
                        path.insert(0, older)
                    system.predict(path, trial)
                system.before_step()
                tracker.start_attempt()
                first = run.step == 0 and run.cuts == 0 and restart is None
                if first:
                    check_first_tangent(run, lam)
                report = solve_step(system, Stepper(trial), self.newton)
                if not report.converged and report.singular_start and first:
                    system.restore(cp)
                    singular_model(run, report.reason)
                if report.converged:
                    absurd = run.implausible(self.newton.max_displacement)
                    if absurd:
                        system.restore(cp)
                        run.fail(f"step {run.step + 1} to load factor {trial:.6g}: {absurd}")
                if not report.converged:
                    system.restore(cp)
                    if system.another_start():
                        logger.info("step %d: lambda %.6g failed (%s); tried again from another start", run.step + 1,
                                    trial, report.reason)
                        continue
                    cuts += 1
                    run.cuts += 1
                    logger.info("step %d: lambda %.6g failed (%s); cut %d", run.step + 1, trial, report.reason, cuts)
                    if cuts > self.max_cuts:
                        if previous is not None and tracker.enabled:
                            self._limit_ahead(run, tracker, previous, lam, target)
                        run.fail(f"step {run.step + 1}: no convergence to load factor {trial:.6g} from "
                                 f"{lam:.6g} after {self.max_cuts} cuts; last attempt: {report.reason}. "
                                 "Try smaller steps, or arc-length past a limit point.")
                    continue
                before, after, passed = tracker.converged(trial, starts_next=not self.extrapolate)
                # past a critical point (the path already unstable) the iterates' counts say nothing
                passed = passed and before == 0
                passed = passed or _far_beyond_prediction(system, tracker, report, before, after)
                leap = None
                if passed and after == before and report.increments and \
                        system.step_increment_norm() <= LEAP_RATIO * report.increments[0]:
                    # the step ended near where its first (tangent) correction pointed: Newton's
                    # first iterates overshot into less stable states and came back
                    passed = False
                if passed and after == before:
                    # the iterates crossed less stable states than both ends and the step went
                    # far beyond its tangent prediction: a leap across a limit point, or a strongly
                    # nonlinear step that Newton overshot. States on the secant between
                    # the ends tell (2D); where they cannot (rotations in 3D) or say unstable, the
                    # step is followed again in halves (not recorded) down to 1/16 of it
                    verdict = tracker.secant_unstable(cp, system.checkpoint(), lam, trial, before)
                    if verdict is False:
                        passed = False
                        tracker.count_here(trial)  # the next step's first tangent again
                    else:
                        passed, leap, checked = self._verify_step(run, tracker, cp, lam, trial, before)
                        retried += 1
                        check_iterations += checked
                extra = {} if after is None else {"negative_eigenvalues": after, "stability_checks": retried,
                                                  "stability_iterations": check_iterations}
                retried = check_iterations = 0
                if leap is not None:  # a leap within the step: its sub-step (a, b) from state cp_a
                    a, b, cp_a = leap
                    self._critical_point(run, tracker, cp_a, (lam, cp) if a != lam else previous, a, b, before,
                                         after, True, stop_at=cp, trial_here=trial)
                elif before is not None and after is not None and (after != before or passed):
                    self._critical_point(run, tracker, cp, previous, lam, trial, before, after, passed)
                older, previous = previous, (lam, cp)
                lam = trial
                reached = abs(target - lam) <= 1e-14 * max(1.0, abs(target))
                run.record(lam, report, cuts, started, extra,
                           position=index + (1.0 if reached else (lam - origin) / (target - origin)))
                if run.checkpoint_path is not None:
                    run.save({**self.describe(), "next_target": index + 1 if reached else index})
                cuts = max(cuts - 1, 0)
        return run.result()

    def _limit_ahead(self, run: Run, tracker: StabilityTracker, previous, lam: float, target: float) -> None:
        """Load control could not go beyond λ = ``lam``: if the smallest eigenvalue μ of the tangent
        falls towards zero there — μ² extrapolated from the last two converged states vanishes
        before ``target`` — a limit point lies ahead; record it and stop with its estimate."""
        system = run.system
        here = system.checkpoint()
        mu0 = tracker.eigenvalue_here(lam)
        system.restore(previous[1])
        mum = tracker.eigenvalue_here(previous[0])
        system.restore(here)
        if not (mum**2 > mu0**2 > 0.0 and abs(mu0) < abs(mum)):
            return
        estimate = lam + mu0**2 * (lam - previous[0]) / (mum**2 - mu0**2)
        if not min(lam, target) <= estimate <= max(lam, target):
            return
        point = CriticalPoint("limit point", float(estimate), (float(lam), float(target)), run.step + 1,
                              int(tracker.negative or 0), int(tracker.negative or 0),
                              "squared smallest eigenvalue extrapolated to zero")
        run.critical_points.append(point)
        run.fail(f"step {run.step + 1}: a limit point near load factor {estimate:.6g}: load control cannot go "
                 f"beyond {lam:.6g} (towards {target:.6g}), where the smallest eigenvalue of the tangent "
                 f"falls to zero. Follow the path with ArcLength (or prescribe a displacement: displacement "
                 "control).", CriticalPointError)

    def _verify_step(self, run: Run, tracker: StabilityTracker, cp, lam: float, trial: float,
                     before: int) -> tuple[bool, tuple | None, int]:
        """The step λ = ``lam`` (state ``cp``) → ``trial`` (the current state) whose iterates crossed
        less stable states, followed again in halves from ``cp`` (nothing recorded): (leapt, the
        leap's sub-step (a, b, state at a) or None, Newton iterations spent). Where the halves reach
        ``trial`` on a stable path, the step stands — at its own end state if the halves end there,
        else at theirs (the original step had jumped to another equilibrium)."""
        system = run.system
        end = system.checkpoint()
        system.restore(cp)
        tracker.negative = before
        status, where, iterations = self._follow(run, tracker, lam, trial, before, 1)
        if status == "leap":
            system.restore(end)  # the step as it was made (recorded with 'continue')
            return True, where, iterations
        here = system.checkpoint()
        moved = system.translation_difference(cp, end)
        differ = system.translation_difference(end, here)  # leaves the halves' end state
        if differ <= 1e-3 * moved:
            system.restore(end)
        else:
            logger.warning("step %d: load control had jumped to another equilibrium at lambda %.6g; the state "
                           "reached in halves is kept (translations differ by %.3g)", run.step + 1, trial, differ)
        tracker.negative = tracker.count_here(trial)  # the next step's first tangent, at this state
        return False, None, iterations

    def _follow(self, run: Run, tracker: StabilityTracker, lam0: float, lam1: float, before: int,
                depth: int) -> tuple[str, tuple | None, int]:
        """Follow λ0 → λ1 from the current state in two halves, each halved again where its
        iterates cross less stable states, its count changes or it fails, down to 1/2**LEAP_CUTS of
        the step: ('ok', None, iterations) at λ1, or ('leap', (a, b, state at a), iterations)."""
        system = run.system
        iterations = 0
        mid = 0.5 * (lam0 + lam1)
        for a, b in ((lam0, mid), (mid, lam1)):
            cp_a = system.checkpoint()
            system.before_step()
            tracker.start_attempt()
            report = solve_step(system, Stepper(b), self.newton)
            iterations += report.iterations
            flagged = not report.converged
            if report.converged:
                _, after, passed = tracker.converged(b)
                flagged = passed or after != before or _far_beyond_prediction(system, tracker, report, before, after)
            if flagged:
                system.restore(cp_a)
                tracker.negative = before
                if depth >= LEAP_CUTS:
                    return "leap", (a, b, cp_a), iterations
                status, where, n = self._follow(run, tracker, a, b, before, depth + 1)
                iterations += n
                if status != "ok":
                    return status, where, iterations
        return "ok", None, iterations

    def _critical_point(self, run: Run, tracker: StabilityTracker, cp, previous, lam: float, trial: float,
                        before: int, after: int, passed: bool, stop_at=None, trial_here=None) -> None:
        """Record the critical point crossed between λ = ``lam`` (state ``cp``) and ``trial`` (the
        current state, reached at ``trial_here`` if given); stop there (at state ``stop_at``, default
        ``cp``) unless ``at_critical_point`` is 'continue'."""
        system = run.system
        here = system.checkpoint()
        if after != before:
            # a bifurcation: the eigenvalue closest to zero changes sign between the two states
            kind = "bifurcation"
            mu1 = tracker.eigenvalue_here(trial)
            system.restore(cp)
            mu0 = tracker.eigenvalue_here(lam)
            if mu0 * mu1 < 0.0:
                estimate, how = lam + (trial - lam) * mu0 / (mu0 - mu1), "smallest eigenvalue interpolated to zero"
            else:
                estimate, how = 0.5 * (lam + trial), "middle of the bracket"
        else:
            # the Newton iterates crossed an unstable region and landed on a stable state: the step
            # leapt across a limit point (snap-through); near it the smallest eigenvalue μ goes as
            # √(λc − λ), so μ² is extrapolated to zero from the last two states before it
            kind = "limit point (jumped)"
            system.restore(cp)
            mu0 = tracker.eigenvalue_here(lam)
            estimate, how = 0.5 * (lam + trial), "middle of the bracket"
            if previous is not None:
                system.restore(previous[1])
                mum = tracker.eigenvalue_here(previous[0])
                if mum**2 > mu0**2 > 0.0:
                    estimate = lam + mu0**2 * (lam - previous[0]) / (mum**2 - mu0**2)
                    estimate = min(max(estimate, min(lam, trial)), max(lam, trial))
                    how = "squared smallest eigenvalue extrapolated to zero"
            system.restore(cp)
        point = CriticalPoint(kind, float(estimate), (float(lam), float(trial)), run.step + 1, int(before),
                              int(after), how)
        run.critical_points.append(point)
        change = (f"the step leapt: its Newton iterates crossed states whose tangent has more than {before} "
                  f"negative eigenvalues, or it went over {FAR_LEAP_RATIO:g} times as far as its tangent "
                  f"predicted, also in parts down to 1/{2**LEAP_CUTS} of it" if after == before
                  else f"negative eigenvalues of the tangent {before} → {after}")
        words = (f"step {run.step + 1}: a {kind} near load factor {estimate:.6g} (between {lam:.6g} and "
                 f"{trial:.6g}; {change})")
        if self.at_critical_point == "stop":
            system.restore(cp if stop_at is None else stop_at)
            tracker.negative = before
            run.fail(f"{words}: past it, load control follows an unstable or a remote branch. Follow the path "
                     "with ArcLength (or prescribe a displacement: displacement control); "
                     "LoadControl(at_critical_point='continue') goes on regardless.", CriticalPointError)
        logger.warning("%s; continuing under load control", words)
        system.restore(here)
        # residual (reactions, monitors) and the next step's first tangent at this state again
        system.tangent_at(trial if trial_here is None else trial_here)
        system.take_inertia()


class ArcLengthStepper(Stepper):
    """Corrections of Crisfield's cylindrical arc-length method: K dx_t = f, K dx_r = r,
    dx = dx_r + δλ dx_t with δλ the root of ‖Δx + dx‖² + ψ²F(Δλ + δλ)² = Δl² whose increment
    makes the smaller angle with the current one (Crisfield 1991, §9.3–9.4)."""

    check_growth = False  # the constraint, not the residual, steers the first iterations

    def __init__(self, lam: float, Dlam: float, f, dxt, dxr, Dx, arc: float, psi2F: float):
        self.lam, self.Dlam = lam, Dlam
        self.f, self.dxt, self.dxr, self.Dx = f, dxt, dxr, Dx
        self.arc, self.psi2F = arc, psi2F
        self.dl = 0.0

    @property
    def load_factor(self) -> float:
        return self.lam + self.Dlam

    def correct(self, system, rhs) -> float:
        dxt, dxr, Dx, psi2F = self.dxt, self.dxr, self.Dx, self.psi2F
        system.solve(self.f, dxt)
        system.solve(rhs, dxr)
        a = dxt.dot(dxt) + psi2F
        Dx.copy(system.dx)
        system.dx.axpy(1.0, dxr)  # Δx + dx_r
        b = 2.0 * (dxt.dot(system.dx) + psi2F * self.Dlam)
        c = system.dx.dot(system.dx) + psi2F * self.Dlam**2 - self.arc**2
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            # no point of the line dx_r + δλ dx_t lies on the constraint: take the
            # closest one (Crisfield 1991, §9.4.1) and let the next iterations return
            roots = [-b / (2 * a)]
        else:
            roots = [(-b + math.sqrt(disc)) / (2 * a), (-b - math.sqrt(disc)) / (2 * a)]
        # angle with the current increment: (Δx + dx_r + δλ dx_t)·Δx + ψ²F Δλ(Δλ+δλ)
        base = system.dx.dot(Dx)
        tdot = dxt.dot(Dx)
        cosines = [base + r * tdot + psi2F * self.Dlam * (self.Dlam + r) for r in roots]
        self.dl = roots[int(np.argmax(cosines))]
        dxr.copy(system.dx)
        system.dx.axpy(self.dl, dxt)
        return system.dx.norm()

    def scale(self, factor: float) -> None:
        self.dl *= factor

    def trial_load_factor(self, s: float) -> float:
        return self.lam + (self.Dlam + s * self.dl)

    def accept(self, system, s: float) -> None:
        self.Dx.axpy(s, system.dx)
        self.Dlam = self.Dlam + s * self.dl


@dataclass(frozen=True)
class ArcLength:
    """Crisfield's cylindrical arc-length method (Crisfield 1981; 1991, §9.3).

    Unknowns x and λ satisfy r(x, λ) = 0 and ‖Δx‖² + ψ²Δλ²‖f_ext‖² = Δl²
    within each step. Corrections: K dx_r = r, K dx_t = f_ext,
    dx = dx_r + δλ dx_t with δλ a root of the constraint; the root whose
    increment makes the smaller angle with the previous one is taken. The
    predictor follows the sign of Δx_prev·dx_t, which passes limit points
    and snap-backs. The predictor's load direction is the sign of det K (the
    parity of the number of negative eigenvalues, counted by the LDLᵀ
    factorization), so λ turns exactly at limit points; without that count it
    follows the sign of Δx_prev·dx_t (Feng, Perić & Owen 1996). Δl adapts as
    Δl·√(desired/used iterations), within [min_length, max_length].

    initial_increment: load-factor increment of the first step (sets Δl);
    max_steps; max_load_factor: stop when ``|λ|`` reaches it; stop: a function of
    the history row that returns True to stop (e.g. a displacement reached);
    psi: load term weight (0: cylindrical); max_growth: largest factor by which Δl
    grows from one step to the next; stability: count the negative eigenvalues of the tangent
    at every converged state (as for :class:`LoadControl`) and list the limit points (where λ
    turns) and bifurcations (where the count changes while λ does not turn) in
    ``result.critical_points``.
    """

    initial_increment: float = 0.05
    max_steps: int = 100
    max_load_factor: float = math.inf
    stop: Callable[[dict], bool] | None = None
    desired_iterations: int = 5
    min_length: float | None = None
    max_length: float | None = None
    psi: float = 0.0
    max_growth: float = 1.5
    max_cuts: int = 8
    newton: NewtonOptions = field(default_factory=NewtonOptions)
    stability: str = "auto"

    def __post_init__(self):
        validate.choice("ArcLength", "stability", self.stability, STABILITY)
        validate.whole("ArcLength", "max_steps", self.max_steps, 1)
        validate.whole("ArcLength", "max_cuts", self.max_cuts, 0)
        validate.whole("ArcLength", "desired_iterations", self.desired_iterations, 1)
        if not (isinstance(self.initial_increment, (int, float)) and math.isfinite(self.initial_increment)
                and self.initial_increment != 0.0):
            raise ValueError(f"ArcLength: initial_increment = {self.initial_increment!r} must be a finite "
                             "number other than 0")
        for name in ("min_length", "max_length"):
            validate.positive("ArcLength", name, getattr(self, name), allow_none=True)
        validate.positive("ArcLength", "psi", self.psi, allow_zero=True)
        if not self.max_growth >= 1.0:
            raise ValueError(f"ArcLength: max_growth = {self.max_growth!r} must be ≥ 1")

    def describe(self) -> dict:
        d = {k: v for k, v in asdict(self).items() if k not in ("stop", "newton")}
        return {"name": "ArcLength", **{k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                                        for k, v in d.items()}}

    def run(self, run: Run, restart: str | None = None) -> Result:
        """Follow the path; a restart continues with the checkpoint's arc length and direction
        (this driver's stopping rules — ``max_steps``, ``max_load_factor``, ``stop`` — apply)."""
        system = run.system
        if system.has_prescribed_motion:
            raise NotImplementedError("arc-length with prescribed displacements is not supported; "
                                      "follow them with LoadControl (displacement control)")
        if run.scene.follower_loads:
            raise NotImplementedError("arc-length with follower loads (pressures, follower loads per length) is not "
                                      "supported: its reference load would change with the configuration; follow "
                                      "them with LoadControl or displacement control")
        if system.reference_load_norm == 0.0:
            raise ValueError("arc-length needs a reference load: the scene has no loads proportional to λ")
        if system.amplitude_loads:
            raise NotImplementedError("arc-length follows proportional loading only; loads with an "
                                      "amplitude are applied with LoadControl")
        opts = self.newton
        f = system.new_vector()
        system.reference_load(f)
        F = f.dot(f)
        psi2F = self.psi**2 * F
        dxt, dxr, Dx, Dx_prev = (system.new_vector() for _ in range(4))
        lam = run.load_factor
        dlam_prev = 0.0
        have_prev = False
        arc = None
        arc_min = arc_max = None
        cuts = 0
        tracker = StabilityTracker(system, self.stability)
        pending = None
        if restart is not None:
            state, arrays = run.load(restart, "ArcLength")
            arc, arc_min, arc_max = state["arc"], state["arc_min"], state["arc_max"]
            dlam_prev, have_prev = state["dlam_prev"], state["have_prev"]
            lam = run.load_factor
            system.global_to_vector(arrays, "Dx_prev", Dx_prev)
        run.expect(self.max_steps, run.step)
        reached = float(run.step)
        while run.step < self.max_steps:
            cp = system.checkpoint()
            started = run.begin()
            report = NewtonReport(False, 0)
            system.before_step()
            first = run.step == 0 and run.cuts == 0 and restart is None
            if first:
                check_first_tangent(run, lam)
            try:
                # predictor along the tangent (of the converged state: contributions evaluated there)
                system.residual(lam)
                system.jacobian()
                try:
                    system.solve(f, dxt)
                except np.linalg.LinAlgError as err:
                    if first:
                        system.restore(cp)
                        singular_model(run, str(err))
                    raise
                tnorm = math.sqrt(dxt.dot(dxt) + psi2F)
                if arc is None:
                    arc = abs(self.initial_increment) * tnorm
                    arc_min = self.min_length if self.min_length is not None else 1e-6 * arc
                    arc_max = self.max_length if self.max_length is not None else 1e3 * arc
                neg = system.negative_eigenvalues()
                if not have_prev:
                    sign = math.copysign(1.0, self.initial_increment)
                elif neg is not None:
                    # sign(δλ) = sign(det K) (Crisfield 1991, §9.5): λ turns where an eigenvalue
                    # of K crosses zero (a limit point), nowhere else
                    sign = math.copysign(1.0, self.initial_increment) * (-1.0) ** neg
                else:
                    sign = math.copysign(1.0, dxt.dot(Dx_prev) + psi2F * dlam_prev)
                dlam = sign * arc / tnorm
                dxt.copy(system.dx)
                system.dx.scale(dlam)
                system.begin_step()
                system.update()
                system.dx.copy(Dx)
                # corrections on the constraint, then (augmented-Lagrangian contact) updates of the
                # contributions at the converged load factor, each followed by Newton at that load
                # factor (the arc-length constraint then holds to the size of these corrections)
                stepper = ArcLengthStepper(lam, dlam, f, dxt, dxr, Dx, arc, psi2F)
                report = solve_step(system, stepper, opts, begin=False)
                ok = report.converged
                Dlam = stepper.Dlam
            except np.linalg.LinAlgError as err:
                ok = False
                report.reason = str(err)
            if not ok:
                system.restore(cp)
                if system.another_start():
                    logger.info("arc-length step %d failed (%s); tried again from another start", run.step + 1,
                                report.reason)
                    continue
                cuts += 1
                run.cuts += 1
                logger.info("arc-length step %d failed (%s); cut %d", run.step + 1, report.reason, cuts)
                if arc is None or cuts > self.max_cuts or arc / 2 < arc_min:
                    run.fail(f"arc-length step {run.step + 1} at load factor {lam:.6g}: no convergence after "
                             f"{cuts - 1} cuts (arc length {arc:.3e}); last attempt: {report.reason}")
                arc /= 2
                continue
            before, after, _ = tracker.converged(lam + Dlam)
            if pending is not None:
                pending["arc_next"] = arc
                self._classify(run, pending, turned=Dlam * pending["Dlam"] < 0.0, lam_next=lam + Dlam)
                pending = None
            if before is not None and after is not None and after != before:
                pending = self._event(run, tracker, cp, lam, lam + Dlam, Dlam, dlam_prev, before, after)
            lam += Dlam
            Dx.copy(Dx_prev)
            dlam_prev = Dlam
            have_prev = True
            extra = {"arc_length": arc}
            if after is not None:
                extra["negative_eigenvalues"] = after
            if math.isfinite(self.max_load_factor):  # the steps or the load factor, whichever is further
                reached = max(reached, self.max_steps * abs(lam) / self.max_load_factor)
            reached = max(reached, run.step + 1.0)
            row = run.record(lam, report, cuts, started, extra, position=reached)
            cuts = 0
            factor = math.sqrt(self.desired_iterations / max(report.iterations, 1))
            arc = min(max(arc * min(max(factor, 0.5), self.max_growth), arc_min), arc_max)
            run.save({**self.describe(), "arc": arc, "arc_min": arc_min, "arc_max": arc_max,
                      "dlam_prev": dlam_prev, "have_prev": have_prev}, {"Dx_prev": Dx_prev})
            if abs(lam) >= self.max_load_factor or (self.stop is not None and self.stop(row)):
                break
        if pending is not None:
            self._classify(run, pending, turned=False, lam_next=None)
        for v in (f, dxt, dxr, Dx, Dx_prev):
            v.destroy()
        return run.result()

    @staticmethod
    def _event(run: Run, tracker: StabilityTracker, cp, lam: float, lam_new: float, Dlam: float,
               dlam_prev: float, before: int, after: int) -> dict:
        """A change of the count between λ = ``lam`` (state ``cp``) and ``lam_new`` (current): the
        eigenvalue closest to zero on either side, for a bifurcation's estimate."""
        system = run.system
        here = system.checkpoint()
        mu1 = tracker.eigenvalue_here(lam_new)
        system.restore(cp)
        mu0 = tracker.eigenvalue_here(lam)
        system.restore(here)
        tracker.system.tangent_at(lam_new)  # the next predictor's tangent
        tracker.system.take_inertia()
        return {"step": run.step + 1, "lam": lam, "lam_new": lam_new, "Dlam": Dlam, "before": before,
                "after": after, "mu": (mu0, mu1), "turned": dlam_prev * Dlam < 0.0}

    @staticmethod
    def _classify(run: Run, e: dict, turned: bool, lam_next: float | None) -> None:
        """A limit point if λ turns at the event's step or the next (its load factor: the vertex of
        the parabola through the three path points around it), else a bifurcation (the smallest
        eigenvalue interpolated to zero)."""
        lam, lam_new = e["lam"], e["lam_new"]
        if e["turned"] or turned:
            rows = run.history.rows
            estimate, how = lam_new, "load factor of the path point nearest to it"
            if len(rows) >= 2 and lam_next is not None:
                # λ(s) along the path's arc length s: a parabola through the last three points
                y = np.array([rows[-2]["load_factor"], rows[-1]["load_factor"], lam_next])
                s = np.array([0.0, rows[-1]["arc_length"], rows[-1]["arc_length"] + e["arc_next"]])
                c = np.polyfit(s, y, 2)
                vertex = -c[1] / (2 * c[0]) if c[0] != 0.0 else -1.0
                if s[0] <= vertex <= s[2]:
                    estimate, how = float(np.polyval(c, vertex)), "parabola through the path points around it"
            kind = "limit point"
        else:
            mu0, mu1 = e["mu"]
            kind = "bifurcation"
            if mu0 * mu1 < 0.0:
                estimate, how = lam + (lam_new - lam) * mu0 / (mu0 - mu1), "smallest eigenvalue interpolated to zero"
            else:
                estimate, how = 0.5 * (lam + lam_new), "middle of the bracket"
        point = CriticalPoint(kind, float(estimate), (float(lam), float(lam_new)), e["step"], int(e["before"]),
                              int(e["after"]), how)
        run.critical_points.append(point)
        logger.info("arc-length: a %s near load factor %.6g (negative eigenvalues %d → %d)", kind, estimate,
                    e["before"], e["after"])

"""Drivers: how the load path is followed.

:class:`LoadControl` applies the load factors λ₁ < λ₂ < … in turn. A step
whose Newton iterations fail is cut in half and retried from the exact last
converged state (configuration, rotations, history), up to ``max_cuts``
times in a row; after a successful sub-step the remainder is attempted
whole again.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..assembly import System
from ..result import History, Result
from .newton import ConvergenceError, NewtonOptions, newton

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class LoadControl:
    """Load factors ``load_factors`` (increasing), or ``steps`` equal steps up to ``final``.

    max_cuts: successive halvings of a failing step before giving up;
    extrapolate: start each step from the secant extrapolation of the last
    converged increment instead of the last converged state (exact rollback
    still restores the converged state).
    """

    steps: int = 10
    final: float = 1.0
    load_factors: Sequence[float] | None = None
    max_cuts: int = 8
    extrapolate: bool = False
    newton: NewtonOptions = NewtonOptions()

    def targets(self) -> np.ndarray:
        if self.load_factors is not None:
            lf = np.asarray(self.load_factors, dtype=float)
        else:
            if self.steps < 1:
                raise ValueError(f"LoadControl: steps = {self.steps} must be at least 1")
            lf = np.linspace(0.0, self.final, self.steps + 1)[1:]
        if len(lf) == 0 or not np.all(np.isfinite(lf)):
            raise ValueError("LoadControl: load factors must be finite and not empty")
        return lf


def solve(scene, driver: LoadControl, system: System | None = None, on_step=None) -> Result:
    """Run ``driver`` on ``scene``; returns a :class:`Result`.

    On a step that fails after all cuts, raises :class:`ConvergenceError`
    whose ``result`` holds every converged step, and the configuration is
    left at the last converged state. ``on_step(row)`` is called after every
    converged step with its history row (e.g. to store snapshots).
    """
    own_system = system is None
    if own_system:
        system = System(scene.model)
    history = History()
    t_start = time.perf_counter()
    lam = 0.0
    previous = None
    step = 0
    cuts_total = 0
    iters_total = 0
    try:
        for target in driver.targets():
            cuts = 0
            while lam < target - 1e-14 * max(1.0, abs(target)):
                trial = target if cuts == 0 else lam + (target - lam) / 2**cuts
                cp = system.checkpoint()
                t0 = time.perf_counter()
                timings0 = system.timings.copy()
                if driver.extrapolate and previous is not None and lam > previous[0]:
                    # secant predictor along the last converged increment
                    system.extrapolate(previous[1], cp, (trial - lam) / (lam - previous[0]))
                report = newton(system, trial, driver.newton)
                if not report.converged:
                    system.restore(cp)
                    cuts += 1
                    cuts_total += 1
                    logger.info("step %d: lambda %.6g failed (%s); cut %d", step + 1, trial, report.reason, cuts)
                    if cuts > driver.max_cuts:
                        msg = (f"step {step + 1}: no convergence to load factor {trial:.6g} from "
                               f"{lam:.6g} after {driver.max_cuts} cuts; last attempt: {report.reason}. "
                               "Try smaller steps, or arc-length past a limit point.")
                        raise ConvergenceError(msg, Result(history, False, msg,
                                                           _totals(history, t_start, cuts_total, iters_total)))
                    continue
                previous = (lam, cp)
                lam = trial
                step += 1
                iters_total += report.iterations
                dt = time.perf_counter() - t0
                row = {"step": step, "load_factor": lam, "iterations": report.iterations,
                       "cuts": cuts, "wall_time": dt,
                       "time_assembly": system.timings.assembly - timings0.assembly,
                       "time_solve": system.timings.solve - timings0.solve,
                       "time_update": system.timings.update - timings0.update,
                       "residuals": " ".join(f"{r:.2e}" for r in report.residuals)}
                row.update(scene.monitor_values(system))
                history.append(row)
                logger.info("step %d: lambda = %.6g, %d iterations, |r|: %s", step, lam, report.iterations,
                            row["residuals"])
                cuts = max(cuts - 1, 0)
                if on_step is not None:
                    on_step(row)
    finally:
        if own_system:
            system.destroy()
    return Result(history, True, "", _totals(history, t_start, cuts_total, iters_total))


def _totals(history: History, t_start: float, cuts: int, iterations: int) -> dict:
    return {"steps": len(history), "newton_iterations": iterations, "cuts": cuts,
            "wall_time": time.perf_counter() - t_start}

"""Drivers: how the load path is followed.

* :class:`LoadControl` applies the load factors λ₁ < λ₂ < … in turn. With
  prescribed displacements (``Scene.prescribe``) the same driver is
  *displacement control*: λ scales the prescribed motion and the reactions
  are read with ``Scene.monitor_reaction``.
* :class:`ArcLength` follows the equilibrium path through limit points
  (snap-through and snap-back) by Crisfield's cylindrical arc-length method.

A step that fails is cut in half and retried from the exact last converged
state (configuration, rotations, history), up to ``max_cuts`` times in a row.
After all cuts a :class:`ConvergenceError` carries every converged step.
"""
from __future__ import annotations

import json
import logging
import math
import os
import time
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from ..assembly import System, make_system
from ..result import History, Result
from .newton import ConvergenceError, NewtonOptions, NewtonReport, converged, newton

logger = logging.getLogger(__name__)


def newton_with_contact(system, load_factor: float, options: NewtonOptions) -> NewtonReport:
    """Newton at ``load_factor``, then, for augmented-Lagrangian contact, Uzawa updates of the
    contact pressures each followed by a new Newton solve until the penetrations are below
    tolerance. The report sums the iterations; ``uzawa`` counts the updates."""
    contact = getattr(system, "contact", None)
    if contact is not None:
        contact.begin_step()
    report = newton(system, load_factor, options)
    report.uzawa = 0
    if contact is None:
        return report
    while report.converged and contact.augment():
        again = newton(system, load_factor, options)
        again.uzawa = report.uzawa + 1
        again.iterations += report.iterations
        again.residuals = report.residuals + again.residuals
        report = again
    return report


class _Run:
    """Bookkeeping shared by the drivers: history rows, totals, failure, checkpoints."""

    def __init__(self, scene, system: System, on_step, checkpoint: str | None = None):
        self.scene = scene
        self.system = system
        self.on_step = on_step
        self.checkpoint_path = checkpoint
        self.history = History()
        self.t_start = time.perf_counter()
        self.cuts = 0
        self.iterations = 0
        self.step = 0
        self.load_factor = 0.0

    def begin(self):
        return time.perf_counter(), self.system.timings.copy()

    def record(self, lam: float, report: NewtonReport, cuts: int, started, extra: dict | None = None) -> dict:
        t0, tm0 = started
        tm = self.system.timings
        self.load_factor = lam
        self.step += 1
        self.iterations += report.iterations
        row = {"step": self.step, "load_factor": lam, "iterations": report.iterations, "cuts": cuts,
               "wall_time": time.perf_counter() - t0,
               "time_assembly": tm.assembly - tm0.assembly, "time_solve": tm.solve - tm0.solve,
               "time_update": tm.update - tm0.update,
               "residuals": " ".join(f"{r:.2e}" for r in report.residuals)}
        if getattr(self.system, "contact", None) is not None:
            row["uzawa_updates"] = getattr(report, "uzawa", 0)
        row.update(extra or {})
        row.update(self.scene.monitor_values(self.system))
        self.history.append(row)
        logger.info("step %d: lambda = %.6g, %d iterations, |r|: %s", self.step, lam, report.iterations,
                    row["residuals"])
        if self.on_step is not None:
            self.on_step(row)
        return row

    def save(self, driver_state: dict, vectors: dict | None = None) -> None:
        """Write the checkpoint (if asked for): configuration, history, driver state.

        vectors: name → ghosted PETSc vector laid out like the solution.
        The file is replaced atomically, so a crash never leaves it half written.
        """
        if self.checkpoint_path is None:
            return
        arrays = self.system.global_arrays(vectors or {})
        if self.system.comm.rank == 0:
            meta = {"large_rotations": self.scene.large_rotations, "step": self.step,
                    "load_factor": self.load_factor, "cuts": self.cuts, "iterations": self.iterations,
                    "history": self.history.rows, "driver": driver_state}
            os.makedirs(os.path.dirname(os.path.abspath(self.checkpoint_path)), exist_ok=True)
            tmp = self.checkpoint_path + ".tmp.npz"
            np.savez(tmp, meta=np.array(json.dumps(meta)), **arrays)
            os.replace(tmp, self.checkpoint_path)

    def load(self, path: str, driver_name: str) -> tuple[dict, dict]:
        """Restore configuration, history and counters from a checkpoint; returns (driver state, arrays)."""
        with np.load(path) as data:
            meta = json.loads(str(data["meta"]))
            arrays = {k: data[k] for k in data.files if k != "meta"}
        if bool(meta["large_rotations"]) != self.scene.large_rotations:
            raise ValueError(
                f"the checkpoint {path} was computed with large_rotations={meta['large_rotations']}; switching "
                "large rotations on or off at a restart is not allowed (seed §2.2): restart with the same scene")
        if meta["driver"].get("name") != driver_name:
            raise ValueError(f"the checkpoint {path} was written by {meta['driver'].get('name')}, "
                             f"not {driver_name}")
        self.system.set_global_arrays(arrays)
        self.step, self.load_factor = meta["step"], meta["load_factor"]
        self.cuts, self.iterations = meta["cuts"], meta["iterations"]
        for row in meta["history"]:
            self.history.append(row)
        return meta["driver"], arrays

    def totals(self) -> dict:
        return {"steps": len(self.history), "newton_iterations": self.iterations, "cuts": self.cuts,
                "wall_time": time.perf_counter() - self.t_start}

    def fail(self, msg: str):
        raise ConvergenceError(msg, Result(self.history, False, msg, self.totals()))

    def result(self, message: str = "") -> Result:
        return Result(self.history, True, message, self.totals())


@dataclass(frozen=True)
class LoadControl:
    """Load factors ``load_factors`` in turn (they may decrease, to unload), or ``steps`` equal
    steps up to ``final``.

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

    def run(self, run: _Run, restart: str | None = None) -> Result:
        system = run.system
        start = 0
        if restart is not None:
            state, _ = run.load(restart, "LoadControl")
            start = state["next_target"]
        lam = run.load_factor
        previous = None
        targets = self.targets()
        for index in range(start, len(targets)):
            target = targets[index]
            cuts = 0
            while abs(target - lam) > 1e-14 * max(1.0, abs(target)):
                trial = target if cuts == 0 else lam + (target - lam) / 2**cuts
                cp = system.checkpoint()
                started = run.begin()
                if self.extrapolate and previous is not None and lam != previous[0]:
                    # secant predictor along the last converged increment
                    system.extrapolate(previous[1], cp, (trial - lam) / (lam - previous[0]))
                report = newton_with_contact(system, trial, self.newton)
                if not report.converged:
                    system.restore(cp)
                    cuts += 1
                    run.cuts += 1
                    logger.info("step %d: lambda %.6g failed (%s); cut %d", run.step + 1, trial, report.reason, cuts)
                    if cuts > self.max_cuts:
                        run.fail(f"step {run.step + 1}: no convergence to load factor {trial:.6g} from "
                                 f"{lam:.6g} after {self.max_cuts} cuts; last attempt: {report.reason}. "
                                 "Try smaller steps, or arc-length past a limit point.")
                    continue
                previous = (lam, cp)
                lam = trial
                run.record(lam, report, cuts, started)
                reached = abs(target - lam) <= 1e-14 * max(1.0, abs(target))
                run.save({"name": "LoadControl", "next_target": index + 1 if reached else index})
                cuts = max(cuts - 1, 0)
        return run.result()


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
    max_steps; max_load_factor: stop when |λ| reaches it; stop: a function of
    the history row that returns True to stop (e.g. a displacement reached);
    psi: load term weight (0: cylindrical); max_growth: largest factor by which Δl
    grows from one step to the next.
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

    def run(self, run: _Run, restart: str | None = None) -> Result:
        system = run.system
        if getattr(system.model, "has_prescribed_motion", False):
            raise NotImplementedError("arc-length with prescribed displacements is not supported; "
                                      "follow them with LoadControl (displacement control)")
        if system._fext_norm == 0.0:
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
        if restart is not None:
            state, arrays = run.load(restart, "ArcLength")
            arc, arc_min, arc_max = state["arc"], state["arc_min"], state["arc_max"]
            dlam_prev, have_prev = state["dlam_prev"], state["have_prev"]
            lam = run.load_factor
            system.global_to_vector(arrays, "Dx_prev", Dx_prev)
        contact = getattr(system, "contact", None)
        while run.step < self.max_steps:
            cp = system.checkpoint()
            started = run.begin()
            report = NewtonReport(False, 0)
            if contact is not None:
                contact.begin_step()
            try:
                # predictor along the tangent (of the converged state: contact pairs evaluated there)
                system.residual(lam)
                system.jacobian()
                system.solve(f, dxt)
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
                Dlam = dlam
                norm, ref = system.residual(lam + Dlam)
                report.residuals.append(norm)
                ok = False
                for it in range(1, opts.max_iterations + 1):
                    if converged(norm, ref, report, system, opts):
                        ok = True
                        break
                    system.jacobian()
                    system.solve(f, dxt)
                    system.solve(system.b, dxr)
                    a = dxt.dot(dxt) + psi2F
                    Dx.copy(system.dx)
                    system.dx.axpy(1.0, dxr)  # Δx + dx_r
                    b = 2.0 * (dxt.dot(system.dx) + psi2F * Dlam)
                    c = system.dx.dot(system.dx) + psi2F * Dlam**2 - arc**2
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
                    cosines = [base + r * tdot + psi2F * Dlam * (Dlam + r) for r in roots]
                    dl = roots[int(np.argmax(cosines))]
                    dxr.copy(system.dx)
                    system.dx.axpy(dl, dxt)
                    report.increments.append(system.dx.norm())
                    system.update()
                    Dx.axpy(1.0, system.dx)
                    Dlam += dl
                    report.iterations = it
                    norm, ref = system.residual(lam + Dlam)
                    report.residuals.append(norm)
                    if not math.isfinite(norm):
                        report.reason = "residual is not finite"
                        break
                else:
                    report.reason = f"no convergence in {opts.max_iterations} iterations: |r| = {norm:.3e}"
                # augmented-Lagrangian contact: Uzawa updates at the converged load factor, each
                # followed by Newton at that load factor (the arc-length constraint then holds to
                # the size of these corrections)
                while ok and contact is not None and contact.augment():
                    again = newton(system, lam + Dlam, opts)
                    report.uzawa += 1
                    report.iterations += again.iterations
                    report.residuals += again.residuals
                    ok = again.converged
                    if not ok:
                        report.reason = f"after an augmented-Lagrangian update: {again.reason}"
            except np.linalg.LinAlgError as err:
                ok = False
                report.reason = str(err)
            if not ok:
                system.restore(cp)
                cuts += 1
                run.cuts += 1
                logger.info("arc-length step %d failed (%s); cut %d", run.step + 1, report.reason, cuts)
                if arc is None or cuts > self.max_cuts or arc / 2 < arc_min:
                    run.fail(f"arc-length step {run.step + 1} at load factor {lam:.6g}: no convergence after "
                             f"{cuts - 1} cuts (arc length {arc:.3e}); last attempt: {report.reason}")
                arc /= 2
                continue
            lam += Dlam
            Dx.copy(Dx_prev)
            dlam_prev = Dlam
            have_prev = True
            row = run.record(lam, report, cuts, started, {"arc_length": arc})
            cuts = 0
            factor = math.sqrt(self.desired_iterations / max(report.iterations, 1))
            arc = min(max(arc * min(max(factor, 0.5), self.max_growth), arc_min), arc_max)
            run.save({"name": "ArcLength", "arc": arc, "arc_min": arc_min, "arc_max": arc_max,
                      "dlam_prev": dlam_prev, "have_prev": have_prev}, {"Dx_prev": Dx_prev})
            if abs(lam) >= self.max_load_factor or (self.stop is not None and self.stop(row)):
                break
        for v in (f, dxt, dxr, Dx, Dx_prev):
            v.destroy()
        return run.result()


def solve(scene, driver, system: System | None = None, on_step=None, checkpoint: str | None = None,
          restart: str | None = None) -> Result:
    """Run ``driver`` (LoadControl or ArcLength) on ``scene``; returns a :class:`Result`.

    On a step that fails after all cuts, raises :class:`ConvergenceError`
    whose ``result`` holds every converged step, and the configuration is
    left at the last converged state. ``on_step(row)`` is called after every
    converged step with its history row (e.g. to store snapshots).

    checkpoint: file (``.npz``) rewritten after every converged step with the
    configuration, the history and the driver's state; restart: such a file
    to continue from (same scene and driver; the continued run reproduces an
    uninterrupted one). Switching ``large_rotations`` at a restart is refused.
    """
    own_system = system is None
    if own_system:
        system = make_system(scene.model, solver=getattr(scene, "linear_solver", "auto"),
                             contacts=getattr(scene, "interfaces", ()))
    try:
        return driver.run(_Run(scene, system, on_step, checkpoint), restart)
    finally:
        if own_system:
            system.destroy()

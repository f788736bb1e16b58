"""A run of a driver on a scene: history rows, totals, failure, checkpoint files and restart.

Checkpoint files (``.npz``) hold the configuration of every part and the
state of every contribution (contact multipliers, candidate pairs) as
partition-independent arrays, the history and the monitored profiles, the
driver's position and a
*fingerprint* of the scene: a SHA-256 of its description (mesh sizes, a hash
of the node coordinates, groups, elements and materials of every part, the
contact interfaces). A restart refuses a file written for another scene
and says what differs; a file that cannot be read is refused with its name.
"""
from __future__ import annotations

import hashlib
import json
import logging
import math
import os
import time
import zipfile
import zlib

import numpy as np

from ..assembly import System, make_system
from ..result import History, Profile, Result
from .newton import ConvergenceError, NewtonReport
from .progress import Progress, progress_mode

logger = logging.getLogger(__name__)

FORMAT = "dolfinx_corot checkpoint 2"


class CheckpointError(ValueError):
    """A checkpoint file that cannot be used for a restart (unreadable, or of another scene)."""


def fingerprint(description) -> str:
    return hashlib.sha256(json.dumps(description, sort_keys=True, default=str).encode()).hexdigest()


def _first_difference(a, b, path: str = "scene") -> str | None:
    """Where two JSON-like descriptions first differ, in words (None if equal)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                return f"{path}.{key} is only in the {'checkpoint' if key in a else 'current scene'}"
            found = _first_difference(a[key], b[key], f"{path}.{key}")
            if found:
                return found
        return None
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        if len(a) != len(b):
            return f"{path} has {len(a)} entries in the checkpoint, {len(b)} now"
        for i, (x, y) in enumerate(zip(a, b)):
            found = _first_difference(x, y, f"{path}[{i}]")
            if found:
                return found
        return None
    if a != b:
        return f"{path} is {a!r} in the checkpoint, {b!r} now"
    return None


def read_checkpoint(path: str) -> tuple[dict, dict]:
    """(meta, arrays) of a checkpoint file, or a :class:`CheckpointError` naming the file."""
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            arrays = {k: data[k] for k in data.files if k != "meta"}
    except FileNotFoundError:
        raise CheckpointError(f"checkpoint {path}: no such file") from None
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile, zlib.error, json.JSONDecodeError) as err:
        raise CheckpointError(f"checkpoint {path} cannot be read ({type(err).__name__}: {err}): the file is "
                              "truncated, corrupted or not a dolfinx_corot checkpoint") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise CheckpointError(f"checkpoint {path} is not a {FORMAT} file (format: "
                              f"{meta.get('format') if isinstance(meta, dict) else None!r})")
    return meta, arrays


def read_checkpoint_on_all_ranks(path: str, comm) -> tuple[dict, dict]:
    """:func:`read_checkpoint` on rank 0, its result (or its refusal) on every rank."""
    found = None
    if comm.rank == 0:
        try:
            found = read_checkpoint(path)
        except CheckpointError as err:
            found = err
    found = comm.bcast(found, root=0)
    if isinstance(found, CheckpointError):
        raise found
    return found


class Run:
    """Bookkeeping shared by the drivers: history rows, totals, failure, checkpoints."""

    def __init__(self, scene, system: System, on_step, checkpoint: str | None = None, attach=None,
                 progress: Progress | None = None):
        self.scene = scene
        self.progress = Progress("off", system.comm) if progress is None else progress
        # (meta, arrays) written with every checkpoint by the run that holds this one (a staged
        # run: the stage and what the stages before it left; ({}, None) without a checkpoint);
        # arrays on rank 0
        self.attach = attach
        self.system = system
        self.on_step = on_step
        self.checkpoint_path = checkpoint
        self.history = History()
        self.profiles: dict[str, Profile] = scene.profiles()
        self.monitor_columns: dict[str, list[str]] = {}  # monitor → its history columns
        self.t_start = time.perf_counter()
        self.cuts = 0
        self.iterations = 0
        self.step = 0
        self.load_factor = 0.0
        self.critical_points: list = []
        self._size = None
        self._description = scene.describe()
        self.fingerprint = fingerprint(self._description)
        if checkpoint is not None:
            self._check_writable(checkpoint)

    def _check_writable(self, path: str) -> None:
        """Fail before the first step if the checkpoint cannot be written."""
        folder = os.path.dirname(os.path.abspath(path))
        ok = True
        if self.system.comm.rank == 0:
            try:
                os.makedirs(folder, exist_ok=True)
                ok = os.access(folder, os.W_OK) and not os.path.isdir(path)
            except OSError:
                ok = False
        if not self.system.comm.bcast(ok, root=0):
            raise CheckpointError(f"checkpoint {path}: cannot write in {folder}")

    def begin(self):
        return time.perf_counter(), self.system.timings.copy()

    def record(self, lam: float, report: NewtonReport, cuts: int, started, extra: dict | None = None,
               position: float | None = None) -> dict:
        """Commit the converged step and add its history row (``position``: where the run is,
        for its progress, in the measure given to :meth:`expect`)."""
        t0, tm0 = started
        tm = self.system.timings
        self.load_factor = lam
        self.step += 1
        self.iterations += report.iterations
        self.system.commit()
        row = {"step": self.step, "load_factor": lam, "iterations": report.iterations, "cuts": cuts,
               "wall_time": time.perf_counter() - t0,
               "time_assembly": tm.assembly - tm0.assembly, "time_solve": tm.solve - tm0.solve,
               "time_update": tm.update - tm0.update,
               "residuals": " ".join(f"{r:.2e}" for r in report.residuals)}
        row.update(self.system.history(report))
        row.update(extra or {})
        for name, values in self.scene.monitor_values_by_name(self.system).items():
            row.update(values)
            known = self.monitor_columns.setdefault(name, [])
            known += [c for c in values if c not in known]
        self.history.append(row)
        for name, values in self.scene.profile_values().items():
            self.profiles[name].append(self.step, lam, values)
        logger.info("step %d: lambda = %.6g, %d iterations, |r|: %s", self.step, lam, report.iterations,
                    row["residuals"])
        self.progress.step(row, position)
        if self.on_step is not None:
            self.on_step(row)
        return row

    def expect(self, total: float | None, done: float = 0.0) -> None:
        """The run's length in the driver's measure (its targets, steps; None: unknown) and how much
        of it was done before a restart, for the progress shown."""
        self.progress.expect(total, done)

    def save(self, driver_state: dict, vectors: dict | None = None) -> None:
        """Write the checkpoint (if asked for): configuration, contribution states, history,
        driver state and the scene's fingerprint.

        vectors: name → ghosted PETSc vector laid out like the solution.
        The file is replaced atomically, so a crash never leaves it half written.
        """
        if self.checkpoint_path is None:
            return
        arrays = self.system.global_arrays(vectors or {})
        if self.system.comm.rank == 0:
            meta = {"format": FORMAT, "fingerprint": self.fingerprint, "scene": self._description,
                    "large_rotations": self.scene.large_rotations, "step": self.step,
                    "load_factor": self.load_factor, "cuts": self.cuts, "iterations": self.iterations,
                    "history": self.history.rows, "driver": driver_state, "profiles": list(self.profiles),
                    "critical_points": [c.as_dict() for c in self.critical_points]}
            if self.attach is not None:
                meta["staging"] = self.attach[0]
                arrays.update(self.attach[1] or {})
            for i, profile in enumerate(self.profiles.values()):
                arrays.update(profile.arrays(f"profile{i}_"))
            tmp = self.checkpoint_path + ".tmp"
            with open(tmp, "wb") as f:
                np.savez(f, meta=np.array(json.dumps(meta, default=str)), **arrays)
            os.replace(tmp, self.checkpoint_path)
        self.system.comm.barrier()

    def load(self, path: str, driver_name: str) -> tuple[dict, dict]:
        """Restore configuration, contribution states, history and counters from a checkpoint;
        returns (driver state, arrays). Refuses a file of another scene or another driver."""
        meta, arrays = read_checkpoint_on_all_ranks(path, self.system.comm)
        if bool(meta["large_rotations"]) != self.scene.large_rotations:
            raise CheckpointError(
                f"the checkpoint {path} was computed with large_rotations={meta['large_rotations']}; switching "
                "large rotations on or off at a restart is not allowed (seed §2.2): restart with the same scene")
        if meta["fingerprint"] != self.fingerprint:
            where = _first_difference(meta["scene"], json.loads(json.dumps(self._description, default=str)))
            raise CheckpointError(f"the checkpoint {path} was written for another scene: {where}. A restart "
                                  "continues the same scene (same meshes, parts, materials and interfaces)")
        if ("staging" in meta) != (self.attach is not None):
            raise CheckpointError(f"the checkpoint {path} was written by a "
                                  f"{'staged run: restart it with solve_stages' if 'staging' in meta else 'run without stages: restart it with solve'}")
        if meta["driver"].get("name") != driver_name:
            raise CheckpointError(f"the checkpoint {path} was written by {meta['driver'].get('name')}, "
                                  f"not {driver_name}")
        try:
            self.system.set_global_arrays(arrays)
        except (KeyError, ValueError, IndexError) as err:
            raise CheckpointError(f"checkpoint {path}: its arrays do not fit this scene ({err})") from None
        self.step, self.load_factor = meta["step"], meta["load_factor"]
        self.cuts, self.iterations = meta["cuts"], meta["iterations"]
        for row in meta["history"]:
            self.history.append(row)
        self._restore_profiles(path, meta.get("profiles", []), arrays)
        from .stability import CriticalPoint
        self.critical_points = [CriticalPoint(**{**c, "bracket": tuple(c["bracket"])})
                                for c in meta.get("critical_points", [])]
        return meta["driver"], arrays

    def _restore_profiles(self, path: str, saved: list, arrays: dict) -> None:
        """The profiles' steps up to the checkpoint; a profile the checkpoint does not hold (a monitor
        added at the restart) has NaN values for them."""
        rows = self.history.rows
        for name, profile in self.profiles.items():
            if name in saved:
                old = Profile.from_arrays(arrays, f"profile{saved.index(name)}_")
                if old.X.shape != profile.X.shape or not np.array_equal(old.X, profile.X):
                    raise CheckpointError(f"checkpoint {path}: profile '{name}' was recorded on other nodes "
                                          f"({len(old.X)}) than the monitor of that name now ({len(profile.X)}, "
                                          f"group '{profile.where}')")
                profile.restore(old.steps, old.load_factors, old.values)
            else:
                nan = np.full((len(rows), len(profile.X), len(profile.dofs)), np.nan)
                profile.restore([r["step"] for r in rows], [r["load_factor"] for r in rows], nan)

    def totals(self) -> dict:
        return {"steps": len(self.history), "newton_iterations": self.iterations, "cuts": self.cuts,
                "wall_time": time.perf_counter() - self.t_start}

    def fail(self, msg: str, error=ConvergenceError):
        self.progress.close(msg)
        raise error(msg, Result(self.history, False, msg, self.totals(), self.profiles, list(self.critical_points),
                                dict(self.monitor_columns)))

    def result(self, message: str = "") -> Result:
        self.progress.close()
        return Result(self.history, True, message, self.totals(), self.profiles, list(self.critical_points),
                      dict(self.monitor_columns))

    # -- plausibility ---------------------------------------------------------------------
    def model_size(self) -> float:
        """The diameter of the parts' reference bounding box."""
        if self._size is None:
            self._size = float(max(self.system.length_scale, 1e-300))
        return self._size

    def implausible(self, limit: float) -> str | None:
        """Why the converged state is absurd (a displacement larger than ``limit`` model sizes, or
        not finite), or None."""
        from mpi4py import MPI
        largest = 0.0
        for m in self.system.models:
            n = m.V.dofmap.index_map.size_local
            u = m.translations_of(np.arange(n))
            if u.size:
                peak = float(np.abs(u).max())  # (NaN where any is: not finite)
                largest = max(largest, peak) if math.isfinite(peak) else math.inf
        if self.system.comm.size > 1:
            largest = self.system.comm.allreduce(largest, op=MPI.MAX)
        size = self.model_size()
        if math.isfinite(largest) and largest <= limit * size:
            return None
        return (f"the converged displacement reaches {largest:.3e}, {largest / size:.3g} times the model's size "
                f"{size:.3g}: the result is absurd (check the magnitude and units of the loads and materials)")


def solve(scene, driver, system: System | None = None, on_step=None, checkpoint: str | None = None,
          restart: str | None = None, attach=None, progress=None, quiet: bool = False,
          label: str = "") -> Result:
    """Run ``driver`` (LoadControl or ArcLength) on ``scene``; returns a :class:`Result`.

    On a step that fails after all cuts, raises :class:`ConvergenceError`
    whose ``result`` holds every converged step, and the configuration is
    left at the last converged state. ``on_step(row)`` is called after every
    converged step with its history row (e.g. to store snapshots).

    checkpoint: file (``.npz``) rewritten after every converged step with the
    configuration, the contributions' state (contact multipliers), the history,
    the driver's state and the scene's fingerprint; restart: such a file to
    continue from. The scene must be the same (checked by the fingerprint; switching
    ``large_rotations`` is refused too); the driver of the same kind may ask for more
    (a larger ``final`` or ``max_steps``): see each driver's ``run``. A restarted run
    reproduces the uninterrupted one. attach: (meta, arrays on rank 0) written into every
    checkpoint besides (:func:`dolfinx_corot.staging.solve_stages` keeps its stage there).

    progress: how the run reports its steps on standard output (rank 0): 'auto' (default: a
    bar on a terminal, one line per step otherwise), 'bar', 'lines' or 'off'; ``quiet=True``
    is 'off'; the environment variable ``DC_PROGRESS`` sets the default
    (:mod:`~dolfinx_corot.solvers.progress`). label: the run's name in those lines.
    """
    mode = progress_mode(progress, quiet)
    own_system = system is None
    if own_system:
        system = make_system(scene.model, solver=scene.linear_solver,
                             contributions=scene.contributions(), tangent=scene.tangent)
    shown = Progress(mode, system.comm, label)
    try:
        return driver.run(Run(scene, system, on_step, checkpoint, attach, shown), restart)
    except BaseException as err:
        shown.close(type(err).__name__)
        raise
    finally:
        if own_system:
            system.destroy()

"""The demo harness: what every demo of the gallery (``demos/``) shares.

A demo is a narrated script whose computation lives in ``main() -> dict``::

    def main() -> dict:
        demo = Demo("euler_beam_2d")                      # output/euler_beam_2d/
        demo.say("N_cr =", Ncr)                           # rank 0 prints
        result, wall = timed(dc.solve, scene, driver)     # wall time: largest over the ranks
        demo.write_result(result)                         # history.csv on rank 0
        demo.table("work_precision.csv", rows)            # a CSV on rank 0
        fig, ax = demo.figure(1, 2, figsize=(11, 4))      # a matplotlib figure
        ...
        demo.save(fig, "euler_beam_2d.png")               # the PNG, on rank 0
        demo.picture(shots, "euler_beam_2d_shapes.png")   # a PyVista picture (dolfinx_corot.plot)
        demo.record(load_factor=lam, ux=ux)               # tip_values.json
        demo.check("tip error", err, bound=2e-4, reference="B1 exact elastica")
        return demo.finish()                              # "<name>: verified"


    if __name__ == "__main__":
        logging.basicConfig(level=logging.WARNING)        # the script's choice, not the harness's
        main()

Each :meth:`Demo.check` asserts one number against a *named* reference and
keeps the verification; :meth:`Demo.finish` returns them with the recorded
values as ``{"name", "checks", "values"}``, which the test-suite inspects
(``tests/test_demos.py``), and writes them to ``verification.json``, with the PyVista pictures
written by :meth:`Demo.picture`.

The recorded values (:meth:`Demo.record`) are the numbers that a run under
``mpirun -n 2`` must reproduce: they go to ``<out>/tip_values.json`` with
the number of ranks.

``demo.ci`` is true for the shortened runs of the test-suite (``CI=true``).
No global state is touched: figures are :class:`matplotlib.figure.Figure`
objects drawn without pyplot (nothing to close, no backend to switch), and
logging is left as the caller configured it.
"""
from __future__ import annotations

import csv
import json
import os
import time
from typing import Any, Optional, Sequence, Union

import numpy as np
from mpi4py import MPI

from .io import output_dir

__all__ = ["Demo", "VerificationError", "timed"]

Bound = Union[float, tuple]


class VerificationError(AssertionError):
    """A demo's number missed its reference (an :class:`AssertionError`, as a failed assert)."""


def _plain(value: Any) -> Any:
    """``value`` as JSON: arrays and numpy scalars become lists and Python numbers."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    return value


def timed(function, *args, **kwargs) -> tuple:
    """``(function(*args, **kwargs), wall time in seconds)``, the time the largest over the ranks of
    ``MPI.COMM_WORLD`` (every rank must call it, as for a solve)."""
    start = time.perf_counter()
    value = function(*args, **kwargs)
    return value, MPI.COMM_WORLD.allreduce(time.perf_counter() - start, op=MPI.MAX)


class Demo:
    """Output folder, printing, figures, verifications and recorded values of one demo run.

    name: the demo's name; its files go to ``dolfinx_corot.io.output_dir(name)``
    (``output/<name>``, or ``$DC_OUTPUT_DIR/<name>``). A demo runs on ``MPI.COMM_WORLD``.
    """

    def __init__(self, name: str):
        self.name = name
        self.comm = MPI.COMM_WORLD
        self.rank = self.comm.rank
        self.out = output_dir(name)
        #: shortened runs (``CI=true`` in the environment)
        self.ci = os.environ.get("CI") == "true"
        self.checks: list[dict] = []
        self.values: dict[str, Any] = {}
        self.pictures: list[str] = []

    def say(self, *args: Any) -> None:
        """``print(*args)`` on rank 0, flushed."""
        if self.rank == 0:
            print(*args, flush=True)

    def path(self, filename: str) -> str:
        """``<out>/<filename>``."""
        return os.path.join(self.out, filename)

    def write_result(self, result, folder: Optional[str] = None) -> None:
        """``result.write`` (history CSV and summary JSON of a :class:`dolfinx_corot.Result`) into
        ``<out>`` or ``<out>/<folder>``, on rank 0."""
        if self.rank == 0:
            path = self.path(folder) if folder else self.out
            os.makedirs(path, exist_ok=True)
            result.write(path)

    # -- figures and tables ---------------------------------------------------------------------

    def figure(self, nrows: int = 1, ncols: int = 1, *, figsize: tuple = (6.0, 4.2), **subplots):
        """A new figure and its axes, ``Figure.subplots(nrows, ncols, **subplots)`` (``nrows=0``:
        no axes; add them with ``fig.add_subplot``). Built on every rank (cheap: nothing is
        rendered before :meth:`save`), outside pyplot, so no figure stays open."""
        from matplotlib.figure import Figure

        fig = Figure(figsize=figsize)
        return fig, (fig.subplots(nrows, ncols, **subplots) if nrows else None)

    def save(self, fig, filename: str, dpi: int = 120) -> None:
        """Tight layout and ``<out>/<filename>`` (PNG), on rank 0."""
        if self.rank == 0:
            fig.tight_layout()
            fig.savefig(self.path(filename), dpi=dpi)

    def picture(self, states, filename: str, **options) -> None:
        """A PyVista picture of the deformed parts, ``<out>/<filename>``: ``states`` is a
        :class:`dolfinx_corot.plot.Snapshots` (its kept states), a list of
        :class:`~dolfinx_corot.plot.State`, or a scene (its current state; collective). Options:
        those of :func:`dolfinx_corot.plot.picture` (field, scale, layout, title, camera, …)."""
        from . import plot

        if isinstance(states, plot.Snapshots):
            states = states.states
        plot.picture(states, self.path(filename), **options)
        self.pictures.append(filename)

    def work_precision(self, resolution: Sequence, error: Sequence[float], time: Sequence[float], *,
                       quantity: str, reference: str, series: str | None = None) -> None:
        """What accuracy costs: the relative ``error`` of ``quantity`` (against ``reference``) and the
        wall ``time`` of each run, mesh by mesh (``resolution``: elements, nodes or dofs), to
        ``<out>/work_precision.json`` on rank 0; the documentation gathers every demo's in one
        plot (accuracy against time). Runs whose error is not a number are left out. ``series``
        names one of several element families of the demo (e.g. "triangles", "quadrilaterals"):
        each call with a series adds a curve to the demo's file."""
        if not (len(resolution) == len(error) == len(time)):
            raise ValueError("work_precision: resolution, error and time need one entry per run")
        keep = [k for k, e in enumerate(error) if np.isfinite(float(e))]  # runs without a value are left out
        data = {"quantity": quantity, "reference": reference,
                "resolution": [_plain(resolution[k]) for k in keep],
                "error": [abs(float(error[k])) for k in keep], "time": [float(time[k]) for k in keep]}
        if series is None:
            self._series = []
        else:
            self._series = [s for s in getattr(self, "_series", []) if s["series"] != series]
            self._series.append({"series": series, **data})
            data = {"series": self._series}
        if self.rank == 0:
            with open(self.path("work_precision.json"), "w") as f:
                json.dump(data, f, indent=1)

    def work_precision_to_finest(self, resolution: Sequence, value: Sequence[float], time: Sequence[float], *,
                                 quantity: str, series: str | None = None, finest: float | None = None,
                                 finest_label: str | None = None) -> None:
        """:meth:`work_precision` of a self-convergence study: the error of each run is its relative
        distance from the finest run's ``value`` (the finest run itself left out of the plot), or
        from ``finest`` (e.g. another family's finest run, named by ``finest_label``; then every
        run is kept)."""
        value = np.asarray(value, dtype=float)
        if finest is None:
            error = np.abs(value / value[-1] - 1.0)
            error[-1] = np.nan
            label = f"the finest run ({_plain(resolution[-1])})"
        else:
            error = np.abs(value / float(finest) - 1.0)
            label = finest_label or f"the value {finest:g}"
        self.work_precision(resolution, error, time, quantity=quantity, reference=f"self-convergence: {label}",
                            series=series)

    def table(self, filename: str, rows: Union[Sequence[dict], np.ndarray],
              columns: Optional[Sequence[str]] = None) -> None:
        """``<out>/<filename>`` as CSV, on rank 0: dict rows (the first row's keys as header), or
        a 2D array rows with the header ``columns``."""
        if self.rank != 0:
            return
        if columns is not None:
            np.savetxt(self.path(filename), np.asarray(rows), delimiter=",", header=",".join(columns),
                       comments="")
            return
        with open(self.path(filename), "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)

    # -- verification ---------------------------------------------------------------------------

    def check(self, label: str, value: Any, expected: Any = None, *, rtol: Optional[float] = None,
              atol: Optional[float] = None, bound: Optional[Bound] = None, reference: str) -> dict:
        """Assert one verification and keep it.

        Either ``expected`` with a tolerance: ``|value − expected| ≤ atol + rtol |expected|``
        (``atol``, ``rtol`` default 0: exact), or ``bound``: ``value ≤ bound``, or with
        ``bound=(low, high)`` ``low ≤ value ≤ high`` (``None`` for an open side). Arrays are
        checked elementwise, all must pass; NaN never passes. ``reference`` names what the
        number is checked against (a published value, a closed form, a reference file, or
        plainly "self-convergence (no published value)"). Raises :class:`VerificationError`
        with the numbers when the check fails.
        """
        if not isinstance(reference, str) or not reference.strip():
            raise ValueError(f"check '{label}': name the reference the value is checked against")
        if (expected is None) == (bound is None):
            raise ValueError(f"check '{label}': give either expected (with rtol/atol) or bound")
        v = np.asarray(value, dtype=float)
        if expected is not None:
            e = np.asarray(expected, dtype=float)
            tol = (atol or 0.0) + (rtol or 0.0) * np.abs(e)
            with np.errstate(invalid="ignore"):
                passed = bool(np.all(np.abs(v - e) <= tol))
            tolerance = {"rtol": rtol or 0.0, "atol": atol or 0.0}
        else:
            low, high = bound if isinstance(bound, tuple) else (None, bound)
            with np.errstate(invalid="ignore"):
                passed = bool(np.all((low is None or v >= low) & (high is None or v <= high))
                              and not np.any(np.isnan(v)))
            tolerance = {"bound": [low, high]}
        entry = {"label": label, "value": _plain(value), "expected": _plain(expected), **tolerance,
                 "reference": reference, "passed": passed}
        self.checks.append(entry)
        if not passed:
            limits = (f"expected {expected} (rtol {rtol}, atol {atol})" if expected is not None
                      else f"bounds {tolerance['bound']}")
            raise VerificationError(f"{self.name}: {label} = {value}, {limits}; reference: {reference}")
        return entry

    # -- recorded values and the end of a run ---------------------------------------------------

    def record(self, **values: Any) -> None:
        """Keep ``values`` (numbers or arrays) and write all kept values with ``ranks`` (the
        communicator's size) to ``<out>/tip_values.json`` on rank 0: the numbers that the run
        under ``mpirun -n 2`` must reproduce."""
        self.values.update({k: _plain(v) for k, v in values.items()})
        if self.rank == 0:
            with open(self.path("tip_values.json"), "w") as f:
                json.dump({**self.values, "ranks": self.comm.size}, f)

    def finish(self) -> dict:
        """Write ``<out>/verification.json`` (rank 0), say ``"<name>: verified"`` and return
        ``{"name", "checks", "values"}``. Raises :class:`VerificationError` if no check was made
        or one failed."""
        if not self.checks:
            raise VerificationError(f"{self.name}: no verification was made")
        failed = [c["label"] for c in self.checks if not c["passed"]]
        if failed:
            raise VerificationError(f"{self.name}: failed checks: {'; '.join(failed)}")
        report = {"name": self.name, "checks": list(self.checks), "values": dict(self.values),
                  "pictures": list(self.pictures)}
        if self.rank == 0:
            with open(self.path("verification.json"), "w") as f:
                json.dump({**report, "ranks": self.comm.size}, f, indent=1)
        self.say(f"{self.name}: verified")
        return report

"""Progress of a run: a bar over the load steps on a terminal, one line per step otherwise.

``solve(scene, driver, progress=...)`` chooses the form:

- ``"auto"`` (default): a bar when standard output is a terminal, else one line per step;
- ``"bar"``: a bar (tqdm) with the load factor, Newton iterations, cuts and time of the last step;
- ``"lines"``: ``step 12/40: λ = 1.2, 4 iterations, 0 cuts, 0.011 s`` per converged step and a
  closing line with the totals;
- ``"off"`` (or ``quiet=True``): nothing.

The default can be set for a whole session with the environment variable ``DC_PROGRESS``
(``auto``, ``bar``, ``lines`` or ``off``). Only rank 0 writes, to standard output; warnings
and errors keep going to the :mod:`logging` loggers ``dolfinx_corot.*``.
"""
from __future__ import annotations

import os
import shutil
import sys
import time

MODES = ("auto", "bar", "lines", "off")


def progress_mode(progress, quiet: bool) -> str:
    """The mode asked for: ``quiet`` wins; ``None`` takes ``$DC_PROGRESS`` or 'auto'."""
    if quiet:
        return "off"
    if progress is None:
        progress = os.environ.get("DC_PROGRESS", "auto") or "auto"
    if progress is False:
        return "off"
    if progress is True:
        return "auto"
    if progress not in MODES:
        raise ValueError(f"progress = {progress!r} is not one of {MODES} (or True/False)")
    return progress


def _terminal(stream) -> bool:
    """Whether ``stream`` is an interactive terminal: a tty, and not one that an MPI launcher
    gives each rank (Open MPI forwards the ranks' output through pseudo-terminals of no width)."""
    isatty = getattr(stream, "isatty", None)
    if isatty is None or not isatty():
        return False
    launched = any(v in os.environ for v in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"))
    return not launched and shutil.get_terminal_size((0, 0)).columns > 0


class Progress:
    """What one run reports while it goes (see the module docstring).

    mode: one of :data:`MODES`; comm: the run's communicator (rank 0 writes);
    label: a prefix naming the run (a stage); stream: where to write (standard output).
    """

    def __init__(self, mode: str, comm, label: str = "", stream=None):
        self.stream = sys.stdout if stream is None else stream
        if comm.rank != 0:
            mode = "off"
        elif mode == "auto":
            mode = "bar" if _terminal(self.stream) else "lines"
        self.mode = mode
        self.label = label
        self.total: int | None = None
        self._bar = None
        self._start = time.perf_counter()
        self._steps = self._iterations = self._cuts = 0
        self._closed = False

    def expect(self, total: float | None, done: float = 0.0) -> None:
        """The run's length in the driver's measure (its targets or steps; None: unknown), ``done``
        of it before (a restart)."""
        self.total = total
        if self.mode == "bar" and self._bar is None:
            from tqdm import tqdm

            width = shutil.get_terminal_size((0, 0)).columns
            self._bar = tqdm(total=total, initial=done, file=self.stream, desc=self.label or "solve",
                             ncols=width if width >= 40 else 100, leave=True, mininterval=0.2,
                             bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}{postfix}]")

    def step(self, row: dict, position: float | None = None) -> None:
        """One converged step (its history row) and where the run is (``position`` in the measure of
        :meth:`expect`; None: one more)."""
        if self.mode == "off":
            return
        self._steps += 1
        self._iterations += int(row.get("iterations", 0))
        self._cuts += int(row.get("cuts", 0))
        words = (f"λ = {row['load_factor']:.6g}, {row['iterations']} iterations, {row['cuts']} cuts, "
                 f"{row['wall_time']:.3g} s")
        if self.mode == "bar":
            if self._bar is None:
                self.expect(self.total)
            self._bar.set_postfix_str(f"step {row['step']}: λ={row['load_factor']:.4g}, {row['iterations']} its, "
                                      f"{self._cuts} cuts", refresh=False)
            if position is None:
                self._bar.update(1)
            else:
                self._bar.n = min(position, self.total) if self.total else position
                self._bar.refresh()
        else:
            prefix = f"{self.label}: " if self.label else ""
            self.stream.write(f"{prefix}step {row['step']}: {words}\n")
            self.stream.flush()

    def close(self, message: str = "") -> None:
        """End of the run (``message``: why it stopped, if not at its end)."""
        if self._closed:
            return
        self._closed = True
        if self.mode == "off":
            return
        if self._bar is not None:
            self._bar.close()
        elif self.mode == "lines":
            prefix = f"{self.label}: " if self.label else ""
            self.stream.write(f"{prefix}{'stopped: ' + message if message else 'done'} — {self._steps} steps, "
                              f"{self._iterations} Newton iterations, {self._cuts} cuts, "
                              f"{time.perf_counter() - self._start:.3g} s\n")
            self.stream.flush()
        if message and self._bar is not None:
            self.stream.write(f"{self.label + ': ' if self.label else ''}stopped: {message}\n")
            self.stream.flush()

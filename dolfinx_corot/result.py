"""Results: the per-step history of an analysis."""
from __future__ import annotations

import csv
import json
import os
from dataclasses import dataclass, field

import numpy as np


@dataclass
class History:
    """One row per converged step (load factor, monitored dofs, iterations, timings)."""

    rows: list[dict] = field(default_factory=list)

    def append(self, row: dict) -> None:
        self.rows.append(dict(row))

    def __len__(self) -> int:
        return len(self.rows)

    @property
    def columns(self) -> list[str]:
        cols: list[str] = []
        for r in self.rows:
            cols += [k for k in r if k not in cols]
        return cols

    def column(self, name: str) -> np.ndarray:
        """Values of one column as an array (nan where a row lacks it). The ``residuals`` column
        (the residual norms of each step's Newton iterations, a text of numbers per row) is an
        object array of float arrays, one per step."""
        if self.rows and all(name not in r for r in self.rows):
            raise KeyError(f"no column '{name}' in the history; columns: {self.columns}")
        if name == "residuals":
            out = np.empty(len(self.rows), dtype=object)
            for i, r in enumerate(self.rows):
                out[i] = np.array([float(v) for v in str(r.get(name, "")).split()])
            return out
        return np.array([r.get(name, np.nan) for r in self.rows], dtype=float)

    def to_csv(self, path: str) -> None:
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        cols = self.columns
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=cols)
            w.writeheader()
            for r in self.rows:
                w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})


@dataclass
class Result:
    """History plus totals of one analysis."""

    history: History
    completed: bool = True
    message: str = ""
    totals: dict = field(default_factory=dict)
    critical_points: list = field(default_factory=list)  # CriticalPoint: limit points, bifurcations

    def write(self, directory: str, name: str = "history") -> str:
        """Write ``<directory>/<name>.csv`` and a JSON summary; returns the CSV path."""
        path = os.path.join(directory, f"{name}.csv")
        self.history.to_csv(path)
        with open(os.path.join(directory, f"{name}_summary.json"), "w") as f:
            json.dump({"completed": self.completed, "message": self.message, **self.totals,
                       "critical_points": [c.as_dict() for c in self.critical_points]}, f, indent=1)
        return path


def limit_load(load: np.ndarray, *coordinates: np.ndarray, kind: str = "max", first: bool = True) -> float:
    """Load extremum of a traced equilibrium path, refined by a parabola through the three
    path points around it, with the path length in ``coordinates`` as parameter.

    load: (n,) load factors along the path (start at the unloaded state for a
    first maximum); coordinates: (n,) arrays, e.g. monitored displacements;
    kind: 'max' or 'min'; first: the first local extremum instead of the global one.
    A path whose extremum is its first or last point has none inside it (the load still rises,
    or falls, at its end): that is a ValueError, not a limit load.
    """
    lam = np.asarray(load, dtype=float)
    xs = np.array([np.asarray(c, dtype=float) for c in coordinates])
    sign = 1.0 if kind == "max" else -1.0
    if first:
        turns = np.flatnonzero(sign * np.diff(lam) < 0)
        stop = turns[0] + 1 if len(turns) else len(lam) - 1
        k = int(np.argmax(sign * lam[: stop + 1]))
    else:
        k = int(np.argmax(sign * lam))
    if k == 0 or k == len(lam) - 1:
        word = "maximum" if kind == "max" else "minimum"
        raise ValueError(f"the path has no {word} of the load inside it: its {word} is at its "
                         f"{'first' if k == 0 else 'last'} point (λ = {lam[k]:.6g}), so the load may go on "
                         f"{'rising' if kind == 'max' else 'falling'}; follow the path further")
    s = np.concatenate([[0.0], np.cumsum(np.sqrt((np.diff(xs, axis=1) ** 2).sum(axis=0)))])
    c = np.polyfit(s[k - 1:k + 2], lam[k - 1:k + 2], 2)
    return float(c[2] - c[1] ** 2 / (4 * c[0]))

"""Results: the per-step history of an analysis and the profiles of monitored groups."""
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

    def to_pandas(self):
        """The history as a :class:`pandas.DataFrame`, one row per step, indexed by step (needs
        pandas); the ``residuals`` column holds each step's residual norms as an array."""
        try:
            import pandas
        except ImportError:
            raise ImportError("History.to_pandas needs pandas (Debian: apt install python3-pandas; "
                              "or pip install pandas)") from None
        frame = pandas.DataFrame({name: (list(self.column(name)) if name == "residuals" else self.column(name))
                                  for name in self.columns})
        if "step" in frame:
            frame["step"] = frame["step"].astype(int)
            frame = frame.set_index("step")
        return frame

    @classmethod
    def read_csv(cls, path: str) -> "History":
        """The history written by :meth:`to_csv` (or :meth:`Result.write`): numbers as floats,
        ``step``, ``iterations`` and ``cuts`` as integers, ``residuals`` as its text."""
        rows = []
        with open(path, newline="") as f:
            for raw in csv.DictReader(f):
                row = {}
                for key, text in raw.items():
                    if text is None or text == "":
                        continue
                    if key == "residuals":
                        row[key] = text
                    elif key in ("step", "iterations", "cuts"):
                        row[key] = int(float(text))
                    else:
                        try:
                            row[key] = float(text)
                        except ValueError:
                            row[key] = text
                rows.append(row)
        return cls(rows)

    def to_csv(self, path: str) -> None:
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        cols = self.columns
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=cols)
            w.writeheader()
            for r in self.rows:
                w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})


class Profile:
    """The dofs of every node of a group, step by step, ordered along the group
    (``Scene.monitor(..., reduce='profile')``).

    X: (n, gdim) reference coordinates of the nodes, in profile order; s: (n,) their coordinate
    along the group (``along``: 'arc length', an axis or a direction); dofs: the dof names;
    steps, load_factors: (steps,) the history's step numbers and load factors; values:
    (steps, n, len(dofs)). A profile monitored from a restart on only has NaN before it.
    """

    def __init__(self, name: str, where: str, dofs, X: np.ndarray, s: np.ndarray, along="arc length",
                 steps=(), load_factors=(), values=None, order: np.ndarray | None = None):
        self.name, self.where, self.dofs, self.along = name, where, tuple(dofs), along
        self.X = np.asarray(X, dtype=float)
        self.s = np.asarray(s, dtype=float)
        self._order = order  # the group's order → profile order
        self._steps = [int(k) for k in steps]
        self._load_factors = [float(v) for v in load_factors]
        rows = np.zeros((0, len(self.X), len(self.dofs))) if values is None else np.asarray(values, dtype=float)
        self._rows = list(rows)

    def __repr__(self) -> str:
        return (f"Profile('{self.name}' on '{self.where}': {len(self.X)} nodes along {self.along}, "
                f"{len(self._rows)} steps, dofs {self.dofs})")

    def __len__(self) -> int:
        return len(self._rows)

    @property
    def steps(self) -> np.ndarray:
        return np.array(self._steps, dtype=np.int64)

    @property
    def load_factors(self) -> np.ndarray:
        return np.array(self._load_factors, dtype=float)

    @property
    def values(self) -> np.ndarray:
        """(steps, n, dofs)."""
        return np.array(self._rows, dtype=float).reshape(len(self._rows), len(self.X), len(self.dofs))

    def append(self, step: int, load_factor: float, values: np.ndarray) -> None:
        """Add one step: ``values`` (n, dofs) in the group's order (put in profile order here)."""
        values = np.asarray(values, dtype=float)
        self._steps.append(int(step))
        self._load_factors.append(float(load_factor))
        self._rows.append(values if self._order is None else values[self._order])

    def restore(self, steps, load_factors, values: np.ndarray) -> None:
        """Replace the steps by those given (``values`` (steps, n, dofs) already in profile order)."""
        self._steps = [int(k) for k in steps]
        self._load_factors = [float(v) for v in load_factors]
        self._rows = list(np.asarray(values, dtype=float).reshape(len(self._steps), len(self.X), len(self.dofs)))

    def column(self, dof: str) -> np.ndarray:
        """(steps, n) the values of one dof (e.g. 'uy': the settlement trough at every step)."""
        if dof not in self.dofs:
            raise KeyError(f"profile '{self.name}' has no dof '{dof}'; its dofs: {list(self.dofs)}")
        return self.values[:, :, self.dofs.index(dof)]

    def arrays(self, prefix: str = "") -> dict:
        """The profile as named arrays (for ``.npz`` files); :meth:`from_arrays` reads them back."""
        meta = json.dumps({"name": self.name, "where": self.where, "dofs": list(self.dofs), "along": self.along})
        return {f"{prefix}meta": np.array(meta), f"{prefix}X": self.X, f"{prefix}s": self.s,
                f"{prefix}steps": self.steps, f"{prefix}load_factors": self.load_factors,
                f"{prefix}values": self.values}

    @classmethod
    def from_arrays(cls, arrays, prefix: str = "", order: np.ndarray | None = None) -> "Profile":
        meta = json.loads(str(arrays[f"{prefix}meta"]))
        return cls(meta["name"], meta["where"], meta["dofs"], arrays[f"{prefix}X"], arrays[f"{prefix}s"],
                   meta["along"], arrays[f"{prefix}steps"], arrays[f"{prefix}load_factors"],
                   arrays[f"{prefix}values"], order)


class ElementResults:
    """Results element by element of one part at one state, in engineering terms, on every rank
    (the same arrays in serial and under MPI, elements ordered by their input index).

    kind: 'section forces' (beams and bars: the two ends of each element), 'shell resultants'
    (shells and membranes: the centroid), 'ply stresses' (laminated shells: the bottom and top
    of every ply above the centroid) or 'stresses' (solids: the centre of each cell);
    components: the names of the values; cells: (n,) input index of each element; points:
    (n, p, gdim) current positions where the values hold (p = 2 ends, 2 per ply, or 1 centre); values:
    (n, p, len(components)); axes: (n, gdim, gdim) the element axes, rows e1, e2 (, e3), in the
    current configuration (None for solids, whose components are global).

    ``results["M"]`` is a component's (n, p) array; :meth:`extreme` its largest magnitude.
    """

    def __init__(self, kind: str, components, cells, points, values, axes=None, label: str = ""):
        self.kind, self.components, self.label = kind, tuple(components), label
        self.cells = np.asarray(cells, dtype=np.int64)
        self.points = np.asarray(points, dtype=float)
        self.values = np.asarray(values, dtype=float).reshape(len(self.cells), self.points.shape[1],
                                                              len(self.components))
        self.axes = None if axes is None else np.asarray(axes, dtype=float)

    def __repr__(self) -> str:
        return (f"ElementResults({self.kind} of {self.label or 'the part'}: {len(self.cells)} elements, "
                f"components {', '.join(self.components)})")

    def __len__(self) -> int:
        return len(self.cells)

    def __getitem__(self, component: str) -> np.ndarray:
        """(n, p) values of one component."""
        if component not in self.components:
            raise KeyError(f"{self.kind} have no component '{component}'; they have {list(self.components)}")
        return self.values[:, :, self.components.index(component)]

    def reduce(self, how: str) -> dict[str, float]:
        """One value per component over all elements and points: 'max', 'min', 'mean' or 'absmax'
        (the value of largest magnitude, with its sign)."""
        flat = self.values.reshape(-1, len(self.components))
        if len(flat) == 0:
            return {c: float("nan") for c in self.components}
        if how == "absmax":
            picked = flat[np.argmax(np.abs(flat), axis=0), np.arange(flat.shape[1])]
        elif how in ("max", "min", "mean"):
            picked = getattr(np, how)(flat, axis=0)
        else:
            raise ValueError(f"reduce = {how!r}: give 'max', 'min', 'mean' or 'absmax'")
        return {c: float(v) for c, v in zip(self.components, picked)}

    def extreme(self, component: str) -> float:
        """The value of ``component`` of largest magnitude, with its sign."""
        return self.reduce("absmax")[component]

    def at(self, point, tolerance: float | None = None) -> dict[str, float]:
        """The values at the element points nearest to ``point`` (current positions), averaged
        over the elements meeting there (a beam's node: the ends of the elements on either side,
        equal without a load on the node). tolerance: the largest distance accepted (default: a
        thousandth of the extent of the points)."""
        point = np.asarray(point, dtype=float)
        flat = self.points.reshape(-1, self.points.shape[-1])
        if len(flat) == 0:
            raise ValueError(f"{self!r} holds no elements")
        distance = np.linalg.norm(flat - point[: flat.shape[1]], axis=1)
        extent = float(np.ptp(flat, axis=0).max()) or 1.0
        tolerance = 1e-3 * extent if tolerance is None else tolerance
        if distance.min() > tolerance:
            raise ValueError(f"no element point of {self.label or 'the part'} within {tolerance:.3g} of "
                             f"{point.tolist()} (the nearest is {distance.min():.3g} away)")
        near = distance <= distance.min() + 1e-9 * extent
        return {c: float(v) for c, v in zip(self.components,
                                            self.values.reshape(-1, len(self.components))[near].mean(axis=0))}

    def to_pandas(self):
        """One row per element and point: cell, point index, x, y (, z), then the components."""
        try:
            import pandas
        except ImportError:
            raise ImportError("ElementResults.to_pandas needs pandas (Debian: apt install python3-pandas)") from None
        n, p, _ = self.values.shape
        data = {"cell": np.repeat(self.cells, p), "point": np.tile(np.arange(p), n)}
        for k, axis in enumerate("xyz"[: self.points.shape[-1]]):
            data[axis] = self.points[:, :, k].ravel()
        for k, c in enumerate(self.components):
            data[c] = self.values[:, :, k].ravel()
        return pandas.DataFrame(data)


def read_profiles(path: str) -> dict[str, Profile]:
    """The profiles of a ``<name>_profiles.npz`` file written by :meth:`Result.write`."""
    with np.load(path, allow_pickle=False) as data:
        names = json.loads(str(data["names"]))
        return {name: Profile.from_arrays(data, f"profile{i}_") for i, name in enumerate(names)}


@dataclass
class Result:
    """History, profiles and totals of one analysis.

    profiles: name → :class:`Profile` of the scene's profile monitors."""

    history: History
    completed: bool = True
    message: str = ""
    totals: dict = field(default_factory=dict)
    profiles: dict = field(default_factory=dict)
    critical_points: list = field(default_factory=list)  # CriticalPoint: limit points, bifurcations
    monitors: dict = field(default_factory=dict)  # monitor name → its history columns

    def monitor(self, name: str):
        """The values of monitor ``name`` step by step: a dict {dof or component: (steps,) array}
        (``{"ux": …, "uy": …, "rz": …}`` for a point; ``"uy_absmax"`` for a reduction; ``"Fx"`` …
        for a reaction; the contact columns of ``scene.monitor_contact``), or the
        :class:`Profile` of a profile monitor."""
        if name in self.profiles:
            return self.profiles[name]
        columns = self.monitors.get(name)
        if columns is None:  # a history read back or restarted: the columns named after the monitor
            columns = [c for c in self.history.columns if c.startswith(f"{name}_")]
        if not columns:
            known = sorted(set(self.monitors) | set(self.profiles))
            raise KeyError(f"no monitor '{name}' in this result; monitors: {known}")
        return {c[len(name) + 1:]: self.history.column(c) for c in columns}

    def write(self, directory: str, name: str = "history") -> str:
        """Write ``<directory>/<name>.csv``, a JSON summary and, with profiles,
        ``<name>_profiles.npz`` (read it with :func:`read_profiles`); returns the CSV path."""
        path = os.path.join(directory, f"{name}.csv")
        self.history.to_csv(path)
        summary = {"completed": self.completed, "message": self.message, **self.totals}
        if self.profiles:
            summary["profiles"] = {p.name: {"where": p.where, "dofs": list(p.dofs), "nodes": len(p.X),
                                            "along": p.along, "file": f"{name}_profiles.npz"}
                                   for p in self.profiles.values()}
            arrays = {"names": np.array(json.dumps(list(self.profiles)))}
            for i, p in enumerate(self.profiles.values()):
                arrays.update(p.arrays(f"profile{i}_"))
            with open(os.path.join(directory, f"{name}_profiles.npz"), "wb") as f:
                np.savez(f, **arrays)
        with open(os.path.join(directory, f"{name}_summary.json"), "w") as f:
            summary["critical_points"] = [c.as_dict() for c in self.critical_points]
            json.dump(summary, f, indent=1)
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


def path_distance(path: np.ndarray, points: np.ndarray, scale) -> np.ndarray:
    """Distances of reference points from a traced path: path (n, k), the polyline through the
    path's states (e.g. columns displacement, load); points (m, k), e.g. a published table;
    scale (k,) divides each coordinate first, so that the distance is relative. Returns (m,).

    Where a curve is steep, a difference of loads at equal displacement (or the reverse)
    magnifies small offsets; the distance from the polyline does not."""
    path, points, scale = (np.asarray(v, dtype=float) for v in (path, points, scale))
    if path.ndim != 2 or len(path) < 2:
        raise ValueError(f"path_distance: the path needs at least two states as rows (n, k), not shape {path.shape}")
    k = path.shape[1]
    if points.ndim != 2 or points.shape[1] != k or scale.shape != (k,):
        raise ValueError(f"path_distance: the points {points.shape} and the scale {scale.shape} need the path's "
                         f"{k} coordinates per row")
    if not np.all(scale > 0.0):
        raise ValueError(f"path_distance: every scale must be positive, not {scale.tolist()}")
    a = path[:-1] / scale
    d = path[1:] / scale - a
    dd = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    out = np.empty(len(points))
    for i, q in enumerate(points / scale):
        s = np.clip(np.einsum("ij,ij->i", q - a, d) / dd, 0.0, 1.0)
        out[i] = np.min(np.linalg.norm(a + s[:, None] * d - q, axis=1))
    return out

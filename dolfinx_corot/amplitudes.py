"""Amplitudes: how a load or a prescribed motion varies with the load factor."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Amplitude:
    """Piecewise-linear amplitude g(λ) through ``points`` = ((λ₀, g₀), (λ₁, g₁), …), λ increasing.

    A load with an amplitude is g(λ)·value instead of λ·value; beyond the
    first and last points g keeps its end values. Example: apply F₁, then
    hold it while F₂ grows: ``Amplitude([(0, 0), (1, 1)])`` for F₁ and
    ``Amplitude([(1, 0), (2, 1)])`` for F₂, with load factors up to 2.
    """

    points: tuple[tuple[float, float], ...]

    def __post_init__(self):
        pts = np.asarray(self.points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 1 or not np.all(np.isfinite(pts)):
            raise ValueError(f"Amplitude: give (load factor, value) pairs; got {self.points}")
        if np.any(np.diff(pts[:, 0]) <= 0):
            raise ValueError(f"Amplitude: load factors must increase; got {pts[:, 0].tolist()}")
        object.__setattr__(self, "points", tuple(map(tuple, pts.tolist())))

    def __call__(self, load_factor: float) -> float:
        pts = np.asarray(self.points)
        return float(np.interp(load_factor, pts[:, 0], pts[:, 1]))

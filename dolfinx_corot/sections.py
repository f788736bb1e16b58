"""Beam cross-sections (frozen dataclasses).

In 2D the beam bends in its plane: ``I`` is the second moment of area about
the axis normal to the plane, and for a rectangle ``h`` is the in-plane depth.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Section:
    """General section: area A, second moment I, shear area As (k·A)."""

    A: float
    I: float
    As: float = 0.0

    def __post_init__(self):
        for name in ("A", "I", "As"):
            v = getattr(self, name)
            if not math.isfinite(v) or v < 0.0:
                raise ValueError(f"{type(self).__name__}: {name} = {v} must be finite and not negative")
        if self.A <= 0.0:
            raise ValueError(f"{type(self).__name__}: area A = {self.A} must be positive")


def Rectangle(b: float, h: float, shear_factor: float = 5.0 / 6.0) -> Section:
    """Rectangle of width b (out of plane) and depth h (in plane): A = bh, I = bh³/12, As = k·A."""
    if not (b > 0.0 and h > 0.0):
        raise ValueError(f"Rectangle: b = {b} and h = {h} must be positive")
    return Section(A=b * h, I=b * h**3 / 12.0, As=shear_factor * b * h)


def Circle(d: float, shear_factor: float = 0.9) -> Section:
    """Solid circle of diameter d: A = πd²/4, I = πd⁴/64, As = k·A."""
    if not d > 0.0:
        raise ValueError(f"Circle: diameter d = {d} must be positive")
    A = math.pi * d * d / 4.0
    return Section(A=A, I=math.pi * d**4 / 64.0, As=shear_factor * A)

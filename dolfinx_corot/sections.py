"""Beam cross-sections (frozen dataclasses).

In 2D the beam bends in its plane: ``I`` is the second moment of area about
the axis normal to the plane, and for a rectangle ``h`` is the in-plane depth.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Section:
    """General section: area A, second moment I (about the local z axis; the in-plane
    bending of 2D beams), shear area As (k·A); in 3D also Iy (about the local y axis,
    default I) and the torsion constant J (default Iy + I, the polar moment); ``outer`` the
    distance from the axis to the section's outer face, where a 3D beam meets a contact surface
    (default: the half depth √(3 I_max/A) of the rectangle of the same A and I)."""

    A: float
    I: float
    As: float = 0.0
    Iy: float | None = None
    J: float | None = None
    outer: float | None = None

    @property
    def second_moment_y(self) -> float:
        return self.I if self.Iy is None else self.Iy

    @property
    def torsion_constant(self) -> float:
        return self.second_moment_y + self.I if self.J is None else self.J

    @property
    def contact_radius(self) -> float:
        """The distance from the axis at which a 3D beam meets a contact surface."""
        if self.outer is not None:
            return self.outer
        return math.sqrt(3.0 * max(self.I, self.second_moment_y) / self.A)

    def __post_init__(self):
        for name in ("A", "I", "As", "Iy", "J", "outer"):
            if getattr(self, name) is None:
                continue
            v = getattr(self, name)
            if not math.isfinite(v) or v < 0.0:
                raise ValueError(f"{type(self).__name__}: {name} = {v} must be finite and not negative")
        if self.A <= 0.0:
            raise ValueError(f"{type(self).__name__}: area A = {self.A} must be positive")


def Rectangle(b: float, h: float, shear_factor: float = 5.0 / 6.0) -> Section:
    """Rectangle of width b (along local z) and depth h (along local y; in plane in 2D):
    A = bh, I = bh³/12 (about z), Iy = hb³/12, As = k·A, J = Saint-Venant β·a·c³
    (a ≥ c the sides; Roark's series)."""
    if not (b > 0.0 and h > 0.0):
        raise ValueError(f"Rectangle: b = {b} and h = {h} must be positive")
    a, c = max(b, h), min(b, h)
    J = a * c**3 * (1.0 / 3.0 - 0.21 * (c / a) * (1.0 - (c / a) ** 4 / 12.0))
    return Section(A=b * h, I=b * h**3 / 12.0, As=shear_factor * b * h, Iy=h * b**3 / 12.0, J=J, outer=0.5 * h)


def Circle(d: float, shear_factor: float = 0.9) -> Section:
    """Solid circle of diameter d: A = πd²/4, I = πd⁴/64, As = k·A."""
    if not d > 0.0:
        raise ValueError(f"Circle: diameter d = {d} must be positive")
    A = math.pi * d * d / 4.0
    return Section(A=A, I=math.pi * d**4 / 64.0, As=shear_factor * A, Iy=math.pi * d**4 / 64.0,
                   J=math.pi * d**4 / 32.0, outer=0.5 * d)


def Pipe(d: float, t: float, shear_factor: float = 0.5) -> Section:
    """Circular hollow section (a pipe) of outer diameter d and wall thickness t:
    A = π(d² − d_i²)/4, I = Iy = π(d⁴ − d_i⁴)/64, J = 2I, As = k·A (k = 0.5 for a thin tube),
    d_i = d − 2t; it meets contact surfaces at its outer radius d/2."""
    if not (d > 0.0 and 0.0 < t <= 0.5 * d):
        raise ValueError(f"Pipe: diameter d = {d} and wall thickness t = {t} must satisfy 0 < t ≤ d/2")
    di = d - 2.0 * t
    A = math.pi * (d * d - di * di) / 4.0
    I = math.pi * (d**4 - di**4) / 64.0
    return Section(A=A, I=I, As=shear_factor * A, Iy=I, J=2.0 * I, outer=0.5 * d)

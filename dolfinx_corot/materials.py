"""Materials (frozen dataclasses; units are the user's consistent set)."""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass


@dataclass(frozen=True)
class Elastic:
    """Isotropic linear elastic material.

    E: Young's modulus (> 0); nu: Poisson's ratio in (-1, 0.5); density: mass per unit
    volume ρ (≥ 0), or None. ``scene.gravity`` takes ρ from here when it is not given
    a density: ρ·g per unit volume of a solid, ρ·A·g per unit length of a beam or bar,
    ρ·t·g per unit area of a shell or membrane.
    """

    E: float
    nu: float = 0.0
    density: float | None = None

    def __post_init__(self):
        name = type(self).__name__
        if not (math.isfinite(self.E) and self.E > 0.0):
            raise ValueError(f"{name}: Young's modulus E = {self.E} must be positive and finite")
        if not (-1.0 < self.nu < 0.5):
            raise ValueError(f"{name}: Poisson's ratio nu = {self.nu} must lie in (-1, 0.5)")
        if self.density is not None:
            ok = isinstance(self.density, numbers.Real) and not isinstance(self.density, bool) \
                and math.isfinite(self.density) and self.density >= 0.0
            if not ok:
                raise ValueError(f"{name}(E={self.E}, nu={self.nu}): density = {self.density!r} must be a finite "
                                 "number ≥ 0 (or None: no self-weight from the material)")

    @property
    def G(self) -> float:
        """Shear modulus E / (2 (1 + ν))."""
        return self.E / (2.0 * (1.0 + self.nu))


@dataclass(frozen=True)
class Orthotropic:
    """Orthotropic linear elastic layer in plane stress (a ply of a laminate, a timber or FRP
    panel, a woven membrane), in its material axes 1 (along the fibres), 2 (across them) and 3
    (through the thickness).

    E1, E2: Young's moduli along 1 and 2; G12: in-plane shear modulus; nu12: the Poisson ratio of
    a stretch along 1 (ν21 = ν12 E2/E1); G13, G23: transverse shear moduli (Reissner–Mindlin
    shells; default G12); density: mass per unit volume (or None). ν12ν21 < 1 keeps the layer
    stable.
    """

    E1: float
    E2: float
    G12: float
    nu12: float
    G13: float | None = None
    G23: float | None = None
    density: float | None = None

    def __post_init__(self):
        name = type(self).__name__
        for key in ("E1", "E2", "G12", "G13", "G23"):
            v = getattr(self, key)
            if v is not None and not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"{name}: {key} = {v} must be positive and finite")
        if not (math.isfinite(self.nu12) and self.nu12 * self.nu12 * self.E2 / self.E1 < 1.0):
            raise ValueError(f"{name}: nu12 = {self.nu12} makes the layer unstable (ν12²·E2/E1 must be below 1)")
        if self.density is not None and not (math.isfinite(self.density) and self.density >= 0.0):
            raise ValueError(f"{name}: density = {self.density!r} must be a finite number ≥ 0 (or None)")

    @property
    def transverse_shear(self) -> tuple[float, float]:
        """(G13, G23), each defaulting to G12."""
        return (self.G12 if self.G13 is None else self.G13, self.G12 if self.G23 is None else self.G23)


@dataclass(frozen=True)
class SaintVenantKirchhoff(Elastic):
    """Hyperelastic St Venant–Kirchhoff material for large-deformation continua:
    S = λ tr(E) I + 2μ E with the Green–Lagrange strain E (Lamé constants from E, ν).
    Exact for large rotations, meant for moderate strains."""


@dataclass(frozen=True)
class NeoHookean(Elastic):
    """Compressible neo-Hookean material: ψ = μ/2 (I₁ − 3 − 2 ln J) + λ/2 (ln J)²
    (Lamé constants from E, ν at small strain)."""

r"""Normal contact laws (Wriggers 2006, §6.2 and §10.3; Simo & Laursen 1992).

* :class:`Penalty` — pressure p = ε⟨−g⟩ with ε in pressure per unit
  penetration; by default ε = ``factor`` · E*/h with E* the smallest
  plane-strain modulus E/(1−ν²) of the two bodies and h the mean master
  segment length.
* :class:`AugmentedLagrangian` — p = ⟨λ − ε g⟩; after each converged
  Newton solve λ ← ⟨λ − ε g⟩ (Uzawa) until the largest penetration is below
  ``gap_tolerance`` · h; multipliers are carried over to the next step.

The tangential law, :class:`Coulomb`, is given with either: ``Scene.contact(..., friction=...)``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .. import validate
from ..parts.surface import SurfaceError

ContactError = SurfaceError  # a contact surface that cannot be built (missing group, unsupported part)


@dataclass(frozen=True)
class Penalty:
    """Penalty contact. penalty: ε in pressure per unit penetration (None: ``factor`` · E*/h)."""

    penalty: float | None = None
    factor: float = 10.0

    augmented = False

    def __post_init__(self):
        name = type(self).__name__
        validate.positive(name, "penalty", self.penalty, allow_none=True)
        validate.positive(name, "factor", self.factor)


@dataclass(frozen=True)
class AugmentedLagrangian(Penalty):
    """Penalty plus Uzawa updates of the contact pressure until the largest penetration is below
    ``gap_tolerance`` times the mean master segment length (at most ``max_updates`` per step)."""

    gap_tolerance: float = 1e-3
    max_updates: int = 10

    augmented = True

    def __post_init__(self):
        super().__post_init__()
        validate.positive("AugmentedLagrangian", "gap_tolerance", self.gap_tolerance)
        validate.whole("AugmentedLagrangian", "max_updates", self.max_updates, 0)


@dataclass(frozen=True)
class Coulomb:
    """Coulomb friction with cohesion: the shear traction of a slave in contact is bounded by
    τ ≤ c + μ σₙ, with μ = ``mu`` (structural users) or μ = tan φ from ``friction_angle`` φ in
    degrees (geotechnical users; give one of the two) and ``cohesion`` c a stress (force per
    unit area in 3D, per unit length in 2D, as the pressure). Below the bound the slave sticks
    through a tangential penalty ε_T = ``tangential_factor`` · ε (ε the normal penalty): it slips
    elastically by τ/ε_T before it slides.

    ``slip_tolerance`` (with an :class:`AugmentedLagrangian` normal law): the tangential
    traction is augmented too (Simo & Laursen 1992). Each Uzawa update also sets every sticking
    slave's tangential multiplier to its traction, λ_T ← t, the slave keeping its stick point,
    until the elastic slip of every sticking slave is below ``slip_tolerance`` times the mean
    master segment length: the stick is then exact to that tolerance, whatever ε_T. It costs
    Newton solves (one per update) and, where slaves pass from stick to slip, iterations.
    None (the default): the tangential penalty alone."""

    mu: float | None = None
    friction_angle: float | None = None
    cohesion: float = 0.0
    tangential_factor: float = 1.0
    slip_tolerance: float | None = None

    def __post_init__(self):
        if (self.mu is None) == (self.friction_angle is None):
            raise ValueError("Coulomb: give the friction coefficient mu or the friction angle friction_angle "
                             f"(degrees), one of them: got mu={self.mu}, friction_angle={self.friction_angle}")
        if self.mu is not None:
            validate.positive("Coulomb", "mu", self.mu, allow_zero=True)
        else:
            validate.positive("Coulomb", "friction_angle", self.friction_angle, allow_zero=True)
            if not self.friction_angle < 90.0:
                raise ValueError(f"Coulomb: friction_angle must be below 90 degrees, got {self.friction_angle}")
        validate.positive("Coulomb", "cohesion", self.cohesion, allow_zero=True)
        validate.positive("Coulomb", "tangential_factor", self.tangential_factor)
        validate.positive("Coulomb", "slip_tolerance", self.slip_tolerance, allow_none=True)

    @property
    def coefficient(self) -> float:
        """μ (tan φ when given by the friction angle)."""
        return float(self.mu) if self.mu is not None else math.tan(math.radians(self.friction_angle))

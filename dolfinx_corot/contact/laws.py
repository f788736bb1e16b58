r"""Normal contact laws (Wriggers 2006, §6.2 and §10.3; Simo & Laursen 1992).

* :class:`Penalty` — pressure p = ε⟨−g⟩ with ε in pressure per unit
  penetration; by default ε = ``factor`` · E*/h with E* the smallest
  plane-strain modulus E/(1−ν²) of the two bodies and h the mean master
  segment length.
* :class:`AugmentedLagrangian` — p = ⟨λ − ε g⟩; after each converged
  Newton solve λ ← ⟨λ − ε g⟩ (Uzawa) until the largest penetration is below
  ``gap_tolerance`` · h; multipliers are carried over to the next step.
"""
from __future__ import annotations

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

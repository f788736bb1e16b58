"""The per-element properties of the line elements (beams and bars): their layout in the kernels'
``props`` and the checks of a section's values.

Plain Python (no compiled code): a part checks and packs its sections without loading the
element laws (:mod:`.line2d`, :mod:`.beam3d`), which import these names.
"""
from __future__ import annotations

import numpy as np

#: planar line elements (:mod:`.line2d`): ``props = (EA, EI, GAs, N0)``
NPROPS_2D = 4
#: line elements in space (:mod:`.beam3d`): ``props = (EA, GJ, EIy, EIz, GAy, GAz, N0, vx, vy, vz)``
NPROPS_3D = 10


def check_props_2d(EA: float, EI: float, GAs: float, where: str) -> None:
    """Raise ValueError naming ``where`` for non-physical section properties of a planar element."""
    for name, v in (("EA", EA), ("EI", EI), ("GAs", GAs)):
        if not np.isfinite(v):
            raise ValueError(f"{where}: {name} = {v} is not finite")
    if EA <= 0.0:
        raise ValueError(f"{where}: axial stiffness EA = {EA} must be positive")
    if EI < 0.0 or GAs < 0.0:
        raise ValueError(f"{where}: EI = {EI} and GAs = {GAs} must not be negative")


def check_props_3d(values: dict, where: str) -> None:
    """Raise ValueError naming ``where`` for non-physical section properties of an element in space."""
    for name, v in values.items():
        if not np.isfinite(v) or v < 0.0:
            raise ValueError(f"{where}: {name} = {v} must be finite and not negative")
    if values["EA"] <= 0.0:
        raise ValueError(f"{where}: axial stiffness EA = {values['EA']} must be positive")

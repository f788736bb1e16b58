"""Checks of settings made when they are given, each naming the setting and its value."""
from __future__ import annotations

import math
import numbers

#: what Newton factorizes for parts whose tangent is symmetric at equilibrium only (Scene, System)
TANGENTS = ("auto", "consistent", "symmetrized")


def whole(owner: str, name: str, value, minimum: int) -> None:
    """``value`` must be a whole number (not a bool) ≥ ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
        raise ValueError(f"{owner}: {name} = {value!r} must be a whole number ≥ {minimum}")


def positive(owner: str, name: str, value, allow_zero: bool = False, allow_none: bool = False) -> None:
    """``value`` must be a finite number > 0 (≥ 0 with ``allow_zero``; None with ``allow_none``)."""
    if value is None and allow_none:
        return
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value) \
        and (value >= 0.0 if allow_zero else value > 0.0)
    if not ok:
        raise ValueError(f"{owner}: {name} = {value!r} must be a finite number "
                         f"{'≥ 0' if allow_zero else '> 0'}")


def choice(owner: str, name: str, value, options) -> None:
    """``value`` is one of ``options``, or a ValueError naming ``owner.name``."""
    if value not in options:
        raise ValueError(f"{owner}: {name} = {value!r} is not one of {tuple(options)}")

"""Node-to-segment contact: search, kernels, laws, interfaces (a contribution of the system).

The interfaces and their kernels are imported when a scene first makes contact
(``Scene.contact``): a scene without contact loads none of them.
"""
from __future__ import annotations

import importlib as _importlib

from .laws import AugmentedLagrangian, ContactError, Penalty
from .pair import ContactPair, InterfacePressure

__all__ = ["AugmentedLagrangian", "Contact", "ContactError", "ContactPair", "Interface", "InterfacePressure", "Penalty"]


def __getattr__(name: str):
    if name in ("Contact", "Interface"):
        return getattr(_importlib.import_module(".interface", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

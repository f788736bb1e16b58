"""Node-to-segment contact: search, kernels, laws, interfaces (a contribution of the system)."""
from .interface import Contact, Interface
from .laws import AugmentedLagrangian, ContactError, Penalty
from .pair import ContactPair, InterfacePressure

__all__ = ["AugmentedLagrangian", "Contact", "ContactError", "ContactPair", "Interface", "InterfacePressure", "Penalty"]

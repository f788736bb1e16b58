"""Closed-form solutions used as references by demos and tests."""
from __future__ import annotations

import numpy as np


def cantilever_elastica_force_ratio(w_over_L: float) -> float:
    """F/F_cr of the inextensible cantilever elastica under an axial dead tip force, at the lateral
    tip deflection w/L (first branch, w/L < 0.806).

    With k = sin(α/2) (α the tip rotation) and K the complete elliptic
    integral of the first kind: F/F_cr = (2K(k)/π)², w/L = 2k/K(k), F_cr = π²EI/(4L²).
    """
    from scipy.optimize import brentq
    from scipy.special import ellipk

    if not 0.0 < w_over_L < 0.806:
        raise ValueError(f"w/L = {w_over_L} is outside (0, 0.806), the first branch of the elastica")
    k = brentq(lambda k: 2.0 * k / ellipk(k * k) - w_over_L, 1e-12, 0.8375)  # 2k/K(k) is largest (0.806) there
    return float((2.0 * ellipk(k * k) / np.pi) ** 2)

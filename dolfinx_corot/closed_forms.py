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


def cantilever_uniform_load(k: float, points: int = 2001) -> dict:
    """The inextensible Bernoulli cantilever (clamped at s = 0, length L) under a uniform dead load
    q per unit length in −y, transverse to its straight axis along x, at k = qL³/EI: the elastica
    EI θ'' = q (L − s) cos θ, θ(0) = 0, θ'(L) = 0 (EI θ' is the moment at s of the load beyond
    it), x' = cos θ, y' = sin θ, solved as a boundary-value problem by collocation
    (scipy.integrate.solve_bvp, tolerance 1e-10).

    Returns, in units of L, {"x_tip", "y_tip" (negative: along the load), "theta_tip" (the tip
    rotation, negative), "s", "x", "y", "moment" (EI θ'/(qL²) along s)}."""
    return _cantilever_elastica(k, lambda t: 1.0 - t, points, "cantilever_uniform_load")


def cantilever_tip_load(k: float, points: int = 2001) -> dict:
    """The inextensible Bernoulli cantilever (clamped at s = 0, length L) under a dead tip force P
    in −y, transverse to its straight axis along x, at k = PL²/EI: the elastica EI θ'' = P cos θ,
    θ(0) = 0, θ'(L) = 0 (EI θ'(s) = P (x_tip − x(s)), the moment at s of the tip force), by
    collocation as :func:`cantilever_uniform_load`. At k = 1 and 2 it gives the tip displacements
    of Mattiasson (1981, Table 1): (L − x_tip, −y_tip)/L = (0.05643, 0.30172) and (0.16064, 0.49346),
    tip rotations 0.46135 and 0.78175.

    Returns, in units of L, {"x_tip", "y_tip", "theta_tip", "s", "x", "y", "moment" (EI θ'/(PL))}."""
    return _cantilever_elastica(k, lambda t: np.ones_like(t), points, "cantilever_tip_load")


def _cantilever_elastica(k: float, load, points: int, name: str) -> dict:
    """EI θ'' = k load(s) cos θ on the unit cantilever (see :func:`cantilever_uniform_load`)."""
    from scipy.integrate import solve_bvp

    s = np.linspace(0.0, 1.0, points)

    def rhs(t, z):  # z = (θ, θ', x, y), lengths in L, θ toward the load
        return np.vstack([z[1], k * load(t) * np.cos(z[0]), np.cos(z[0]), np.sin(z[0])])

    def bc(a, b):
        return np.array([a[0], b[1], a[2], a[3]])

    guess = np.zeros((4, points))
    guess[0] = -k * (s - s**2 / 2) / 2  # of the order of the small-deflection slope
    guess[2] = s
    sol = solve_bvp(rhs, bc, s, guess, tol=1e-10, max_nodes=200000)
    if not sol.success:
        raise RuntimeError(f"{name}(k = {k}): the collocation did not converge ({sol.message})")
    theta, dtheta, x, y = sol.sol(s)
    return {"x_tip": float(x[-1]), "y_tip": float(y[-1]), "theta_tip": float(theta[-1]), "s": s, "x": x, "y": y,
            "moment": dtheta / k}


def hertz_ellipse_fit(x: np.ndarray, p: np.ndarray, above: float = 0.0) -> tuple[float, float]:
    """(p₀, a) of Hertz's ellipse p² = p₀² (1 − x²/a²) fitted by least squares to nodal pressures p at
    distances x from the centre of contact (line contact: x; point contact: the radius), over the
    nodes whose pressure exceeds ``above`` × the largest (0: every node in contact)."""
    x, p = np.asarray(x, dtype=float), np.asarray(p, dtype=float)
    on = p > max(above * p.max(), 0.0)
    A = np.column_stack([np.ones(on.sum()), x[on] ** 2])
    (c0, c1), *_ = np.linalg.lstsq(A, p[on] ** 2, rcond=None)
    return float(np.sqrt(c0)), float(np.sqrt(c0 / -c1))

r"""Small-strain law of a straight two-node beam (or bar) in space, in its element frame.

Basic deformations :math:`(\bar u, \bar{\boldsymbol\theta}_1, \bar{\boldsymbol\theta}_2)`
(rotation vectors in the element frame: x torsion, y and z bending) →
basic forces :math:`\bar{\mathbf f} = \partial U/\partial\bar{\mathbf d}` (7,), with

.. math::

    U = \tfrac12 EA\,l_0\bar\varepsilon^2 + N_0 l_0\bar\varepsilon
        + \frac{GJ}{2l_0}(\bar\theta_{2x}-\bar\theta_{1x})^2
        + \tfrac12\bar{\boldsymbol\theta}_y^T\mathbf k_y\bar{\boldsymbol\theta}_y
        + \tfrac12\bar{\boldsymbol\theta}_z^T\mathbf k_z\bar{\boldsymbol\theta}_z,

    \bar\varepsilon = \frac{\bar u}{l_0} + \frac{1}{30}\sum_{a=y,z}
        (2\bar\theta_{1a}^2 - \bar\theta_{1a}\bar\theta_{2a} + 2\bar\theta_{2a}^2),

the shallow-arch strain of Crisfield (1991, §7.2.1) in both bending planes,
:math:`\mathbf k_a = \frac{EI}{l_0(1+\Phi)}\begin{bmatrix}4+\Phi & 2-\Phi\\2-\Phi & 4+\Phi\end{bmatrix}`,
:math:`\Phi = 12EI/(GA_s l_0^2)` (0 for Bernoulli). Bending about z
(deflection along local y) uses EI_z and GA_y; about y, EI_y and GA_z.
A geometrically linear analysis drops the bending part of ε̄.

``props = (EA, GJ, EIy, EIz, GAy, GAz, N0, vx, vy, vz)``: section
stiffnesses, initial axial force, and the orientation vector v that fixes the
local y axis (its part normal to the element). Bars have GJ = EI = 0.
The functions are complex-analytic (complex-step tangents).
"""
from __future__ import annotations

import numba
import numpy as np

from .line_properties import NPROPS_3D

NPROPS = NPROPS_3D
EA, GJ, EIY, EIZ, GAY, GAZ, N0, VX, VY, VZ = range(NPROPS)


@numba.njit(cache=True)
def basic_force(l0, ubar, th1, th2, props, shallow_arch, fbar):
    """Fill fbar (7,) = (N̄, m̄1 (3), m̄2 (3)) = ∂U/∂d̄."""
    ea, gj, eiy, eiz = props[EA], props[GJ], props[EIY], props[EIZ]
    bending = shallow_arch and (eiy > 0.0 or eiz > 0.0)
    eps = ubar / l0
    if bending:
        eps = eps + (2.0 * th1[1] * th1[1] - th1[1] * th2[1] + 2.0 * th2[1] * th2[1]
                     + 2.0 * th1[2] * th1[2] - th1[2] * th2[2] + 2.0 * th2[2] * th2[2]) / 30.0
    n = ea * eps + props[N0]
    fbar[0] = n
    t = gj / l0 * (th2[0] - th1[0])
    fbar[1] = -t
    fbar[4] = t
    for a, ei, gas in ((1, eiy, props[GAZ]), (2, eiz, props[GAY])):
        phi = 12.0 * ei / (gas * l0 * l0) if gas > 0.0 else 0.0
        k = ei / (l0 * (1.0 + phi))
        kd = k * (4.0 + phi)
        ko = k * (2.0 - phi)
        fbar[1 + a] = kd * th1[a] + ko * th2[a]
        fbar[4 + a] = ko * th1[a] + kd * th2[a]
        if bending:
            fbar[1 + a] += n * l0 * (4.0 * th1[a] - th2[a]) / 30.0
            fbar[4 + a] += n * l0 * (4.0 * th2[a] - th1[a]) / 30.0


@numba.njit(cache=True)
def basic_stiffness_linear(l0, props, kbar):
    """kbar (7, 7) of the geometrically linear law (no shallow-arch coupling)."""
    kbar[:, :] = 0.0
    kbar[0, 0] = props[EA] / l0
    g = props[GJ] / l0
    kbar[1, 1] = g
    kbar[4, 4] = g
    kbar[1, 4] = -g
    kbar[4, 1] = -g
    for a, ei, gas in ((1, props[EIY], props[GAZ]), (2, props[EIZ], props[GAY])):
        phi = 12.0 * ei / (gas * l0 * l0) if gas > 0.0 else 0.0
        k = ei / (l0 * (1.0 + phi))
        kbar[1 + a, 1 + a] = k * (4.0 + phi)
        kbar[4 + a, 4 + a] = k * (4.0 + phi)
        kbar[1 + a, 4 + a] = k * (2.0 - phi)
        kbar[4 + a, 1 + a] = k * (2.0 - phi)



@numba.njit(cache=True)
def basic_stiffness(l0, ubar, th1, th2, props, shallow_arch, kbar):
    """kbar (7, 7) = ∂f̄/∂d̄ of :func:`basic_force`: the linear law, and with the shallow-arch
    strain EA l₀ g gᵀ + n l₀ ∂g/∂d̄ in place of EA/l₀ (g = ∂ε̄/∂d̄, n the axial force)."""
    basic_stiffness_linear(l0, props, kbar)
    ea, eiy, eiz = props[EA], props[EIY], props[EIZ]
    if not (shallow_arch and (eiy > 0.0 or eiz > 0.0)):
        return
    g = np.zeros(7)
    g[0] = 1.0 / l0
    eps = ubar / l0
    for a in (1, 2):
        g[1 + a] = (4.0 * th1[a] - th2[a]) / 30.0
        g[4 + a] = (4.0 * th2[a] - th1[a]) / 30.0
        eps += (2.0 * th1[a] * th1[a] - th1[a] * th2[a] + 2.0 * th2[a] * th2[a]) / 30.0
    n = ea * eps + props[N0]
    kbar[0, 0] = 0.0
    for i in range(7):
        for j in range(7):
            kbar[i, j] += ea * l0 * g[i] * g[j]
    for a in (1, 2):
        kbar[1 + a, 1 + a] += n * l0 * 4.0 / 30.0
        kbar[4 + a, 4 + a] += n * l0 * 4.0 / 30.0
        kbar[1 + a, 4 + a] -= n * l0 / 30.0
        kbar[4 + a, 1 + a] -= n * l0 / 30.0

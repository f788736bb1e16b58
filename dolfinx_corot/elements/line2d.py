r"""Small-strain laws of straight two-node line elements in their element frame.

Basic deformations :math:`(\bar u, \bar\theta_1, \bar\theta_2)` → basic forces
:math:`(\bar N, \bar M_1, \bar M_2)` and the basic stiffness (3, 3).

Properties per element, ``props = (EA, EI, GAs, N0)``.

Beams use the *shallow-arch* local law (Crisfield 1991, §7.2.1): with the
cubic transverse interpolation of the element-frame rotations, the mean axial
strain includes the length of the bent element beyond its chord,

.. math::

    \bar\varepsilon = \frac{\bar u}{l_0}
        + \frac{2\bar\theta_1^2 - \bar\theta_1\bar\theta_2 + 2\bar\theta_2^2}{30},\qquad
    \bar N = EA\,\bar\varepsilon + N_0 ,

    \begin{bmatrix}\bar M_1\\ \bar M_2\end{bmatrix} = \mathbf k_b
    \begin{bmatrix}\bar\theta_1\\ \bar\theta_2\end{bmatrix}
    + \frac{\bar N l_0}{30}\begin{bmatrix}4 & -1\\ -1 & 4\end{bmatrix}
    \begin{bmatrix}\bar\theta_1\\ \bar\theta_2\end{bmatrix},\qquad
    \mathbf k_b = \frac{EI}{l_0(1+\Phi)}
      \begin{bmatrix}4+\Phi & 2-\Phi\\ 2-\Phi & 4+\Phi\end{bmatrix},

i.e. the gradient of :math:`U = \tfrac12 EA\,l_0\bar\varepsilon^2 + N_0 l_0\bar\varepsilon
+ \tfrac12\bar{\boldsymbol\theta}^T\mathbf k_b\bar{\boldsymbol\theta}`, whose
Hessian is the basic stiffness. :math:`\Phi = 12EI/(GA_s l_0^2)` gives the
exact linear Timoshenko element (Przemieniecki 1968, §5.6); ``GAs = 0``
means Bernoulli (Φ = 0). On the eccentric Euler column (seed §2.3.1) this
law is about 50 times more accurate than the plain linear one with 10
elements (tip error 5e-5 instead of 4e-3).

Bars (trusses, anchors) have ``EI = 0``; their rotations are not used and
:math:`\bar N = EA\,\bar u/l_0 + N_0`.

``N0`` is an initial axial force (prestress of an anchor; 0 otherwise).
"""
from __future__ import annotations

import numba

from .line_properties import NPROPS_2D

#: number of entries of ``props`` per element
NPROPS = NPROPS_2D
EA, EI, GAS, N0 = range(NPROPS)


@numba.njit(cache=True, inline="always")
def basic_response(l0, ubar, t1, t2, props, fbar, kbar, shallow_arch):
    """Fill fbar (3,) and kbar (3, 3) from the basic deformations.

    shallow_arch: include the bending part of the axial strain (co-rotational
    analysis); False gives the linear law of a geometrically linear analysis.
    """
    ea = props[EA]
    ei = props[EI]
    gas = props[GAS]
    phi = 12.0 * ei / (gas * l0 * l0) if gas > 0.0 else 0.0
    k = ei / (l0 * (1.0 + phi))
    kd = k * (4.0 + phi)
    ko = k * (2.0 - phi)
    if shallow_arch and ei > 0.0:
        # shallow-arch coupling: ∂ε̄/∂(ū, θ̄1, θ̄2)
        g0 = 1.0 / l0
        g1 = (4.0 * t1 - t2) / 30.0
        g2 = (4.0 * t2 - t1) / 30.0
        eps = ubar / l0 + (2.0 * t1 * t1 - t1 * t2 + 2.0 * t2 * t2) / 30.0
    else:
        g0 = 1.0 / l0
        g1 = 0.0
        g2 = 0.0
        eps = ubar / l0
    n = ea * eps + props[N0]
    nl = n * l0
    fbar[0] = n
    fbar[1] = kd * t1 + ko * t2 + nl * g1
    fbar[2] = ko * t1 + kd * t2 + nl * g2
    eal = ea * l0
    kbar[0, 0] = eal * g0 * g0
    kbar[0, 1] = eal * g0 * g1
    kbar[0, 2] = eal * g0 * g2
    kbar[1, 0] = kbar[0, 1]
    kbar[2, 0] = kbar[0, 2]
    kbar[1, 1] = eal * g1 * g1 + kd
    kbar[2, 2] = eal * g2 * g2 + kd
    kbar[1, 2] = eal * g1 * g2 + ko
    kbar[2, 1] = kbar[1, 2]
    if shallow_arch and ei > 0.0:
        kbar[1, 1] += 4.0 * nl / 30.0
        kbar[2, 2] += 4.0 * nl / 30.0
        kbar[1, 2] -= nl / 30.0
        kbar[2, 1] -= nl / 30.0

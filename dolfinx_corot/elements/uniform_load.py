r"""Nodal loads equivalent to a uniform dead load on straight lines, triangles and quadrilaterals.

A load :math:`\mathbf q` per unit *reference* length (beams, bars: self-weight
:math:`\rho A \mathbf g`) or per unit reference area (shells, membranes:
:math:`\rho t \mathbf g`) is replaced by its work-equivalent nodal loads,
computed once from the reference geometry; they are dead (they keep their
value and direction as the structure deforms), so the total weight is exact
in every configuration.

* Lines of length :math:`l_0` along :math:`\mathbf d_0 = \mathbf X_2 - \mathbf X_1`:
  forces :math:`\mathbf q\,l_0/2` at each node (the work-equivalent of the linear
  axial and the cubic transverse interpolation alike), and for bending elements the
  moments

  .. math::

      \mathbf m_1 = -\mathbf m_2 = \frac{l_0}{12}\,\mathbf d_0\times\mathbf q ,

  the fixed-end moments :math:`\pm q_\perp l_0^2/12` of the transverse part of the
  load (Przemieniecki 1968, §5.6; also for the exact Timoshenko element, whose
  fixed-end moments under a uniform load are those of the Bernoulli beam). With
  them a geometrically linear beam's nodal displacements are exact (the cantilever's
  tip deflection :math:`q L^4/8EI` with any number of elements). The moments keep
  their reference value under large rotation, whereas the work-equivalent moments
  of a rotated element are :math:`(l_0/12)\,\mathbf d\times\mathbf q`: between
  collinear elements of equal length they cancel at the common node either way,
  and the difference at the ends of a member and at kinks, of order :math:`q l_0^2`,
  vanishes as :math:`O(h^2)` with refinement.
* Triangles: a third of :math:`\mathbf q A_0` at each node (exact for the linear
  membrane interpolation; the usual lumping for the DKT plate part).
* Quadrilaterals: :math:`\mathbf q\int N_a\,dA_0`, bilinear :math:`N_a`, 2×2 Gauss
  points (exact for flat quadrilaterals; the same rule gives the area of warped ones).
* Edges of shells and membranes (:func:`edge_loads`): a load :math:`\mathbf q` per unit
  reference length on the edge i → j (counter-clockwise about the cell's normal
  :math:`\mathbf n`, outward normal in the cell's plane :math:`\mathbf n_o = \mathbf t\times
  \mathbf n`): forces :math:`\mathbf q\,l_0/2` at each end, and the moments of the edge's
  displacement field. The OPT membrane's edge displacement along :math:`\mathbf n_o` has the
  quadratic part :math:`\alpha_b\,(l/8)(\theta_j - \theta_i)\,4s(1-s)` in the drilling
  rotations (Allman 1984, scaled by α_b = 3/2: Felippa 2003), so the in-plane normal part
  :math:`q_o = \mathbf q\cdot\mathbf n_o` does work on them:
  :math:`\mathbf m_j = -\mathbf m_i = \alpha_b\,q_o\,l_0^2/12\;\mathbf n`. Without them the
  nodal forces of a uniform edge traction are not a constant-stress load: at a free corner
  of OPT triangles the moments of the two edges do not cancel: in a free plate pulled by
  nodal forces the middle of the loaded edges moves 37 % (4 × 4 cells), 20 % (8 × 8), 10 %
  (16 × 16) too far. The other membranes (CST, the quadrilaterals') have linear edges and take the
  forces alone, and so does the plates' part of the load: the discrete Kirchhoff triangle and
  quadrilateral define no deflection inside an edge, and with nodal forces a cantilever
  strip's tip deflection under a uniform edge load is exact on quadrilaterals (tested; edge
  moments of a cubic deflection would spoil it); MITC4's deflection is bilinear. Like the
  beams' moments the drilling moments keep their reference values under large rotation.
"""
from __future__ import annotations

import numpy as np


def line_loads(X: np.ndarray, q: np.ndarray, bending: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodal forces and moments of a uniform load on straight two-node elements.

    X: (n, 2, g) reference node coordinates, g = 2 or 3; q: (g,) load per unit length, or (n, g)
    one per element;
    bending: (n,) True for beams (moments added), False for bars.
    Returns forces (n, 2, g) and moments (n, 2) in 2D (about z) or (n, 2, 3) in 3D.
    """
    d = X[:, 1] - X[:, 0]
    length = np.linalg.norm(d, axis=1)
    forces = np.repeat((0.5 * length[:, None] * q)[:, None, :], 2, axis=1)
    if X.shape[2] == 2:
        m = (d[:, 0] * q[..., 1] - d[:, 1] * q[..., 0]) * length / 12.0 * bending
        moments = np.stack([m, -m], axis=1)
    else:
        m = np.cross(d, q) * (length / 12.0 * bending)[:, None]
        moments = np.stack([m, -m], axis=1)
    return forces, moments


def triangle_loads(X: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Nodal forces (n, 3, 3) of a uniform load q (3,) (or (n, 3), one per triangle) per unit area on
    triangles X (n, 3, 3)."""
    area = 0.5 * np.linalg.norm(np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), axis=1)
    return np.repeat((area[:, None] * q / 3.0)[:, None, :], 3, axis=1)


#: 2×2 Gauss points on [0, 1] (weight 1/4 each)
_GAUSS = 0.5 + np.array([-0.5, 0.5]) / np.sqrt(3.0)


def quad_loads(X: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Nodal forces (n, 4, 3) of a uniform load q (3,) (or (n, 3)) per unit area on bilinear quadrilaterals
    X (n, 4, 3) whose nodes are in DOLFINx's order (0, 0), (1, 0), (0, 1), (1, 1) of the unit
    square: ∫ N_a dA by 2×2 Gauss points."""
    weights = np.zeros((len(X), 4))
    for xi in _GAUSS:
        for eta in _GAUSS:
            N = np.array([(1 - xi) * (1 - eta), xi * (1 - eta), (1 - xi) * eta, xi * eta])
            dxi = np.array([-(1 - eta), 1 - eta, -eta, eta])
            deta = np.array([-(1 - xi), -xi, 1 - xi, xi])
            jac = np.linalg.norm(np.cross(np.einsum("a,nai->ni", dxi, X), np.einsum("a,nai->ni", deta, X)), axis=1)
            weights += 0.25 * jac[:, None] * N
    return weights[:, :, None] * (q[:, None, :] if np.ndim(q) == 2 else q)


def edge_loads(X: np.ndarray, normal: np.ndarray, q: np.ndarray,
               drilling: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodal forces and moments of a uniform load per unit length on edges of shells and membranes
    (see the module's docstring).

    X: (n, 2, 3) reference coordinates of the edges' ends i, j, counter-clockwise about ``normal``
    (n, 3), the unit normal of each edge's cell; q: (3,) per unit length; drilling: (n,) α_b of
    the cell's membrane (OPT: 3/2; 0 for membranes with linear edges).
    Returns forces (n, 2, 3) and moments (n, 2, 3).
    """
    d = X[:, 1] - X[:, 0]
    length = np.linalg.norm(d, axis=1)
    forces = np.repeat((0.5 * length[:, None] * q)[:, None, :], 2, axis=1)
    outward = np.cross(d / length[:, None], normal)
    m = (drilling * (outward @ q) * length**2 / 12.0)[:, None] * normal  # at j; −m at i
    return forces, np.stack([-m, m], axis=1)

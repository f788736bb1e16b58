r"""Follower loads: nodal forces of pressures and distributed loads that turn with the structure,
and their load stiffness (the derivative of the nodal forces with respect to the nodal positions).

The loads act per unit *current* length or area (a pressure), in the current configuration:

* 2D beams and bars: a load :math:`\mathbf q = (q_a, q_n)` per unit current length in the
  element's current axes, :math:`\mathbf t = \mathbf d/l` along the chord
  :math:`\mathbf d = \mathbf x_2 - \mathbf x_1` and :math:`\mathbf n = \mathbf e_z\times\mathbf t`.
  Since :math:`l\,\mathbf t = \mathbf d` and :math:`l\,\mathbf n = \mathbf R\,\mathbf d` (R the rotation
  by +90°), the work-equivalent forces :math:`\tfrac12 l (q_a\mathbf t + q_n\mathbf n) =
  \tfrac12 (q_a\mathbf I + q_n\mathbf R)\,\mathbf d` at each node are *linear* in the positions,
  and beams add the fixed-end moments :math:`\pm q_n l^2/12` of the transverse part
  (Przemieniecki 1968, §5.6), whose derivative is :math:`\pm q_n\,\mathbf d^{\mathsf T}/6`.
* Triangles: a pressure p along the normal of the current triangle (right-hand rule over its
  nodes): :math:`\mathbf f_a = \tfrac{p}{6}\,\mathbf e_1\times\mathbf e_2` at each node,
  :math:`\mathbf e_1 = \mathbf x_2-\mathbf x_1`, :math:`\mathbf e_2 = \mathbf x_3-\mathbf x_1`, the
  exact work-equivalent of a uniform pressure for linear interpolation; its derivative follows
  from :math:`d(\mathbf e_1\times\mathbf e_2) = -[\mathbf e_2]_\times d\mathbf e_1 +
  [\mathbf e_1]_\times d\mathbf e_2`.
* Bilinear quadrilaterals: :math:`\mathbf f_a = p\int N_a\,\mathbf x_{,\xi}\times\mathbf x_{,\eta}
  \,d\xi\,d\eta` by 2×2 Gauss points, exact: on a bilinear patch :math:`\mathbf x_{,\xi}` is linear
  in η alone and :math:`\mathbf x_{,\eta}` in ξ alone, so the integrand is of degree ≤ 2 in each
  parameter.

The load stiffness of a pressure is not symmetric element by element; on a closed surface (a
ring, an inflated membrane) the assembled one is (the pressure is conservative there). The
unsymmetric tangent is assembled as it is (Schweizerhof & Ramm 1984).
"""
from __future__ import annotations

import numpy as np

#: rotation by +90° in the plane
R90 = np.array([[0.0, -1.0], [1.0, 0.0]])


def _skew(a: np.ndarray) -> np.ndarray:
    """(n, 3, 3) [a]× for a (n, 3): [a]× b = a × b."""
    out = np.zeros(a.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -a[..., 2], a[..., 1]
    out[..., 1, 0], out[..., 1, 2] = a[..., 2], -a[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -a[..., 1], a[..., 0]
    return out


def line2d(x: np.ndarray, q: np.ndarray, bending: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodal loads of (q_a, q_n) per current length on 2D lines.

    x: (n, 2, 2) current node positions; q: (n, 2) the load in the element's current axes
    (along the chord, normal to it: e_z × t); bending: (n,) True for beams (fixed-end moments).
    Returns f (n, 6) the loads on (ux, uy, rz) of both nodes and K (n, 6, 6) = ∂f/∂(x, θ)
    (no dependence on the rotations)."""
    n = len(x)
    d = x[:, 1] - x[:, 0]
    A = q[:, 0, None, None] * np.eye(2) + q[:, 1, None, None] * R90  # (n, 2, 2): ½A d per node
    force = 0.5 * np.einsum("nij,nj->ni", A, d)
    moment = q[:, 1] * np.einsum("ni,ni->n", d, d) / 12.0 * bending
    f = np.zeros((n, 6))
    f[:, 0:2], f[:, 3:5] = force, force
    f[:, 2], f[:, 5] = moment, -moment
    K = np.zeros((n, 6, 6))
    for a in (0, 3):  # ∂(½ A d)/∂x₁ = −½A, ∂/∂x₂ = +½A
        K[:, a:a + 2, 0:2] = -0.5 * A
        K[:, a:a + 2, 3:5] = 0.5 * A
    dm = (q[:, 1] * bending / 6.0)[:, None] * d  # ∂m/∂x₂ = q_n d/6 = −∂m/∂x₁
    K[:, 2, 0:2], K[:, 2, 3:5] = -dm, dm
    K[:, 5, 0:2], K[:, 5, 3:5] = dm, -dm
    return f, K


def triangle(x: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodal forces of a pressure p (n,) along the current normal of triangles x (n, 3, 3):
    f (n, 9) on the translations of the three nodes, K (n, 9, 9) = ∂f/∂x."""
    e1, e2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
    c = np.cross(e1, e2)
    f = np.tile((p[:, None] / 6.0) * c, (1, 3))
    S1, S2 = _skew(e1), _skew(e2)
    dc = [S2 - S1, -S2, S1]  # ∂c/∂x_b
    K = np.zeros((len(x), 9, 9))
    for a in range(3):
        for b in range(3):
            K[:, 3 * a:3 * a + 3, 3 * b:3 * b + 3] = (p / 6.0)[:, None, None] * dc[b]
    return f, K


#: 2×2 Gauss points on [0, 1] (weight 1/4 each)
_GAUSS = 0.5 + np.array([-0.5, 0.5]) / np.sqrt(3.0)


def quad(x: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodal forces of a pressure p (n,) along the current normal x_ξ × x_η of bilinear
    quadrilaterals x (n, 4, 3), nodes in DOLFINx's order (0, 0), (1, 0), (0, 1), (1, 1) of the
    unit square: f (n, 12), K (n, 12, 12) = ∂f/∂x, by 2×2 Gauss points."""
    n = len(x)
    f = np.zeros((n, 4, 3))
    K = np.zeros((n, 4, 3, 4, 3))
    for xi in _GAUSS:
        for eta in _GAUSS:
            N = np.array([(1 - xi) * (1 - eta), xi * (1 - eta), (1 - xi) * eta, xi * eta])
            dxi = np.array([-(1 - eta), 1 - eta, -eta, eta])
            deta = np.array([-(1 - xi), -xi, 1 - xi, xi])
            a1, a2 = np.einsum("a,nai->ni", dxi, x), np.einsum("a,nai->ni", deta, x)
            c = np.cross(a1, a2)
            w = 0.25 * p
            f += w[:, None, None] * N[None, :, None] * c[:, None, :]
            S1, S2 = _skew(a1), _skew(a2)
            # ∂c/∂x_b = −[a2]× dxi_b + [a1]× deta_b
            dc = -S2[:, None] * dxi[None, :, None, None] + S1[:, None] * deta[None, :, None, None]  # (n, b, 3, 3)
            K += w[:, None, None, None, None] * N[None, :, None, None, None] * dc.transpose(0, 2, 1, 3)[:, None]
    return f.reshape(n, 12), K.reshape(n, 12, 12)

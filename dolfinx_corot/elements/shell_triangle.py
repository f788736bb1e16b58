r"""Flat triangular shell in its element frame: membrane + drilling + DKT bending (linear).

Local dofs per node, node-major: (u, v, w, θx, θy, θz); the element lies in
the local x–y plane. Material: isotropic, plane stress, thickness t.

* Membrane (default): the optimal ANDES triangle with drilling freedoms, OPT
  (Felippa 2003, CMAME 192:2125): :math:`\mathbf K_m = \mathbf K_b + \mathbf K_h` on
  (u, v, θz) per node. The basic stiffness :math:`\mathbf K_b = V^{-1}\mathbf L\mathbf D\mathbf L^T`
  (V = At) lumps a constant stress field to the nodes, its drilling rows
  scaled by :math:`\alpha_b = 3/2`; the higher-order stiffness
  :math:`\mathbf K_h = \tfrac34\beta_0\mathbf T_{\theta u}^T\mathbf K_\theta\mathbf T_{\theta u}`
  acts on the hierarchical rotations :math:`\tilde\theta_i = \theta_{zi} - \theta_0`
  (θ0 the CST's rotation), whose natural strains at the corners are
  :math:`\mathbf Q_i\tilde{\boldsymbol\theta}` with the OPT signature
  β1..β9 = (1, 2, 1, 0, 1, −1, −1, −1, −2), :math:`\beta_0 = \max(\tfrac12(1-4\nu^2), 0.01)`;
  :math:`\mathbf K_\theta = V\sum_{m=4}^{6}\mathbf Q_m^T\mathbf T_e^T\mathbf D\mathbf T_e\mathbf Q_m`
  at the mid-sides. It reproduces the energy of in-plane pure bending of
  rectangular mesh units exactly, for any aspect ratio and ν (tested).
* Membrane ``"cst"``: constant-strain triangle, :math:`\mathbf K_m = tA\,\mathbf B_m^T\mathbf D_m\mathbf B_m`,
  with a drilling penalty :math:`U_d = \tfrac12\,\alpha G t A\sum_i(\theta_{zi} - \omega)^2`,
  :math:`\omega = \tfrac12(v_{,x} - u_{,y})` the CST's rotation (Hughes & Brezzi 1989
  style; rigid in-plane rotations cost nothing). It locks in in-plane bending.
* Bending: the discrete Kirchhoff triangle (Batoz, Bathe & Ho 1980), built as in
  its original derivation: the slopes :math:`\boldsymbol\beta = (w_{,x}, w_{,y})` vary
  quadratically; at the corners :math:`\beta_x = -\theta_y`, :math:`\beta_y = \theta_x`;
  at mid-sides the tangential slope follows the cubic edge deflection,
  :math:`\beta_s = \tfrac{3}{2l}(w_j - w_i) - \tfrac14(\beta_{si} + \beta_{sj})`, and the
  normal slope is linear, :math:`\beta_n = \tfrac12(\beta_{ni} + \beta_{nj})`. Curvatures
  :math:`\boldsymbol\kappa = (\beta_{x,x}, \beta_{y,y}, \beta_{x,y} + \beta_{y,x})`,
  :math:`\mathbf K_b = \int\mathbf B_b^T\mathbf D_b\mathbf B_b\,dA` by a 3-point rule (exact).

``props = (E, nu, t, alpha, bending, opt, A (3 × 3), B (3 × 3), D (3 × 3), shallow)``, the
matrices row-major: the section N = Aε + Bκ, M = Bε + Dκ (κ of the rotations of the normal, u(z) = zβ;
isotropic: A = tC, B = 0, D = t³C/12, see :func:`isotropic_props`; laminates:
:class:`dolfinx_corot.sections.Laminate`). The membranes take A (OPT: D = A/t in its formulas,
β₀ from ν = A12/A22), the DKT takes D; B couples the constant membrane strain of the CST with
the DKT's curvatures (for the OPT membrane, its constant-strain part: exact for symmetric
laminates, where B = 0). E and ν are a reference (contact stiffness scale, OPT's β₀).
``bending = 0`` gives a membrane: the constant-strain triangle alone, no drilling and no
bending stiffness; ``opt = 1`` selects the OPT membrane, 0 the CST with drilling penalty
α·A66·A (A66 = Gt).
"""
from __future__ import annotations

import numba
import numpy as np

from . import shallow_shell

E_, NU, T, ALPHA, BENDING, OPT = range(6)
A0, B0, D0 = 6, 15, 24
SHALLOW = 33  # 1: the shallow-shell term in the co-rotational local law (:mod:`.shallow_shell`)
NPROPS = 34


def isotropic_props(E: float, nu: float, t: float, alpha: float, bending: bool, opt: bool,
                    shallow: bool = False) -> np.ndarray:
    """props of a homogeneous isotropic shell or membrane (see the module's docstring)."""
    c = E / (1.0 - nu * nu)
    C = np.array([[c, c * nu, 0.0], [c * nu, c, 0.0], [0.0, 0.0, 0.5 * c * (1.0 - nu)]])
    props = np.zeros(NPROPS)
    props[:6] = E, nu, t, alpha, float(bending), float(opt)
    props[SHALLOW] = float(shallow)
    props[A0:A0 + 9] = (t * C).ravel()
    if bending:
        props[D0:D0 + 9] = (t ** 3 / 12.0 * C).ravel()
    return props

# OPT signature (Felippa 2003): α_b and β1..β9 (index 0 unused)
ALPHA_B = 1.5
_BETA = np.array([0.0, 1.0, 2.0, 1.0, 0.0, 1.0, -1.0, -1.0, -1.0, -2.0])
# entries of Q1, Q2, Q3 (row-major 3 × 3) as indices into β
_OPT_INDEX = np.array([[1, 2, 3, 4, 5, 6, 7, 8, 9], [9, 7, 8, 3, 1, 2, 6, 4, 5], [5, 6, 4, 8, 9, 7, 2, 3, 1]])

_GP = np.array([[1.0 / 6.0, 1.0 / 6.0], [2.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 2.0 / 3.0]])


@numba.njit(cache=True)
def plane_stress(E, nu):
    D = np.zeros((3, 3))
    c = E / (1.0 - nu * nu)
    D[0, 0] = c
    D[1, 1] = c
    D[0, 1] = c * nu
    D[1, 0] = c * nu
    D[2, 2] = c * (1.0 - nu) / 2.0
    return D


@numba.njit(cache=True)
def membrane_B(xy):
    """CST strain matrix (3, 6) for in-plane dofs (u1, v1, u2, v2, u3, v3) and twice the area."""
    x1, y1, x2, y2, x3, y3 = xy[0, 0], xy[0, 1], xy[1, 0], xy[1, 1], xy[2, 0], xy[2, 1]
    A2 = (x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1)
    b = np.array([y2 - y3, y3 - y1, y1 - y2]) / A2
    c = np.array([x3 - x2, x1 - x3, x2 - x1]) / A2
    B = np.zeros((3, 6))
    for i in range(3):
        B[0, 2 * i] = b[i]
        B[1, 2 * i + 1] = c[i]
        B[2, 2 * i] = c[i]
        B[2, 2 * i + 1] = b[i]
    return B, A2


@numba.njit(cache=True)
def opt_membrane(xy, D, nu, t):
    """OPT membrane stiffness (9, 9) on (u, v, θz) of nodes 1–3 (counter-clockwise, local x–y),
    plane-stress stiffness D (3, 3) (the section's A/t), ν for β₀, thickness t."""
    return opt_membrane_edges(xy, D, nu, t, np.zeros(3))


@numba.njit(cache=True)
def opt_membrane_edges(xy, D, nu, t, linear):
    """:func:`opt_membrane` with the edges (1–2, 2–3, 3–1) where ``linear`` is nonzero kept
    linear: the basic stiffness lumps no drilling moments there. The lumping matrix's drilling
    rows are a sum over the edges (Felippa 2003, eq. 26): edge i → j adds
    (α_b/6)(y_ji², x_ji², −2x_ji y_ji) to node j's row and subtracts it from node i's (before
    the factor t/2), the moments ∓α_b t l² σ_nn/12 of Allman's quadratic edge; a linear
    neighbour (a quadrilateral, a constant-strain triangle) has none, and with them the
    interface passes the constant-stress patch test."""
    x1, y1, x2, y2, x3, y3 = xy[0, 0], xy[0, 1], xy[1, 0], xy[1, 1], xy[2, 0], xy[2, 1]
    x12, x21, x13, x31, x23, x32 = x1 - x2, x2 - x1, x1 - x3, x3 - x1, x2 - x3, x3 - x2
    y12, y21, y13, y31, y23, y32 = y1 - y2, y2 - y1, y1 - y3, y3 - y1, y2 - y3, y3 - y2
    A = 0.5 * (x21 * y31 - x31 * y21)
    V = A * t
    a6, a3 = ALPHA_B / 6.0, ALPHA_B / 3.0
    L = np.zeros((9, 3))
    L[0, 0], L[0, 2] = y23, x32
    L[1, 1], L[1, 2] = x32, y23
    L[2, 0], L[2, 1], L[2, 2] = a6 * y23 * (y13 - y21), a6 * x32 * (x31 - x12), a3 * (x31 * y13 - x12 * y21)
    L[3, 0], L[3, 2] = y31, x13
    L[4, 1], L[4, 2] = x13, y31
    L[5, 0], L[5, 1], L[5, 2] = a6 * y31 * (y21 - y32), a6 * x13 * (x12 - x23), a3 * (x12 * y21 - x23 * y32)
    L[6, 0], L[6, 2] = y12, x21
    L[7, 1], L[7, 2] = x21, y12
    L[8, 0], L[8, 1], L[8, 2] = a6 * y12 * (y32 - y13), a6 * x21 * (x23 - x31), a3 * (x23 * y32 - x31 * y13)
    for k in range(3):  # edges 1→2, 2→3, 3→1
        if linear[k] != 0.0:
            i, j = k, (k + 1) % 3
            xji, yji = xy[j, 0] - xy[i, 0], xy[j, 1] - xy[i, 1]
            e0, e1, e2 = a6 * yji * yji, a6 * xji * xji, -2.0 * a6 * xji * yji
            L[3 * j + 2, 0] -= e0
            L[3 * j + 2, 1] -= e1
            L[3 * j + 2, 2] -= e2
            L[3 * i + 2, 0] += e0
            L[3 * i + 2, 1] += e1
            L[3 * i + 2, 2] += e2
    L *= 0.5 * t
    K = np.empty((9, 9))
    _congruence(L, D, 1.0 / V, K)
    # higher-order stiffness on the hierarchical rotations θ̃ = T_θu d
    l21, l32, l13 = x21 * x21 + y21 * y21, x32 * x32 + y32 * y32, x13 * x13 + y13 * y13
    Ttu = np.zeros((9, 3))  # transposed: columns are θ̃_1..3
    for r in range(3):
        Ttu[0, r], Ttu[1, r], Ttu[3, r], Ttu[4, r], Ttu[6, r], Ttu[7, r] = x32, y32, x13, y13, x21, y21
        Ttu[3 * r + 2, r] = 4.0 * A
    for i in range(9):
        for r in range(3):
            Ttu[i, r] /= 4.0 * A
    Te = np.empty((3, 3))
    Te[0, 0], Te[0, 1], Te[0, 2] = y23 * y13 * l21, y31 * y21 * l32, y12 * y32 * l13
    Te[1, 0], Te[1, 1], Te[1, 2] = x23 * x13 * l21, x31 * x21 * l32, x12 * x32 * l13
    Te[2, 0] = (y23 * x31 + x32 * y13) * l21
    Te[2, 1] = (y31 * x12 + x13 * y21) * l32
    Te[2, 2] = (y12 * x23 + x21 * y32) * l13
    for i in range(3):
        for j in range(3):
            Te[i, j] /= 4.0 * A * A
    # En = Teᵀ D Te (natural-strain elasticity)
    TeT = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            TeT[i, j] = Te[j, i]
    En = np.empty((3, 3))
    _congruence(TeT, D, 1.0, En)
    b = _BETA
    inv = (1.0 / l21, 1.0 / l32, 1.0 / l13)
    Q = np.empty((3, 3, 3))
    for c in range(3):
        for r in range(3):
            for k in range(3):
                Q[c, r, k] = 2.0 * A / 3.0 * b[_OPT_INDEX[c, 3 * r + k]] * inv[r]
    Kth = np.zeros((3, 3))
    QmT = np.empty((3, 3))
    Km = np.empty((3, 3))
    for c in range(3):
        c2 = (c + 1) % 3
        for i in range(3):
            for j in range(3):
                QmT[i, j] = 0.5 * (Q[c, j, i] + Q[c2, j, i])
        _congruence(QmT, En, V, Km)
        for i in range(3):
            for j in range(3):
                Kth[i, j] += Km[i, j]
    beta0 = max(0.5 * (1.0 - 4.0 * nu * nu), 0.01)
    Kh = np.empty((9, 9))
    _congruence(Ttu, Kth, 0.75 * beta0, Kh)
    for i in range(9):
        for j in range(9):
            K[i, j] += Kh[i, j]
    return K


@numba.njit(cache=True)
def _congruence(L, D, scale, out):
    """out = scale · L D Lᵀ for L (n, 3), D (3, 3) (explicit loops: tiny matrices)."""
    n = L.shape[0]
    LD = np.empty((n, 3))
    for i in range(n):
        for k in range(3):
            LD[i, k] = L[i, 0] * D[0, k] + L[i, 1] * D[1, k] + L[i, 2] * D[2, k]
    for i in range(n):
        for j in range(n):
            out[i, j] = scale * (LD[i, 0] * L[j, 0] + LD[i, 1] * L[j, 1] + LD[i, 2] * L[j, 2])


@numba.njit(cache=True)
def _dkt_midside(xy):
    """T (6, 9): slopes (βx, βy) at the three mid-sides (edges 23, 31, 12) from the corner
    dofs (w, θx, θy) of nodes 1–3."""
    T = np.zeros((6, 9))
    edges = ((1, 2), (2, 0), (0, 1))
    for k in range(3):
        i, j = edges[k]
        dx = xy[j, 0] - xy[i, 0]
        dy = xy[j, 1] - xy[i, 1]
        l = np.sqrt(dx * dx + dy * dy)
        c, s = dx / l, dy / l  # tangent s = (c, s), normal n = (s, −c)
        # corner slopes: βx = −θy (col 3a+2), βy = θx (col 3a+1)
        # β_s,a = c βx + s βy ; β_n,a = s βx − c βy
        row_s = np.zeros(9)
        row_n = np.zeros(9)
        row_s[3 * j] += 1.5 / l
        row_s[3 * i] -= 1.5 / l
        for a in (i, j):
            row_s[3 * a + 2] += -0.25 * c * -1.0
            row_s[3 * a + 1] += -0.25 * s
            row_n[3 * a + 2] += 0.5 * s * -1.0
            row_n[3 * a + 1] += 0.5 * -c
        # back to x, y: βx = c β_s + s β_n, βy = s β_s − c β_n
        T[2 * k] = c * row_s + s * row_n
        T[2 * k + 1] = s * row_s - c * row_n
    return T


@numba.njit(cache=True)
def _dkt_slope_nodes(xy):
    """S (12, 9): the slopes (βx, βy) at the corners 1–3, then at the mid-sides of edges 23, 31,
    12, from the corner dofs (w, θx, θy)."""
    S = np.zeros((12, 9))
    for a in range(3):
        S[2 * a, 3 * a + 2] = -1.0
        S[2 * a + 1, 3 * a + 1] = 1.0
    S[6:, :] = _dkt_midside(xy)
    return S


@numba.njit(cache=True)
def slopes(xy, xi, eta):
    """The DKT's slopes (βx, βy) = (w,x, w,y) at (ξ, η), (2, 9) on the dofs (w, θx, θy) of nodes 1–3."""
    L1 = 1.0 - xi - eta
    N = np.array([L1 * (2.0 * L1 - 1.0), xi * (2.0 * xi - 1.0), eta * (2.0 * eta - 1.0),
                  4.0 * xi * eta, 4.0 * eta * L1, 4.0 * L1 * xi])
    S = _dkt_slope_nodes(xy)
    return shallow_shell.interpolate_slopes(N, S)


# Strang & Fix's six-point rule, degree 4 (barycentric weights summing to 1)
_Q4 = np.array([[0.445948490915965, 0.445948490915965, 0.223381589678011],
                [0.108103018168070, 0.445948490915965, 0.223381589678011],
                [0.445948490915965, 0.108103018168070, 0.223381589678011],
                [0.091576213509771, 0.091576213509771, 0.109951743655322],
                [0.816847572980459, 0.091576213509771, 0.109951743655322],
                [0.091576213509771, 0.816847572980459, 0.109951743655322]])


@numba.njit(cache=True)
def shallow_data(xy, props, out):
    """out (:func:`.shallow_shell.size` (3)): the shallow-shell term of the co-rotational
    triangle (:mod:`.shallow_shell`): G of the DKT's slopes (exact: degree 4), C_N from the
    CST strain and the curvature at the centroid, A_m, the area (0: switched off, and for a
    membrane)."""
    G = np.zeros((3, 9, 9))
    CN = np.zeros((3, 18))
    Am = props[A0:A0 + 9].copy().reshape(3, 3)
    out[:] = 0.0
    if props[BENDING] == 0.0 or props[SHALLOW] == 0.0:
        return
    Bc = props[B0:B0 + 9].copy().reshape(3, 3)
    Bm, A2 = membrane_B(xy)
    for q in range(6):
        S = slopes(xy, _Q4[q, 0], _Q4[q, 1])
        shallow_shell.add_slope_products(S, _Q4[q, 2], G)
    AB = Am @ Bm
    for a in range(3):
        for k in range(3):
            CN[k, 6 * a] = AB[k, 2 * a]
            CN[k, 6 * a + 1] = AB[k, 2 * a + 1]
    BB = Bc @ bending_B(xy, 1.0 / 3.0, 1.0 / 3.0)  # κ = −(the DKT's curvature of the slopes)
    for a in range(3):
        for m in range(3):
            for k in range(3):
                CN[k, 6 * a + 2 + m] -= BB[k, 3 * a + m]
    shallow_shell.pack(G, CN, Am, 0.5 * A2, out)


@numba.njit(cache=True)
def bending_B(xy, xi, eta):
    """DKT curvature matrix (3, 9) at (ξ, η) for the dofs (w, θx, θy) of nodes 1–3."""
    L1 = 1.0 - xi - eta
    # derivatives of the 6 quadratic shape functions w.r.t. ξ and η
    dN = np.zeros((2, 6))
    dN[0, 0] = -(4.0 * L1 - 1.0)
    dN[1, 0] = -(4.0 * L1 - 1.0)
    dN[0, 1] = 4.0 * xi - 1.0
    dN[1, 2] = 4.0 * eta - 1.0
    dN[0, 3] = 4.0 * eta        # mid-side of edge 23: 4 L2 L3
    dN[1, 3] = 4.0 * xi
    dN[0, 4] = -4.0 * eta       # edge 31: 4 L3 L1
    dN[1, 4] = 4.0 * (L1 - eta)
    dN[0, 5] = 4.0 * (L1 - xi)  # edge 12: 4 L1 L2
    dN[1, 5] = -4.0 * xi
    J = np.empty((2, 2))
    J[0, 0] = xy[1, 0] - xy[0, 0]
    J[0, 1] = xy[1, 1] - xy[0, 1]
    J[1, 0] = xy[2, 0] - xy[0, 0]
    J[1, 1] = xy[2, 1] - xy[0, 1]
    det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
    dNx = np.empty((2, 6))  # ∂N/∂x, ∂N/∂y = J⁻¹ (∂N/∂ξ, ∂N/∂η)
    for n in range(6):
        dNx[0, n] = (J[1, 1] * dN[0, n] - J[0, 1] * dN[1, n]) / det
        dNx[1, n] = (-J[1, 0] * dN[0, n] + J[0, 0] * dN[1, n]) / det
    S = _dkt_slope_nodes(xy)
    B = np.zeros((3, 9))
    for n in range(6):
        for col in range(9):
            bx = S[2 * n, col]
            by = S[2 * n + 1, col]
            B[0, col] += dNx[0, n] * bx
            B[1, col] += dNx[1, n] * by
            B[2, col] += dNx[1, n] * bx + dNx[0, n] * by
    return B


@numba.njit(cache=True)
def _add_btdb(B, D, w, dofs, K):
    """K[dofs, dofs] += w Bᵀ D B for a strain matrix B (3, n) (explicit loops: tiny blocks)."""
    n = B.shape[1]
    DB = np.empty((3, n))
    for i in range(3):
        for j in range(n):
            DB[i, j] = D[i, 0] * B[0, j] + D[i, 1] * B[1, j] + D[i, 2] * B[2, j]
    for a in range(n):
        for b in range(n):
            K[dofs[a], dofs[b]] += w * (B[0, a] * DB[0, b] + B[1, a] * DB[1, b] + B[2, a] * DB[2, b])


@numba.njit(cache=True)
def local_stiffness(xy, props, K):
    """Fill K (18, 18), the linear stiffness of the flat triangle with local node coordinates xy (3, 2)."""
    local_stiffness_edges(xy, props, K, np.zeros(3))


@numba.njit(cache=True)
def local_stiffness_edges(xy, props, K, linear):
    """:func:`local_stiffness` with the OPT's edges where ``linear`` (3,) is nonzero kept linear
    (:func:`opt_membrane_edges`)."""
    t, alpha = props[T], props[ALPHA]
    Am = props[A0:A0 + 9].copy().reshape(3, 3)
    Bc = props[B0:B0 + 9].copy().reshape(3, 3)
    Db = props[D0:D0 + 9].copy().reshape(3, 3)
    K[:, :] = 0.0
    Bm, A2 = membrane_B(xy)
    A = 0.5 * A2
    mem = np.array([0, 1, 6, 7, 12, 13])
    if props[BENDING] != 0.0 and props[OPT] != 0.0:
        Km = opt_membrane_edges(xy, Am / t, Am[0, 1] / Am[1, 1], t, linear)
        mdofs = np.array([0, 1, 5, 6, 7, 11, 12, 13, 17])
        for a in range(9):
            for b in range(9):
                K[mdofs[a], mdofs[b]] += Km[a, b]
    else:
        _add_btdb(Bm, Am, A, mem, K)
    if props[BENDING] == 0.0:
        return
    if props[OPT] == 0.0:
        # drilling: (θz_i − ω), ω = ½(v,x − u,y) from the CST
        kd = alpha * Am[2, 2] * A
        om = np.zeros(18)
        for a in range(3):
            om[6 * a] = -0.5 * Bm[1, 2 * a + 1]   # −½ ∂N/∂y on u
            om[6 * a + 1] = 0.5 * Bm[0, 2 * a]    # ½ ∂N/∂x on v
        for i in range(3):
            g = -om.copy()
            g[6 * i + 5] += 1.0
            for a in range(18):
                for b in range(18):
                    K[a, b] += kd * g[a] * g[b]
    # bending (the DKT's curvature of the slopes is −κ)
    bend = np.array([2, 3, 4, 8, 9, 10, 14, 15, 16])
    coupled = np.abs(Bc).max() > 0.0
    for q in range(3):
        Bb = bending_B(xy, _GP[q, 0], _GP[q, 1])
        _add_btdb(Bb, Db, A / 3.0, bend, K)
        if coupled:  # εᵀ B κ + κᵀ B ε with κ = −Bb w
            BB = Bc @ Bb
            for a in range(6):
                for b in range(9):
                    v = -(A / 3.0) * (Bm[0, a] * BB[0, b] + Bm[1, a] * BB[1, b] + Bm[2, a] * BB[2, b])
                    K[mem[a], bend[b]] += v
                    K[bend[b], mem[a]] += v

r"""Four-node flat shell in its element frame (linear): membrane with incompatible modes and
drilling rotations, MITC4 bending and transverse shear.

Local dofs per node, node-major: (u, v, w, θx, θy, θz); nodes counter-clockwise in the local
x–y plane (the projection of a warped element onto its mean plane), bilinear shape functions
:math:`N_a = \tfrac14(1+\xi_a\xi)(1+\eta_a\eta)`, 2 × 2 Gauss points.

* **Section.** Resultants per unit length from the mid-surface strains ε = (u,x, v,y, u,y + v,x),
  curvatures κ and transverse shear strains γ:
  :math:`\mathbf N = \mathbf A\boldsymbol\varepsilon + \mathbf B\boldsymbol\kappa`,
  :math:`\mathbf M = \mathbf B\boldsymbol\varepsilon + \mathbf D\boldsymbol\kappa`,
  :math:`\mathbf Q = \mathbf S\boldsymbol\gamma` (an isotropic plate:
  A = tC, B = 0, D = t³C/12, S = κGt I with C the plane-stress matrix and κ = 5/6), so that
  the element stiffness is :math:`\int[\boldsymbol\varepsilon;\boldsymbol\kappa]^T
  [\mathbf A\ \mathbf B; \mathbf B\ \mathbf D][\boldsymbol\varepsilon;\boldsymbol\kappa]
  + \boldsymbol\gamma^T\mathbf S\boldsymbol\gamma\,dA`.
* **Membrane**: the bilinear field plus Wilson's incompatible modes
  :math:`\alpha_1(1-\xi^2) + \alpha_2(1-\eta^2)` in u and v, their derivatives taken with the
  Jacobian at the centre and scaled by det J₀/det J (Taylor, Beresford & Wilson 1976: QM6, which
  passes the patch test on any convex quadrilateral), condensed statically; it bends in its plane
  without locking (exact in pure bending of a rectangle, tested).
* **Drilling** rotations θz by a penalty on their difference from the in-plane rotation of the
  membrane field (Hughes & Brezzi 1989), :math:`\tfrac12\alpha A_{66}\int(\theta_z-\omega)^2dA`,
  :math:`\omega = \tfrac12(v_{,x}-u_{,y})` including the incompatible modes, θz bilinear; a rigid
  in-plane rotation costs nothing.
* **Bending**: Reissner–Mindlin rotations of the normal :math:`\beta_x = \theta_y`,
  :math:`\beta_y = -\theta_x` (so that u(z) = zβ), κ = (βx,x, βy,y, βx,y + βy,x).
* **Transverse shear**: MITC4 (Dvorkin & Bathe 1984; Bathe & Dvorkin 1985): the covariant shear
  strains :math:`\gamma_{\xi} = w_{,\xi} + \boldsymbol\beta\cdot\mathbf x_{,\xi}` tied at the
  mid-sides η = ∓1 and interpolated linearly in η (γ_η likewise at ξ = ∓1), then
  :math:`(\gamma_{xz}, \gamma_{yz}) = \mathbf J^{-1}(\gamma_\xi, \gamma_\eta)`. Free of shear
  locking; passes the constant-curvature and constant-shear patch tests.
* **Warping.** The corners sit at heights z_a off the mean plane; they are tied to the flat
  element's corners by rigid links (Taylor 1987): :math:`u_p = u - z\theta_y`,
  :math:`v_p = v + z\theta_x`, i.e. :math:`\bar{\mathbf K} = \mathbf W^T\mathbf K_{flat}\mathbf W`.

``props`` (:data:`NPROPS`): E, ν, t (a reference material and the thickness, for contact
offsets and face stresses), α (drilling factor), A (3 × 3), B (3 × 3), D (3 × 3), S (2 × 2) row-major,
the bending kinematics (:data:`KIRCHHOFF`) and the shallow-shell switch (:data:`SHALLOW`).
"""
from __future__ import annotations

import numba
import numpy as np

from . import shallow_shell

E_, NU, T, ALPHA = range(4)
A0, B0, D0, S0 = 4, 13, 22, 31
KIRCHHOFF = 35  # 1: discrete Kirchhoff bending (DKQ), 0: MITC4 (Reissner–Mindlin)
SHALLOW = 36  # 1: the shallow-shell term in the co-rotational local law (:mod:`.shallow_shell`)
NPROPS = 37
KAPPA = 5.0 / 6.0  # shear correction factor of a homogeneous plate

_G = 1.0 / np.sqrt(3.0)
_GAUSS = np.array([[-_G, -_G], [_G, -_G], [_G, _G], [-_G, _G]])
_NODES = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])


def isotropic_props(E: float, nu: float, t: float, alpha: float, kirchhoff: bool = True,
                    shallow: bool = False) -> np.ndarray:
    """props of a homogeneous isotropic shell (see the module's docstring); bending by the DKQ
    (``kirchhoff``) or MITC4; ``shallow``: the shallow-shell term (:mod:`.shallow_shell`)."""
    c = E / (1.0 - nu * nu)
    C = np.array([[c, c * nu, 0.0], [c * nu, c, 0.0], [0.0, 0.0, 0.5 * c * (1.0 - nu)]])
    G = E / (2.0 * (1.0 + nu))
    props = np.zeros(NPROPS)
    props[:4] = E, nu, t, alpha
    props[A0:A0 + 9] = (t * C).ravel()
    props[D0:D0 + 9] = (t ** 3 / 12.0 * C).ravel()
    props[S0:S0 + 4] = (KAPPA * G * t * np.eye(2)).ravel()
    props[KIRCHHOFF] = 1.0 if kirchhoff else 0.0
    props[SHALLOW] = 1.0 if shallow else 0.0
    return props


@numba.njit(cache=True)
def _serendipity(xi, eta):
    """d (2, 8): derivatives (∂/∂ξ, ∂/∂η) of the 8-node serendipity functions: corners 0–3
    counter-clockwise, then the mid-sides of edges 01, 12, 23, 30."""
    d = np.empty((2, 8))
    for a in range(4):
        xa, ya = _NODES[a, 0], _NODES[a, 1]
        d[0, a] = 0.25 * xa * (1.0 + eta * ya) * (2.0 * xi * xa + eta * ya)
        d[1, a] = 0.25 * ya * (1.0 + xi * xa) * (xi * xa + 2.0 * eta * ya)
    for k in range(4):
        xm = 0.5 * (_NODES[k, 0] + _NODES[(k + 1) % 4, 0])
        ym = 0.5 * (_NODES[k, 1] + _NODES[(k + 1) % 4, 1])
        if xm == 0.0:  # edge at η = ym: ½(1 − ξ²)(1 + η ym)
            d[0, 4 + k] = -xi * (1.0 + eta * ym)
            d[1, 4 + k] = 0.5 * (1.0 - xi * xi) * ym
        else:          # edge at ξ = xm: ½(1 + ξ xm)(1 − η²)
            d[0, 4 + k] = 0.5 * xm * (1.0 - eta * eta)
            d[1, 4 + k] = -(1.0 + xi * xm) * eta
    return d


@numba.njit(cache=True)
def dkq_B(xy, xi, eta):
    """Bκ (3, 12): the curvatures κ = (βx,x, βy,y, βx,y + βy,x) of the discrete Kirchhoff
    quadrilateral (Batoz & Ben Tahar 1982) at (ξ, η) on the plate dofs (w, θx, θy) per node.

    The rotations of the normal β (u = zβ: βx = θy, βy = −θx at the corners) vary as the 8-node
    serendipity field; at the mid-sides the Kirchhoff constraints fix them: the tangential
    component follows the cubic deflection of the edge, β_s = −(3/2l)(w_j − w_i) − ¼(β_si + β_sj),
    the normal one is linear, β_n = ½(β_ni + β_nj)."""
    S = _dkq_slope_nodes(xy)
    d = _serendipity(xi, eta)
    _, _, J, det = shape(xy, xi, eta)
    B = np.zeros((3, 12))
    for n in range(8):
        nx = (J[1, 1] * d[0, n] - J[0, 1] * d[1, n]) / det
        ny = (-J[1, 0] * d[0, n] + J[0, 0] * d[1, n]) / det
        for col in range(12):
            bx = S[2 * n, col]
            by = S[2 * n + 1, col]
            B[0, col] += nx * bx
            B[1, col] += ny * by
            B[2, col] += ny * bx + nx * by
    return B


@numba.njit(cache=True)
def _dkq_slope_nodes(xy):
    """S (16, 12): the DKQ's rotations of the normal (βx, βy) at the corners, then at the
    mid-sides of edges 01, 12, 23, 30, from the corner dofs (w, θx, θy) (see :func:`dkq_B`)."""
    S = np.zeros((16, 12))
    for a in range(4):
        S[2 * a, 3 * a + 2] = 1.0
        S[2 * a + 1, 3 * a + 1] = -1.0
    for k in range(4):
        i, j = k, (k + 1) % 4
        dx = xy[j, 0] - xy[i, 0]
        dy = xy[j, 1] - xy[i, 1]
        l = np.sqrt(dx * dx + dy * dy)
        c, s = dx / l, dy / l  # tangent (c, s), normal (s, −c)
        rs = np.zeros(12)
        rn = np.zeros(12)
        rs[3 * j] -= 1.5 / l
        rs[3 * i] += 1.5 / l
        for a in (i, j):  # β_s,a = c βx + s βy = c θy − s θx; β_n,a = s βx − c βy = s θy + c θx
            rs[3 * a + 2] -= 0.25 * c
            rs[3 * a + 1] += 0.25 * s
            rn[3 * a + 2] += 0.5 * s
            rn[3 * a + 1] += 0.5 * c
        for col in range(12):
            S[8 + 2 * k, col] = c * rs[col] + s * rn[col]
            S[8 + 2 * k + 1, col] = s * rs[col] - c * rn[col]
    return S


@numba.njit(cache=True)
def _serendipity_values(xi, eta):
    """The 8-node serendipity functions at (ξ, η), ordered as in :func:`_serendipity`."""
    N = np.empty(8)
    for a in range(4):
        xa, ya = _NODES[a, 0], _NODES[a, 1]
        N[a] = 0.25 * (1.0 + xi * xa) * (1.0 + eta * ya) * (xi * xa + eta * ya - 1.0)
    for k in range(4):
        xm = 0.5 * (_NODES[k, 0] + _NODES[(k + 1) % 4, 0])
        ym = 0.5 * (_NODES[k, 1] + _NODES[(k + 1) % 4, 1])
        if xm == 0.0:
            N[4 + k] = 0.5 * (1.0 - xi * xi) * (1.0 + eta * ym)
        else:
            N[4 + k] = 0.5 * (1.0 + xi * xm) * (1.0 - eta * eta)
    return N


@numba.njit(cache=True)
def slopes(xy, xi, eta):
    """The DKQ's rotations of the normal (βx, βy) = −(w,x, w,y) at (ξ, η), (2, 12) on the plate
    dofs (w, θx, θy) per node. The MITC4 uses the same field for its shallow-shell term: its own
    bilinear rotations carry no edge deflection."""
    N = _serendipity_values(xi, eta)
    S = _dkq_slope_nodes(xy)
    return shallow_shell.interpolate_slopes(N, S)


_G3 = np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
_W3 = np.array([5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])


@numba.njit(cache=True)
def shallow_data(xbar0, props, out):
    """out (:func:`.shallow_shell.size` (4)): the shallow-shell term of the co-rotational
    quadrilateral (:mod:`.shallow_shell`) on the projected corners: G of the DKQ's slopes (3 × 3
    Gauss points, exact), C_N the mean of A ε + B κ of the bilinear membrane field and the
    bending field over the cell (the incompatible modes have no mean strain), through the rigid
    links of a warped cell; A_m; the area (0: switched off)."""
    if props[SHALLOW] == 0.0:
        out[:] = 0.0
        return
    xy = np.ascontiguousarray(xbar0[:, :2])
    A = props[A0:A0 + 9].copy().reshape(3, 3)
    Bc = props[B0:B0 + 9].copy().reshape(3, 3)
    kirchhoff = props[KIRCHHOFF] != 0.0
    _, _, J0, det0 = shape(xy, 0.0, 0.0)
    G = np.zeros((3, 12, 12))
    area = 0.0
    for i in range(3):
        for j in range(3):
            _, _, _, det = shape(xy, _G3[i], _G3[j])
            w = _W3[i] * _W3[j] * det
            area += w
            shallow_shell.add_slope_products(slopes(xy, _G3[i], _G3[j]), w, G)
    G /= area
    Cf = np.zeros((3, 24))
    for q in range(4):
        Be, Bk, _, _, det = _strains(xy, _GAUSS[q, 0], _GAUSS[q, 1], J0, det0, kirchhoff)
        Nq = A @ np.ascontiguousarray(Be[:, :24]) + Bc @ np.ascontiguousarray(Bk[:, :24])
        Cf += det * Nq
    Cf /= area
    CN = np.zeros((3, 24))  # C_f W: u_p = u − z θy, v_p = v + z θx
    for k in range(3):
        for j in range(24):
            CN[k, j] = Cf[k, j]
        for a in range(4):
            z = xbar0[a, 2]
            CN[k, 6 * a + 4] -= z * Cf[k, 6 * a]
            CN[k, 6 * a + 3] += z * Cf[k, 6 * a + 1]
    shallow_shell.pack(G, CN, A, area, out)


@numba.njit(cache=True)
def shape(xy, xi, eta):
    """(N (4,), dN/dx (2, 4), J (2, 2), det J) of the bilinear map at (ξ, η); xy (4, 2)."""
    N = np.empty(4)
    dN = np.empty((2, 4))
    for a in range(4):
        N[a] = 0.25 * (1.0 + _NODES[a, 0] * xi) * (1.0 + _NODES[a, 1] * eta)
        dN[0, a] = 0.25 * _NODES[a, 0] * (1.0 + _NODES[a, 1] * eta)
        dN[1, a] = 0.25 * _NODES[a, 1] * (1.0 + _NODES[a, 0] * xi)
    J = np.zeros((2, 2))
    for a in range(4):
        for i in range(2):
            J[i, 0] += dN[i, a] * xy[a, 0]
            J[i, 1] += dN[i, a] * xy[a, 1]
    det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
    dx = np.empty((2, 4))
    for a in range(4):
        dx[0, a] = (J[1, 1] * dN[0, a] - J[0, 1] * dN[1, a]) / det
        dx[1, a] = (-J[1, 0] * dN[0, a] + J[0, 0] * dN[1, a]) / det
    return N, dx, J, det


@numba.njit(cache=True)
def _shear_tied(xy, xi, eta):
    """Bs (2, 12): MITC4 Cartesian transverse shear strains (γxz, γyz) at (ξ, η) on the plate
    dofs (w, θx, θy) per node."""
    cov = np.zeros((2, 12))
    for k in range(4):  # tying points: γ_ξ at (0, −1), (0, 1); γ_η at (−1, 0), (1, 0)
        if k < 2:
            txi, teta, comp = 0.0, -1.0 if k == 0 else 1.0, 0
            weight = 0.5 * (1.0 + teta * eta)
        else:
            txi, teta, comp = -1.0 if k == 2 else 1.0, 0.0, 1
            weight = 0.5 * (1.0 + txi * xi)
        N = np.empty(4)
        dN = np.empty((2, 4))
        for a in range(4):
            N[a] = 0.25 * (1.0 + _NODES[a, 0] * txi) * (1.0 + _NODES[a, 1] * teta)
            dN[0, a] = 0.25 * _NODES[a, 0] * (1.0 + _NODES[a, 1] * teta)
            dN[1, a] = 0.25 * _NODES[a, 1] * (1.0 + _NODES[a, 0] * txi)
        xc = 0.0
        yc = 0.0
        for a in range(4):
            xc += dN[comp, a] * xy[a, 0]
            yc += dN[comp, a] * xy[a, 1]
        # γ_c = w,c + βx x,c + βy y,c with βx = θy, βy = −θx
        for a in range(4):
            cov[comp, 3 * a] += weight * dN[comp, a]
            cov[comp, 3 * a + 1] -= weight * N[a] * yc
            cov[comp, 3 * a + 2] += weight * N[a] * xc
    _, _, J, det = shape(xy, xi, eta)
    Bs = np.empty((2, 12))
    for j in range(12):
        Bs[0, j] = (J[1, 1] * cov[0, j] - J[0, 1] * cov[1, j]) / det
        Bs[1, j] = (-J[1, 0] * cov[0, j] + J[0, 0] * cov[1, j]) / det
    return Bs


# local dof numbers: membrane (u, v) of node a at 6a, 6a + 1; w, θx, θy at 6a + 2..4; θz at 6a + 5
@numba.njit(cache=True)
def _strains(xy, xi, eta, J0, det0, kirchhoff):
    """(Bε (3, 28), Bκ (3, 28), Bω (28,), N, det J) at (ξ, η) on the 24 dofs and the 4
    incompatible modes (u: α1, α2; v: α3, α4) at 24..27; κ of the DKQ (``kirchhoff``) or of the
    bilinear rotations (MITC4)."""
    N, dx, J, det = shape(xy, xi, eta)
    Be = np.zeros((3, 28))
    Bk = np.zeros((3, 28))
    Bw = np.zeros(28)
    for a in range(4):
        nx, ny = dx[0, a], dx[1, a]
        Be[0, 6 * a] = nx
        Be[1, 6 * a + 1] = ny
        Be[2, 6 * a] = ny
        Be[2, 6 * a + 1] = nx
        Bw[6 * a] = -0.5 * ny
        Bw[6 * a + 1] = 0.5 * nx
        if not kirchhoff:  # κ = (βx,x, βy,y, βx,y + βy,x), βx = θy, βy = −θx
            Bk[0, 6 * a + 4] = nx
            Bk[1, 6 * a + 3] = -ny
            Bk[2, 6 * a + 4] = ny
            Bk[2, 6 * a + 3] = -nx
    if kirchhoff:
        Bp = dkq_B(xy, xi, eta)
        for a in range(4):
            for m in range(3):
                for r in range(3):
                    Bk[r, 6 * a + 2 + m] = Bp[r, 3 * a + m]
    # incompatible modes P1 = 1 − ξ², P2 = 1 − η² with J₀ and det J₀/det J
    s = det0 / det
    dP = np.array([[-2.0 * xi, 0.0], [0.0, -2.0 * eta]])  # dP[m] = (∂P_m/∂ξ, ∂P_m/∂η)
    for m in range(2):
        px = s * (J0[1, 1] * dP[m, 0] - J0[0, 1] * dP[m, 1]) / det0
        py = s * (-J0[1, 0] * dP[m, 0] + J0[0, 0] * dP[m, 1]) / det0
        Be[0, 24 + m] = px
        Be[2, 24 + m] = py
        Be[1, 26 + m] = py
        Be[2, 26 + m] = px
        Bw[24 + m] = -0.5 * py
        Bw[26 + m] = 0.5 * px
    return Be, Bk, Bw, N, det


@numba.njit(cache=True)
def flat_stiffness(xy, props, K):
    """K (24, 24) of the flat element with local node coordinates xy (4, 2), counter-clockwise."""
    A = props[A0:A0 + 9].copy().reshape(3, 3)
    Bc = props[B0:B0 + 9].copy().reshape(3, 3)
    D = props[D0:D0 + 9].copy().reshape(3, 3)
    S = props[S0:S0 + 4].copy().reshape(2, 2)
    kd = props[ALPHA] * A[2, 2]
    kirchhoff = props[KIRCHHOFF] != 0.0
    _, _, J0, det0 = shape(xy, 0.0, 0.0)
    Kf = np.zeros((28, 28))
    plate = np.array([2, 3, 4, 8, 9, 10, 14, 15, 16, 20, 21, 22])
    for q in range(4):
        Be, Bk, Bw, N, det = _strains(xy, _GAUSS[q, 0], _GAUSS[q, 1], J0, det0, kirchhoff)
        g = -Bw
        for a in range(4):
            g[6 * a + 5] += N[a]
        # [ε; κ]ᵀ [A B; B D] [ε; κ]
        Ne = A @ Be + Bc @ Bk
        Mk = Bc @ Be + D @ Bk
        Bs = _shear_tied(xy, _GAUSS[q, 0], _GAUSS[q, 1])
        Qs = S @ Bs
        for i in range(28):
            for j in range(28):
                acc = 0.0
                for r in range(3):
                    acc += Be[r, i] * Ne[r, j] + Bk[r, i] * Mk[r, j]
                Kf[i, j] += det * (acc + kd * g[i] * g[j])
        if kirchhoff:
            continue
        for i in range(12):
            for j in range(12):
                Kf[plate[i], plate[j]] += det * (Bs[0, i] * Qs[0, j] + Bs[1, i] * Qs[1, j])
    # static condensation of the incompatible modes
    Kii = Kf[24:, 24:].copy()
    Kic = Kf[24:, :24].copy()
    X = np.linalg.solve(Kii, Kic)
    for i in range(24):
        for j in range(24):
            acc = Kf[i, j]
            for m in range(4):
                acc -= Kf[i, 24 + m] * X[m, j]
            K[i, j] = acc


@numba.njit(cache=True)
def local_stiffness(xbar0, props, K):
    """K̄ (24, 24) of the element with initial local coordinates xbar0 (4, 3) (counter-clockwise,
    about the centroid, z the warping): the flat element on the projection, tied to the corners
    by rigid links, :math:`\\bar{\\mathbf K} = \\mathbf W^T\\mathbf K_{flat}\\mathbf W`."""
    xy = np.ascontiguousarray(xbar0[:, :2])
    Kf = np.empty((24, 24))
    flat_stiffness(xy, props, Kf)
    W = np.eye(24)
    for a in range(4):
        z = xbar0[a, 2]
        W[6 * a, 6 * a + 4] = -z      # u_p = u − z θy
        W[6 * a + 1, 6 * a + 3] = z   # v_p = v + z θx
    K[:, :] = W.T @ Kf @ W


@numba.njit(cache=True)
def _moments(xy, props, d, xi, eta, J0, det0, kirchhoff):
    """(N (3,), M (3,)) at (ξ, η) from the flat element's dofs d (24,)."""
    A = props[A0:A0 + 9].copy().reshape(3, 3)
    Bc = props[B0:B0 + 9].copy().reshape(3, 3)
    D = props[D0:D0 + 9].copy().reshape(3, 3)
    Be, Bk, _, _, _ = _strains(xy, xi, eta, J0, det0, kirchhoff)
    eps = np.ascontiguousarray(Be[:, :24]) @ d
    kap = np.ascontiguousarray(Bk[:, :24]) @ d
    return A @ eps + Bc @ kap, Bc @ eps + D @ kap


@numba.njit(cache=True)
def centre_resultants(xbar0, props, dbar, out):
    """out[:8] = (Nxx, Nyy, Nxy, Mxx, Myy, Mxy, Qx, Qy) at the centre from the local deformational
    dofs dbar (24,) (the incompatible modes vanish in ε at the centre; the membrane forces are
    those of the bilinear field). M = ∫σ z dz; Q = S γ of the MITC4 shear, or for the DKQ from
    the moments' equilibrium, Qx = Mxx,x + Mxy,y, Qy = Mxy,x + Myy,y (central differences in
    ξ, η over half the cell)."""
    xy = np.ascontiguousarray(xbar0[:, :2])
    d = dbar.copy()
    for a in range(4):
        z = xbar0[a, 2]
        d[6 * a] -= z * dbar[6 * a + 4]
        d[6 * a + 1] += z * dbar[6 * a + 3]
    kirchhoff = props[KIRCHHOFF] != 0.0
    _, _, J0, det0 = shape(xy, 0.0, 0.0)
    N, M = _moments(xy, props, d, 0.0, 0.0, J0, det0, kirchhoff)
    out[0:3] = N
    out[3:6] = M
    if kirchhoff:
        h = 0.5
        dxi = (_moments(xy, props, d, h, 0.0, J0, det0, kirchhoff)[1]
               - _moments(xy, props, d, -h, 0.0, J0, det0, kirchhoff)[1]) / (2.0 * h)
        deta = (_moments(xy, props, d, 0.0, h, J0, det0, kirchhoff)[1]
                - _moments(xy, props, d, 0.0, -h, J0, det0, kirchhoff)[1]) / (2.0 * h)
        # (∂/∂x, ∂/∂y) = J⁻¹ (∂/∂ξ, ∂/∂η)
        dx = (J0[1, 1] * dxi - J0[0, 1] * deta) / det0
        dy = (-J0[1, 0] * dxi + J0[0, 0] * deta) / det0
        out[6] = dx[0] + dy[2]
        out[7] = dx[2] + dy[1]
        return
    S = props[S0:S0 + 4].copy().reshape(2, 2)
    Bs = _shear_tied(xy, 0.0, 0.0)
    pd = np.empty(12)
    for a in range(4):
        pd[3 * a:3 * a + 3] = d[6 * a + 2:6 * a + 5]
    out[6:8] = S @ (Bs @ pd)

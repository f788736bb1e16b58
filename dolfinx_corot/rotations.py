r"""Rotation algebra for SO(2) and SO(3).

Finite rotations are stored as rotation tensors (or unit quaternions) and are
updated *multiplicatively*, never by adding rotation vectors (seed §2.1;
Argyris 1982; Simo & Vu-Quoc 1986; Crisfield 1997, ch. 16–17):

.. math::

    \mathbf R^{n+1} = \exp(\mathrm{spin}(\Delta\boldsymbol\theta))\,\mathbf R^n ,

with the exponential map given by the Rodrigues formula

.. math::

    \exp(\boldsymbol\Theta) = \mathbf I + \frac{\sin\theta}{\theta}\boldsymbol\Theta
        + \frac{1-\cos\theta}{\theta^2}\boldsymbol\Theta^2,
    \qquad \boldsymbol\Theta = \mathrm{spin}(\boldsymbol\theta),\ \theta = \|\boldsymbol\theta\| .

Every coefficient that is 0/0 at :math:`\theta = 0` is evaluated by its Taylor
series below :math:`\theta = 10^{-3}` (next omitted term below 1e-19), so the
maps are accurate to rounding for every angle, including 1e-12.

The logarithm goes through the quaternion of ``R`` (Spurrier's branch-free
choice of the largest diagonal term), which stays accurate near
:math:`\theta = \pi`, where the usual formula ``arccos((tr R − 1)/2)`` loses
half of its digits.

Tangent operator (spatial form): for :math:`\mathbf R = \exp(\boldsymbol\theta)`,
:math:`\delta\mathbf R\,\mathbf R^T = \mathrm{spin}(\mathbf T(\boldsymbol\theta)\,\delta\boldsymbol\theta)` with

.. math::

    \mathbf T(\boldsymbol\theta) = \mathbf I + \frac{1-\cos\theta}{\theta^2}\boldsymbol\Theta
        + \frac{\theta-\sin\theta}{\theta^3}\boldsymbol\Theta^2 ,\qquad
    \mathbf T^{-1}(\boldsymbol\theta) = \mathbf I - \tfrac12\boldsymbol\Theta
        + \frac{1}{\theta^2}\Bigl(1-\frac{\theta}{2}\cot\frac{\theta}{2}\Bigr)\boldsymbol\Theta^2

(Ibrahimbegović, Frey & Kožar 1995; Crisfield 1997, eq. 16.119). The material
form is :math:`\mathbf T^T`.

SO(2) is commutative: :math:`\exp(\Delta\theta)\exp(\theta) = \exp(\theta+\Delta\theta)`,
so the multiplicative update of a planar rotation is the addition of angles,
and the stored angle may grow past :math:`2\pi` without loss (a beam rolled
into two turns stores :math:`4\pi` at its tip).

All functions are numba-compiled (``cache=True``) so that element kernels can
call them; they take plain numpy arrays: vectors ``(3,)``, matrices
``(3, 3)``, quaternions ``(4,)`` as ``(w, x, y, z)``. The SO(3) maps (exp,
log, tangent maps and the 3 × 3 products) are complex-analytic: they are
compiled for the dtype of their input and branch on real parts only, so that
element kernels differentiate through them by complex step (Squire & Trapp
1998). Given ``out``, they fill it instead of allocating (the kernels' hot
loops) and return it.
"""
from __future__ import annotations

import numba
import numpy as np

__all__ = [
    "spin", "axial", "dot", "cross", "matmul3", "matmul3_tn",
    "exp_so3", "log_so3", "tangent_so3", "tangent_inv_so3",
    "compose", "update_so3", "quat_from_rotvec", "quat_to_matrix", "quat_from_matrix",
    "quat_mul", "quat_update", "rotvec_from_quat", "exp_so2", "log_so2", "update_so2",
    "orthogonality_error",
]

_SMALL = 1e-3  # below this angle the 0/0 coefficients use their Taylor series
_SMALL2 = 1e-6  # its square, compared with |w|² (no square root on the way)


@numba.njit(cache=True)
def spin(w):
    """Skew-symmetric matrix of ``w`` (3,): ``spin(w) @ v == cross(w, v)``."""
    W = _like(w, (3, 3))
    W[0, 1] = -w[2]
    W[0, 2] = w[1]
    W[1, 0] = w[2]
    W[1, 2] = -w[0]
    W[2, 0] = -w[1]
    W[2, 1] = w[0]
    return W


@numba.njit(cache=True)
def axial(W):
    """Axial vector (3,) of the skew part of ``W`` (3, 3); inverse of :func:`spin`."""
    return 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])


@numba.njit(cache=True, inline="always")
def _like(x, shape):
    """Zeros of the given shape in the floating type of ``x`` (float64, or complex128 in a complex step)."""
    return np.zeros(shape, dtype=(x[:1] * 1.0).dtype)


@numba.njit(cache=True, inline="always")
def dot(a, b):
    """a · b of two 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@numba.njit(cache=True, inline="always")
def cross(a, b, out):
    """out (3,) = a × b."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@numba.njit(cache=True, inline="always")
def matmul3(A, B, out):
    """out (3, 3) = A B (explicit loops: no BLAS call for tiny blocks)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@numba.njit(cache=True, inline="always")
def matmul3_tn(A, B, out):
    """out (3, 3) = Aᵀ B."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[0, i] * B[0, j] + A[1, i] * B[1, j] + A[2, i] * B[2, j]


@numba.njit(cache=True, inline="always")
def _rodrigues_form(w, t2, a, b, out):
    """out (3, 3) = I + a W + b W² with W = spin(w), t2 = |w|², using W² = w wᵀ − t2 I; returns
    out (a new array if None).

    exp, T and T⁻¹ all have this form; only the coefficients differ.
    """
    if out is None:
        out = _like(w, (3, 3))
    d = 1.0 - b * t2
    for i in range(3):
        for j in range(3):
            out[i, j] = b * w[i] * w[j]
        out[i, i] += d
    out[0, 1] -= a * w[2]
    out[0, 2] += a * w[1]
    out[1, 0] += a * w[2]
    out[1, 2] -= a * w[0]
    out[2, 0] -= a * w[1]
    out[2, 1] += a * w[0]
    return out


@numba.njit(cache=True, inline="always")
def _exp_coefficients(t2):
    """a = sin t / t and b = (1 − cos t)/t² of t = √t2, both accurate for every t."""
    if abs(t2.real) < _SMALL2:
        return 1.0 - t2 / 6.0 + t2 * t2 / 120.0, 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    t = np.sqrt(t2)
    s = np.sin(0.5 * t)
    # 1 - cos t = 2 sin²(t/2) has no cancellation
    return np.sin(t) / t, 2.0 * s * s / (t * t)


@numba.njit(cache=True, inline="always")
def exp_so3(w, out=None):
    """Rotation tensor (3, 3) = exp(spin(w)) of the rotation vector ``w`` (3,) (Rodrigues formula)."""
    t2 = dot(w, w)
    a, b = _exp_coefficients(t2)
    return _rodrigues_form(w, t2, a, b, out)


@numba.njit(cache=True, inline="always")
def _quaternion(R):
    """(w, x, y, z) of ``R`` (3, 3) with w ≥ 0, of norm 1 up to the rounding of R (Spurrier 1978:
    from the largest of tr R and the diagonal, so no branch loses digits); branches on real parts."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    if tr.real >= R[0, 0].real and tr.real >= R[1, 1].real and tr.real >= R[2, 2].real:
        w = 0.5 * np.sqrt(1.0 + tr)
        f = 0.25 / w
        return w, (R[2, 1] - R[1, 2]) * f, (R[0, 2] - R[2, 0]) * f, (R[1, 0] - R[0, 1]) * f
    return _quaternion_from_diagonal(R, tr)


@numba.njit(cache=True)
def _quaternion_from_diagonal(R, tr):
    """:func:`_quaternion` when a diagonal term R_ii exceeds tr R (only beyond a quarter turn)."""
    d0, d1, d2 = R[0, 0].real, R[1, 1].real, R[2, 2].real
    m = max(d0, d1, d2)
    i = 0
    if d1 == m:
        i = 1
    elif d2 == m:
        i = 2
    j = (i + 1) % 3
    k = (i + 2) % 3
    qi = 0.5 * np.sqrt(1.0 + 2.0 * R[i, i] - tr)
    f = 0.25 / qi
    w = (R[k, j] - R[j, k]) * f
    qj = (R[j, i] + R[i, j]) * f
    qk = (R[k, i] + R[i, k]) * f
    if i == 0:
        x, y, z = qi, qj, qk
    elif i == 1:
        x, y, z = qk, qi, qj
    else:
        x, y, z = qj, qk, qi
    if w.real < 0.0:
        return -w, -x, -y, -z
    return w, x, y, z


@numba.njit(cache=True, inline="always")
def _rotation_vector(w, x, y, z, th):
    """th (3,) = rotation vector of the quaternion (w, x, y, z), w ≥ 0, of norm 1 up to rounding:
    angle 2 atan(|v|/w) in [0, π] along v = (x, y, z); returns th."""
    s2 = x * x + y * y + z * z
    if abs(s2.real) < 1e-16:
        # t/s = (2/w)·atan(s/w)/(s/w) = (2/w)(1 − s²/(3w²)) + O(s⁴): exact to rounding here
        c = (2.0 / w) * (1.0 - s2 / (3.0 * w * w))
    else:
        s = np.sqrt(s2)
        if w.real >= s.real:
            c = 2.0 * np.arctan(s / w) / s
        else:  # beyond a quarter turn: atan(s/w) = π/2 − atan(w/s), no division by a small w
            c = (np.pi - 2.0 * np.arctan(w / s)) / s
    th[0] = c * x
    th[1] = c * y
    th[2] = c * z
    return th


@numba.njit(cache=True)
def quat_from_matrix(R):
    """Unit quaternion (4,) ``(w, x, y, z)`` of ``R`` (3, 3), with w ≥ 0 (Spurrier 1978)."""
    w, x, y, z = _quaternion(R)
    q = np.array([w, x, y, z])
    return q / np.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2 + q[3] ** 2)


@numba.njit(cache=True)
def rotvec_from_quat(q):
    """Rotation vector (3,) of the unit quaternion ``q`` (4,), with norm in [0, π]."""
    if q[0].real < 0.0:
        return _rotation_vector(-q[0], -q[1], -q[2], -q[3], _like(q, 3))
    return _rotation_vector(q[0], q[1], q[2], q[3], _like(q, 3))


@numba.njit(cache=True)
def rotvecs_from_quats(Q):
    """Rotation vectors (n, 3) of the unit quaternions ``Q`` (n, 4), each with norm in [0, π]."""
    out = np.empty((Q.shape[0], 3))
    for i in range(Q.shape[0]):
        out[i] = rotvec_from_quat(Q[i])
    return out


@numba.njit(cache=True, inline="always")
def log_so3(R, out=None):
    """Rotation vector (3,) = log(R) of ``R`` (3, 3), with norm in [0, π]; robust near 0 and π."""
    if out is None:
        out = _like(R, 3)
    w, x, y, z = _quaternion(R)
    return _rotation_vector(w, x, y, z, out)


@numba.njit(cache=True, inline="always")
def tangent_so3(w, out=None):
    """Spatial tangent operator T(w) (3, 3): δR Rᵀ = spin(T(w) δw) for R = exp(w)."""
    t2 = dot(w, w)
    if abs(t2.real) < _SMALL2:
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
        c = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0
    else:
        t = np.sqrt(t2)
        s = np.sin(0.5 * t)
        b = 2.0 * s * s / (t * t)
        c = (t - np.sin(t)) / (t * t * t)
    return _rodrigues_form(w, t2, b, c, out)


@numba.njit(cache=True, inline="always")
def tangent_inv_so3(w, out=None):
    """Inverse of :func:`tangent_so3` (3, 3), I − ½W + (1 − (t/2)cot(t/2))/t² W²; singular only at
    |w| = 2π, 4π, …"""
    t2 = dot(w, w)
    if abs(t2.real) < _SMALL2:
        c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    else:
        h = 0.5 * np.sqrt(t2)
        c = (1.0 - h * np.cos(h) / np.sin(h)) / t2
    return _rodrigues_form(w, t2, -0.5, c, out)


@numba.njit(cache=True)
def tangent_inv_so3_derivative(th, m, out):
    """out (3, 3) = ∂(T⁻ᵀ(θ) m)/∂θ for θ, m (3,) (real), T⁻¹ of :func:`tangent_inv_so3`: the
    derivative co-rotational tangents contract with a nodal moment (Battini & Pacoste 2002's K_h).

    T⁻ᵀ(θ) m = m + ½ θ × m + c θ × (θ × m), c(s) = (1 − h cot h)/s, s = |θ|², h = |θ|/2, so
    out = −½ S(m) + c((θ·m) I + θ mᵀ − 2 m θᵀ) + 2c′(s) (θ × (θ × m)) θᵀ, with
    c′(s) = −(cot h − h/sin²h)/(32h³) − c/s, or, for s < 10⁻² (where that cancels), c and c′ from
    their Bernoulli series c = Σ_k |B₂ₖ| s^(k−1)/(2k)!. Tested against
    :func:`tangent_inv_so3_derivative_complex_step`."""
    s = th[0] * th[0] + th[1] * th[1] + th[2] * th[2]
    if s < 1e-2:
        c = 1.0 / 12.0 + s * (1.0 / 720.0 + s * (1.0 / 30240.0 + s * (1.0 / 1209600.0 + s / 47900160.0)))
        dc = 1.0 / 720.0 + s * (2.0 / 30240.0 + s * (3.0 / 1209600.0 + s * 4.0 / 47900160.0))
    else:
        h = 0.5 * np.sqrt(s)
        sn = np.sin(h)
        cot = np.cos(h) / sn
        c = (1.0 - h * cot) / s
        dc = -(cot - h / (sn * sn)) / (32.0 * h * h * h) - c / s
    tm = th[0] * m[0] + th[1] * m[1] + th[2] * m[2]
    for a in range(3):
        wa = th[a] * tm - m[a] * s  # (θ × (θ × m))_a
        for b in range(3):
            out[a, b] = c * (th[a] * m[b] - 2.0 * m[a] * th[b]) + 2.0 * dc * wa * th[b]
        out[a, a] += c * tm
    out[0, 1] += 0.5 * m[2]
    out[0, 2] -= 0.5 * m[1]
    out[1, 0] -= 0.5 * m[2]
    out[1, 2] += 0.5 * m[0]
    out[2, 0] += 0.5 * m[1]
    out[2, 1] -= 0.5 * m[0]


@numba.njit(cache=True)
def tangent_inv_so3_derivative_complex_step(th, m, out):
    """:func:`tangent_inv_so3_derivative` by complex-step differentiation (its test's reference)."""
    h = 1e-30
    thc = np.empty(3, dtype=np.complex128)
    Tc = np.empty((3, 3), dtype=np.complex128)
    for j in range(3):
        for k in range(3):
            thc[k] = th[k]
        thc[j] += 1j * h
        tangent_inv_so3(thc, Tc)
        for i in range(3):
            out[i, j] = (Tc[0, i] * m[0] + Tc[1, i] * m[1] + Tc[2, i] * m[2]).imag / h


@numba.njit(cache=True)
def compose(R1, R2):
    """Composition R1·R2 (3, 3): first R2, then R1."""
    return R1 @ R2


@numba.njit(cache=True)
def update_so3(R, dtheta):
    """Multiplicative (spatial) update ``exp(spin(dtheta)) @ R`` (3, 3)."""
    return exp_so3(dtheta) @ R


@numba.njit(cache=True)
def quat_from_rotvec(w):
    """Unit quaternion (4,) of the rotation vector ``w`` (3,)."""
    t = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    h = 0.5 * t
    if t < _SMALL:
        t2 = t * t
        f = 0.5 - t2 / 48.0 + t2 * t2 / 3840.0  # sin(t/2)/t
    else:
        f = np.sin(h) / t
    q = np.empty(4)
    q[0] = np.cos(h)
    q[1] = f * w[0]
    q[2] = f * w[1]
    q[3] = f * w[2]
    return q


@numba.njit(cache=True)
def quat_mul(p, q):
    """Quaternion product p∘q (4,): the rotation q followed by p."""
    r = np.empty(4)
    r[0] = p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3]
    r[1] = p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2]
    r[2] = p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1]
    r[3] = p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0]
    return r


@numba.njit(cache=True)
def quat_update(q, dtheta):
    """Multiplicative update of a unit quaternion, renormalised: exp(dθ)∘q (4,)."""
    r = quat_mul(quat_from_rotvec(dtheta), q)
    return r / np.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2 + r[3] ** 2)


@numba.njit(cache=True)
def quat_to_matrix(q):
    """Rotation tensor (3, 3) of the unit quaternion ``q`` (4,)."""
    R = np.empty((3, 3))
    quat_to_matrix_into(q, R)
    return R


@numba.njit(cache=True, inline="always")
def quat_to_matrix_into(q, R):
    """R (3, 3) = the rotation tensor of the unit quaternion ``q`` (4,), in place (element kernels:
    no allocation)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    R[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    R[0, 1] = 2.0 * (x * y - w * z)
    R[0, 2] = 2.0 * (x * z + w * y)
    R[1, 0] = 2.0 * (x * y + w * z)
    R[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    R[1, 2] = 2.0 * (y * z - w * x)
    R[2, 0] = 2.0 * (x * z - w * y)
    R[2, 1] = 2.0 * (y * z + w * x)
    R[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@numba.njit(cache=True)
def exp_so2(theta):
    """Planar rotation tensor (2, 2) of the angle ``theta``."""
    c = np.cos(theta)
    s = np.sin(theta)
    R = np.empty((2, 2))
    R[0, 0] = c
    R[0, 1] = -s
    R[1, 0] = s
    R[1, 1] = c
    return R


@numba.njit(cache=True)
def log_so2(R):
    """Angle in (-π, π] of the planar rotation ``R`` (2, 2)."""
    return np.arctan2(R[1, 0] - R[0, 1], R[0, 0] + R[1, 1])


@numba.njit(cache=True)
def update_so2(theta, dtheta):
    """Multiplicative update exp(dθ)·exp(θ) of a planar rotation, stored as its
    unwrapped angle: θ + dθ (SO(2) is commutative; exact)."""
    return theta + dtheta


def orthogonality_error(R: np.ndarray) -> float:
    """‖RᵀR − I‖_max of one (3, 3) or many (n, 3, 3) rotation tensors."""
    R = np.asarray(R)
    RtR = np.einsum("...ji,...jk->...ik", R, R)
    return float(np.max(np.abs(RtR - np.eye(R.shape[-1]))))

"""Beam cross-sections and shell sections (frozen dataclasses).

In 2D the beam bends in its plane: ``I`` is the second moment of area about
the axis normal to the plane, and for a rectangle ``h`` is the in-plane depth.

Shells: a :class:`Laminate` of :class:`Ply` layers (classical lamination theory with
first-order transverse shear): its A, B, D and S matrices in any in-plane axes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Section:
    """General section: area A, second moment I (about the local z axis; the in-plane
    bending of 2D beams), shear area As (k·A); in 3D also Iy (about the local y axis,
    default I) and the torsion constant J (default Iy + I, the polar moment); ``outer`` the
    distance from the axis to the section's outer face, where a 3D beam meets a contact surface
    (default: the half depth √(3 I_max/A) of the rectangle of the same A and I)."""

    A: float
    I: float
    As: float = 0.0
    Iy: float | None = None
    J: float | None = None
    outer: float | None = None

    @property
    def second_moment_y(self) -> float:
        return self.I if self.Iy is None else self.Iy

    @property
    def torsion_constant(self) -> float:
        return self.second_moment_y + self.I if self.J is None else self.J

    @property
    def contact_radius(self) -> float:
        """The distance from the axis at which a 3D beam meets a contact surface."""
        if self.outer is not None:
            return self.outer
        return math.sqrt(3.0 * max(self.I, self.second_moment_y) / self.A)

    def __post_init__(self):
        for name in ("A", "I", "As", "Iy", "J", "outer"):
            if getattr(self, name) is None:
                continue
            v = getattr(self, name)
            if not math.isfinite(v) or v < 0.0:
                raise ValueError(f"{type(self).__name__}: {name} = {v} must be finite and not negative")
        if self.A <= 0.0:
            raise ValueError(f"{type(self).__name__}: area A = {self.A} must be positive")


def Rectangle(b: float, h: float, shear_factor: float = 5.0 / 6.0) -> Section:
    """Rectangle of width b (along local z) and depth h (along local y; in plane in 2D):
    A = bh, I = bh³/12 (about z), Iy = hb³/12, As = k·A, J = Saint-Venant β·a·c³
    (a ≥ c the sides; Roark's series)."""
    if not (b > 0.0 and h > 0.0):
        raise ValueError(f"Rectangle: b = {b} and h = {h} must be positive")
    a, c = max(b, h), min(b, h)
    J = a * c**3 * (1.0 / 3.0 - 0.21 * (c / a) * (1.0 - (c / a) ** 4 / 12.0))
    return Section(A=b * h, I=b * h**3 / 12.0, As=shear_factor * b * h, Iy=h * b**3 / 12.0, J=J, outer=0.5 * h)


def Circle(d: float, shear_factor: float = 0.9) -> Section:
    """Solid circle of diameter d: A = πd²/4, I = πd⁴/64, As = k·A."""
    if not d > 0.0:
        raise ValueError(f"Circle: diameter d = {d} must be positive")
    A = math.pi * d * d / 4.0
    return Section(A=A, I=math.pi * d**4 / 64.0, As=shear_factor * A, Iy=math.pi * d**4 / 64.0,
                   J=math.pi * d**4 / 32.0, outer=0.5 * d)


def Pipe(d: float, t: float, shear_factor: float = 0.5) -> Section:
    """Circular hollow section (a pipe) of outer diameter d and wall thickness t:
    A = π(d² − d_i²)/4, I = Iy = π(d⁴ − d_i⁴)/64, J = 2I, As = k·A (k = 0.5 for a thin tube),
    d_i = d − 2t; it meets contact surfaces at its outer radius d/2."""
    if not (d > 0.0 and 0.0 < t <= 0.5 * d):
        raise ValueError(f"Pipe: diameter d = {d} and wall thickness t = {t} must satisfy 0 < t ≤ d/2")
    di = d - 2.0 * t
    A = math.pi * (d * d - di * di) / 4.0
    I = math.pi * (d**4 - di**4) / 64.0
    return Section(A=A, I=I, As=shear_factor * A, Iy=I, J=2.0 * I, outer=0.5 * d)


@dataclass(frozen=True)
class Ply:
    """One layer of a :class:`Laminate`: its thickness, its fibre angle in degrees (from the
    shell's material axis 1 about the shell normal e₃, counter-clockwise seen from the e₃ side)
    and its material (:class:`dolfinx_corot.materials.Orthotropic`, or an isotropic
    :class:`dolfinx_corot.materials.Elastic`)."""

    thickness: float
    angle: float
    material: object

    def __post_init__(self):
        from .materials import Elastic, Orthotropic

        if not (math.isfinite(self.thickness) and self.thickness > 0.0):
            raise ValueError(f"Ply: thickness = {self.thickness} must be positive and finite")
        if not math.isfinite(self.angle):
            raise ValueError(f"Ply: angle = {self.angle} must be finite (degrees)")
        if not isinstance(self.material, (Elastic, Orthotropic)):
            raise TypeError(f"Ply: material must be dc.Orthotropic or dc.Elastic, got {type(self.material).__name__}")

    def stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        """(Q (3, 3), G (2, 2)): the plane-stress stiffness on (ε11, ε22, γ12) and the transverse
        shear moduli on (γ13, γ23), in the ply's own axes."""
        from .materials import Elastic

        m = self.material
        if isinstance(m, Elastic):
            E1 = E2 = m.E
            nu12, G12 = m.nu, m.G
            G13 = G23 = m.G
        else:
            E1, E2, G12, nu12 = m.E1, m.E2, m.G12, m.nu12
            G13, G23 = m.transverse_shear
        nu21 = nu12 * E2 / E1
        d = 1.0 - nu12 * nu21
        Q = np.array([[E1 / d, nu12 * E2 / d, 0.0], [nu12 * E2 / d, E2 / d, 0.0], [0.0, 0.0, G12]])
        return Q, np.diag([G13, G23])

    @property
    def isotropic(self) -> bool:
        from .materials import Elastic

        return isinstance(self.material, Elastic)


def turned_stiffness(Q: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Q̄ (n, 3, 3): a plane-stress stiffness Q (3, 3) on (ε11, ε22, γ12) in axes (1, 2) expressed
    in axes (x, y) with axis 1 at the angles θ (n,) (radians, counter-clockwise) from x
    (Jones 1999, eq. 2.84): σ_xy = Q̄ ε_xy."""
    c, s = np.cos(theta), np.sin(theta)
    q11, q12, q22, q66 = Q[0, 0], Q[0, 1], Q[1, 1], Q[2, 2]
    q16 = Q[0, 2]
    q26 = Q[1, 2]
    if abs(q16) + abs(q26) > 1e-14 * abs(q11):  # a general (anisotropic) Q: turn the tensor
        return _turn_tensor(Q, theta)
    c2, s2 = c * c, s * s
    out = np.empty((len(theta), 3, 3))
    out[:, 0, 0] = q11 * c2 * c2 + 2.0 * (q12 + 2.0 * q66) * s2 * c2 + q22 * s2 * s2
    out[:, 0, 1] = out[:, 1, 0] = (q11 + q22 - 4.0 * q66) * s2 * c2 + q12 * (s2 * s2 + c2 * c2)
    out[:, 1, 1] = q11 * s2 * s2 + 2.0 * (q12 + 2.0 * q66) * s2 * c2 + q22 * c2 * c2
    out[:, 0, 2] = out[:, 2, 0] = (q11 - q12 - 2.0 * q66) * c2 * c * s + (q12 - q22 + 2.0 * q66) * c * s2 * s
    out[:, 1, 2] = out[:, 2, 1] = (q11 - q12 - 2.0 * q66) * c * s2 * s + (q12 - q22 + 2.0 * q66) * c2 * c * s
    out[:, 2, 2] = (q11 + q22 - 2.0 * q12 - 2.0 * q66) * s2 * c2 + q66 * (s2 * s2 + c2 * c2)
    return out


_VOIGT = ((0, 0), (1, 1), (0, 1))


def _turn_tensor(Q: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """:func:`turned_stiffness` by turning the fourth-order tensor (any Q). With engineering
    shear γ12 = ε12 + ε21, C_ijkl = Q_IJ for every ordering of (i, j) and (k, l)."""
    C = np.zeros((2, 2, 2, 2))
    for I, (i, j) in enumerate(_VOIGT):
        for J, (k, l) in enumerate(_VOIGT):
            for a, b in {(i, j), (j, i)}:
                for c, d in {(k, l), (l, k)}:
                    C[a, b, c, d] = Q[I, J]
    out = np.empty((len(theta), 3, 3))
    for n, t in enumerate(theta):
        R = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])  # columns: axes 1, 2 in (x, y)
        Ct = np.einsum("ip,jq,kr,ls,pqrs->ijkl", R, R, R, R, C)
        for I, (i, j) in enumerate(_VOIGT):
            for J, (k, l) in enumerate(_VOIGT):
                out[n, I, J] = Ct[i, j, k, l]
    return out


def turned_shear(G: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Ḡ (n, 2, 2) = aᵀ G a, a = [[c, s], [−s, c]]: transverse shear moduli G (2, 2) on
    (γ13, γ23) in axes (x, y), axis 1 at the angles θ (n,) from x."""
    c, s = np.cos(theta), np.sin(theta)
    a = np.empty((len(theta), 2, 2))
    a[:, 0, 0], a[:, 0, 1], a[:, 1, 0], a[:, 1, 1] = c, s, -s, c
    return np.einsum("nki,kl,nlj->nij", a, G, a)


@dataclass(frozen=True)
class Laminate:
    """A shell section of plies stacked from the bottom face (z = −t/2, opposite the element
    normal e₃) to the top (+t/2); classical lamination theory (Jones 1999, ch. 4; Reddy 2004,
    ch. 3) with first-order transverse shear:

    N = Aε + Bκ, M = Bε + Dκ, Q = Sγ with A = Σ Q̄_k h_k, B = ½ Σ Q̄_k (z²_{k+1} − z²_k),
    D = ⅓ Σ Q̄_k (z³_{k+1} − z³_k), S = k Σ Ḡ_k h_k (k = ``shear_factor``, 5/6), the Q̄_k the
    plies' stiffnesses turned to the axes asked for.

    ``Laminate([Ply(0.25, 0, m), Ply(0.25, 90, m), Ply(0.25, 90, m), Ply(0.25, 0, m)])`` is a
    symmetric cross-ply [0/90]s of one material; ``Laminate.single(t, m)`` one layer.
    """

    plies: tuple
    shear_factor: float = 5.0 / 6.0

    def __post_init__(self):
        plies = tuple(self.plies)
        if not plies:
            raise ValueError("Laminate: give at least one Ply")
        for k, p in enumerate(plies):
            if not isinstance(p, Ply):
                raise TypeError(f"Laminate: ply {k} is a {type(p).__name__}, not a dc.Ply")
        if not (0.0 < self.shear_factor <= 1.0):
            raise ValueError(f"Laminate: shear_factor = {self.shear_factor} must lie in (0, 1]")
        object.__setattr__(self, "plies", plies)

    @classmethod
    def single(cls, thickness: float, material, angle: float = 0.0) -> "Laminate":
        """One layer of ``material`` (orthotropic: its axis 1 at ``angle`` degrees from the shell's
        material axis)."""
        return cls((Ply(thickness, angle, material),))

    @property
    def thickness(self) -> float:
        return float(sum(p.thickness for p in self.plies))

    @property
    def isotropic(self) -> bool:
        """All plies isotropic (no material axis needed)."""
        return all(p.isotropic for p in self.plies)

    @property
    def density(self) -> float | None:
        """The mean density (mass per unit area / thickness), None if a ply has none."""
        rho = [p.material.density for p in self.plies]
        if any(r is None for r in rho):
            return None
        return float(sum(r * p.thickness for r, p in zip(rho, self.plies)) / self.thickness)

    def matrices(self, angles) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, D (n, 3, 3), S (n, 2, 2)) in in-plane axes (x, y) whose x axis lies at the angles
        (n,) (radians) clockwise from the material axis 1 — i.e. axis 1 at +angle from x."""
        phi = np.atleast_1d(np.asarray(angles, dtype=float))
        n = len(phi)
        A, B, D = (np.zeros((n, 3, 3)) for _ in range(3))
        S = np.zeros((n, 2, 2))
        z = -0.5 * self.thickness
        for p in self.plies:
            Q, G = p.stiffness()
            theta = phi + math.radians(p.angle)
            Qb = turned_stiffness(Q, theta)
            z1 = z + p.thickness
            A += Qb * (z1 - z)
            B += Qb * (z1**2 - z**2) / 2.0
            D += Qb * (z1**3 - z**3) / 3.0
            S += turned_shear(G, theta) * (self.shear_factor * p.thickness)
            z = z1
        return A, B, D, S

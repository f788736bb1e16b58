"""Stability of the tangent along the path: singular models, critical points.

*Singular models.* A tangent that is singular in the unloaded state is a model
error, not a hard step: a part without supports, a mechanism, a rotation
without stiffness, a body held only by contact that is still open. It is
found at the first solve (MUMPS reports zero pivots; for continua solved by
CG + AMG, the rigid-body modes are applied to the first tangent) and the run
stops at once with :class:`SingularModelError`, which names the free motion:
the part, and whether it translates (in which direction), rotates (about
which point) or deforms as a mechanism (at which nodes). The motion is the
softest eigenvector of the tangent, found by inverse iteration.

*Critical points* (Crisfield 1997, §21.2; Wriggers 2008, §5.3). Along a
stable path the tangent is positive definite; at a limit point or a
bifurcation one of its eigenvalues passes through zero, and the number of
negative eigenvalues (the inertia, Sylvester's law: the negative pivots of
LDLᵀ) changes. The drivers count them at every converged state — from the
Newton factorizations themselves with LDLᵀ, by an LDLᵀ of the symmetric part
of the tangent once per step otherwise — and record a
:class:`CriticalPoint` where the count changes. Its load factor is found by
interpolating the eigenvalue of the tangent closest to zero linearly to zero
between the two states around it (a bifurcation), or by a parabola through
the path points around the maximum of the load (a limit point followed by
arc-length). Under load control, a step whose Newton iterates pass through
an unstable region and land on a stable state again has jumped across a limit
point to a remote branch (snap-through); that is a critical point too.
"""
from __future__ import annotations

import logging
import math
from dataclasses import asdict, dataclass

import numpy as np
from petsc4py import PETSc

from .newton import ConvergenceError

logger = logging.getLogger(__name__)


class SingularModelError(ConvergenceError):
    """The model's tangent is singular before any load: a free motion (named in the message)."""


class CriticalPointError(ConvergenceError):
    """Load control reached a critical point (``result.critical_points``) and stopped there."""


@dataclass(frozen=True)
class CriticalPoint:
    """A limit point or a bifurcation found along the path.

    kind: 'bifurcation', 'limit point' or 'limit point (jumped)' (load control leapt past it);
    load_factor: its estimate; bracket: the converged load factors around it; step: the step
    that crossed it; negative_before/after: negative eigenvalues of the tangent on either side;
    estimate: how ``load_factor`` was found."""

    kind: str
    load_factor: float
    bracket: tuple[float, float]
    step: int
    negative_before: int
    negative_after: int
    estimate: str

    def as_dict(self) -> dict:
        return asdict(self)


# -- naming a free motion ----------------------------------------------------------------
def _label(model) -> str:
    names = [f"{p.kind} '{p.name}'" if p.name else f"{p.kind} (all cells)" for p in model.parts]
    return ", ".join(dict.fromkeys(names)) or model.kind_name


def _fmt(x, length: float = 0.0) -> str:
    """A point or vector in words; coordinates below 1e-12 of ``length`` (the model's size) are
    round-off and read 0."""
    x = np.asarray(x, dtype=float)
    x = np.where(np.abs(x) < 1e-12 * length, 0.0, x)
    return "(" + ", ".join(f"{v:.4g}" for v in x) + ")"


def _rigid_fit(X: np.ndarray, t: np.ndarray):
    """Least-squares rigid motion t ≈ a + ω × (X − c) of translations t at points X; returns
    (a, ω, c, relative misfit)."""
    n, d = X.shape
    c = X.mean(axis=0)
    Y = X - c
    if d == 2:
        B = np.zeros((2 * n, 3))
        B[0::2, 0] = 1.0
        B[1::2, 1] = 1.0
        B[0::2, 2] = -Y[:, 1]
        B[1::2, 2] = Y[:, 0]
    else:
        B = np.zeros((3 * n, 6))
        for k in range(3):
            B[k::3, k] = 1.0
        # ω × Y
        B[0::3, 4], B[0::3, 5] = Y[:, 2], -Y[:, 1]
        B[1::3, 3], B[1::3, 5] = -Y[:, 2], Y[:, 0]
        B[2::3, 3], B[2::3, 4] = Y[:, 1], -Y[:, 0]
    coef, *_ = np.linalg.lstsq(B, t.ravel(), rcond=None)
    misfit = np.linalg.norm(B @ coef - t.ravel()) / max(np.linalg.norm(t), 1e-300)
    return coef[:d], coef[d:], c, misfit


def describe_motion(system, vec, scene=None) -> list[str]:
    """Words for the motion ``vec`` (a system vector): for each part that carries a share of it,
    a rigid translation or rotation, rotations without stiffness, or a mechanism at named nodes."""
    comm = system.comm
    pieces = []
    for model in system.models:
        arr = system.model_array(model, vec)
        n_owned = model.V.dofmap.index_map.size_local
        vals = arr.reshape(-1, model.ndof)[:n_owned]
        X = model.V.tabulate_dof_coordinates()[:n_owned, : model.gdim] + model.translations_of(np.arange(n_owned))
        gathered = comm.gather((X, vals), root=0)
        pieces.append((model, gathered))
    out = None
    if comm.rank == 0:
        total = math.sqrt(sum(float(np.sum(np.concatenate([v for _, v in g]) ** 2)) for _, g in pieces))
        out = []
        for model, gathered in pieces:
            X = np.concatenate([x for x, _ in gathered])
            v = np.concatenate([v for _, v in gathered])
            share = np.linalg.norm(v) / max(total, 1e-300)
            if share < 0.1 or len(X) == 0:
                continue
            out.append(_describe_part(model, X, v, scene))
    return comm.bcast(out, root=0)


def _describe_part(model, X: np.ndarray, v: np.ndarray, scene) -> str:
    name = _label(model)
    d = model.gdim
    t = v[:, : model.translations][:, :d]
    r = v[:, model.translations:]
    nt, nr = np.linalg.norm(t), np.linalg.norm(r)
    if nt < 1e-3 * max(nt + nr, 1e-300):
        k = np.argsort(-np.abs(r).max(axis=1))[:3]
        names = model.dof_names[model.translations:]
        return (f"{name}: the rotations ({', '.join(names)}) of the node(s) at "
                f"{', '.join(_fmt(X[i]) for i in k)} have no stiffness (a hinge, a section without bending "
                "stiffness, or nodes that no element connects)")
    a, w, c, misfit = _rigid_fit(X, t)
    held = _contact_note(model, scene)
    if misfit < 1e-3:
        size = max(float(np.ptp(X, axis=0).max()), 1e-300)
        spin = np.linalg.norm(w) * size
        if spin < 1e-3 * np.linalg.norm(a):
            return f"{name} translates freely along {_fmt(a / np.linalg.norm(a))}{held}"
        if d == 2:
            w = float(w[0])
            centre = c + np.array([-a[1], a[0]]) / w
            return f"{name} rotates freely about the point {_fmt(centre, size)}{held}"
        axis = w / np.linalg.norm(w)
        through = c + np.cross(w, a) / (w @ w)
        return f"{name} rotates freely about the axis {_fmt(axis)} through {_fmt(through, size)}{held}"
    size = np.linalg.norm(t, axis=1)
    k = [i for i in np.argsort(-size)[:3] if size[i] > 0.1 * size.max()]
    return (f"{name} deforms without resistance (a mechanism): the node(s) at "
            f"{', '.join(_fmt(X[i]) for i in k)} move most")


def _contact_note(model, scene) -> str:
    if scene is None:
        return ""
    names = scene.contacts_holding(model)
    if not names:
        return " (no support holds it)"
    return (f"; it is held only by contact ({', '.join(repr(n) for n in names)}), which carries nothing in "
            "this state (an initial gap, or a frictionless body free to slide or spin): support it, close the "
            "gap; or stabilise it until contact closes (scene.stabilise)")


def _canonical_modes(model) -> tuple[list[np.ndarray], np.ndarray]:
    """Unit rigid motions of a part as local arrays of its V (owned and ghost blocks): translations
    along the axes, then rotations about the axes through the centroid ``c`` of its current nodes
    (rotation dofs turn alike); and c."""
    from mpi4py import MPI
    n_owned = model.V.dofmap.index_map.size_local
    nb = n_owned + model.V.dofmap.index_map.num_ghosts
    X = model.V.tabulate_dof_coordinates()[:nb, : model.gdim] + model.translations_of(np.arange(nb))
    d = model.gdim
    total = np.r_[X[:n_owned].sum(axis=0), n_owned]
    if model.comm.size > 1:
        total = model.comm.allreduce(total, op=MPI.SUM)
    c = total[:d] / max(total[d], 1.0)
    Y = np.zeros((nb, 3))
    Y[:, :d] = X - c
    modes = []
    for k in range(d):
        m = np.zeros((nb, model.ndof))
        m[:, k] = 1.0
        modes.append(m)
    nrot = model.ndof - model.translations
    for a in ([2] if d == 2 else [0, 1, 2]):
        w = np.zeros(3)
        w[a] = 1.0
        m = np.zeros((nb, model.ndof))
        m[:, :d] = np.cross(w, Y)[:, :d]
        if nrot == 1:
            m[:, model.translations] = 1.0
        elif nrot == 3:
            m[:, model.translations + a] = 1.0
        modes.append(m)
    return modes, c


def free_rigid_motions(system, scene=None) -> list[str]:
    """The rigid motions of each part that the last assembled tangent does not resist, in words.

    For the rigid modes R of a part (translations, rotations), the smallest generalised
    eigenvalues of ((K R)ᵀ(K R) + s² R_cᵀ R_c, RᵀR) — R_c: R on constrained dofs, s = max|diag K| —
    say which combinations R c meet neither stiffness nor a support: a few matrix–vector
    products per part."""
    A = system.A
    diag = A.getDiagonal()
    scale = max(diag.norm(PETSc.NormType.INFINITY), 1e-300)
    diag.destroy()
    constrained = system.constrained_global_dofs()
    start, stop = system.ownership_range()
    own = constrained[(constrained >= start) & (constrained < stop)] - start
    free_rows = np.ones(stop - start, dtype=bool)
    free_rows[own] = False
    comm = system.comm
    out = []
    v, Kv = A.createVecs()
    try:
        for model in system.models:
            modes, centre = _canonical_modes(model)
            KR, R = [], []
            for m in modes:
                vec = system.new_vector()
                system.set_model_array(model, m.ravel(), vec)
                vec.copy(v)
                vec.destroy()
                A.mult(v, Kv)
                k = Kv.array.copy()
                r = v.array.copy()
                k[~free_rows] = scale * r[~free_rows]  # a support resists as stiffly as the stiffest dof
                KR.append(k)
                R.append(r)
            KR, R = np.array(KR), np.array(R)
            G1, G0 = KR @ KR.T, R @ R.T
            if comm.size > 1:  # (mpi4py's pickling allreduce costs 40 µs a call even on one rank)
                G1, G0 = comm.allreduce(G1), comm.allreduce(G0)
            G1 = G1 / scale**2
            if not np.all(np.isfinite(G1)):
                continue
            G0 = G0 + 1e-14 * np.trace(G0) * np.eye(len(G0))
            # G1 c = μ G0 c reduced by G0's Cholesky factor L (as LAPACK's dsygv does; SciPy's
            # eigh wrapper costs 1.4 ms a call here, NumPy's 6 × 6 steps 0.05 ms)
            Li = np.linalg.inv(np.linalg.cholesky(G0))
            mu, V = np.linalg.eigh(Li @ G1 @ Li.T)
            C = Li.T @ V
            F = C[:, mu < 1e-16]
            if F.shape[1] == 0:
                continue
            out.append(_words_of_rigid(model, F, centre, scene))
    finally:
        v.destroy()
        Kv.destroy()
    return out


def _words_of_rigid(model, F: np.ndarray, centre: np.ndarray, scene) -> str:
    """Words for the span of the rigid-mode coefficients F (columns; translations first)."""
    from ..parts.cells import mesh_extent

    d = model.gdim
    length = mesh_extent(model.V.mesh)  # (collective, as the caller's search)
    Q, _ = np.linalg.qr(F)
    names = []
    for k in range(d):
        e = np.zeros(F.shape[0])
        e[k] = 1.0
        if np.linalg.norm(e - Q @ (Q.T @ e)) < 1e-6:
            names.append(f"translation along {'xyz'[k]}")
    rotations = F.shape[1] - len(names)
    if rotations > 0:
        if names:  # with a free translation the axis of a free rotation is not fixed
            names += [f"rotation about {'z' if d == 2 else 'xyz'[a]}" for a in range(rotations if d == 3 else 1)]
        else:
            for j in range(F.shape[1]):
                a, w = F[:d, j], F[d:, j]
                if np.linalg.norm(w) > 1e-9 * max(np.linalg.norm(a), 1e-300):
                    break
            if d == 2:
                point = centre + np.array([-a[1], a[0]]) / w[0]
                names.append(f"rotation about z through the point {_fmt(point, length)}")
            else:
                point = centre + np.cross(w, a) / (w @ w)
                names.append(f"rotation about the axis {_fmt(w / np.linalg.norm(w))} through {_fmt(point, length)}")
    return f"{_label(model)} moves freely ({', '.join(names)}){_contact_note(model, scene)}"


def singular_model(run, reason: str) -> None:
    """Stop the run with a :class:`SingularModelError` naming the free motions of the tangent last
    assembled: the parts' free rigid motions, else the mechanism its softest motion shows."""
    system = run.system
    words = free_rigid_motions(system, run.scene)
    kind = "singular"
    if not words:
        vectors, quotients = system.softest_motions(1)
        kind = "singular" if quotients[0] < 1e-7 else "nearly singular"
        words = describe_motion(system, vectors[0], run.scene)
        for v in vectors:
            v.destroy()
    detail = "; ".join(words) if words else "the free motion could not be located"
    msg = (f"the model is {kind} before any load can be carried ({reason}): {detail}. "
           "Add the supports (scene.fix) that stop this motion, or connect the parts.")
    from ..result import Result
    raise SingularModelError(msg, Result(run.history, False, msg, run.totals()))


def check_first_tangent(run, load_factor: float) -> None:
    """Before the first step: the parts' rigid motions applied to the tangent of the start state
    (assembled here; the first Newton solve uses it). One the tangent does not resist is a free
    motion: the run stops before any solve (an iterative solver would not say so, and a direct
    one may miss a pivot)."""
    system = run.system
    system.tangent_at(load_factor, factorize=False)
    if free_rigid_motions(system, run.scene):
        singular_model(run, "the tangent of the start state does not resist a rigid motion")


# -- critical points ------------------------------------------------------------------------
class StabilityTracker:
    """Counts the negative eigenvalues of the tangent at converged states and finds critical points.

    mode: 'auto' (count with the Newton solver's LDLᵀ; with LU, by an LDLᵀ of the symmetric
    part of the converged tangent when the system has at most ``max_dofs`` dofs; with the
    iterative solver, which factorizes nothing, likewise up to ``max_dofs`` in 2D but only up to
    ``max_dofs_iterative_3d`` in 3D, where the factor's fill grows fastest: a 116 k-dof block's
    LDLᵀ costs 10 s, twice its whole step by CG + AMG), 'on' (always), 'off'."""

    def __init__(self, system, mode: str = "auto", max_dofs: int = 200_000,
                 max_dofs_iterative_3d: int = 20_000):
        self.system = system
        self.mode = mode
        self.free = system.counts_inertia
        size = system.A.getSize()[0]
        limit = max_dofs
        if getattr(system, "iterative", False) and max(m.gdim for m in system.models) == 3:
            limit = max_dofs_iterative_3d
        self._small = size <= limit
        self.enabled = mode == "on" or (mode == "auto" and (self.free or self._small))
        if mode == "auto" and not self.enabled:
            logger.info("critical points are not tracked: the tangent (%d dofs) is not factorized by LDLᵀ and "
                        "counting its inertia separately would cost a factorization per step "
                        "(stability='on' asks for it)", size)
        self.negative: int | None = None   # at the last converged state
        self.points: list[CriticalPoint] = []

    def start_attempt(self) -> None:
        self.system.take_inertia()  # forget factorizations of failed attempts

    def converged(self, load_factor: float, starts_next: bool = True) -> tuple[int | None, int | None, bool]:
        """After a converged step: (negative eigenvalues before, after, whether the Newton iterates
        passed through a less stable region than both ends). starts_next: the next step starts
        from this state (no predictor), so a factorization of its tangent here serves it."""
        if not self.enabled:
            return None, None, False
        system = self.system
        # follower loads turn the solver from LDLᵀ to LU (their load stiffness is not symmetric):
        # the symmetric part is then factorized apart, as for any LU system
        if system.fload is not None:
            self.free = system.counts_inertia
            if not self.free and not (self.mode == "on" or self._small):
                return None, None, False
        counts, signs = system.take_inertia()
        before = self.negative
        reusable = system.tangent_reusable
        if self.free:
            if before is None and counts:
                before = counts[0]  # the first tangent of the run: at the start state
            after = counts[-1] if counts else before
            if (reusable and (starts_next or not counts)) or self.mode == "on":
                # the tangent of the converged state, factorized now, is the next step's first.
                # Otherwise 'auto' takes the step's last factorization, one Newton correction
                # short of the converged state (a count that differs there only within round-off
                # of a critical point): with contributions, whose pairs the next solve may
                # change, and with a predictor, where the next step starts elsewhere
                system.tangent_at(load_factor)
                exact, _ = system.take_inertia()
                after = exact[-1] if exact else after
            passed = bool(counts) and before is not None and after is not None and \
                max(counts) > max(before, after)
        else:
            system.tangent_at(load_factor, factorize=reusable and starts_next)
            system.take_inertia()
            after = system.inertia()
            if before is None:
                before = 0 if not signs or signs[0] > 0 else 1
            passed = before == after and any(s != (-1) ** before for s in signs)
        self.negative = after
        return before, after, passed

    def count_here(self, load_factor: float) -> int:
        """Negative eigenvalues of the tangent at the current configuration."""
        self.system.take_inertia()
        if self.free:
            self.system.tangent_at(load_factor)
            counts, _ = self.system.take_inertia()
            return counts[-1] if counts else -1
        self.system.tangent_at(load_factor, factorize=False)
        return self.system.inertia()

    def secant_unstable(self, older, newer, lam0: float, lam1: float, before: int) -> bool | None:
        """Whether states on the secant between two converged states (configurations ``older``
        and ``newer``) have more negative eigenvalues than ``before``: the step crossed an
        unstable region (snap-through), rather than Newton's iterates merely overshooting;
        None where the secant cannot be formed (rotations in 3D)."""
        system = self.system
        unstable = False
        for t in (0.25, 0.5, 0.75):
            system.restore(newer)
            try:
                system.extrapolate(older, newer, -(1.0 - t))
            except NotImplementedError:  # no secant between rotations in 3D
                unstable = None
                break
            if self.count_here(lam0 + t * (lam1 - lam0)) > before:
                unstable = True
                break
        system.restore(newer)
        return unstable

    def eigenvalue_here(self, load_factor: float) -> float:
        self.system.tangent_at(load_factor)
        return self.system.smallest_eigenvalue()

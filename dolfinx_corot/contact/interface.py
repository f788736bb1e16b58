r"""Contact interfaces in 2D: slave nodes of one body against master segments of another.

An :class:`Interface` pairs the nodes of a boundary group of one part (the
slaves, or contactors) with the boundary segments of a group of another
part (the masters). Every rank holds both surfaces whole (contact
surfaces are small next to the bodies): reference coordinates, the global
dofs of their nodes and the orientation of the master segments, whose
body lies on the left of each segment. At each residual evaluation the
current positions are gathered, the broad phase (bounding boxes inflated
by a margin) gives the candidate pairs, each slave takes the segment of
its closest point on the master surface — by default the C¹ Hermite curve
through the master nodes, or the straight segments — and the kernels
(:mod:`.kernels2d`) give forces and the consistent tangent. Beams are
contact surfaces on either side of their axis, at half their depth.

Each rank evaluates the slaves whose dofs it owns. Forces go into the
internal-force vector, the tangent into a matrix C with a COO pattern over
all candidate pairs (entries on constrained dofs are left out), added to
the system matrix. The pattern is rebuilt only when the candidate set
grows (a slave moves more than half the margin since the last search).

The interface pressure of a contact declaration (both passes of two-pass contact, on the
actual contact faces) is in :mod:`.pair`. The laws are in :mod:`.laws`. :class:`Contact` is the
interfaces of a scene as one
:class:`~dolfinx_corot.assembly.contribution.Contribution` of the system: its Newton
hooks are the safeguards near contact and the Uzawa updates, its state the
multipliers and the candidate pairs.
"""
from __future__ import annotations

import logging
import time
from typing import NamedTuple

import numpy as np
from mpi4py import MPI

from ..assembly.contribution import Contribution
from .kernels2d import (node_to_smooth_segment, node_to_smooth_segment_friction, node_to_vertex,
                        node_to_vertex_friction, slipped_stick_point, smooth_gap, vertex_stick_point)
from .laws import ContactError, Coulomb, Penalty
from .search import broad_phase, narrow_phase

logger = logging.getLogger(__name__)


def fingerprint_float(value: float) -> float:
    """``value`` to 12 significant digits, for a scene's fingerprint: a default penalty's last bits
    follow the rounding of the surface's coordinates, which may differ from run to run under MPI
    (4748.293279387663 and …662 in two runs of one scene on two ranks)."""
    return float(f"{value:.12g}")


def tributary_lengths(X: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Half the summed lengths of the segments at each node (the node's share of the boundary)."""
    length = np.linalg.norm(X[segments[:, 1]] - X[segments[:, 0]], axis=1)
    out = np.zeros(len(X))
    np.add.at(out, segments[:, 0], 0.5 * length)
    np.add.at(out, segments[:, 1], 0.5 * length)
    return out


def _smoothing_neighbours(X: np.ndarray, segments: np.ndarray, sharp: float) -> np.ndarray:
    """(m, 4) nodes (p, a, b, q) of each master segment a → b: p the node before a and q the node
    after b along the surface, whose positions set the smooth curve's tangents at a and b; p = a
    (q = b) at a free end, where more than two segments meet, or where the surface turns by more
    than ``sharp`` radians (a corner: the curve ends there without a neighbour)."""
    nodes = len(X)
    starts = np.bincount(segments[:, 0], minlength=nodes)
    ends = np.bincount(segments[:, 1], minlength=nodes)
    into = np.full(nodes, -1)   # the segment that ends at each node
    out = np.full(nodes, -1)    # the segment that starts at it
    into[segments[:, 1]] = np.arange(len(segments))
    out[segments[:, 0]] = np.arange(len(segments))
    manifold = (starts == 1) & (ends == 1)
    t = X[segments[:, 1]] - X[segments[:, 0]]
    t /= np.linalg.norm(t, axis=1)[:, None]
    a, b = segments[:, 0], segments[:, 1]
    ext = np.column_stack([a, a, b, b])
    prev = into[a]
    ok = manifold[a] & (prev >= 0)
    ok[ok] &= np.einsum("ij,ij->i", t[ok], t[prev[ok]]) >= np.cos(sharp)
    ext[ok, 0] = segments[prev[ok], 0]
    nxt = out[b]
    ok = manifold[b] & (nxt >= 0)
    ok[ok] &= np.einsum("ij,ij->i", t[ok], t[nxt[ok]]) >= np.cos(sharp)
    ext[ok, 3] = segments[nxt[ok], 1]
    return ext


class FrictionTrial(NamedTuple):
    """The closed pairs' friction at the last evaluation (this rank's): slaves s, segments m, the
    stencils' positions x (k, 10), closest-point parameters xi, stick points start, tractions t,
    slipping, pressures p, tangential multipliers lam_t, and which vertex of the segment a slave
    at a sharp corner meets (1: a, 2: b; 0: on the segment)."""
    s: np.ndarray
    m: np.ndarray
    x: np.ndarray
    xi: np.ndarray
    start: np.ndarray
    t: np.ndarray
    slipping: np.ndarray
    p: np.ndarray
    lam_t: np.ndarray
    which: np.ndarray


class Interface:
    """One direction of contact: the nodes of ``slaves`` against the segments of ``masters``
    (each a (part, boundary group name) pair). The symmetric (two-pass) contact of two
    deformable bodies is two interfaces, one each way."""

    FACETS = "segments"  # what the master surface is made of (for Scene.effects)
    XI_TOLERANCE = 0.05  # beyond a free end of the master surface: this far (× length) still on it
    SMOOTH_ANGLE = np.radians(60.0)  # master vertices where the surface turns more than this stay sharp
    BAND_USES = 3  # corrections per Newton solve that may count lifted pairs as closed
    SYMMETRIC_TANGENT = True
    STICK_SHAPE = ()  # a stick point's parameters on its master facet: ξ on a segment's curve
    LAMBDA_SHAPE = ()  # a tangential multiplier: the traction along the curve's unit tangent

    def __init__(self, slaves, masters, law: Penalty, smooth: bool = True, friction: Coulomb | None = None):
        if not isinstance(law, Penalty):
            raise TypeError(f"contact law must be dc.Penalty or dc.AugmentedLagrangian, got {type(law).__name__}")
        if friction is not None and not isinstance(friction, Coulomb):
            raise TypeError(f"contact friction must be dc.Coulomb(...) or None, got {type(friction).__name__}")
        if friction is not None and friction.slip_tolerance is not None and not law.augmented:
            raise ValueError(f"contact '{slaves[1]} -> {masters[1]}': Coulomb's slip_tolerance needs the augmented "
                             f"Lagrangian normal law (law=dc.AugmentedLagrangian(...)), got {law!r}: its Uzawa updates "
                             "augment the shear")
        self.friction = friction
        if slaves[0].model is masters[0].model and slaves[1] == masters[1]:
            raise ContactError(f"contact of surface '{slaves[1]}' with itself is not supported: give two "
                               "surfaces (self-contact is not implemented)")
        self.slave_spec, self.master_spec, self.law = slaves, masters, law
        # a solid region's face (its lines may border cells of another region of the mesh)
        self.slave = slaves[0].model.surface(slaves[1], body=slaves[0].name or None)
        self.master = masters[0].model.surface(masters[1], body=masters[0].name or None)
        self.name = f"{slaves[1]} -> {masters[1]}"
        # slaves: all nodes of the slave group; their tributary lengths (areas) on the slave boundary
        self.area = self._tributary(self.slave.X, self.slave.facets)
        Xm, sm = self.master.X, self.master.facets
        # beams: contact on either side of the axis, at half the section's depth from it
        self.two_sided = self.master.two_sided
        self.master_offset = self.master.offsets
        self.slave_face = self.slave.node_offsets()  # a beam's half depth at its slave nodes
        # the mean edge, summed in sorted order: the surface's facets come in the order of the ranks
        # that hold them, and the penalty (part of a checkpoint's fingerprint) must not depend on it
        self.h = float(np.mean(np.sort(np.linalg.norm(Xm[sm] - Xm[np.roll(sm, -1, axis=1)], axis=2), axis=None)))
        if law.penalty is not None:
            if not law.penalty > 0.0:
                raise ValueError(f"contact '{self.name}': the penalty must be positive, got {law.penalty}")
            self.penalty = float(law.penalty)
        else:
            moduli = [surf.modulus for surf in (self.slave, self.master) if surf.modulus is not None]
            if not moduli:
                raise ContactError(f"contact '{self.name}': between two beams the penalty has no solid to scale "
                                   "with: give it, e.g. dc.Penalty(penalty=...)")
            self.penalty = law.factor * min(moduli) / self.h
        self.smooth = bool(smooth)
        self._init_master()
        self.multiplier = np.zeros(len(self.area))
        self.margin = 0.5 * self.h
        # the interface's extent (its two surfaces' joint bounding box): no Newton correction
        # separates a slave from its master by more than this
        both = np.vstack([self.slave.X, Xm])
        self.size = float(np.linalg.norm(both.max(axis=0) - both.min(axis=0)))
        self.touch = 1e-6 * self.h  # a gap below this keeps the penalty stiffness (no force)
        self.uzawa_updates = 0
        self.after_update = False  # whether this step's Newton solve follows an Uzawa update (of any pass)
        # staged construction: the slaves and master segments that exist (None: all), and the
        # initial gaps taken as zero (approach I, :meth:`cancel_initial_gaps`), added to the offsets
        self.slave_on = self.segment_on = None
        self.exists = True  # (a stage may add or remove the interface)
        self.initial_gap = np.zeros(len(self.area))
        self.gap_cancelled = np.zeros(len(self.area), dtype=bool)
        # friction: each slave's stick point, the master segment and the parameter on its curve of
        # the material point it is attached to (−1: none, the slave is not in contact); the last
        # converged state, the same on every rank
        self.stick_segment = np.full(len(self.area), -1)
        self.stick_xi = np.zeros((len(self.area),) + self.STICK_SHAPE)
        # and the tangential multiplier λ_T (the augmented Lagrangian's, and the traction a slipping
        # slave carries, attached under itself): in 2D the traction along the master curve's unit
        # tangent, in 3D its components on the master face's convected basis (a₁, a₂, a₁ × a₂) at
        # the stick point (which turns with the face)
        self.stick_lambda = np.zeros((len(self.area),) + self.LAMBDA_SHAPE)
        # within a step: the stick points the step's evaluations use (a slave that touches, or
        # passes to another segment, gets its point at the first evaluation that needs it and keeps
        # it until the step converges, so that the step's tangent is the derivative of its forces)
        self.trial_segment = self.stick_segment.copy()
        self.trial_xi = self.stick_xi.copy()
        self.trial_lambda = self.stick_lambda.copy()
        self._friction_trial = None
        if friction is not None:
            self.tangential_penalty = friction.tangential_factor * self.penalty
        # the augmented Lagrangian's Uzawa updates act on the tangential traction as well
        self.augment_friction = bool(law.augmented and friction is not None and friction.slip_tolerance is not None)

    @property
    def master_surface(self) -> str:
        """The master surface the slaves meet, in words."""
        return "smooth master curve" if self.smooth else "straight master segments"

    @property
    def symmetric_tangent(self) -> bool:
        """Whether the pairs' tangents are symmetric (the Hessians of their energies; a slipping
        slave's traction follows its pressure: not with friction)."""
        return self.SYMMETRIC_TANGENT and self.friction is None

    @staticmethod
    def _tributary(X: np.ndarray, facets: np.ndarray) -> np.ndarray:
        """(n,) each node's share of the surface: its tributary length of the segments."""
        return tributary_lengths(X, facets)

    def _init_master(self) -> None:
        """What the search and the kernels need of the master segments: the segments at each
        node, and the nodes (p, a, b, q) of each segment's curve (p = a, q = b: straight)."""
        Xm, sm = self.master.X, self.master.facets
        self.valence = np.bincount(sm.ravel(), minlength=len(Xm))
        self.ext = (_smoothing_neighbours(Xm, sm, self.SMOOTH_ANGLE) if self.smooth
                    else np.column_stack([sm[:, 0], sm[:, 0], sm[:, 1], sm[:, 1]]))
        # each segment's neighbours along the surface, before its node a and after its node b (−1: an end of
        # the surface, or a node that more than two segments share)
        into, out = np.full(len(Xm), -1), np.full(len(Xm), -1)
        into[sm[:, 1]] = np.arange(len(sm))
        out[sm[:, 0]] = np.arange(len(sm))
        chain = self.valence == 2
        self.neighbours = (np.where(chain[sm[:, 0]], into[sm[:, 0]], -1), np.where(chain[sm[:, 1]], out[sm[:, 1]], -1))

    # -- binding to a system ---------------------------------------------------------
    def bind(self, system) -> None:
        """Global dofs of both surfaces in ``system``'s numbering; the dofs it constrains."""
        self.comm = self.slave.part.comm
        self.slave_gdofs, self.master_gdofs = (self._global_dofs(surf, system) for surf in (self.slave, self.master))
        self.constrained = system.constrained_global_dofs()
        n = len(self.area)
        # each rank evaluates the slaves whose x dof it owns
        start, stop = system.ownership_range()
        self.mine = np.flatnonzero((self.slave_gdofs[:, 0] >= start) & (self.slave_gdofs[:, 0] < stop))
        self.candidates = np.zeros((0, 2), dtype=np.int64)
        self.anchor = None  # slave and master positions at the last search
        self.pairs_changed = True
        self.active = np.full(n, -1)
        self._assigned = None
        self.first_evaluation = True
        self.had_contact = False
        self.predicting = False  # friction: the elastic predictor in this evaluation (a step tried again)
        self.band_used = 0
        self._virtual = None
        self.step_start = None  # slave and master positions at the start of the step (friction)
        self._update_existence()

    def kept_state(self):
        """What a restore brings back besides the multipliers (friction): the committed stick
        points and the step's own (a line search's restore within a step keeps the step's)."""
        if self.friction is None:
            return None
        return tuple(a.copy() for a in (self.stick_segment, self.stick_xi, self.stick_lambda, self.trial_segment,
                                         self.trial_xi, self.trial_lambda))

    def restore_kept(self, state) -> None:
        if state is not None:
            (self.stick_segment, self.stick_xi, self.stick_lambda, self.trial_segment, self.trial_xi,
             self.trial_lambda) = (a.copy() for a in state)

    def kept_faces(self) -> np.ndarray | None:
        """Each slave's master facet of the last evaluation, if the search keeps it (3D)."""
        return None

    def restore_faces(self, faces: np.ndarray) -> None:
        """Sets what :meth:`kept_faces` returns (a restart)."""

    def begin_step(self) -> None:
        """A step (or its retry after a cut) starts from the converged stick points."""
        self.trial_segment = self.stick_segment.copy()
        self.trial_xi = self.stick_xi.copy()
        self.trial_lambda = self.stick_lambda.copy()

    def note_step_start(self, converged: bool = False) -> None:
        """Keeps the slave and master positions of the last converged configuration (friction: a
        slave that touches in a step is attached where it was at the step's start, see
        :meth:`evaluate`): at a commit (``converged``), or at the start of a run's first step or of
        the first step after a restart (before any predictor moves the nodes). Collective."""
        if self.friction is not None and (converged or self.step_start is None):
            self.step_start = (self._positions(self.slave), self._positions(self.master))

    def commit(self) -> None:
        """The step converged: each slave in contact keeps its stick point and multiplier λ_T
        (sticking) or is attached under itself (s = 0), its traction becoming its λ_T (slipping:
        the next step starts on the slip surface, a reversal elastic); a slave out of contact has
        none."""
        if self.friction is None:
            return
        seg = np.full(len(self.area), -1)
        xi0 = np.zeros(len(self.area))
        lam0 = np.zeros(len(self.area))
        if self._friction_trial is not None:
            tr = self._friction_trial
            s = tr.s
            for k in np.flatnonzero(tr.p > 0.0):
                seg[s[k]] = tr.m[k]
                if tr.slipping[k]:
                    xi0[s[k]] = (vertex_stick_point(tr.x[k], tr.which[k], tr.start[k]) if tr.which[k] else
                                 slipped_stick_point(tr.x[k], tr.xi[k], tr.start[k], 0.0, self.tangential_penalty))
                    lam0[s[k]] = tr.t[k]
                else:
                    xi0[s[k]], lam0[s[k]] = tr.start[k], tr.lam_t[k]
        self.commit_stick_points(seg, xi0, lam0)

    def commit_stick_points(self, seg: np.ndarray, xi0: np.ndarray, lam0: np.ndarray) -> None:
        """The converged stick points: each rank's own slaves' segments or faces seg (−1 elsewhere),
        parameters xi0 and tangential multipliers lam0 (zero elsewhere), combined over the ranks
        (the same on every rank); the next step starts from them and from the converged
        positions."""
        self.stick_segment = np.empty_like(seg)
        self.stick_xi = np.empty_like(xi0)
        self.stick_lambda = np.empty_like(lam0)
        self.comm.Allreduce(seg, self.stick_segment, op=MPI.MAX)
        self.comm.Allreduce(xi0, self.stick_xi, op=MPI.SUM)
        self.comm.Allreduce(lam0, self.stick_lambda, op=MPI.SUM)
        self.begin_step()
        self.note_step_start(converged=True)

    def _stick_parameters(self, x: np.ndarray, s: np.ndarray, m: np.ndarray, xm: np.ndarray) -> np.ndarray:
        """The parameters ξ₀ (n,) of the slaves' stick points on the curves of their segments m
        (pairs x (n, 10); master positions xm): the committed one on the same segment; a slave that
        comes into contact is attached where it was at the step's start, projected onto the master
        as it was then (the segment it then faced: a material point of the master, whatever path the
        iterates take); one that has passed to another segment carries its stick point along the
        surface (:meth:`_carried`). A constant of the step's tangent."""
        xi0 = self.trial_xi[s].copy()
        old = self.trial_segment[s]
        _, now, ok = smooth_gap(x)
        a, b = x[:, 4:6], x[:, 6:8]  # (no closest point on the curve, a slave at a corner: the chord's, on it)
        chord = np.einsum("ij,ij->i", x[:, :2] - a, b - a) / np.einsum("ij,ij->i", b - a, b - a)
        now = np.where(ok, now, np.clip(chord, 0.0, 1.0))
        new = old < 0
        xi0[new] = now[new]
        if new.any() and self.step_start is not None:  # (None: evaluated outside a step)
            xs0, xm0 = self.step_start
            seg, then = self._faced(xs0[s[new]], m[new], xm0)
            xi0[new] = np.where(seg >= 0, self._carried(seg, then, m[new], xm), now[new])
        moved = np.flatnonzero(~new & (old != m))
        if len(moved):
            xi0[moved] = self._carried(old[moved], self.trial_xi[s[moved]], m[moved], xm)
        xi0 = np.where(np.isnan(xi0), now, xi0)  # (not along the surface within reach: attached where it is)
        changed = new | (old != m)
        self.trial_segment[s[changed]] = m[changed]
        self.trial_xi[s[changed]] = xi0[changed]
        self.trial_lambda[s[new]] = 0.0  # (a slave passing to the next segment keeps its traction)
        return xi0

    HOPS = 4  # how far along the surface (in segments) a stick point is followed

    def _faced(self, xs: np.ndarray, seg: np.ndarray, xm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The segments and parameters ξ ∈ [0, 1] of the closest points of the points xs (n, 2) on the
        master (positions xm), searched from the segments seg along the surface: a projection beyond an
        end of a segment's curve passes to the neighbour there (a segment's extrapolated curve is no
        material point of the master). Beyond a free end, the extrapolated parameter of the end segment;
        segment −1 where no projection was found."""
        seg, prev = seg.copy(), np.full(len(seg), -1)
        xi = np.full(len(seg), np.nan)
        todo = np.arange(len(seg))
        for _ in range(self.HOPS + 1):
            ext = self.ext[seg[todo]]
            _, t, ok = smooth_gap(np.hstack([xs[todo]] + [xm[ext[:, j]] for j in range(4)]))
            # (no projection on this curve: the side of the chord's projection tells the way on)
            a, b = xm[ext[:, 1]], xm[ext[:, 2]]
            way = np.where(ok, t, np.einsum("ij,ij->i", xs[todo] - a, b - a) / np.einsum("ij,ij->i", b - a, b - a))
            nb = np.where(way > 1.0, self.neighbours[1][seg[todo]],
                          np.where(way < 0.0, self.neighbours[0][seg[todo]], -1))
            back = (nb >= 0) & (nb == prev[todo])  # (beyond the node that two segments share: that node)
            xi[todo] = np.where(back, np.clip(way, 0.0, 1.0), t)
            go = (nb >= 0) & ~back
            seg[todo[~ok & ~go & ~back]] = -1
            todo, nb = todo[go], nb[go]
            prev[todo], seg[todo] = seg[todo], nb
            if not len(todo):
                break
        seg[todo], xi[todo] = prev[todo], np.clip(xi[todo], 0.0, 1.0)  # (not settled within reach: the last end)
        return seg, xi

    def _carried(self, seg: np.ndarray, xi: np.ndarray, target: np.ndarray, xm: np.ndarray) -> np.ndarray:
        """The parameters on the curves of the segments target (n,) of the points at ξ (n,) on the
        segments seg: followed along the surface segment by segment (at most HOPS), the parameter
        continued through each shared node at the rate of the curves' speeds |dx/dξ| there (positions
        xm): first-order exact at the node (a C¹ curve has the same speed on both sides, the
        continuation is ξ ∓ 1; a faceted one, the ratio of the lengths), and the same point when
        carried back. NaN where target is not within reach."""
        ext = self.ext
        # the speeds at the ends of each segment's curve: (x_b − x_p)/2 at ξ = 0, (x_q − x_a)/2 at ξ = 1
        speed = (np.linalg.norm(xm[ext[:, 2]] - xm[ext[:, 0]], axis=1),
                 np.linalg.norm(xm[ext[:, 3]] - xm[ext[:, 1]], axis=1))
        out = np.where(seg == target, xi, np.nan)
        for forward in (False, True):
            cur, t = seg.copy(), xi.copy()
            for _ in range(self.HOPS):
                live = np.flatnonzero((cur >= 0) & np.isnan(out))
                if not len(live):
                    break
                a = cur[live]
                b = self.neighbours[1 if forward else 0][a]
                has = b >= 0
                live, a, b = live[has], a[has], b[has]
                cur[:] = -1
                cur[live] = b
                if forward:
                    t[live] = (t[live] - 1.0) * speed[1][a] / speed[0][b]
                else:
                    t[live] = 1.0 + t[live] * speed[0][a] / speed[1][b]
                hit = live[b == target[live]]
                out[hit] = t[hit]
        return out

    @property
    def slave_offset(self) -> np.ndarray:
        """(n_slaves,) the distance of each slave's contact face from its node: a beam's half depth,
        plus the initial gap taken as zero (staged construction, approach I)."""
        return self.slave_face + self.initial_gap

    def _update_existence(self) -> None:
        """Which slaves and master segments exist (staged construction): a slave exists when an
        existing facet of its surface touches it, a segment when its element exists; none while
        the interface itself does not exist. The multipliers of slaves that do not exist are reset."""
        slave, master = self.slave.existence(self.comm), self.master.existence(self.comm)
        self.slave_on = None if slave is None else slave[1]
        self.segment_on = None if master is None else master[0]
        if not self.exists:
            self.slave_on = np.zeros(len(self.area), dtype=bool)
        if self.slave_on is not None:
            self.multiplier[~self.slave_on] = 0.0

    def _existing_pairs(self, pairs: np.ndarray) -> np.ndarray:
        keep = np.ones(len(pairs), dtype=bool)
        if self.slave_on is not None:
            keep &= self.slave_on[pairs[:, 0]]
        if self.segment_on is not None:
            keep &= self.segment_on[pairs[:, 1]]
        return pairs[keep]

    def cancel_initial_gaps(self, slaves: np.ndarray | None = None) -> int:
        """Approach I of staged construction (seed §3.1.2): an interface that appears cancels the
        initial deformation of the bodies it joins. Each existing slave (of ``slaves``, indices;
        None: all) that finds an existing master (within the search margin) for the first time
        takes its current gap — open or overlapping — as zero from now on (it is added to the
        slave's offset). Returns how many slaves did so (all ranks)."""
        xs, xm = self._positions(self.slave), self._positions(self.master)
        self.anchor = None
        self._search(xs, xm)
        segment, mode, sides = self._assign(xs, xm, self.candidates)
        s = self.mine[(segment[self.mine] >= 0) & ~self.gap_cancelled[self.mine]]
        if slaves is not None:
            s = s[np.isin(s, slaves)]
        g = np.zeros(len(self.area))
        done = np.zeros(len(self.area))
        if len(s):
            m = segment[s]
            lam = np.zeros(len(s))
            gs = np.zeros(len(s))
            self._pair_kernels(xs, xm, s, m, mode, sides, self.ext[m], lam, np.full(len(s), self.penalty),
                               self.touch, gs, np.zeros((len(s), 10)), np.zeros((len(s), 10, 10)),
                               np.zeros((len(s), 10)))
            g[s] = gs
            done[s] = 1.0
        return self._take_initial_gaps(g, done)

    def _take_initial_gaps(self, g: np.ndarray, done: np.ndarray) -> int:
        """The gaps ``g`` of the slaves this rank has ``done`` (1.0) become their initial gaps, over
        all ranks; returns how many slaves took theirs."""
        g = self.comm.allreduce(g, op=MPI.SUM)
        done = self.comm.allreduce(done, op=MPI.SUM) > 0.0
        self.initial_gap[done] = g[done]
        self.gap_cancelled |= done
        self.anchor = None
        return int(done.sum())

    def project_slaves(self, slaves: np.ndarray) -> np.ndarray:
        """(k, 2) positions of the slaves ``slaves`` (indices) moved onto the current existing master
        surface at zero gap (its contact face: a beam's at half its depth), along the master's
        normal from their current positions; NaN for a slave that finds no existing segment.
        Collective (all ranks get the same)."""
        self.comm = self.slave.part.comm
        self._update_existence()
        xs, xm = self._positions(self.slave), self._positions(self.master)
        seg = self.master.facets
        on = np.arange(len(seg)) if self.segment_on is None else np.flatnonzero(self.segment_on)
        out = np.full((len(slaves), 2), np.nan)
        if not len(on) or not len(slaves):
            return out
        a, b = xm[seg[on, 0]], xm[seg[on, 1]]
        ab = b - a
        for i, k in enumerate(slaves):
            # of the nearest segments, the one whose projection falls within it, or least beyond
            # its ends (at a sharp convex corner of the master the point is as near to both
            # segments' ends, and the projection on the wrong one lands far beyond it)
            t = np.clip(np.einsum("ij,ij->i", xs[k] - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
            dist = np.linalg.norm(xs[k] - a - t[:, None] * ab, axis=1)
            best = np.inf
            nearest = on[np.argsort(dist, kind="stable")[:4]]
            for m in nearest:
                x, xi = self._project_on_segment(xs[k], k, m, xm)
                if x is not None and max(-xi, xi - 1.0, 0.0) < best:
                    best, out[i] = max(-xi, xi - 1.0, 0.0), x
                    if best == 0.0:
                        break
            if best > self.XI_TOLERANCE:
                # outside a convex corner, beyond both segments: onto the corner's face (the
                # vertex, or the circle of the offsets around it)
                m = nearest[0]
                ends = xm[seg[m]]
                v = ends[np.argmin(np.linalg.norm(ends - xs[k], axis=1))]
                d = xs[k] - v
                r = self.slave_offset[k] + self.master_offset[m]
                out[i] = v + (r * d / np.linalg.norm(d) if np.linalg.norm(d) > 0.0 else 0.0)
        return out

    def _project_on_segment(self, point: np.ndarray, k: int, m: int, xm: np.ndarray):
        """``point`` (slave ``k``) moved along master segment ``m``'s normal onto its contact face
        (the C¹ curve, offsets included) at zero gap: (position, local coordinate ξ on the
        segment), or (None, None) if the iteration fails."""
        seg = self.master.facets
        t = xm[seg[m, 1]] - xm[seg[m, 0]]
        n = np.array([t[1], -t[0]]) / np.linalg.norm(t)  # outward: the body is on the left
        ext = self.ext[m]
        x, side = point.copy(), None
        for _ in range(50):
            g, xi, ok = smooth_gap(np.hstack([x] + [xm[ext[j]] for j in range(4)])[None, :])
            if not ok[0]:
                return None, None
            if side is None:
                side = -1.0 if (self.two_sided and g[0] < 0.0) else 1.0
            gap = side * g[0] - self.slave_offset[k] - self.master_offset[m]
            x -= side * gap * n
            if abs(gap) <= 1e-13 * self.h:
                _, xi, _ = smooth_gap(np.hstack([x] + [xm[ext[j]] for j in range(4)])[None, :])
                return x, float(xi[0])
        return None, None

    def _broad_phase(self, xs: np.ndarray, xm: np.ndarray) -> np.ndarray:
        """Candidate pairs (k, 2) [index into xs, segment]: the segments' boxes inflated by the
        margin and the offsets (beams: the surfaces lie up to half their depth from the axes the
        search sees)."""
        seg = self.master.facets
        reach = self.margin + self.slave_offset.max(initial=0.0) + self.master_offset.max(initial=0.0)
        return broad_phase(xs, xm[seg[:, 0]], xm[seg[:, 1]], reach)

    def pair_dofs(self, slaves: np.ndarray, segments: np.ndarray) -> np.ndarray:
        """Global dofs (k, 10) of slave–segment pairs (slave, p, a, b, q), −1 on constrained dofs
        (PETSc skips them in matrices)."""
        ext, gd = self.ext[segments], self.master_gdofs
        dofs = np.hstack([self.slave_gdofs[slaves]] + [gd[ext[:, j]] for j in range(4)])
        dofs[np.isin(dofs, self.constrained)] = -1
        return dofs

    def _global_dofs(self, surf, system) -> np.ndarray:
        """(n, gdim) global dofs of the surface's nodes' translations in ``system``, on every rank."""
        g = system.global_dofs(surf.part, surf.local_dofs().ravel()).reshape(-1, surf.gdim)
        gd = np.zeros((len(surf.keys), surf.gdim), dtype=np.int64)
        for pos, vals in zip(self.comm.allgather(surf.local), self.comm.allgather(g)):
            gd[pos] = vals
        return gd

    def _positions(self, surf) -> np.ndarray:
        return surf.positions(self.comm)

    def _search(self, xs, xm) -> None:
        moved = np.inf if self.anchor is None else max(
            np.abs(xs - self.anchor[0]).max(initial=0.0), np.abs(xm - self.anchor[1]).max(initial=0.0))
        if moved <= 0.5 * self.margin:
            return
        pairs = self._candidate_pairs(xs, xm)
        union = np.unique(np.vstack([self.candidates, pairs]), axis=0)
        grown = self.comm.allreduce(int(len(union) > len(self.candidates)), op=MPI.MAX)
        if grown:
            self.candidates = union
            self.pairs_changed = True
        self.anchor = (xs.copy(), xm.copy())

    def own_pairs(self, pairs: np.ndarray) -> np.ndarray:
        """The pairs (k, 2) whose slave this rank evaluates."""
        return pairs[np.isin(pairs[:, 0], self.mine)]

    def _candidate_pairs(self, xs, xm) -> np.ndarray:
        """(k, 2) [slave, master facet] of this rank's slaves near existing master facets."""
        pairs = self._broad_phase(xs[self.mine], xm)
        pairs[:, 0] = self.mine[pairs[:, 0]]
        return self._existing_pairs(pairs)

    def evaluate(self):
        """Forces and tangents of this rank's slaves at the current configuration.

        Returns (dofs (k, 10) global, f (k, 10), K (k, 10, 10), (slave, segment) (k,)) over the
        pairs in contact (p > 0)."""
        xs, xm = self._positions(self.slave), self._positions(self.master)
        self._search(xs, xm)
        seg = self.master.facets
        mine_pairs = self.candidates
        self.active[:] = -1
        # (a rank without candidates goes on as well: the steps below agree across ranks)
        # narrow phase over this rank's candidates on the smooth surface: each slave takes the
        # segment on which its closest point falls inside [0, 1] (a little beyond a free end of
        # the surface) with the smallest |g|, chosen afresh at every evaluation (the smooth curve
        # makes the choice continuous). A slave outside a sharp convex corner has none: it meets
        # the corner's vertex (node-to-vertex).
        self._assigned = self._assign(xs, xm, mine_pairs)
        segment, mode, sides = self._assigned
        s = self.mine[segment[self.mine] >= 0]
        m = segment[s]
        self.active[:] = -1
        self.active[s] = m
        n = len(s)
        ext = self.ext[m]
        g = np.zeros(n)
        f = np.zeros((n, 10))
        K = np.zeros((n, 10, 10))
        lam, eps = self.multiplier[s], np.full(n, self.penalty)
        touch = self.touch
        normal = np.zeros((n, 10))
        # bodies in contact at the start of the Newton solve whose pairs have all opened a little
        # at an iterate (a tangential step along a curved master lifts a slave) — a body held by
        # contact alone would have no stiffness there: then the pairs within a tenth of a segment
        # count as closed for the next correction — penalty stiffness in the tangent, and their
        # penalty force at the current gap (a pull, in the correction's right-hand side only, see
        # Contact.correction_rhs); the residual keeps the contact law. At most BAND_USES corrections
        # per Newton solve: bodies that really separate (held otherwise) are then left to do so
        self._virtual = None
        for attempt in range(2):
            self._pair_kernels(xs, xm, s, m, mode, sides, ext, lam, eps, touch, g, f, K, normal)
            if self.first_evaluation:  # the Newton solve's start: were the bodies in contact?
                self.first_evaluation = False
                self.had_contact = bool(self.comm.allreduce(
                    int(np.any(lam - self.penalty * g >= -self.penalty * self.touch)), op=MPI.MAX))
            closed = self.comm.allreduce(int(np.any(lam - self.penalty * g > 0.0)), op=MPI.MAX)
            if closed or attempt or not self.had_contact or self.band_used >= self.BAND_USES:
                break
            touch = 0.1 * self.h
        keep = (lam - self.penalty * g) >= -self.penalty * touch  # closed or touching
        gd = self.master_gdofs
        dofs = np.hstack([self.slave_gdofs[s]] + [gd[ext[:, j]] for j in range(4)])
        if touch > self.touch:
            pull = keep & (lam - self.penalty * g < 0.0)
            self._virtual = (s[pull], m[pull],
                             -(self.area[s[pull]] * (lam[pull] - self.penalty * g[pull]))[:, None] * normal[pull])
        self._last = (s, g)
        self._x = (xs, xm)
        self._forces = (s[keep], m[keep], f[keep])
        return dofs[keep], f[keep], K[keep], (s[keep], m[keep])

    def _pair_kernels(self, xs, xm, s, m, mode, sides, ext, lam, eps, touch, g, f, K, normal) -> None:
        """Gaps, forces, tangents and gap gradients of the assigned pairs into g (n,), f (n, 10),
        K (n, 10, 10), normal (n, 10) (zero for node-to-vertex pairs)."""
        g[:] = 0.0
        f[:] = 0.0
        K[:] = 0.0
        normal[:] = 0.0
        self._friction_trial = None
        law, trials = self.friction, []
        on = mode[s] == 0
        if on.any():
            i = np.flatnonzero(on)
            x = np.hstack([xs[s[i]], xm[ext[i, 0]], xm[ext[i, 1]], xm[ext[i, 2]], xm[ext[i, 3]]])
            offset = self.slave_offset[s[i]] + self.master_offset[m[i]]
            g[i], _, _, f[i], K[i], _, normal[i] = node_to_smooth_segment(x, sides[s[i]], offset, lam[i], eps[i],
                                                                          self.area[s[i]], True, touch)
            if self.friction is not None:  # the pairs with a pressure: Coulomb's law on the same curve
                closed = self._closed(lam[i], eps[i], g[i])
                j = i[closed]
                xj = x[closed]
                start = self._stick_parameters(xj, s[j], m[j], xm)
                lam_t = self.trial_lambda[s[j]]
                one = np.ones(len(j))
                gj, xij, pj, tj, _, slipping, fj, Kj = node_to_smooth_segment_friction(
                    xj, sides[s[j]], offset[closed], lam[j], eps[j], self.area[s[j]], self.tangential_penalty * one,
                    self._coefficient * one, law.cohesion * one, start, lam_t, True)
                f[j], K[j] = fj, Kj
                trials.append(FrictionTrial(s[j], m[j], xj, xij, start, tj, slipping, pj, lam_t,
                                            np.zeros(len(j), dtype=np.int64)))
        if (~on).any():
            normals = self._vertex_normals(xm)
            for k in (1, 2):
                i = np.flatnonzero(mode[s] == k)
                if not len(i):
                    continue
                v = ext[i, k]
                # a beam master (either side of its axis): the side is the slave's, the face half
                # the beam's depth around its kink
                normal_v = xs[s[i]] - xm[v] if self.two_sided else normals[v]
                offset = self.slave_offset[s[i]] + self.master_offset[m[i]]
                gv, _, fv, Kv = node_to_vertex(xs[s[i]], xm[v], normal_v, offset, lam[i],
                                               eps[i], self.area[s[i]], True, touch)
                idx = np.array([0, 1, 2 * k + 2, 2 * k + 3])
                g[i] = gv
                f[np.ix_(i, idx)] = fv
                K[np.ix_(i, idx, idx)] = Kv
                if self.friction is not None:  # Coulomb's law at the corner, the stick point on the segment
                    closed = self._closed(lam[i], eps[i], gv)
                    j = i[closed]
                    xj = np.hstack([xs[s[j]]] + [xm[ext[j, c]] for c in range(4)])
                    start = self._stick_parameters(xj, s[j], m[j], xm)
                    lam_t = self.trial_lambda[s[j]]
                    one = np.ones(len(j))
                    which = np.full(len(j), k)
                    _, pj, tj, _, slipping, fj, Kj = node_to_vertex_friction(
                        xj, which, normal_v[closed], offset[closed], lam[j], eps[j], self.area[s[j]],
                        self.tangential_penalty * one, self._coefficient * one, law.cohesion * one, start, lam_t,
                        True)
                    f[j], K[j] = fj, Kj
                    trials.append(FrictionTrial(s[j], m[j], xj, np.full(len(j), k - 1.0), start, tj, slipping, pj,
                                                lam_t, which))
        if trials:
            self._friction_trial = FrictionTrial(*(np.concatenate(parts) for parts in zip(*trials)))

    @property
    def _coefficient(self) -> float:
        """Coulomb's μ for this evaluation: infinite in the elastic predictor (the first evaluation
        of a step tried again, :meth:`Contact.another_start`), where every slave in contact sticks
        (t = λ_T + ε_T s, the stick tangent): the step's first correction is then elastic, the right
        one for a reversal."""
        return np.inf if self.predicting else self.friction.coefficient

    def _closed(self, lam: np.ndarray, eps: np.ndarray, g: np.ndarray) -> np.ndarray:
        """The pairs with friction: those with a pressure above the touch band's (the round-off of
        bodies that touch unloaded has no friction: its cone, of that size, would turn the
        traction with the round-off)."""
        return np.flatnonzero(lam - eps * g > self.penalty * self.touch)

    def _assign(self, xs, xm, pairs):
        """(segment, mode, side), each (n_slaves,), of this rank's candidate pairs: mode 0 on the
        segment, 1 / 2 at its vertex a / b (a sharp corner); segment −1: no contact partner; side
        −1 for a slave on the far side of a beam's axis (two-sided masters), else 1."""
        n = len(self.area)
        ext = self.ext[pairs[:, 1]]
        x = np.hstack([xs[pairs[:, 0]]] + [xm[ext[:, j]] for j in range(4)])
        g, xi, ok = smooth_gap(x)
        side = np.where(g < 0.0, -1.0, 1.0) if self.two_sided else np.ones(len(g))
        g = side * g - self.slave_offset[pairs[:, 0]] - self.master_offset[pairs[:, 1]]
        lo = np.where(self.valence[ext[:, 1]] >= 2, -1e-9, -self.XI_TOLERANCE)
        hi = np.where(self.valence[ext[:, 2]] >= 2, 1.0 + 1e-9, 1.0 + self.XI_TOLERANCE)
        # a pair counts within the search margin outside and one mean segment length inside: the
        # candidates of a wild Newton iterate stay in the list, and the far side of a body is no
        # partner
        valid = ok & (xi >= lo) & (xi <= hi) & (g > -self.h) & (g < self.margin)
        segment = np.full(n, -1)
        mode = np.zeros(n, dtype=np.int64)
        sides = np.ones(n)
        if valid.any():
            v = np.flatnonzero(valid)
            order = np.lexsort((pairs[v, 1], np.abs(g[v]), pairs[v, 0]))  # by slave, |g|, segment
            first = v[order][np.r_[True, np.diff(pairs[v[order], 0]) != 0]]
            segment[pairs[first, 0]] = pairs[first, 1]
            sides[pairs[first, 0]] = side[first]
        # slaves without a projection: the closest point of the straight surface, if it is a sharp
        # vertex shared by two segments (outside a convex corner) within the search margin; a
        # beam's kink is rounded by its thickness (the face at half its depth around the vertex)
        rest = pairs[segment[pairs[:, 0]] < 0]
        if len(rest):
            seg = self.master.facets
            near, t = narrow_phase(xs, xm[seg[:, 0]], xm[seg[:, 1]], rest)
            end = np.where(t < 0.0, 0, 1)
            m = np.maximum(near, 0)
            vertex = seg[m, end]
            sharp = np.where(end == 0, self.ext[m, 0] == self.ext[m, 1], self.ext[m, 3] == self.ext[m, 2])
            close = np.linalg.norm(xs - xm[vertex], axis=1) - self.slave_offset - self.master_offset[m] < self.margin
            corner = (near >= 0) & ((t < 0.0) | (t > 1.0)) & (self.valence[vertex] >= 2) & sharp & close
            # of the two segments at the vertex, the one whose normal is the closer to the slave's
            # direction from it (what friction at the corner measures its slip along)
            other = np.where(end == 0, self.neighbours[0][m], self.neighbours[1][m])
            j = np.flatnonzero(corner & (other >= 0))
            if len(j):
                d = xs[j] - xm[vertex[j]]

                def facing(k):
                    chord = xm[seg[k, 1]] - xm[seg[k, 0]]
                    return (d[:, 0] * chord[:, 1] - d[:, 1] * chord[:, 0]) / np.linalg.norm(chord, axis=1)

                listed = np.isin(j * len(seg) + other[j], rest[:, 0] * len(seg) + rest[:, 1])  # (a candidate pair)
                swap = j[(facing(other[j]) > facing(near[j])) & listed]
                near[swap], end[swap] = other[swap], 1 - end[swap]
            segment[corner] = near[corner]
            mode[corner] = 1 + end[corner]
        return segment, mode, sides

    def _vertex_normals(self, xm: np.ndarray) -> np.ndarray:
        """Unit averaged outward normals (n_master, 2) of the master nodes (current)."""
        seg = self.master.facets
        t = xm[seg[:, 1]] - xm[seg[:, 0]]
        n = np.column_stack([t[:, 1], -t[:, 0]]) / np.linalg.norm(t, axis=1)[:, None]
        out = np.zeros_like(xm)
        np.add.at(out, seg[:, 0], n)
        np.add.at(out, seg[:, 1], n)
        norm = np.linalg.norm(out, axis=1)
        return out / np.where(norm > 0.0, norm, 1.0)[:, None]

    def describe(self) -> dict:
        """What defines the interface (for the scene's fingerprint and ``Scene.effects``)."""
        return {"slaves": self.slave_spec[1], "masters": self.master_spec[1], "law": repr(self.law),
                "smooth": self.smooth, "penalty": fingerprint_float(self.penalty), "slave_nodes": len(self.area),
                "master_segments": len(self.master.facets),
                **({"friction": repr(self.friction)} if self.friction is not None else {})}

    def correction_ratio(self, ds: np.ndarray, dm: np.ndarray) -> float:
        """How far a Newton correction (ds (n_slaves, 2), dm (n_master, 2) of all nodes) moves this
        rank's slaves relative to their masters, as a multiple of what is allowed (≤ 1: allowed).

        The motion of a slave relative to the point of the master surface it faces,
        Δr = Δx_s − Δx_master(ξ), is split along the master's normal n and tangent:

        * sliding (tangential) at most the search margin, half a master segment: further, the
          closest point and the active set change several times within one linearization;
        * approach at most the current gap plus the margin: the slave ends at most half a
          segment inside the master (a pair is a partner down to one segment length inside);
        * separation at most the interface's extent.

        A slave without a partner (open beyond the margin, or beyond a free end) is referred to its
        nearest master node: it may approach it by its distance, slide by that plus the margin.
        Bodies that move together (a lining pressed into soft ground with the soil's surface)
        are not held back: only relative motion counts, whatever the size of the correction."""
        if not len(self.mine):
            return 0.0
        xs, xm = self._x
        segment, mode, sides = self._assigned
        seg = self.master.facets
        mine = self.mine
        sm = segment[mine]
        worst = 0.0
        gap = np.full(len(self.area), np.inf)
        s_last, g_last = self._last
        gap[s_last] = g_last
        # slaves facing a master segment (mode 0) or vertex (mode 1, 2)
        on = mine[(sm >= 0) & (mode[mine] == 0)]
        if len(on):
            m = segment[on]
            a, b = seg[m, 0], seg[m, 1]
            d = xm[b] - xm[a]
            l2 = np.einsum("ij,ij->i", d, d)
            xi = np.clip(np.einsum("ij,ij->i", xs[on] - xm[a], d) / l2, 0.0, 1.0)
            rel = ds[on] - ((1.0 - xi)[:, None] * dm[a] + xi[:, None] * dm[b])
            t = d / np.sqrt(l2)[:, None]
            n = sides[on][:, None] * np.column_stack([t[:, 1], -t[:, 0]])  # towards the slave's side
            worst = max(worst, self._ratio(rel, n, np.maximum(gap[on], 0.0) + self.margin, self.margin))
        at = mine[(sm >= 0) & (mode[mine] > 0)]
        if len(at):
            m = segment[at]
            v = seg[m, mode[at] - 1]
            u = xs[at] - xm[v]
            u /= np.maximum(np.linalg.norm(u, axis=1), 1e-300)[:, None]
            worst = max(worst, self._ratio(ds[at] - dm[v], u, np.maximum(gap[at], 0.0) + self.margin, self.margin))
        free = mine[sm < 0]
        if len(free):
            from scipy.spatial import cKDTree

            dist, v = cKDTree(xm).query(xs[free])
            u = (xs[free] - xm[v]) / np.maximum(dist, 1e-300)[:, None]
            worst = max(worst, self._ratio(ds[free] - dm[v], u, np.maximum(dist, self.margin),
                                           dist + self.margin))
        return worst

    def _ratio(self, rel, n, approach, slide) -> float:
        """Largest of |sliding| / slide, approach / approach and separation / extent over the
        relative corrections rel (k, 2) with unit normals n (k, 2) pointing to the slaves."""
        normal = np.einsum("ij,ij->i", rel, n)
        sliding = np.linalg.norm(rel - normal[:, None] * n, axis=1)
        ratio = np.maximum(sliding / slide, np.maximum(-normal / approach, normal / self.size))
        return float(ratio.max(initial=0.0))

    def gaps(self) -> tuple[np.ndarray, np.ndarray]:
        """(slave indices, gaps) of this rank's slaves that have a master segment now."""
        return self._last

    def augment(self) -> bool:
        """Uzawa update λ ← ⟨λ − ε g⟩ if the largest |g| of the pairs in contact exceeds the
        tolerance, or, with friction, the largest elastic slip of the sticking slaves exceeds its
        own (all ranks agree); the tangential multipliers are updated with the normal ones (see
        :meth:`augment_tangential`). Returns whether the multipliers changed."""
        if not self.law.augmented:
            return False
        s, g = self._last
        # in contact (p > 0) the gap should vanish: penetration, or an opening the pressure holds
        closed = self.multiplier[s] - self.penalty * g > 0.0
        error = self.comm.allreduce(float(np.max(np.abs(g[closed]), initial=0.0)), op=MPI.MAX)
        slip_error = self.stick_slip() if self.augment_friction else 0.0
        logger.debug("contact %s: largest |g| of closed pairs %.3e (tolerance %.3e), largest elastic slip in "
                     "stick %.3e, %d updates", self.name, error, self.law.gap_tolerance * self.h, slip_error,
                     self.uzawa_updates)
        if self.uzawa_updates >= self.law.max_updates or (
                error <= self.law.gap_tolerance * self.h and
                (not self.augment_friction or slip_error <= self.friction.slip_tolerance * self.h)):
            return False
        if self.augment_friction:
            self.augment_tangential()
        new = np.zeros_like(self.multiplier)
        new[s] = np.maximum(0.0, self.multiplier[s] - self.penalty * g)
        lam = np.zeros_like(new)
        self.comm.Allreduce(new, lam, op=MPI.SUM)
        self.multiplier[:] = lam
        self.uzawa_updates += 1
        return True

    def stick_slip(self) -> float:
        """The largest elastic slip |s| = |t − λ_T|/ε_T of the sticking slaves at the last
        evaluation (all ranks); what the tangential Uzawa updates drive to zero."""
        worst = 0.0
        if self._friction_trial is not None:
            tr = self._friction_trial
            stick = ~tr.slipping & (tr.p > 0.0)
            worst = float(np.max(np.abs(tr.t[stick] - tr.lam_t[stick]), initial=0.0)) / self.tangential_penalty
        return self.comm.allreduce(worst, op=MPI.MAX)

    def augment_tangential(self) -> None:
        """Uzawa update of the tangential multipliers (Simo & Laursen 1992, the augmented
        Lagrangian of Coulomb friction): λ_T ← t at every sticking slave, which keeps its stick
        point, so that the next solve draws it back to the point: its elastic slip, the penalty's
        error, goes to zero while λ_T takes the traction. A slipping slave's traction is c + μp
        whatever λ_T: it keeps both."""
        if self._friction_trial is None:
            return
        tr = self._friction_trial
        stick = ~tr.slipping & (tr.p > 0.0)
        self.trial_lambda[tr.s[stick]] = tr.t[stick]

    def pressure(self, current: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Coordinates (n, gdim) and contact pressure (n,) of all slave nodes of this pass, on every
        rank, at the last evaluation: the nominal pressure ⟨λ − ε g⟩ per reference length (area)
        with the reference coordinates, or (``current``) the nodal force per current tributary
        length (area) of the slave surface (a beam's axis), with the current coordinates. In two-pass contact this is
        one pass's share; :meth:`ContactPair.pressure <dolfinx_corot.contact.ContactPair.pressure>`
        gives the interface pressure (both passes, on the actual contact face)."""
        s, g = self._last
        p = np.zeros(len(self.area))
        p[s] = np.maximum(0.0, self.multiplier[s] - self.penalty * g)
        out = np.zeros_like(p)
        self.comm.Allreduce(p, out, op=MPI.SUM)
        if not current:
            return self.slave.X, out
        x = self._positions(self.slave)
        return x, out * self.area / self._tributary(x, self.slave.facets)

    def friction_traction(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The friction at the last evaluation, on every rank, for all slave nodes of this pass:
        their reference coordinates (n, gdim), tangential traction (force per reference length
        (area), as :meth:`pressure`) and whether they slip (n,) bool. In 2D the traction is the
        scalar t along the master curve's unit tangent τ at the contact point (the direction of
        its segments' numbering), positive where the slave has moved along τ from its stick point:
        the force on the slave is −t τ per length; in 3D (n, 3), the traction vector t with the
        force −t per area on the slave. Zero (and not slipping) at open slaves, and everywhere
        without friction."""
        n = len(self.area)
        t = np.zeros((n, 3)) if self.slave.gdim == 3 else np.zeros(n)
        slip = np.zeros(n)
        if self._friction_trial is not None:
            tr = self._friction_trial
            t[tr.s] = tr.t
            slip[tr.s] = tr.slipping
        out_t, out_slip = np.zeros_like(t), np.zeros_like(slip)
        self.comm.Allreduce(t, out_t, op=MPI.SUM)
        self.comm.Allreduce(slip, out_slip, op=MPI.SUM)
        return self.slave.X, out_t, out_slip > 0.5

    @property
    def contact_forces(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The pairs in contact at the last evaluation, this rank's: slave nodes (k,), their
        master segments (k,) and the contact shares of the internal forces (k, 10): slave node
        (x, y), then the four nodes of the segment's Hermite stencil."""
        return self._forces

    def master_pressure(self, current: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Contact pressure on the master side of this pass: the contact forces on each master node
        over its tributary length of the master surface (n_master,), with the nodes' coordinates
        (n_master, 2), on every rank (see :meth:`pressure` for the interface pressure)."""
        s, m, f = self.contact_forces
        seg = self.master.facets
        force = np.zeros((len(self.master.X), 2))
        for j in range(4):
            np.add.at(force, self.ext[m, j], f[:, 2 * j + 2:2 * j + 4])
        total = np.zeros_like(force)
        self.comm.Allreduce(force, total, op=MPI.SUM)
        length = tributary_lengths(self.master.X, seg)
        x = self._positions(self.master) if current else self.master.X
        return x, np.linalg.norm(total, axis=1) / length


def _positive_part(K: np.ndarray, symmetric: bool = True) -> np.ndarray:
    """The pair tangents (k, n, n) with their negative eigenvalues set to zero; an unsymmetric
    tangent keeps its skew part, its symmetric part projected."""
    skew = 0.0
    if not symmetric:
        K, skew = 0.5 * (K + K.transpose(0, 2, 1)), 0.5 * (K - K.transpose(0, 2, 1))
    lam, vec = np.linalg.eigh(K)
    return np.einsum("kij,kj,klj->kil", vec, np.maximum(lam, 0.0), vec) + skew


class Contact(Contribution):
    """The contact interfaces of a scene as one contribution of the system.

    Residual: every interface evaluated at the current configuration (search,
    pairs, kernels); tangent: the pairs' blocks over the candidate pairs, whose
    10 × 10 dof blocks are the declared couplings. Newton hooks: a Newton solve's
    first tangent is exact; after a rise of the residual the next tangent keeps
    the positive part of each pair's tangent; corrections are capped so that no
    slave slides more than half a master segment relative to its master (the normal approach of
    bodies moving together is free, see :meth:`Interface.correction_ratio`); the line search
    is asked for while any pair is a candidate; lifted pairs of bodies that were
    touching may count as closed for a few corrections (:meth:`correction_rhs`);
    after convergence, Uzawa updates of augmented-Lagrangian multipliers.
    State: the multipliers (and, for files, the candidate pairs and the positions
    of the last search).
    """

    name = "contact"

    def __init__(self, interfaces):
        self.interfaces = list(interfaces)
        # Newton sets this after an iteration that raised the residual: the next tangent keeps only
        # the positive part of each pair's tangent (the curvature terms of a slave pressed on a
        # convex master can make an intermediate iterate's tangent indefinite)
        self.project = False
        self._engaged = False
        self._blocks = []
        # friction: a step that failed is tried again, before it is cut, from the elastic predictor
        self._elastic_start = False
        self._restarted = False
        self._friction = any(itf.friction is not None for itf in self.interfaces)

    def bind(self, system) -> None:
        for itf in self.interfaces:
            itf.bind(system)
        self.comm = system.comm

    @property
    def symmetric_tangent(self) -> bool:
        """Node-to-segment and node-to-face tangents are the Hessians of the pairs' energies;
        mortar tangents are not symmetric."""
        return all(itf.symmetric_tangent for itf in self.interfaces)

    # -- couplings and assembly ---------------------------------------------------------
    @property
    def couplings_changed(self) -> bool:
        return any(itf.pairs_changed for itf in self.interfaces)

    @couplings_changed.setter
    def couplings_changed(self, value: bool) -> None:
        for itf in self.interfaces:
            itf.pairs_changed = bool(value)

    def couplings(self) -> np.ndarray:
        """The dofs of every candidate pair of this rank (2D: slave, p, a, b, q; 3D: the slave and a
        face's nodes, or a slave face's and a master face's), padded with −1 to one width."""
        blocks = [itf.pair_dofs(itf.candidates[:, 0], itf.candidates[:, 1]) for itf in self.interfaces]
        if not blocks:
            return np.zeros((0, 10), dtype=np.int64)
        width = max(b.shape[1] for b in blocks)
        return np.concatenate([np.pad(b, ((0, 0), (0, width - b.shape[1])), constant_values=-1) for b in blocks])

    def engaged(self) -> bool:
        return any(len(itf.candidates) for itf in self.interfaces)

    def add_residual(self, add) -> None:
        self._blocks = []
        for itf in self.interfaces:
            dofs, f, K, pairs = itf.evaluate()
            itf.predicting = False
            self._blocks.append((K, pairs))
            add(dofs, f)
        # some pair is a candidate: the bodies are near each other (Newton's safeguards apply)
        self._engaged = bool(self.comm.allreduce(sum(len(itf.candidates) for itf in self.interfaces), op=MPI.SUM))

    def add_tangent(self, add) -> None:
        for itf, (K, (s, m)) in zip(self.interfaces, self._blocks):
            if len(s):
                add(itf.pair_dofs(s, m), _positive_part(K, itf.symmetric_tangent) if self.project else K)

    def start_stage(self, approach: str) -> None:
        """Approach I: each slave meeting a master for the first time takes its gap as zero
        (:meth:`Interface.cancel_initial_gaps`)."""
        if approach == "I":
            for itf in self.interfaces:
                n = itf.cancel_initial_gaps()
                if n:
                    logger.info("contact '%s': %d slave(s) take their initial gap as zero (approach I)", itf.name, n)

    # -- Newton hooks -----------------------------------------------------------------
    def before_step(self) -> None:
        for itf in self.interfaces:
            itf.uzawa_updates = 0
            itf.after_update = False
            itf.begin_step()
            itf.note_step_start()
            itf.predicting = self._elastic_start and itf.friction is not None

    def another_start(self) -> bool:
        """A step failed: with friction, it is tried again from the elastic predictor (every slave
        in contact sticks in the step's first evaluation, :attr:`Interface._coefficient`), once,
        before the driver cuts it. Newton's first correction from the last step's slip state lets a
        slave that slipped slide freely along its old slip; where the load turns back (a
        reversal), whose first response is elastic, that start does not converge."""
        if not self._friction or self._elastic_start:
            return False
        self._elastic_start = True
        return True

    def before_solve(self) -> None:
        """A Newton solve starts: its first tangent is the exact one; each interface notes whether
        its bodies touch at the start."""
        self.project = False
        for itf in self.interfaces:
            itf.first_evaluation = True
            itf.band_used = 0

    def after_iteration(self, residuals) -> None:
        self.project = len(residuals) > 1 and residuals[-1] > residuals[-2]

    def needs_line_search(self) -> bool:
        return self._engaged

    def correction_rhs(self):
        """When an interface predicts pairs that are open now to be closed (see
        :meth:`Interface.evaluate`): their penalty forces at the current gaps, to be taken out of
        the next correction's right-hand side; None otherwise (all ranks agree)."""
        virtual = [(itf, itf._virtual) for itf in self.interfaces if itf._virtual is not None]
        if not self.comm.allreduce(sum(len(v[0]) for _, v in virtual), op=MPI.SUM):
            return None
        dofs, forces = [np.zeros((0, 10), dtype=np.int64)], [np.zeros((0, 10))]
        for itf, (s, m, f) in virtual:
            itf.band_used += 1
            if len(s):
                dofs.append(itf.pair_dofs(s, m))
                forces.append(f)
        return np.concatenate(dofs), np.concatenate(forces)

    def limit_correction(self, dx) -> float:
        """A factor ≤ 1 for the Newton correction ``dx`` that keeps every slave's motion relative to
        its master within bounds (:meth:`Interface.correction_ratio`): sliding at most half a
        master segment — a correction that would carry a slave several segments along a surface
        comes from a tangent linearized far from there (e.g. indefinite at an intermediate
        iterate) and is shortened, the next iterations continue from the shorter step — and
        approach at most to half a segment inside the master. The normal approach of bodies that
        move together (a beam or lining pressed into soft ground) is not limited."""
        if not self._engaged:
            return 1.0
        start, stop = dx.getOwnershipRange()
        values = dx.getArray(readonly=True)
        worst = 0.0
        for itf in self.interfaces:
            moves = []
            for gd in (itf.slave_gdofs, itf.master_gdofs):
                own = (gd >= start) & (gd < stop)
                d = np.zeros(gd.shape)
                d[own] = values[gd[own] - start]
                total = np.zeros_like(d)
                self.comm.Allreduce(d, total, op=MPI.SUM)
                moves.append(total)
            worst = max(worst, itf.correction_ratio(*moves))
        worst = self.comm.allreduce(worst, op=MPI.MAX)
        return 1.0 if worst <= 1.0 else 1.0 / worst

    def commit(self) -> None:
        """The step converged: the interfaces' stick points (friction) become the converged ones."""
        for itf in self.interfaces:
            itf.commit()
        self._restarted, self._elastic_start = self._elastic_start, False

    def on_converged(self) -> bool:
        """One Uzawa update on every augmented interface that needs it; True if any changed."""
        changed = any([itf.augment() for itf in self.interfaces])
        for itf in self.interfaces:  # the next solve starts from a converged state
            itf.after_update = itf.after_update or changed
        return changed

    def history(self, report) -> dict:
        out = {"uzawa_updates": report.updates}
        if self._friction:  # the step needed the elastic predictor (its first attempt failed)
            out["elastic_restarts"] = int(self._restarted)
        return out

    # -- state ------------------------------------------------------------------------
    def checkpoint(self):
        return [(itf.multiplier.copy(), itf.kept_state()) for itf in self.interfaces]

    def restore(self, state) -> None:
        for itf, (lam, kept) in zip(self.interfaces, state):
            itf.multiplier[:] = lam
            itf.restore_kept(kept)

    def state_arrays(self) -> dict:
        """Multipliers, candidate pairs (all ranks') and the positions of the last search."""
        out = {}
        for k, itf in enumerate(self.interfaces):
            out[f"{k}_multiplier"] = itf.multiplier.copy()
            out[f"{k}_initial_gap"] = itf.initial_gap.copy()
            out[f"{k}_gap_cancelled"] = itf.gap_cancelled.astype(float)
            cand = np.concatenate(self.comm.allgather(itf.candidates)).reshape(-1, 2)
            out[f"{k}_candidates"] = np.unique(cand, axis=0)
            kept = itf.kept_faces()
            if itf.friction is not None:  # the stick points (the same on every rank)
                out[f"{k}_stick_segment"] = itf.stick_segment.astype(float)
                out[f"{k}_stick_xi"] = itf.stick_xi.copy()
                out[f"{k}_stick_lambda"] = itf.stick_lambda.copy()
            if kept is not None:  # each rank's own slaves' faces
                mine = np.full(len(kept), -1, dtype=np.int64)
                mine[itf.mine] = kept[itf.mine]
                every = np.empty_like(mine)
                self.comm.Allreduce(mine, every, op=MPI.MAX)  # (a pickled MAX of arrays fails)
                out[f"{k}_kept"] = every.astype(float)
            if itf.anchor is not None:
                out[f"{k}_anchor_slave"], out[f"{k}_anchor_master"] = itf.anchor
        return out

    def set_state_arrays(self, arrays: dict) -> None:
        for k, itf in enumerate(self.interfaces):
            lam = arrays[f"{k}_multiplier"]
            if lam.shape != itf.multiplier.shape:
                raise ValueError(f"contact '{itf.name}': the checkpoint holds {len(lam)} slave nodes, the "
                                 f"interface has {len(itf.multiplier)}")
            itf.multiplier[:] = lam
            if f"{k}_initial_gap" in arrays:  # (staged construction, approach I)
                itf.initial_gap[:] = arrays[f"{k}_initial_gap"]
                itf.gap_cancelled[:] = arrays[f"{k}_gap_cancelled"] > 0.5
            cand = arrays[f"{k}_candidates"].astype(np.int64).reshape(-1, 2)
            itf.candidates = itf.own_pairs(cand)
            itf.pairs_changed = True
            if f"{k}_kept" in arrays:
                itf.restore_faces(arrays[f"{k}_kept"].astype(np.int64))
            if f"{k}_stick_segment" in arrays:
                itf.stick_segment[:] = arrays[f"{k}_stick_segment"].astype(np.int64)
                itf.stick_xi[:] = arrays[f"{k}_stick_xi"].reshape(itf.stick_xi.shape)
                if f"{k}_stick_lambda" in arrays:  # (a checkpoint written before the tangential multipliers: zero)
                    itf.stick_lambda[:] = arrays[f"{k}_stick_lambda"].reshape(itf.stick_lambda.shape)
                itf.begin_step()
                itf.step_start = None  # (taken when the next step starts, from the restored state)
            if f"{k}_anchor_slave" in arrays:
                itf.anchor = (arrays[f"{k}_anchor_slave"].copy(), arrays[f"{k}_anchor_master"].copy())

    def describe(self) -> dict:
        return {"name": self.name, "interfaces": [itf.describe() for itf in self.interfaces]}

r"""Stabilisation of bodies that are free until contact closes: springs to ground that are
re-anchored until they carry nothing.

A body held by contact alone — a tunnel lining in a hole larger than itself, a
block above its support, a frictionless ring that may spin in a circular hole —
has no stiffness in some directions while its interfaces are open: the tangent
is singular and Newton cannot start. :class:`Stabilisation` adds to the
translations (and the planar rotations of 2D structures) of the nodes of each
stabilised part a spring to ground that acts on the motion since an *anchor*
:math:`\mathbf a`,

.. math:: \mathbf f_s = k\,(\mathbf u - \mathbf a), \qquad \mathbf K_s = k\,\mathbf I,

with the anchor at the configuration where the springs were last released (at
first the initial one). After every converged Newton solve whose spring
forces exceed ``tolerance`` times the residual's reference force (the larger
of the load and internal-force norms, as Newton's own test), the anchors move
to the current configuration and Newton solves again at the same load factor. Each solve is a step of the
proximal-point method (Rockafellar 1976) on the total potential,
:math:`\min_u \Pi(u) + \tfrac12 k\,|u - a|^2`, whose fixed points are the
equilibria of the model without springs:

* once contact (or any support) holds the body with stiffness K, the spring
  force falls by about k/K at each re-anchoring, and the converged answer is
  the answer without stabilisation to ``tolerance``;
* while the body is still free in a loaded direction, each solve moves it by
  its unbalanced load over k: it crosses a gap in pseudo-time, as with the
  viscous contact stabilisation of commercial codes (Abaqus ``*CONTACT
  CONTROLS, STABILIZE``), here on the increment of each solve rather than on a
  velocity; at most ``max_updates`` re-anchorings are made per step;
* the tangent keeps k I throughout, so rigid motions that contact leaves free
  (a frictionless ring spinning in a circular hole) stay regular; when a
  small force drives such a motion (the torque of discretised contact on the
  ring) and, below ``FREE_FORCE`` of the load, no longer halves from one
  re-anchoring to the next, re-anchoring stops and the springs hold it — the
  force is reported, and a step that ends with more than ``FREE_FORCE`` on
  the springs is reported with a warning (the part is not held).

Rotations of 3D structures (quaternion states) carry no springs: the
translational springs remove the rigid motions of any part whose nodes are
not on one line (the twist of a single straight 3D member stays free).

The springs absorb the work :math:`\tfrac12 k\,|u - a|^2`, released (dissipated) at
each re-anchoring; its sum (released and still held) and the springs' force
relative to the load at the end of each step are history columns
(``stab_work``, ``stab_force``; ``stab_peak`` the largest relative force in
the step before re-anchoring, ``stab_updates`` the re-anchorings).

Default spring stiffness: ``factor`` times the mean diagonal entry of the part's
own tangent over its translational (rotational) dofs, computed once when the
system is built; a stiffness given in the scene replaces it.

Reference: R. T. Rockafellar (1976), Monotone operators and the proximal point
algorithm, SIAM J. Control Optim. 14(5), 877–898.
"""
from __future__ import annotations

import logging
import math

import numpy as np
from mpi4py import MPI

import dolfinx.fem

from . import validate
from .assembly import petsc
from .assembly.contribution import Contribution
from .parts import PartRef

logger = logging.getLogger(__name__)

# springs whose force, below this fraction of the load, no longer halves from one re-anchoring to the
# next hold a motion that nothing else holds: re-anchoring stops; above it the body is taken to be on
# its way across a gap (re-anchoring goes on), and a step that ends so is reported with a warning
FREE_FORCE = 1e-3


class Stabiliser:
    """The springs of one part (see the module docstring): made by ``Scene.stabilise`` and kept by the
    scene; bound to each system that solves it (anchors at the configuration then, work from zero;
    the stiffness, once computed, is kept).

    part: the part (from ``Scene.add_*``); where: a group of the part's mesh (None: every node of
    the part's cells); stiffness: translational spring per node (force per length; None: ``factor``
    times the mean diagonal of the part's tangent); rotational_stiffness: per node (moment per
    radian; None: likewise; 0: rotations free) — planar rotations of 2D structures only;
    tolerance: relative spring force below which a solve is not repeated; max_updates: the most
    re-anchorings per step.
    """

    def __init__(self, part: PartRef, stiffness: float | None = None, where: str | None = None,
                 rotational_stiffness: float | None = None, factor: float = 1e-6, tolerance: float = 1e-9,
                 max_updates: int = 20):
        if not isinstance(part, PartRef):
            raise TypeError(f"stabilise: part must be a part of the scene (from Scene.add_*), got "
                            f"{type(part).__name__}")
        self.label = f"{part.kind} '{part.name or 'all cells'}'" + ("" if where is None else f" at {where!r}")
        owner = f"stabilise {self.label}"
        validate.positive(owner, "stiffness", stiffness, allow_none=True)
        validate.positive(owner, "rotational_stiffness", rotational_stiffness, allow_zero=True, allow_none=True)
        validate.positive(owner, "factor", factor)
        validate.positive(owner, "tolerance", tolerance)
        validate.whole(owner, "max_updates", max_updates, 0)
        model = part.model
        self.part, self.model, self.where = part, model, where
        self.stiffness, self.rotational_stiffness = stiffness, rotational_stiffness
        self.factor, self.tolerance, self.max_updates = float(factor), float(tolerance), int(max_updates)
        # the dofs that carry springs: translations, and planar rotations where the state is the dofs
        additive = model.state_size == model.ndof
        rotations = list(range(model.translations, model.ndof)) if additive else []
        if rotational_stiffness is not None and rotational_stiffness > 0.0 and not rotations:
            raise ValueError(f"{owner}: rotational_stiffness = {rotational_stiffness} for a part without planar "
                             f"rotations (its dofs {model.dof_names}): springs act on translations here"
                             + (" (3D rotations are left free: the translational springs remove rigid motions)"
                                if model.ndof > model.translations else ""))
        if rotational_stiffness == 0.0:
            rotations = []
        self.components = np.array(list(range(model.translations)) + rotations, dtype=np.int64)
        self.rotational = self.components >= model.translations
        self.blocks = self._owned_blocks()
        count = model.comm.allreduce(len(self.blocks), op=MPI.SUM)
        if count == 0:
            raise ValueError(f"{owner}: group '{where}' has no node of this part")
        self.nodes = count
        self.k = None  # (ncomp,) springs per component, set on binding
        self.work = 0.0
        self.updates = 0
        self.peak = 0.0
        self.last_force = 0.0
        self.previous = math.inf

    def _owned_blocks(self) -> np.ndarray:
        """Owned dof blocks of the part's nodes (of group ``where`` if given)."""
        model, tm = self.model, self.model.tmesh
        tdim = tm.tdim
        blocks = dolfinx.fem.locate_dofs_topological(model.V, tdim, tm.cells(self.part.name or None))
        if self.where is not None:
            tm.vertices(self.where)  # a GroupNotFoundError naming the mesh's groups if it has no such group
            dim = tm.groups[self.where][0]
            chosen = (dolfinx.fem.locate_dofs_topological(model.V, tdim, tm.cells(self.where)) if dim == tdim
                      else model.dof_blocks(self.where))
            blocks = np.intersect1d(blocks, chosen)
        return np.unique(blocks[blocks < model.V.dofmap.index_map.size_local]).astype(np.int32)

    # -- binding --------------------------------------------------------------------------
    def bind(self, system) -> None:
        """Global dofs in ``system``'s numbering (−1 on constrained dofs), spring stiffnesses and
        anchors at the current configuration."""
        model = self.model
        local = (self.blocks[:, None] * model.ndof + self.components[None, :]).astype(np.int32)
        gd = system.global_dofs(model, local.ravel()).reshape(local.shape)
        gd[np.isin(gd, system.constrained_global_dofs())] = -1
        self.dofs = gd
        self.free = gd >= 0
        if self.k is None:
            self.k = self._stiffness()
        self.anchor = self.values()
        self.work = 0.0
        self.updates = 0
        self.peak = 0.0
        self.last_force = 0.0

    def _stiffness(self) -> np.ndarray:
        """(ncomp,) spring per component: given, or ``factor`` × the mean diagonal entry of the part's
        own tangent (at the current configuration) over the stabilised nodes."""
        model = self.model
        given = {False: self.stiffness, True: self.rotational_stiffness}
        if any(given[bool(r)] is None for r in self.rotational):
            d = petsc.form_diagonal(model.forms()[1])
            local = d[self.blocks[:, None] * model.ndof + self.components[None, :]]
        out = np.zeros(len(self.components))
        for rot in (False, True):
            cols = self.rotational == rot
            if not cols.any():
                continue
            if given[rot] is not None:
                out[cols] = given[rot]
                continue
            total = model.comm.allreduce(float(np.abs(local[:, cols]).sum()), op=MPI.SUM)
            count = model.comm.allreduce(int(local[:, cols].size), op=MPI.SUM)
            scale = total / max(count, 1)
            if not scale > 0.0:
                raise ValueError(f"stabilise {self.label}: its tangent has no stiffness to scale the springs "
                                 "with; give stiffness=...")
            out[cols] = self.factor * scale
        return out

    # -- springs ----------------------------------------------------------------------------
    def values(self) -> np.ndarray:
        """(n_own, ncomp) the current values of the stabilised dofs (displacements, planar angles)."""
        state = self.model.state.x.array.reshape(-1, self.model.state_size)
        return state[self.blocks][:, self.components].copy()

    def stretch(self) -> np.ndarray:
        """(n_own, ncomp) u − a on free dofs (0 on constrained ones)."""
        return (self.values() - self.anchor) * self.free

    def force_norm(self) -> float:
        """‖k (u − a)‖ over all ranks."""
        f = self.k * self.stretch()
        return math.sqrt(self.model.comm.allreduce(float((f * f).sum()), op=MPI.SUM))

    def energy(self) -> float:
        """½ Σ k (u − a)² over all ranks: the work the springs hold now."""
        s = self.stretch()
        return 0.5 * self.model.comm.allreduce(float((self.k * s * s).sum()), op=MPI.SUM)

    def anchor_array(self) -> np.ndarray:
        """The anchors as a node-ordered (n_nodes, ndof) array of the part's model (0 on other dofs and
        nodes; partition-independent), on every rank."""
        model = self.model
        imap = model.V.dofmap.index_map
        local = np.zeros((imap.size_local + imap.num_ghosts, model.ndof))
        local[np.ix_(self.blocks, self.components)] = self.anchor
        return model.comm.bcast(model.to_global(local), root=0)

    def set_anchor_array(self, values: np.ndarray) -> None:
        """The anchors from :meth:`anchor_array`'s output."""
        local = self.model.from_global(np.asarray(values, dtype=float)).reshape(-1, self.model.ndof)
        self.anchor = local[np.ix_(self.blocks, self.components)].copy()

    def reanchor(self) -> None:
        """The springs release their work (it is dissipated) and restart from the current configuration."""
        self.work += self.energy()
        self.anchor = self.values()

    def describe(self) -> dict:
        return {"part": self.part.name, "kind": self.part.kind, "where": self.where, "stiffness": self.stiffness,
                "rotational_stiffness": self.rotational_stiffness, "factor": self.factor,
                "tolerance": self.tolerance, "max_updates": self.max_updates, "nodes": self.nodes,
                "dofs": [self.model.dof_names[c] for c in self.components]}

    def effect(self) -> str:
        dofs = ", ".join(self.model.dof_names[c] for c in self.components)
        k = "factor {:.3g} of the part's stiffness".format(self.factor) if self.stiffness is None else \
            f"k = {self.stiffness:.3g}"
        return (f"stabilisation of {self.label}: springs to "
                f"ground on {dofs} of {self.nodes} nodes ({k}), re-anchored until they carry "
                f"{self.tolerance:.0e} of the load")


class Stabilisation(Contribution):
    """The stabilised parts of a scene as one contribution of the system (see the module docstring).

    Residual k (u − a) and tangent k I on each stabilised dof (1 × 1 blocks); after a converged
    Newton solve, the anchors of springs whose force exceeds their tolerance move to the current
    configuration and the solve is repeated (:meth:`on_converged`). The anchors move only so: a
    step that ends with the springs holding a force (a motion nothing else holds) starts the next
    one in equilibrium with them. State: the anchors and the released work (for files also the
    springs' stiffness)."""

    name = "stabilisation"

    def __init__(self, stabilisers):
        self.stabilisers = list(stabilisers)

    def bind(self, system) -> None:
        self.system = system
        self.comm = system.comm
        for s in self.stabilisers:
            s.bind(system)
        self.couplings_changed = True

    # -- couplings and assembly -------------------------------------------------------------
    def couplings(self) -> np.ndarray:
        blocks = [s.dofs.reshape(-1, 1) for s in self.stabilisers]
        return np.concatenate(blocks) if blocks else np.zeros((0, 1), dtype=np.int64)

    def engaged(self) -> bool:
        return any(s.dofs.size for s in self.stabilisers)

    def add_residual(self, add) -> None:
        for s in self.stabilisers:
            add(s.dofs.reshape(-1, 1), (s.k * s.stretch()).reshape(-1, 1))

    def add_tangent(self, add) -> None:
        for s in self.stabilisers:
            n = s.dofs.shape[0]
            add(s.dofs.reshape(-1, 1), np.broadcast_to(s.k, (n, len(s.k))).reshape(-1, 1, 1))

    # -- Newton hooks ---------------------------------------------------------------------------
    def before_step(self) -> None:
        for s in self.stabilisers:
            s.updates = 0
            s.peak = 0.0
            s.previous = math.inf

    def _reference(self) -> float:
        """The residual's reference force at the last evaluation (as Newton's convergence test)."""
        return max(self.system.fext_total.norm(), self.system.internal_force().norm())

    def on_converged(self) -> bool:
        """Re-anchor the springs that carry more than their tolerance (and may still be re-anchored in
        this step); True if any did (Newton then solves again at this load factor)."""
        ref = self._reference()
        again = False
        for s in self.stabilisers:
            force = s.force_norm()
            s.last_force = force / ref if ref > 0.0 else (0.0 if force == 0.0 else math.inf)
            s.peak = max(s.peak, s.last_force)
            stalled = s.updates > 0 and FREE_FORCE > s.last_force > 0.5 * s.previous
            s.previous = s.last_force
            if s.last_force > s.tolerance and s.updates < s.max_updates and not stalled:
                s.reanchor()
                s.updates += 1
                again = True
            elif s.last_force > FREE_FORCE:
                logger.warning("stabilisation of %s: after %d re-anchorings its springs still carry %.3g of the "
                               "load: the part is not held (yet) in some loaded direction", s.label, s.updates,
                               s.last_force)
        return again

    def history(self, report) -> dict:
        """stab_work: the work the springs absorbed so far (released and still held); stab_force: their
        force over the reference force at the step's end; stab_peak: the largest in the step;
        stab_updates: re-anchorings in the step."""
        return {"stab_work": sum(s.work + s.energy() for s in self.stabilisers),
                "stab_force": max(s.last_force for s in self.stabilisers),
                "stab_peak": max(s.peak for s in self.stabilisers),
                "stab_updates": sum(s.updates for s in self.stabilisers)}

    # -- state -------------------------------------------------------------------------------------
    def checkpoint(self):
        return [(s.anchor.copy(), s.work, s.updates, s.peak, s.last_force, s.previous) for s in self.stabilisers]

    def restore(self, state) -> None:
        for s, (anchor, work, updates, peak, last, previous) in zip(self.stabilisers, state):
            s.anchor = anchor.copy()
            s.work, s.updates, s.peak, s.last_force, s.previous = work, updates, peak, last, previous

    def state_arrays(self) -> dict:
        """The anchors (node-ordered, as the configuration), the dissipated work and the springs of
        every stabilised part, on every rank."""
        out = {}
        for i, s in enumerate(self.stabilisers):
            out[f"{i}_anchor"] = s.anchor_array()
            out[f"{i}_work"] = np.array([s.work])
            out[f"{i}_stiffness"] = s.k.copy()
        return out

    def set_state_arrays(self, arrays: dict) -> None:
        for i, s in enumerate(self.stabilisers):
            k = np.asarray(arrays[f"{i}_stiffness"], dtype=float)
            if k.shape != s.k.shape:
                raise ValueError(f"stabilisation of {s.label}: the checkpoint holds springs on {len(k)} dofs per "
                                 f"node, the part has {len(s.k)}")
            s.k = k.copy()
            s.work = float(arrays[f"{i}_work"][0])
            s.set_anchor_array(arrays[f"{i}_anchor"])

    def describe(self) -> dict:
        return {"name": self.name, "parts": [s.describe() for s in self.stabilisers]}

r"""Mortar (segment-to-segment) contact between the faces of 3D solids.

A :class:`MortarInterface3D` takes the place of an :class:`~.interface3d.Interface3D` when a
contact is declared with ``discretization="mortar"``: the slave side is a surface of faces, not of
nodes, and each pair is a slave face and a master face whose projections overlap (kernels in
:mod:`.mortar3d`). Contact is enforced in the integral sense: the pressure acts at the quadrature
points of each overlap, p = ⟨Σ N_A λ_A − ε g⟩, with the augmented-Lagrangian multipliers λ_A at
the slave nodes; after a converged Newton solve λ_A ← ⟨λ_A − ε ĝ_A⟩ with the nodal weighted gap
ĝ_A = ∫ N_A g dA / ∫ N_A dA over the overlaps, until every node in contact has |ĝ_A| below the
tolerance — the mortar constraint ∫ N_A g dA = 0 (Puso & Laursen 2004). Because both faces' nodal
forces are integrals of one pressure field, a uniform pressure gives each side its consistent
nodal forces whatever the two meshes: the patch test is passed on non-matching faces, which
node-to-face contact cannot do in 3D (docs/theory.md).

Every rank holds both surfaces whole and evaluates the slave faces whose first node's x dof it
owns; the slave nodes' integrals (weighted gaps, overlap areas, forces) are summed over ranks at
each evaluation (one allreduce of three numbers per slave node), so the multipliers and their
updates are the same on every rank. Pairs come from the broad phase (:mod:`.search3d`): the master
faces whose boxes, inflated by the margin and the slave faces' size, hold a slave face's centre.
Frictionless; between solids' faces (linear tetrahedra and hexahedra).
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from . import mortar3d
from .interface3d import Interface3D
from .laws import ContactError, Penalty
from .search3d import broad_phase_boxes, face_boxes

PAIR_DOFS = mortar3d.PAIR_DOFS


class MortarInterface3D(Interface3D):
    """One direction of mortar contact: the faces of ``slaves`` against the faces of ``masters``
    (each a (part, boundary face group) pair of a 3D solid)."""

    master_surface = "mortar: slave faces against master faces"
    SYMMETRIC_TANGENT = False  # the pressure acts along the slave face's normal: not an energy's Hessian
    TOUCH_BAND = 1e-2  # × the mean master edge

    def __init__(self, slaves, masters, law: Penalty, smooth: bool = False):
        if smooth:
            raise ContactError(f"mortar contact '{slaves[1]} -> {masters[1]}': the pressure acts along the slave "
                               "faces' normals, a smoothed master surface does not apply: give smooth=False (or "
                               "discretization='node_to_face' with smooth=True)")
        super().__init__(slaves, masters, law, smooth)
        for (part, group), surf, role in ((slaves, self.slave, "slaves"), (masters, self.master, "masters")):
            if surf.dim != 2 or surf.two_sided:
                raise ContactError(f"mortar contact: the {role} '{group}' of {part.kind} '{part.name}' are not faces "
                                   "of a solid: mortar (segment-to-segment) contact is between solids' faces; for "
                                   "shells and beams give discretization='node_to_face'")
        faces = self.slave.facets
        k = faces.shape[1]
        self.sfaces = np.hstack([faces, np.repeat(faces[:, :1], 4 - k, axis=1)]).astype(np.int64)
        self.snodes = np.full(len(faces), k, dtype=np.int64)
        X = self.slave.X
        centre = X[faces].mean(axis=1)
        self.face_radius = float(np.linalg.norm(X[faces] - centre[:, None, :], axis=2).max(initial=0.0))
        # the touch band of the quadrature points: bodies that touch at a node (a sphere on a plane)
        # touch nowhere at the points around it, whose gaps grow as h²/R; a hundredth of a face holds
        # them until some point closes
        self.touch = self.TOUCH_BAND * self.h
        # each slave node's ∫N g dA, ∫N dA, ∫N p dA over the overlaps at the last evaluation (all ranks)
        self.weighted = np.zeros((len(self.area), 3))
        self.slave_face_on = None

    # -- binding, existence -------------------------------------------------------------
    def bind(self, system) -> None:
        super().bind(system)
        start, stop = system.ownership_range()
        first = self.slave_gdofs[self.sfaces[:, 0], 0]
        self.mine_faces = np.flatnonzero((first >= start) & (first < stop))
        self.weighted[:] = 0.0
        self.closed_before = False

    def _update_existence(self) -> None:
        """As for node-to-face contact, and which slave faces exist (their element exists)."""
        super()._update_existence()
        slave = self.slave.existence(self.comm)
        self.slave_face_on = None if slave is None else slave[0]
        if not self.exists:
            self.slave_face_on = np.zeros(len(self.sfaces), dtype=bool)

    def kept_state(self):
        return None

    def restore_kept(self, state) -> None:
        pass

    # -- pairs ------------------------------------------------------------------------------
    def _centres(self, xs: np.ndarray, faces: np.ndarray) -> np.ndarray:
        k = self.slave.facets.shape[1]
        return xs[self.slave.facets[faces]].reshape(len(faces), k, 3).mean(axis=1)

    def own_pairs(self, pairs: np.ndarray) -> np.ndarray:
        """The pairs (k, 2) [slave face, master face] whose slave face this rank evaluates."""
        return pairs[np.isin(pairs[:, 0], self.mine_faces)]

    def _candidate_pairs(self, xs, xm) -> np.ndarray:
        """(k, 2) [slave face, master face] of this rank's existing slave faces whose centre lies in
        the box of an existing master face inflated by the margin and the slave faces' size."""
        mine = self.mine_faces
        if self.slave_face_on is not None:
            mine = mine[self.slave_face_on[mine]]
        lo, hi = face_boxes(xm, self.master.facets, self.margin + self.face_radius)
        pairs = broad_phase_boxes(self._centres(xs, mine), lo, hi)
        pairs[:, 0] = mine[pairs[:, 0]]
        if self.segment_on is not None:
            pairs = pairs[self.segment_on[pairs[:, 1]]]
        return pairs

    def pair_dofs(self, slaves: np.ndarray, faces: np.ndarray, free: bool = True) -> np.ndarray:
        """Global dofs (k, 24) of slave face–master face pairs (the slave face's four nodes, then
        the master face's; a triangle's fourth node −1, and with ``free`` the constrained dofs)."""
        gs, gm = self.slave_gdofs, self.master_gdofs
        dofs = np.hstack([gs[self.sfaces[slaves, j]] for j in range(4)] + [gm[self.faces[faces, j]] for j in range(4)])
        dofs[:, 9:12][self.snodes[slaves] == 3] = -1
        dofs[:, 21:24][self.nodes[faces] == 3] = -1
        if free:
            dofs[np.isin(dofs, self.constrained)] = -1
        return dofs

    def _integrate(self, xs, xm, sf, mf, lam, off, band: bool, tangent: bool):
        """The kernels over pairs (sf, mf): f (k, 24), K (k, 24, 24), points in contact (k,) and the
        slave nodes' integrals (n, 3) summed over ranks."""
        k = len(sf)
        f = np.zeros((k, PAIR_DOFS))
        K = np.zeros((k, PAIR_DOFS, PAIR_DOFS) if tangent else (k, 0, 0))
        closed = np.zeros(k, dtype=np.int64)
        nodal = np.zeros((len(self.area), 3))
        if k:
            Kbuf = K if tangent else np.zeros((k, PAIR_DOFS, PAIR_DOFS))
            mortar3d.faces_to_faces(xs, xm, self.sfaces, self.snodes, self.faces, self.nodes, sf, mf, lam, off,
                                    self.penalty, self.touch, band, tangent, f, Kbuf, nodal, closed)
        total = np.zeros_like(nodal)
        self.comm.Allreduce(nodal, total, op=MPI.SUM)
        return f, K, closed, total

    def evaluate(self):
        """Forces and tangents of this rank's slave faces at the current configuration: (dofs (k, 24)
        global, f (k, 24), K (k, 24, 24), (slave face, master face) (k,)) over the pairs that carry
        pressure (or touch, in the first evaluations)."""
        xs, xm = self._positions(self.slave), self._positions(self.master)
        if self.first_evaluation:
            self.evaluations = 0
        self._search(xs, xm)
        self._x = (xs, xm)
        if not self.comm.allreduce(len(self.candidates), op=MPI.SUM):  # nothing near: an idle interface
            self.weighted[:] = 0.0
            return self._idle(PAIR_DOFS)
        # the touch band's stiffness only while no point of the interface was in contact at the last
        # evaluation (bodies touching without load): a stiffness without a force is not the
        # residual's derivative, and kept in the first evaluations of every solve as node-to-face
        # contact does, it made each Newton solve of a sphere pressed on a block converge linearly
        # (0.7 per iteration) for those evaluations (measured)
        self.evaluations += 1
        band = not self.closed_before
        sf, mf = self.candidates[:, 0], self.candidates[:, 1]
        f, K, closed, self.weighted = self._integrate(xs, xm, sf, mf, self.multiplier, self.slave_offset, band, True)
        any_closed = bool(self.comm.allreduce(int(closed.sum()), op=MPI.SUM))
        self.closed_before = any_closed
        if self.first_evaluation:
            self.first_evaluation, self.had_contact = False, any_closed
        s = np.flatnonzero(self.weighted[:, 1] > 0.0)
        self._last = (s, self.weighted[s, 0] / self.weighted[s, 1])
        self.active[:] = -1
        self.active[s] = 0
        keep = np.any(f != 0.0, axis=1) | np.any(K != 0.0, axis=(1, 2))
        self._virtual = None
        self._forces = (sf[keep], mf[keep], f[keep])
        return self.pair_dofs(sf[keep], mf[keep], free=False), f[keep], K[keep], (sf[keep], mf[keep])

    def augment(self) -> bool:
        """Uzawa update λ_A ← ⟨λ_A − ε ĝ_A⟩ of every slave node with an overlap while the largest
        |ĝ_A| of the nodes in contact exceeds the tolerance (the same on every rank)."""
        if not self.law.augmented:
            return False
        s, g = self._last
        closed = self.multiplier[s] - self.penalty * g > 0.0
        error = self.comm.allreduce(float(np.max(np.abs(g[closed]), initial=0.0)), op=MPI.MAX)
        if error <= self.law.gap_tolerance * self.h or self.uzawa_updates >= self.law.max_updates:
            return False
        lam = np.zeros_like(self.multiplier)
        lam[s] = np.maximum(0.0, self.multiplier[s] - self.penalty * g)
        self.comm.Bcast(lam, root=0)  # (the integrals are summed over ranks: the same everywhere)
        self.multiplier[:] = lam
        self.uzawa_updates += 1
        return True

    def cancel_initial_gaps(self, slaves: np.ndarray | None = None) -> int:
        """Approach I of staged construction: each existing slave node (of ``slaves``; None: all) whose
        faces overlap an existing master face for the first time takes its weighted gap ĝ_A as zero."""
        xs, xm = self._positions(self.slave), self._positions(self.master)
        self.anchor = None
        self._search(xs, xm)
        _, _, _, nodal = self._integrate(xs, xm, self.candidates[:, 0], self.candidates[:, 1],
                                         np.zeros(len(self.area)), np.zeros(len(self.area)), False, False)
        done = (nodal[:, 1] > 0.0) & ~self.gap_cancelled
        if slaves is not None:
            done &= np.isin(np.arange(len(done)), slaves)
        g = np.where(done, nodal[:, 0] / np.where(nodal[:, 1] > 0.0, nodal[:, 1], 1.0), 0.0)
        first = float(self.comm.rank == 0)  # (the integrals are every rank's: counted once)
        return self._take_initial_gaps(first * g, first * done)

    def correction_ratio(self, ds: np.ndarray, dm: np.ndarray) -> float:
        """As for node-to-face contact: each of this rank's slave nodes with an overlap against the
        nearest master node — sliding at most the margin, approach at most its weighted gap plus
        the margin along the slave surface's normal."""
        if not len(self.mine_faces):
            return 0.0
        from scipy.spatial import cKDTree

        xs, xm = self._x
        nodes = np.unique(self.slave.facets[self.mine_faces])
        nodes = nodes[self.weighted[nodes, 1] > 0.0]
        if not len(nodes):
            return 0.0
        normal = np.zeros_like(xs)
        faces = self.slave.facets
        for j in range(faces.shape[1]):
            a, b, c = faces[:, j], faces[:, (j + 1) % faces.shape[1]], faces[:, j - 1]
            np.add.at(normal, a, np.cross(xs[b] - xs[a], xs[c] - xs[a]))
        n = -normal[nodes] / np.maximum(np.linalg.norm(normal[nodes], axis=1), 1e-300)[:, None]
        _, v = cKDTree(xm).query(xs[nodes])
        gap = self.weighted[nodes, 0] / self.weighted[nodes, 1]
        return self._ratio(ds[nodes] - dm[v], n, np.maximum(gap, 0.0) + self.margin, self.margin)

    # -- results ------------------------------------------------------------------------------
    def nodal_forces(self, on_slaves: bool) -> np.ndarray:
        """(n, 3) the contact shares of the internal forces of this pass on the nodes of the slave
        (or master) surface, this rank's pairs."""
        sf, mf, f = self._forces
        surf, faces, count, first = ((self.slave, self.sfaces, self.snodes[sf], 0) if on_slaves
                                     else (self.master, self.faces, self.nodes[mf], 12))
        pick = sf if on_slaves else mf
        out = np.zeros((len(surf.X), 3))
        for j in range(4):
            real = j < count
            np.add.at(out, faces[pick[real], j], f[real, first + 3 * j: first + 3 * j + 3])
        return out

    def pressure(self, current: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Coordinates and contact pressure of all slave nodes of this pass, on every rank: ∫N_A p dA
        over the node's tributary area of the slave surface (reference, or ``current``)."""
        if not current:
            return self.slave.X, self.weighted[:, 2] / self.area
        x = self._positions(self.slave)
        return x, self.weighted[:, 2] / self._tributary(x, self.slave.facets)

    def describe(self) -> dict:
        return {**super().describe(), "discretization": "mortar", "slave_faces": len(self.sfaces)}

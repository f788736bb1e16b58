r"""Contact interfaces in 3D: slave nodes of one body against master faces of another.

An :class:`Interface3D` is the 3D counterpart of :class:`~dolfinx_corot.contact.interface.Interface`
and takes its place in the scene's :class:`~dolfinx_corot.contact.interface.Contact` contribution
(same laws, Newton hooks, state and staging). Every rank holds both surfaces whole; each rank
evaluates the slaves whose x dof it owns. At each evaluation

1. the broad phase (:mod:`.search3d`) finds the faces whose bounding box, inflated by the search
   margin (half a mean edge) and the offsets, holds a slave; the candidate list only grows until
   a slave has moved by half the margin since the last search (the pattern of the contact
   matrix is rebuilt only then);
2. each slave takes, among its candidate faces, the one onto which its closest point falls (within
   round-off beyond the edges; a solid's slave also a little beyond the surface's border): the
   face it had at the last evaluation while it still falls onto it, else the one with the
   smallest |g|. A slave may change master face at any iteration; keeping the face where the
   slave's projection falls onto two (in the groove of a concave edge, where both faces hold it)
   stops Newton from alternating between them. A slave that falls onto no face but lies within
   the margin of an edge or vertex of one — beyond the faces on both sides of a convex edge, or
   beyond an edge of the surface's border — meets that edge or vertex (:mod:`.kernels3d`, modes
   1 and 2; beyond the border a slave counts as inside only below the 45° line from it, so
   that a slave beside a solid, at its face's level, is not in it): crossing from face to edge
   to face the contact point, the normal and the gap are continuous;
3. the kernels give the pair's gap, force and tangent (15 dofs: the slave, then four face nodes;
   a triangle's fourth is none).

With ``smooth=True`` the master faces are Nagata patches through averaged nodal normals and each
slave meets them along the normal field those interpolate (:mod:`.smooth3d`): a pair's dofs are
then the slave and the face's stencil (the nodes of the faces around the face's nodes), and a
slave beyond the surface's border meets its edges and vertices with the flat kernels.

A shell's mid-surface is a two-sided master: a slave meets the face at half the thickness on its
own side (the side of the mid-surface it is on), and a shell's free edge as a rounded edge. A 3D
beam meets faces by its nodes, each a sphere of the section's outer radius.

The slaves' tributary areas are those of the slave surface in the reference configuration
(∫ N_a dA over the faces at each node; a beam node's share of length times the section's
width). Frictionless.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from mpi4py import MPI

from . import kernels3d, smooth3d
from .interface import Interface, fingerprint_float
from .laws import ContactError, Coulomb, Penalty
from .search3d import broad_phase_boxes, face_boxes

PAIR_DOFS = kernels3d.PAIR_DOFS


class FaceFrictionTrial(NamedTuple):
    """The closed pairs' friction at the last evaluation (this rank's): slaves s, faces m, whether
    on a smoothed patch (curved), stick points xi (k, 2), slipping, tractions t (k, 3), contact
    normals (k, 3), slave positions x_s (k, 3) and the multipliers' components lam_t (k, 3)."""
    s: np.ndarray
    m: np.ndarray
    curved: np.ndarray
    xi: np.ndarray
    slipping: np.ndarray
    t: np.ndarray
    normal: np.ndarray
    x_s: np.ndarray
    lam_t: np.ndarray


def tributary_areas(X: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(n,) ∫ N_a dA of each node a over the faces (m, 3 or 4) of nodes X (n, 3): a third of each
    triangle's area; for quadrilaterals by 2 × 2 Gauss points on the bilinear surface."""
    out = np.zeros(len(X))
    x = X[faces]
    if faces.shape[1] == 3:
        area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
        for j in range(3):
            np.add.at(out, faces[:, j], area / 3.0)
        return out
    g = 1.0 / np.sqrt(3.0)
    sx, sy = kernels3d.QUAD_XI, kernels3d.QUAD_ETA
    for xi in (-g, g):
        for eta in (-g, g):
            N = 0.25 * (1 + sx * xi) * (1 + sy * eta)
            t1 = np.einsum("a,mad->md", 0.25 * sx * (1 + sy * eta), x)
            t2 = np.einsum("a,mad->md", 0.25 * sy * (1 + sx * xi), x)
            J = np.linalg.norm(np.cross(t1, t2), axis=1)
            for j in range(4):
                np.add.at(out, faces[:, j], N[j] * J)
    return out


class Interface3D(Interface):
    """One direction of 3D contact: the nodes of ``slaves`` against the faces of ``masters``
    (each a (part, boundary group name) pair)."""

    FACETS = "faces"
    INSIDE_TOLERANCE = 1e-9  # a projection this far (in the face's parameters) beyond an edge is on it
    FREE_EDGE_TOLERANCE = 0.05  # a solid's slave beyond the surface's border: this far (× the face) still on it
    TOUCH_EVALUATIONS = 8  # evaluations of a Newton solve with the touch band's stiffness whatever the pairs
    STICK_SHAPE = (2,)  # a stick point's parameters (ξ₀, η₀) on its master face
    LAMBDA_SHAPE = (3,)  # a tangential multiplier's components on the face's basis at the stick point

    def __init__(self, slaves, masters, law: Penalty, smooth: bool = False, friction: Coulomb | None = None):
        super().__init__(slaves, masters, law, smooth, friction)
        if self.slave.dim == 1:  # a beam's nodes: its share of length times the section's width
            self.area = self.area * 2.0 * self.slave_face
        self._virtual = None
        self.previous_face = np.full(len(self.area), -1)  # each slave's face at the last evaluation
        self.evaluations = 0  # of the current Newton solve

    @property
    def master_surface(self) -> str:
        """The master surface the slaves meet, in words."""
        return "smoothed master faces (averaged nodal normals)" if self.smooth else "flat master faces"

    @property
    def symmetric_tangent(self) -> bool:
        """Along a smoothed master's normal field, and with friction, the force is not an energy's
        gradient."""
        return self.SYMMETRIC_TANGENT and not self.smooth and self.friction is None

    def bind(self, system) -> None:
        super().bind(system)
        self.previous_face = np.full(len(self.area), -1)

    def kept_state(self):
        """What a cut step restores besides the multipliers: the faces of the last evaluation and
        the stick points (friction)."""
        return self.previous_face.copy(), super().kept_state()

    def restore_kept(self, state) -> None:
        self.previous_face[:] = state[0]
        super().restore_kept(state[1])

    def kept_faces(self) -> np.ndarray:
        return self.previous_face

    def restore_faces(self, faces: np.ndarray) -> None:
        self.previous_face[:] = faces

    def _init_master(self) -> None:
        """The master faces padded to four nodes (a triangle's fourth is its first), the nodes of
        each, and the edges (j, j + 1) of each face that border the surface (one face only). A
        slave with an offset (a beam's radius, a shell's half thickness) beyond such an edge meets
        the edge (or its vertex), as beyond a convex edge inside the surface: gap and normal pass
        continuously from the face to the rounded edge. A solid's slave a little beyond it (by the
        free-edge tolerance) still meets the face, as in 2D beyond a free end: on a border shared
        by both bodies (the patch test's) a slave penetrating by p/ε a hair beyond the edge would
        otherwise take the edge's normal, tilted by the ratio of the two."""
        part, group = self.master_spec
        if self.master.dim != 2:
            raise ContactError(f"3D contact: the master '{group}' of {part.kind} '{part.name}' is a line, not a "
                               "surface of faces: a 3D beam meets solids and shells by its nodes, so give it as "
                               "the slaves (solid–beam contact is one-pass: symmetric=False)")
        part, group = self.slave_spec
        if self.slave.dim == 1 and not np.all(self.slave.offsets > 0.0):
            raise ContactError(f"3D contact: the slaves '{group}' of {part.kind} '{part.name}' are lines without a "
                               "section radius (bars): give the beams a section with an outer size")
        faces = self.master.facets
        k = faces.shape[1]
        self.faces = np.hstack([faces, np.repeat(faces[:, :1], 4 - k, axis=1)]).astype(np.int64)
        self.nodes = np.full(len(faces), k, dtype=np.int64)
        pairs = np.sort(np.stack([faces, np.roll(faces, -1, axis=1)], axis=2), axis=2).reshape(-1, 2)
        _, inverse, count = np.unique(pairs, axis=0, return_inverse=True, return_counts=True)
        self.free_edge = (count[inverse] == 1).reshape(len(faces), k)
        self.border_node = np.zeros(len(self.master.X), dtype=bool)
        self.border_node[faces[self.free_edge]] = True
        self.border_node[np.roll(faces, -1, axis=1)[self.free_edge]] = True
        # each pair's master nodes: the face's (flat), or its stencil: the face's nodes, then the
        # other nodes of the faces around them, whose positions set its nodal normals (smooth)
        if self.smooth:
            self.ext, self.star, self.nstar = smooth3d.build_stencils(self.master.X, faces, self.SMOOTH_ANGLE)
        else:
            self.ext = np.where(np.arange(4) < self.nodes[:, None], self.faces, -1)
        self.width = 3 * (1 + self.ext.shape[1])

    @staticmethod
    def _tributary(X: np.ndarray, facets: np.ndarray) -> np.ndarray:
        """Each slave's share of its surface: of the faces' area, or of a beam's length."""
        if facets.shape[1] == 2:
            return Interface._tributary(X, facets)
        return tributary_areas(X, facets)

    # -- pairs ------------------------------------------------------------------------------
    def pair_dofs(self, slaves: np.ndarray, faces: np.ndarray, free: bool = True) -> np.ndarray:
        """Global dofs (k, width) of slave–face pairs (slave, then the face's four nodes, a triangle's
        fourth −1; on a smoothed master then the rest of the face's stencil, −1 padded; with
        ``free`` the constrained dofs −1 too: PETSc skips them). The forces go to all dofs (on a
        supported one they are part of its reaction), the tangent to the free ones."""
        gd = self.master_gdofs
        ext = self.ext[faces]
        dofs = np.hstack([self.slave_gdofs[slaves]] + [np.where(ext[:, j:j + 1] >= 0, gd[ext[:, j]], -1)
                                                       for j in range(ext.shape[1])])
        if free:
            dofs[np.isin(dofs, self.constrained)] = -1
        return dofs

    def _broad_phase(self, xs: np.ndarray, xm: np.ndarray) -> np.ndarray:
        """Candidate pairs (k, 2) [index into xs, face]: the faces' boxes inflated by the margin,
        the slaves' largest offset and each face's own."""
        reach = self.margin + self.slave_offset.max(initial=0.0) + self.master_offset
        lo, hi = face_boxes(xm, self.master.facets, reach)
        return broad_phase_boxes(xs, lo, hi)

    def _assign(self, xs, xm, pairs, prefer=None):
        """(face, mode, which, side), each (n_slaves,), of this rank's candidate pairs: mode 0 on the
        face, 1 on its edge ``which``, 2 at its vertex ``which``; face −1: no partner; side 0 against
        a one-sided master, ±1 the side of a two-sided one (a shell's) the slave is on. ``prefer``
        (n_slaves,): a face each slave keeps while its projection still falls onto it."""
        n = len(self.area)
        face = np.full(n, -1)
        mode = np.zeros(n, dtype=np.int64)
        which = np.zeros(n, dtype=np.int64)
        side = np.zeros(n)
        if not len(pairs):
            return face, mode, which, side
        s, m = pairs[:, 0], pairs[:, 1]
        k = len(pairs)
        xi, eta, dist = np.zeros(k), np.zeros(k), np.zeros(k)
        on = np.zeros(k, dtype=bool)
        if self.smooth:  # the point along the normal field, on the face within the tolerance
            smooth3d.smooth_on_faces(xs, xm, self.ext, self.nodes, self.star, self.nstar, s, m, xi, eta, dist, on)
            tol = self.INSIDE_TOLERANCE
            three = self.nodes[m] == 3
            on &= np.where(three, (xi >= -tol) & (eta >= -tol) & (xi + eta <= 1.0 + tol),
                           (np.abs(xi) <= 1.0 + tol) & (np.abs(eta) <= 1.0 + tol))
        else:
            kernels3d.closest_on_faces(xs, xm, self.faces, self.nodes, s, m, self.INSIDE_TOLERANCE, xi, eta, dist, on)
        sides = np.where(dist < 0.0, -1.0, 1.0) if self.two_sided else np.zeros(k)
        offset = self.slave_offset[s] + self.master_offset[m]
        g = (np.abs(dist) if self.two_sided else dist) - offset
        on |= self._beyond_free_edges(m, xi, eta) & (offset == 0.0)
        valid = on & (g > -self.h) & (g < self.margin)
        if valid.any():
            v = np.flatnonzero(valid)
            other = np.ones(len(v), dtype=np.int64) if prefer is None else (prefer[s[v]] != m[v]).astype(np.int64)
            # the nearest face, of faces equally near to 1e-9 h (a slave on an edge or a vertex) the
            # lowest-numbered: the choice does not depend on the round-off (of a rank's layout)
            near = np.round(np.abs(g[v]) / (1e-9 * self.h))
            order = np.lexsort((m[v], near, other, s[v]))
            first = v[order][np.r_[True, np.diff(s[v[order]]) != 0]]
            face[s[first]] = m[first]
            side[s[first]] = sides[first]
        # slaves on no face: the nearest point of the faces' edges and vertices, if within the margin
        rest = np.flatnonzero(face[s] < 0)
        if len(rest):
            best = np.full(n, np.inf)
            for j in range(4):
                a = self.faces[m[rest], j]
                b = np.where(j + 1 < self.nodes[m[rest]], self.faces[m[rest], (j + 1) % 4], self.faces[m[rest], 0])
                real = j < self.nodes[m[rest]]
                d = xm[b] - xm[a]
                with np.errstate(invalid="ignore", divide="ignore"):  # (a triangle's fourth edge: not real)
                    t = np.clip(np.einsum("ij,ij->i", xs[s[rest]] - xm[a], d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
                dist_e = np.linalg.norm(xs[s[rest]] - (xm[a] + t[:, None] * d), axis=1)
                dist_e -= self.slave_offset[s[rest]] + self.master_offset[m[rest]]
                for i in np.flatnonzero(real & (dist_e < self.margin)):
                    slave = s[rest[i]]
                    if dist_e[i] < best[slave] - 1e-14 * self.h:
                        best[slave] = dist_e[i]
                        face[slave] = m[rest[i]]
                        side[slave] = 1.0 if self.two_sided else 0.0
                        if 0.0 < t[i] < 1.0:
                            mode[slave], which[slave] = 1, j
                            border = self.free_edge[m[rest[i]], j]
                        else:
                            mode[slave], which[slave] = 2, (j if t[i] == 0.0 else (j + 1) % self.nodes[m[rest[i]]])
                            border = self.border_node[self.faces[m[rest[i]], which[slave]]]
                        # beyond the border of a solid's surface (whose side faces are not part of
                        # it) a slave beside the body, even a hair below the face's plane, is not
                        # in it: the 45° rule of kernels3d
                        if border and not self.two_sided:
                            side[slave] = kernels3d.BORDER
        return face, mode, which, side

    def _beyond_free_edges(self, m: np.ndarray, xi: np.ndarray, eta: np.ndarray) -> np.ndarray:
        """Whether each projection (ξ, η) on face m lies beyond the face's edges by at most the
        free-edge tolerance, and only beyond edges that border the surface."""
        k = self.faces.shape[1] if self.nodes.size == 0 else int(self.nodes[0])
        if k == 3:  # edges (0, 1): η = 0, (1, 2): ξ + η = 1, (2, 0): ξ = 0
            over = np.column_stack([-eta, xi + eta - 1.0, -xi])
        else:  # (0, 1): η = −1, (1, 2): ξ = 1, (2, 3): η = 1, (3, 0): ξ = −1 (in units of the half face)
            over = 0.5 * np.column_stack([-1.0 - eta, xi - 1.0, eta - 1.0, -1.0 - xi])
        free = self.free_edge[m]
        inner_ok = np.all(np.where(free, True, over <= self.INSIDE_TOLERANCE), axis=1)
        return inner_ok & np.all(over <= self.FREE_EDGE_TOLERANCE, axis=1) & np.any(free & (over > 0.0), axis=1)

    def evaluate(self):
        """Forces and tangents of this rank's slaves at the current configuration: (dofs (k, width)
        global, f (k, width), K (k, width, width), (slave, face) (k,)) over the pairs in contact
        (width 15 on flat faces, 3 (1 + stencil) on a smoothed master)."""
        xs, xm = self._positions(self.slave), self._positions(self.master)
        if self.first_evaluation:  # a Newton solve starts
            self.evaluations = 0
        self._search(xs, xm)
        self._x = (xs, xm)
        if not self.comm.allreduce(len(self.candidates), op=MPI.SUM):  # nothing near: an idle interface
            n = len(self.area)
            self._assigned = (np.full(n, -1), np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64), np.zeros(n))
            self.previous_face[:] = -1
            return self._idle(self.width)
        self._assigned = self._assign(xs, xm, self.candidates, self.previous_face)
        face, mode, which, side = self._assigned
        self.previous_face = np.where(mode == 0, face, -1)
        s = self.mine[face[self.mine] >= 0]
        m = face[s]
        self.active[:] = -1
        self.active[s] = m
        lam = self.multiplier[s]
        if self.friction is not None:
            g, f, K = self._friction_pairs(xs, xm, s, m, mode[s], which[s], side[s], lam)
        else:
            g, f, K = self._pairs(xs, xm, s, m, mode[s], which[s], side[s], lam, True)
        if self.first_evaluation:
            self.first_evaluation = False
            self.had_contact = bool(self.comm.allreduce(int(np.any(lam - self.penalty * g > 0.0)), op=MPI.MAX))
        # a pair open by less than the touch band keeps the penalty stiffness (no force): it holds
        # bodies that touch without load, and steadies the first corrections of a stiff penalty.
        # Past TOUCH_EVALUATIONS evaluations of a step's first Newton solve, and in the solves
        # after an Uzawa update (which start from a converged state), it is kept only while no
        # pair is closed: the stiffness without a force is not the residual's derivative, and at
        # pairs with zero pressure and zero gap (overconstrained nodes of a two-pass interface
        # between non-matching faces, or slaves over the master's vertices) Newton would converge
        # linearly (measured: 0.83 and 0.74 per iteration)
        self.evaluations += 1
        band = -self.penalty * self.touch
        if (self.evaluations > self.TOUCH_EVALUATIONS or self.after_update) and \
                self.comm.allreduce(int(np.any(lam - self.penalty * g > 0.0)), op=MPI.MAX):
            band = 0.0
        keep = (lam - self.penalty * g) >= band
        self._virtual = None
        self._last = (s, g)
        self._x = (xs, xm)
        self._forces = (s[keep], m[keep], f[keep])
        return self.pair_dofs(s[keep], m[keep], free=False), f[keep], K[keep], (s[keep], m[keep])

    def _pairs(self, xs, xm, s, m, mode, which, side, lam, tangent: bool):
        """Gaps (n,), forces (n, width) and (``tangent``) tangents (n, width, width) of pairs (slave
        s, face m) in ``mode`` at ``which`` on ``side``: flat faces' kernels (:mod:`.kernels3d`);
        on a smoothed master the normal field's (:mod:`.smooth3d`) over the faces, the flat
        kernels at the edges and vertices of the surface's border."""
        n = len(s)
        g, f, K = np.zeros(n), np.zeros((n, self.width)), np.zeros((n, self.width, self.width))
        offset = self.slave_offset[s] + self.master_offset[m]
        eps = np.full(n, self.penalty)
        flat = np.flatnonzero(mode != 0) if self.smooth else np.arange(n)
        if len(flat):
            i = flat
            gi, fi, Ki = np.zeros(len(i)), np.zeros((len(i), PAIR_DOFS)), np.zeros((len(i), PAIR_DOFS, PAIR_DOFS))
            kernels3d.pairs_to_faces(xs, xm, self.faces, self.nodes, s[i], m[i], mode[i], which[i], side[i], offset[i],
                                     lam[i], eps[i], self.area[s[i]], tangent, gi, fi, Ki, self.touch)
            g[i], f[i, :PAIR_DOFS] = gi, fi
            K[i, :PAIR_DOFS, :PAIR_DOFS] = Ki
        if self.smooth:
            i = np.flatnonzero(mode == 0)
            gi, fi, Ki = np.zeros(len(i)), np.zeros((len(i), self.width)), np.zeros((len(i), self.width, self.width))
            smooth3d.pairs_to_smooth_faces(xs, xm, self.ext, self.nodes, self.star, self.nstar, s[i], m[i], side[i],
                                           offset[i], lam[i], eps[i], self.area[s[i]], tangent, gi, fi, Ki,
                                           self.touch)
            g[i], f[i], K[i] = gi, fi, Ki
        return g, f, K

    def _friction_pairs(self, xs, xm, s, m, mode, which, side, lam):
        """As :meth:`_pairs` (with tangents) with Coulomb's traction at the closed pairs, each slave
        against its step's stick point (attached, or carried to a new face, on first need and then
        held until the step converges); keeps what :meth:`commit` needs."""
        n = len(s)
        old = self.trial_segment[s]
        xi0 = self.trial_xi[s].copy()
        lam_t = self.trial_lambda[s].copy()
        attach = (old != m).astype(np.int64)  # a slave that closes, or has passed to another face
        y = xs[s].copy()
        new = np.flatnonzero(old < 0)
        if len(new):  # a slave that closes: attached where it was at the step's start, projected
            # onto its face as it was then (a material point of the face: whatever path the
            # iterates take, the same point)
            xs0, xm0 = self.step_start if self.step_start is not None else (xs, xm)  # (None: outside a step)
            k = len(new)
            xi, eta, dist, on = np.zeros(k), np.zeros(k), np.zeros(k), np.zeros(k, dtype=bool)
            kernels3d.closest_on_faces(xs0, xm0, self.faces, self.nodes, s[new], m[new], self.INSIDE_TOLERANCE, xi,
                                       eta, dist, on)
            xi0[new, 0], xi0[new, 1] = xi, eta
            attach[new] = 0
            lam_t[new] = 0.0
        moved = np.flatnonzero((old >= 0) & (old != m))
        if len(moved):  # its stick point, where it is now on its old face, and its multiplier
            y[moved] = self._stick_points(xm, old[moved], xi0[moved])
            carried = self._multiplier_vectors(xm, old[moved], xi0[moved], lam_t[moved],
                                               np.full(len(moved), self.smooth))
        offset = self.slave_offset[s] + self.master_offset[m]
        eps = np.full(n, self.penalty)
        curved = (mode == 0) if self.smooth else np.zeros(n, dtype=bool)

        def kernels(i, mu, c, attach, xi0):
            """(g, p, slipping, t, n, ξ₀, f, K) of the pairs i (flat faces or patches, with Coulomb's
            coefficient mu and cohesion c)."""
            k = len(i)
            out = (np.zeros(k), np.zeros(k), np.zeros(k, dtype=bool), np.zeros((k, 3)), np.zeros((k, 3)),
                   xi0.copy(), np.zeros((k, self.width)), np.zeros((k, self.width, self.width)))
            gi, pi, si, ti, ni, xii, fi, Ki = out
            args = (s[i], m[i])
            if self.smooth and k and curved[i[0]]:
                smooth3d.pairs_to_smooth_faces_friction(
                    xs, xm, self.ext, self.nodes, self.star, self.nstar, *args, side[i], offset[i], lam[i], eps[i],
                    self.area[s[i]], self.tangential_penalty, mu, c, attach, y[i], xii, lam_t[i], True, gi, pi, si,
                    ti, ni, fi, Ki, self.touch)
            elif k:
                ff, KK = np.zeros((k, PAIR_DOFS)), np.zeros((k, PAIR_DOFS, PAIR_DOFS))
                kernels3d.pairs_to_faces_friction(
                    xs, xm, self.faces, self.nodes, *args, mode[i], which[i], side[i], offset[i], lam[i], eps[i],
                    self.area[s[i]], self.tangential_penalty, mu, c, attach, y[i], xii, lam_t[i], True, gi, pi, si,
                    ti, ni, ff, KK, self.touch)
                fi[:, :PAIR_DOFS], Ki[:, :PAIR_DOFS, :PAIR_DOFS] = ff, KK
            return out

        g, p, slipping = np.zeros(n), np.zeros(n), np.zeros(n, dtype=bool)
        t, normal = np.zeros((n, 3)), np.zeros((n, 3))
        f, K = np.zeros((n, self.width)), np.zeros((n, self.width, self.width))
        mu, c = self._coefficient, float(self.friction.cohesion)
        if len(moved):  # attached on the new face first (the line along the normal through the old
            # stick point), the multiplier then expressed on the new face's basis there
            lam_t[moved] = 0.0
            for i in (moved[~curved[moved]], moved[curved[moved]]):
                xi0[i] = kernels(i, mu, c, attach[i], xi0[i])[5]
            attach[moved] = 0
            lam_t[moved] = self._multiplier_components(xm, m[moved], xi0[moved], carried, curved[moved])
        for i in (np.flatnonzero(~curved), np.flatnonzero(curved)):
            g[i], p[i], slipping[i], t[i], normal[i], xi0[i], f[i], K[i] = kernels(i, mu, c, attach[i], xi0[i])
        # a pressure below the touch band's (round-off at bodies that touch unloaded) has no
        # friction: its cone, of that size, would turn the traction with the round-off
        faint = np.flatnonzero((p > 0.0) & (p < self.penalty * self.touch))
        if len(faint):
            i = faint
            g[i], f[i], K[i] = self._pairs(xs, xm, s[i], m[i], mode[i], which[i], side[i], lam[i], True)
            p[i] = 0.0
        closed = p > 0.0
        changed = closed & (old != m)
        self.trial_segment[s[changed]] = m[changed]
        self.trial_xi[s[changed]] = xi0[changed]
        self.trial_lambda[s[changed]] = lam_t[changed]
        self._friction_trial = FaceFrictionTrial(s[closed], m[closed], curved[closed], xi0[closed], slipping[closed],
                                                 t[closed], normal[closed], xs[s[closed]], lam_t[closed])
        return g, f, K

    def _bases(self, xm: np.ndarray, faces: np.ndarray, xi0: np.ndarray, curved: np.ndarray) -> np.ndarray:
        """The convected bases (k, 3, 3) (rows a₁, a₂, a₁ × a₂) of faces (their patches where
        ``curved``) at the parameters xi0 (k, 2)."""
        k = len(faces)
        a1, a2 = np.zeros((k, 3)), np.zeros((k, 3))
        flat = np.flatnonzero(~curved)
        if len(flat):
            b1, b2 = np.zeros((len(flat), 3)), np.zeros((len(flat), 3))
            kernels3d.face_frames(xm, self.faces, self.nodes, faces[flat], xi0[flat], np.zeros_like(b1), b1, b2)
            a1[flat], a2[flat] = b1, b2
        on = np.flatnonzero(curved)
        if len(on):
            b1, b2 = np.zeros((len(on), 3)), np.zeros((len(on), 3))
            smooth3d.patch_frames(xm, self.ext, self.nodes, self.star, self.nstar, faces[on], xi0[on],
                                  np.zeros_like(b1), b1, b2)
            a1[on], a2[on] = b1, b2
        return np.stack([a1, a2, np.cross(a1, a2)], axis=1)

    def _multiplier_vectors(self, xm, faces, xi0, lam_t, curved) -> np.ndarray:
        """The multipliers (k, 3) of components lam_t (k, 3) on the bases of :meth:`_bases`."""
        return np.einsum("ka,kad->kd", lam_t, self._bases(xm, faces, xi0, curved))

    def _multiplier_components(self, xm, faces, xi0, vectors, curved) -> np.ndarray:
        """The components (k, 3) of the vectors (k, 3) on the bases of :meth:`_bases`."""
        if not len(faces):
            return np.zeros((0, 3))
        bases = np.transpose(self._bases(xm, faces, xi0, curved), (0, 2, 1))  # columns a₁, a₂, a₁ × a₂
        return np.linalg.solve(bases, vectors[..., None])[..., 0]

    def _slipped(self, xm, m, curved, xi, slipping, t, normal, x_s):
        """The stick points (k, 2) and multipliers (k, 3) of closed pairs after a slip: a slipping
        slave attached under itself (the line along the normal through it meets its face), the
        multiplier its traction on the face's basis there (its components for every pair)."""
        xi = xi.copy()
        for on_patch in (False, True):
            i = np.flatnonzero(slipping & (curved == on_patch))
            if not len(i):
                continue
            new = xi[i].copy()
            if on_patch:
                smooth3d.attach_on_patches(xm, self.ext, self.nodes, self.star, self.nstar, m[i], x_s[i], normal[i],
                                           new)
            else:
                kernels3d.attach_on_faces(xm, self.faces, self.nodes, m[i], x_s[i], normal[i], new)
            xi[i] = new
        return xi, self._multiplier_components(xm, m, xi, t, curved)

    def stick_slip(self) -> float:
        worst = 0.0
        if self._friction_trial is not None:
            tr = self._friction_trial
            i = np.flatnonzero(~tr.slipping)
            if len(i):
                v = self._multiplier_vectors(self._x[1], tr.m[i], tr.xi[i], tr.lam_t[i], tr.curved[i])
                v -= np.einsum("kd,kd->k", v, tr.normal[i])[:, None] * tr.normal[i]  # (in the tangent plane)
                worst = float(np.linalg.norm(tr.t[i] - v, axis=1).max()) / self.tangential_penalty
        return self.comm.allreduce(worst, op=MPI.MAX)

    def augment_tangential(self) -> None:
        if self._friction_trial is None:
            return
        tr = self._friction_trial
        i = np.flatnonzero(~tr.slipping)  # (see Interface.augment_tangential)
        self.trial_lambda[tr.s[i]] = self._multiplier_components(self._x[1], tr.m[i], tr.xi[i], tr.t[i], tr.curved[i])

    def _stick_points(self, xm: np.ndarray, faces: np.ndarray, xi0: np.ndarray) -> np.ndarray:
        """The current positions (k, 3) of the stick points (ξ₀, η₀) on faces: of the flat faces, or
        of their patches (smoothed master)."""
        out = np.zeros((len(faces), 3))
        if self.smooth:
            smooth3d.patch_points(xm, self.ext, self.nodes, self.star, self.nstar, faces, xi0, out)
        else:
            kernels3d.face_points(xm, self.faces, self.nodes, faces, xi0, out)
        return out

    def commit(self) -> None:
        """The step converged: each slave in contact keeps its stick point and multiplier
        (sticking) or is attached under itself, its traction becoming its multiplier (slipping:
        the next step starts on the cone's rim, a reversal elastic); a slave out of contact has
        none. The same on every rank."""
        if self.friction is None:
            return
        seg = np.full(len(self.area), -1)
        xi0 = np.zeros((len(self.area), 2))
        lam0 = np.zeros((len(self.area), 3))
        if self._friction_trial is not None:
            tr = self._friction_trial
            new_xi, new_lam = self._slipped(self._x[1], tr.m, tr.curved, tr.xi, tr.slipping, tr.t, tr.normal, tr.x_s)
            seg[tr.s] = tr.m
            xi0[tr.s] = np.where(tr.slipping[:, None], new_xi, tr.xi)
            lam0[tr.s] = np.where(tr.slipping[:, None], new_lam, tr.lam_t)
        self.commit_stick_points(seg, xi0, lam0)

    def _idle(self, width: int):
        """No candidate pair on any rank: no pair, no force, no tangent (blocks of ``width`` dofs)."""
        none = np.zeros(0, dtype=np.int64)
        self.active[:] = -1
        if self.first_evaluation:
            self.first_evaluation, self.had_contact = False, False
        self._virtual = None
        self._friction_trial = None
        self._last = (none, np.zeros(0))
        self._forces = (none, none, np.zeros((0, width)))
        return np.zeros((0, width), dtype=np.int64), np.zeros((0, width)), np.zeros((0, width, width)), (none, none)

    def cancel_initial_gaps(self, slaves: np.ndarray | None = None) -> int:
        """Approach I of staged construction: each existing slave (of ``slaves``; None: all) that finds
        an existing master face for the first time takes its current gap as zero."""
        xs, xm = self._positions(self.slave), self._positions(self.master)
        self.anchor = None
        self._search(xs, xm)
        face, mode, which, side = self._assign(xs, xm, self.candidates)
        s = self.mine[(face[self.mine] >= 0) & ~self.gap_cancelled[self.mine]]
        if slaves is not None:
            s = s[np.isin(s, slaves)]
        g, done = np.zeros(len(self.area)), np.zeros(len(self.area))
        if len(s):
            g[s] = self._pairs(xs, xm, s, face[s], mode[s], which[s], side[s], np.zeros(len(s)), False)[0]
            done[s] = 1.0
        return self._take_initial_gaps(g, done)

    def project_slaves(self, slaves: np.ndarray) -> np.ndarray:
        raise NotImplementedError("the mapping of new continuum (staged construction, approach II) is 2D so far")

    def correction_ratio(self, ds: np.ndarray, dm: np.ndarray) -> float:
        """As in 2D (:meth:`Interface.correction_ratio`): the motion of each slave relative to the point
        of the master it faces, its sliding at most the margin, its approach at most its gap plus
        the margin, its separation at most the interface's extent; slaves without a partner
        against their nearest master node."""
        if not len(self.mine):
            return 0.0
        xs, xm = self._x
        face, mode, which, side = self._assigned
        mine = self.mine
        worst = 0.0
        gap = np.full(len(self.area), np.inf)
        s_last, g_last = self._last
        gap[s_last] = g_last
        on = mine[face[mine] >= 0]
        if len(on):
            m = face[on]
            # the face's motion: the mean of its nodes' (a rigid face's at its centre)
            three = (self.nodes[m] == 3)[:, None]
            dface = np.where(three, dm[self.faces[m, :3]].mean(axis=1), dm[self.faces[m]].mean(axis=1))
            n = np.cross(xm[self.faces[m, 1]] - xm[self.faces[m, 0]], xm[self.faces[m, 2]] - xm[self.faces[m, 0]])
            n /= np.linalg.norm(n, axis=1)[:, None]
            n[side[on] < 0.0] *= -1.0  # the far side of a two-sided master
            worst = max(worst, self._ratio(ds[on] - dface, n, np.maximum(gap[on], 0.0) + self.margin, self.margin))
        free = mine[face[mine] < 0]
        if len(free):
            from scipy.spatial import cKDTree

            dist, v = cKDTree(xm).query(xs[free])
            u = (xs[free] - xm[v]) / np.maximum(dist, 1e-300)[:, None]
            worst = max(worst, self._ratio(ds[free] - dm[v], u, np.maximum(dist, self.margin), dist + self.margin))
        return worst

    def nodal_forces(self, on_slaves: bool) -> np.ndarray:
        """(n, 3) the contact shares of the internal forces of this pass on the nodes of the slave
        (or master) surface, this rank's pairs."""
        s, m, f = self._forces
        if on_slaves:
            out = np.zeros((len(self.slave.X), 3))
            np.add.at(out, s, f[:, :3])
            return out
        out = np.zeros((len(self.master.X), 3))
        for j in range(self.ext.shape[1]):
            real = self.ext[m, j] >= 0
            np.add.at(out, self.ext[m[real], j], f[real, 3 + 3 * j: 6 + 3 * j])
        return out

    def master_pressure(self, current: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """The contact forces on each master node over its tributary area (n_master,), with the
        nodes' coordinates, on every rank."""
        total = np.zeros((len(self.master.X), 3))
        self.comm.Allreduce(self.nodal_forces(False), total, op=MPI.SUM)
        x = self._positions(self.master) if current else self.master.X
        return x, np.linalg.norm(total, axis=1) / tributary_areas(x, self.master.facets)

    def describe(self) -> dict:
        return {"slaves": self.slave_spec[1], "masters": self.master_spec[1], "law": repr(self.law),
                "smooth": self.smooth, "penalty": fingerprint_float(self.penalty), "slave_nodes": len(self.area),
                "master_segments": len(self.master.facets),
                **({"friction": repr(self.friction)} if self.friction is not None else {})}

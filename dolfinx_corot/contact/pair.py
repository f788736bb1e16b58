r"""One contact declaration (``Scene.contact``) as one interface: its pressure field and resultant.

A two-pass (symmetric) contact is two interfaces, each of which carries a
share of the load — how much depends on the penalties and the meshes, not
on the physics. The interface pressure is therefore taken from the nodal
contact forces of *both* passes, gathered on the nodes of one side A (the
slave nodes of the pass A → B and the master nodes of the pass B → A):

.. math::
   \mathbf F_i = -\sum_{\text{passes}} \mathbf f_i,\qquad
   p_i = \frac{-\mathbf F_i\cdot\mathbf n_i}{L_i},\qquad
   \mathbf R = \sum_i \mathbf F_i,\qquad N = \sum_i p_i L_i,

with :math:`\mathbf f_i` the contact share of node i's internal force,
:math:`\mathbf F_i` the force the other body exerts on it, :math:`\mathbf n_i`
the unit normal of A's contact face towards the other body and :math:`L_i`
the node's tributary length of that face. The face is where contact is
made: a solid's boundary, or for a beam the axis offset by half the
section's depth on the side the force comes from — a lining ring of axis
radius R and depth h presses with its outer face of radius R + h/2, and
:math:`L_i` is measured there. With the straight master segments, whose
forces are shared linearly, a uniform contact traction gives exactly the
consistent nodal forces :math:`F_i = p\,L_i`, so :math:`p_i` recovers it
node by node (Taylor & Papadopoulos 1991, the two-pass patch test); the
smooth (Hermite) master curve shares a slave's force among four master
nodes with cubic weights, so the pressure on the master-side nodes then
oscillates around the true one from node to node (its resultant is exact).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI


@dataclass(frozen=True)
class InterfacePressure:
    """The contact pressure on one side of an interface, at the last converged state, on every
    rank.

    keys: (n,) the nodes (global block numbers of the side's part, as ``Surface.keys``);
    x: (n, gdim) points of the contact face at the nodes (a beam's axis node moved by half its
    depth towards the other body), current or reference positions;
    pressure: (n,) p_i = −F_i·n_i / L_i (≥ 0 in compression);
    length: (n,) L_i, the nodes' tributary lengths (2D) or areas (3D) of the contact face;
    force: (n, gdim) F_i, the force the other body exerts on each node;
    normal: (n, gdim) unit normals of the face towards the other body.
    """

    keys: np.ndarray
    x: np.ndarray
    pressure: np.ndarray
    length: np.ndarray
    force: np.ndarray
    normal: np.ndarray

    @property
    def resultant(self) -> np.ndarray:
        """(gdim,) the force the other body exerts on this side, Σ F_i."""
        return self.force.sum(axis=0)

    @property
    def normal_force(self) -> float:
        """The total normal force Σ p_i L_i."""
        return float(np.sum(self.pressure * self.length))

    @property
    def max_pressure(self) -> float:
        return float(self.pressure.max(initial=0.0))


class ContactPair:
    """The interfaces made by one ``Scene.contact`` call — one (one-pass) or two (two-pass,
    ``symmetric=True``) — as one interface between two surfaces.

    It is a sequence of its :class:`~dolfinx_corot.contact.interface.Interface` objects
    (``(itf,) = scene.contact(...)`` unpacks a one-pass pair), and answers for both passes
    together: :meth:`pressure` (the pressure field on either side's contact face) and
    :meth:`resultant`.
    """

    SIDES = ("slaves", "masters")

    def __init__(self, interfaces):
        self.interfaces = tuple(interfaces)
        first = self.interfaces[0]
        self.name = first.name
        for other in self.interfaces[1:]:
            if not (np.array_equal(other.master.keys, first.slave.keys)
                    and np.array_equal(other.slave.keys, first.master.keys)):
                raise ValueError(f"contact '{self.name}': the second pass '{other.name}' is not the first "
                                 "one reversed")
        self._chains = [_chains(surf.facets) if surf.two_sided and surf.gdim == 2
                        else (surf.facets, np.zeros(len(surf.facets), int)) for surf in (first.slave, first.master)]

    @property
    def exists(self) -> bool:
        """Whether the interface exists (staged construction: a stage may add or remove it)."""
        return self.interfaces[0].exists

    @exists.setter
    def exists(self, value: bool) -> None:
        for itf in self.interfaces:
            itf.exists = bool(value)
            if not value:  # an interface that appears again takes the gaps it then finds anew (approach I)
                itf.initial_gap[:] = 0.0
                itf.gap_cancelled[:] = False

    def __iter__(self):
        return iter(self.interfaces)

    def __len__(self) -> int:
        return len(self.interfaces)

    def __getitem__(self, k):
        return self.interfaces[k]

    def __repr__(self) -> str:
        return f"ContactPair('{self.name}', {'two' if len(self) == 2 else 'one'}-pass)"

    def on_slaves(self, on: str) -> bool:
        """Whether side ``on`` ('slaves' or 'masters') is the surface given as slaves."""
        if on not in self.SIDES:
            raise ValueError(f"contact '{self.name}': on = {on!r} must be one of {self.SIDES} (the surface "
                             "given as slaves or as masters to Scene.contact)")
        return on == "slaves"

    def pressure(self, on: str = "slaves", current: bool = False) -> InterfacePressure:
        """The interface pressure on the contact face of the ``on`` side ('slaves' or 'masters', as
        declared in ``Scene.contact``), both passes combined, from the last evaluation (after a
        step: the converged state), on every rank.

        current: the true pressure, force per current face length, with the current face
        positions; False (default): the nominal pressure, force per reference face length, with
        the reference positions. See the module documentation for the formulae."""
        slaves_side = self.on_slaves(on)
        first = self.interfaces[0]
        surf = first.slave if slaves_side else first.master
        if surf.gdim == 3:
            return self._pressure_3d(surf, slaves_side, current)
        internal = np.zeros((len(surf.keys), 2))
        for k, itf in enumerate(self.interfaces):
            s, m, f = itf.contact_forces
            if (k == 0) == slaves_side:  # this side holds the pass's slave nodes
                np.add.at(internal, s, f[:, 0:2])
            else:
                for j in range(4):
                    np.add.at(internal, itf.ext[m, j], f[:, 2 * j + 2:2 * j + 4])
        total = np.zeros_like(internal)
        first.comm.Allreduce(internal, total, op=MPI.SUM)
        force = -total
        x = surf.positions(first.comm) if current else surf.X
        facets, chain = self._chains[0 if slaves_side else 1]
        face, normal, length = _contact_face(x, facets, chain, surf.node_offsets(), force, surf.two_sided)
        pressure = -np.einsum("ij,ij->i", force, normal) / length
        return InterfacePressure(surf.keys, face, pressure, length, force, normal)

    def _pressure_3d(self, surf, slaves_side: bool, current: bool) -> InterfacePressure:
        """The 3D interface pressure: the nodal contact forces of both passes over the nodes'
        tributary areas, along the area-weighted mean normal at each node — out of a solid; for a
        shell the side the node's force comes from, the face point half the thickness from the
        mid-surface. On a beam (nodes as slaves) the pressure is over the node's share of length
        times the section's width, along the force, on the section's outer face."""
        from .interface import tributary_lengths
        from .interface3d import tributary_areas

        first = self.interfaces[0]
        internal = sum(itf.nodal_forces((k == 0) == slaves_side) for k, itf in enumerate(self.interfaces))
        total = np.zeros_like(internal)
        first.comm.Allreduce(internal, total, op=MPI.SUM)
        force = -total
        x = surf.positions(first.comm) if current else surf.X
        faces = surf.facets
        offsets = surf.node_offsets()
        if surf.dim == 1:
            magnitude = np.linalg.norm(force, axis=1)
            normal = -force / np.where(magnitude > 0.0, magnitude, 1.0)[:, None]
            area = tributary_lengths(x, faces) * 2.0 * offsets
        else:
            normal = np.zeros_like(x)
            for j in range(faces.shape[1]):  # each corner's normal (x_{j+1} − x_j) × (x_{j−1} − x_j)
                a, b, c = faces[:, j], faces[:, (j + 1) % faces.shape[1]], faces[:, j - 1]
                np.add.at(normal, a, np.cross(x[b] - x[a], x[c] - x[a]))
            normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
            if surf.two_sided:  # towards the other body: against the force on the node
                normal *= np.where(np.einsum("ij,ij->i", force, normal) > 0.0, -1.0, 1.0)[:, None]
            area = tributary_areas(x, faces)
        pressure = -np.einsum("ij,ij->i", force, normal) / area
        return InterfacePressure(surf.keys, x + offsets[:, None] * normal, pressure, area, force, normal)

    def resultant(self, on: str = "slaves") -> np.ndarray:
        """(gdim,) the total force that the other body exerts on the ``on`` side (both passes)."""
        return self.pressure(on).resultant

    def monitor_values(self, name: str, on: str) -> dict[str, float]:
        """History columns of the pair: name_Fx, name_Fy (the resultant on the ``on`` side),
        name_N (the total normal force) and name_pmax (the largest nominal pressure)."""
        p = self.pressure(on)
        out = {f"{name}_F{axis}": float(v) for axis, v in zip("xyz", p.resultant)}
        return {**out, f"{name}_N": p.normal_force, f"{name}_pmax": p.max_pressure}


def _chains(facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The segments (m, 2) turned so that each connected chain runs one way (a beam's elements
    may be given either way round), and the chain of each segment (m,)."""
    facets = facets.copy()
    chain = np.full(len(facets), -1)
    at_node: dict[int, list[int]] = {}
    for e, (a, b) in enumerate(facets):
        at_node.setdefault(int(a), []).append(e)
        at_node.setdefault(int(b), []).append(e)
    for seed in range(len(facets)):
        if chain[seed] >= 0:
            continue
        chain[seed] = seed
        todo = [seed]
        while todo:
            e = todo.pop()
            a, b = facets[e]
            for node, end in ((a, 0), (b, 1)):
                for f in at_node[int(node)]:
                    if chain[f] >= 0:
                        continue
                    # a neighbour continues the chain: it starts where e ends, or ends where e starts
                    if facets[f, end] == node:
                        facets[f] = facets[f, ::-1]
                    chain[f] = seed
                    todo.append(f)
    return facets, np.unique(chain, return_inverse=True)[1]


def _contact_face(x: np.ndarray, facets: np.ndarray, chain: np.ndarray, offsets: np.ndarray, force: np.ndarray,
                  two_sided: bool):
    """Points (n, 2), unit normals towards the other body (n, 2) and tributary lengths (n,) of the
    contact face of a surface with nodes x (n, 2), segments ``facets`` (m, 2) (for one-sided
    surfaces with the body on their left; for two-sided ones, beams, each ``chain`` running one
    way) and node offsets (n,) (a beam's half depth; 0 for solids), pressed by the nodal forces
    ``force`` (n, 2).

    A solid's face looks out of the body. A beam's face is the side of its axis the forces come
    from, chosen per chain by their sum (the force on a node points away from the other body);
    a node's normal is the mean of its segments' unit normals, its face point x_i + c_i n_i (c_i
    its offset), and a segment's face length the distance of its two face points."""
    a, b = facets[:, 0], facets[:, 1]
    t = x[b] - x[a]
    nu = np.column_stack([t[:, 1], -t[:, 0]]) / np.linalg.norm(t, axis=1)[:, None]  # right of a → b
    if two_sided:
        toward = -(np.einsum("ij,ij->i", force[a], nu) + np.einsum("ij,ij->i", force[b], nu))
        side = np.where(np.bincount(chain, weights=toward) < 0.0, -1.0, 1.0)
        nu *= side[chain][:, None]
    normal = np.zeros_like(x)
    np.add.at(normal, a, nu)
    np.add.at(normal, b, nu)
    norm = np.linalg.norm(normal, axis=1)
    normal /= np.where(norm > 0.0, norm, 1.0)[:, None]
    face = x + offsets[:, None] * normal
    seg = np.linalg.norm(face[b] - face[a], axis=1)
    length = np.zeros(len(x))
    np.add.at(length, a, 0.5 * seg)
    np.add.at(length, b, 0.5 * seg)
    return face, normal, length

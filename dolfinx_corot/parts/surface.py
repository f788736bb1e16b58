"""Surfaces of parts: what contact (and later output and staging) needs to know of a boundary.

A part answers ``part.surface(group)`` with a :class:`Surface`; contact never
asks what kind of part it touches. Every rank holds the surface whole
(reference coordinates of all its nodes, its facets), and knows which of its
nodes it owns and where their translations sit in the part's dofs.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


class SurfaceError(ValueError):
    """A surface that cannot be built (missing or unsuitable group, unsupported part)."""


@dataclass
class Surface:
    """A boundary of a part, the same on every rank.

    part: the part model that owns the nodes (its ``translations_of(blocks)`` gives their
    displacements, its dofs number them in a system); name: the group;
    dim: 1 for segments (2D), 2 for faces (3D);
    keys: (n,) a global number of each node (the part's global block index), sorted;
    X: (n, gdim) reference coordinates; facets: (m, dim + 1) node indices, oriented with the
    body on the left of a segment (2D) or under the face (3D);
    local: (n_own,) positions in ``keys`` of the nodes this rank owns; blocks: (n_own,) their
    local blocks in the part's space;
    offsets: (m,) distance of the contact surface from the facets (a beam's half depth, a
    shell's half thickness; 0 for solids); two_sided: contact on either side (beams, shells);
    modulus: the stiffness scale E/(1 − ν²) of the body for a default penalty (None: the part
    has none to offer, e.g. a beam);
    cells: the local cell (element) of each of this rank's facets, in the order they were
    gathered — what staged construction asks to know which facets exist.
    """

    part: object
    name: str
    dim: int
    keys: np.ndarray
    X: np.ndarray
    facets: np.ndarray
    local: np.ndarray
    blocks: np.ndarray
    offsets: np.ndarray = field(default_factory=lambda: np.zeros(0))
    two_sided: bool = False
    modulus: float | None = None
    cells: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int32))

    @property
    def gdim(self) -> int:
        return self.X.shape[1]

    def local_dofs(self) -> np.ndarray:
        """(n_own, gdim) local unrolled dofs of the owned nodes' translations in the part's space."""
        ndof = self.part.ndof
        return (self.blocks[:, None] * ndof + np.arange(self.gdim)[None, :]).astype(np.int32)

    def positions(self, comm) -> np.ndarray:
        """(n, gdim) current positions of all nodes, on every rank."""
        u = self.part.translations_of(self.blocks)
        x = self.X.copy()
        for pos, vals in zip(comm.allgather(self.local), comm.allgather(u)):
            x[pos] += vals
        return x

    def existence(self, comm) -> tuple[np.ndarray, np.ndarray] | None:
        """(facets (m,), nodes (n,)) whether each facet's element exists and whether an existing
        facet touches each node, on every rank; None when the part is not staged (all exist)."""
        exists = self.part.cells_existing() if self.part.is_staged() else None
        if exists is None:
            return None
        facet_on = np.concatenate(comm.allgather(exists[self.cells])).astype(bool)
        node_on = np.zeros(len(self.X), dtype=bool)
        node_on[self.facets[facet_on].ravel()] = True
        return facet_on, node_on

    def node_offsets(self) -> np.ndarray:
        """(n,) the largest offset of the facets at each node."""
        out = np.zeros(len(self.X))
        for j in range(self.facets.shape[1]):
            np.maximum.at(out, self.facets[:, j], self.offsets)
        return out


def gather_surface(part, name: str, facet_blocks: np.ndarray, Xdof: np.ndarray, **extra) -> Surface:
    """A :class:`Surface` from this rank's facets given as local dof blocks of ``part.V``
    (each facet on one rank only) and the blocks' coordinates ``Xdof``; ``offsets`` (this rank's
    facets) and the other fields of :class:`Surface` may be given in ``extra``."""
    V = part.V
    imap = V.dofmap.index_map
    gblocks = imap.local_to_global(np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32))
    comm = part.comm
    gdim = part.gdim
    nv = facet_blocks.shape[1]
    facet_keys = np.concatenate(comm.allgather(gblocks[facet_blocks].reshape(-1, nv)))
    if len(facet_keys) == 0:
        raise SurfaceError(f"surface '{name}' has no facets")
    keys, facets = np.unique(facet_keys, return_inverse=True)
    facets = facets.reshape(-1, nv)
    X = np.zeros((len(keys), gdim))
    own_blocks = np.flatnonzero(np.isin(gblocks[: imap.size_local], keys))
    own_pos = np.searchsorted(keys, gblocks[own_blocks])
    for pos, x in zip(comm.allgather(own_pos), comm.allgather(Xdof[own_blocks, :gdim])):
        X[pos] = x
    local_offsets = extra.pop("offsets", np.zeros(len(facet_blocks)))
    extra["cells"] = np.asarray(extra.get("cells", np.zeros(len(facet_blocks))), dtype=np.int32)
    offsets = np.concatenate(comm.allgather(np.asarray(local_offsets, dtype=float)))
    dim = 1 if nv == 2 else 2  # segments, or faces (triangles and quadrilaterals)
    return Surface(part, name, dim, keys, X, facets, own_pos, own_blocks.astype(np.int32), offsets, **extra)

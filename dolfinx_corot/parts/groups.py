"""The nodes of a group of a part, gathered on every rank: what monitors and profiles read.

A :class:`NodeGroup` lists every node of a group once (the rank that owns a
node contributes it; ghosts are never counted twice) in an order that does not
depend on the partition: by reference coordinates (x, then y, then z; nodes
that share a position by their input number). Values read through it are
therefore the same on every rank and equal to the serial ones, bit for bit,
and so are sums and means taken over them in that order.

A profile orders the nodes along the group (:func:`chain_coordinate`): by the
arc length along the chain of lines the group is made of (a beam, a boundary
line of a 2D solid, an edge of a shell), or by the coordinate along a
direction.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

AXES = {"x": 0, "y": 1, "z": 2}


@dataclass
class NodeGroup:
    """The nodes of group ``where`` of a part, the same on every rank.

    keys: (n,) global block index of each node in the part's space (this run's numbering);
    X: (n, gdim) reference coordinates, the rows in partition-independent order;
    local: (n_own,) positions in that order of the nodes this rank owns; blocks: (n_own,)
    their local blocks; segments: (m, 2) positions of the end nodes of the group's lines
    (None: the group is not made of lines).
    """

    where: str
    keys: np.ndarray
    X: np.ndarray
    local: np.ndarray
    blocks: np.ndarray
    segments: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.keys)

    def values(self, part) -> np.ndarray:
        """(n, ndof) dof values of the nodes (displacements; rotations as the part monitors them),
        gathered on every rank in the group's order."""
        out = np.zeros((len(self), part.ndof))
        local = part.dof_values(self.blocks)
        if part.comm.size == 1:  # (mpi4py's pickling allgather costs 40 µs a call even on one rank)
            out[self.local] = local
            return out
        for pos, vals in zip(part.comm.allgather(self.local), part.comm.allgather(local)):
            out[pos] = vals
        return out


def gather_group(part, where: str, blocks: np.ndarray, segment_blocks: np.ndarray | None) -> NodeGroup:
    """A :class:`NodeGroup` from this rank's owned ``blocks`` of the group and the (m, 2) local
    blocks of the group's lines that this rank adds (each line on one rank only; None: no lines)."""
    comm = part.comm
    imap = part.V.dofmap.index_map
    blocks = np.asarray(blocks, dtype=np.int32)
    gkeys = imap.local_to_global(blocks).astype(np.int64)
    inputs = part.node_keys()[blocks]
    X = np.asarray(part.reference[blocks], dtype=float).reshape(len(blocks), part.gdim)
    found = comm.allgather((gkeys, inputs, X))
    keys = np.concatenate([k for k, _, _ in found])
    ties = np.concatenate([t for _, t, _ in found])
    allX = np.concatenate([x for _, _, x in found]).reshape(-1, part.gdim)
    order = np.lexsort((ties, *allX.T[::-1]))
    position = np.empty(len(order), dtype=np.int64)
    position[order] = np.arange(len(order))
    start = sum(len(k) for k, _, _ in found[: comm.rank])
    segments = None
    if segment_blocks is not None:
        seg = imap.local_to_global(np.asarray(segment_blocks, dtype=np.int32).ravel()).astype(np.int64)
        seg = np.concatenate(comm.allgather(seg)).reshape(-1, 2)
        where_key = {k: i for i, k in enumerate(keys[order])}
        segments = np.array([[where_key[a], where_key[b]] for a, b in seg if a in where_key and b in where_key],
                            dtype=np.int64).reshape(-1, 2)
    return NodeGroup(where, keys[order], allX[order], position[start: start + len(blocks)], blocks, segments)


def chain_coordinate(group: NodeGroup, along=None, label: str = "profile") -> np.ndarray:
    """(n,) the coordinate of each node of ``group`` along it: with ``along`` None the arc length
    along the chain of the group's lines in the reference configuration, from the end of
    smallest (x, y, z); a closed chain (a ring) starts at its node of smallest (x, y, z) and runs
    counter-clockwise in 2D, towards the smaller of the node's two neighbours in 3D. Nodes inside
    lines (mid-side nodes) are projected onto them. ``along``: 'x', 'y', 'z' or a direction
    (gdim numbers): the coordinate X·d/|d|."""
    X = group.X
    gdim = X.shape[1]
    if along is not None:
        if isinstance(along, str):
            if along not in AXES or AXES[along] >= gdim:
                raise ValueError(f"{label}: along = {along!r} is not one of {list(AXES)[:gdim]} or a direction "
                                 f"({gdim} numbers)")
            return X[:, AXES[along]].copy()
        d = np.asarray(along, dtype=float).ravel()
        if d.shape != (gdim,) or not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0.0:
            raise ValueError(f"{label}: along = {list(np.ravel(along))} is not a direction of {gdim} finite "
                             f"numbers, nor one of {list(AXES)[:gdim]}")
        return X @ (d / np.linalg.norm(d))
    axes = ", ".join(f"'{a}'" for a in list(AXES)[:gdim])
    hint = f"give along={axes} or a direction"
    if group.segments is None or len(group.segments) == 0:
        raise ValueError(f"{label}: the nodes of group '{group.where}' form no chain of lines (a group of points, "
                         f"surfaces or cells of a continuum): {hint}")
    segs = np.unique(np.sort(group.segments, axis=1), axis=0)
    ends = np.unique(segs)
    degree = np.bincount(segs.ravel(), minlength=len(X))[ends]
    if np.any(degree > 2):
        raise ValueError(f"{label}: the lines of group '{group.where}' branch at "
                         f"{X[ends[degree > 2][0]].tolist()}: {hint}")
    neighbours: dict[int, list[int]] = {int(v): [] for v in ends}
    for a, b in segs:
        neighbours[int(a)].append(int(b))
        neighbours[int(b)].append(int(a))
    smallest = lambda nodes: min(nodes, key=lambda v: tuple(X[v]))  # noqa: E731
    open_ends = [int(v) for v in ends[degree == 1]]
    if open_ends:
        path = [smallest(open_ends)]
    else:
        first = smallest(ends.tolist())
        path = [first, smallest(neighbours[first])]
    while True:
        nxt = [v for v in neighbours[path[-1]] if len(path) < 2 or v != path[-2]]
        if not nxt or nxt[0] == path[0]:
            break
        path.append(nxt[0])
    if len(set(path)) != len(ends):
        raise ValueError(f"{label}: the lines of group '{group.where}' form several pieces: {hint}")
    closed = not open_ends
    if closed and gdim == 2:  # counter-clockwise: a positive enclosed area (shoelace formula)
        x, y = X[path, 0], X[path, 1]
        if np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)) < 0.0:
            path = [path[0]] + path[:0:-1]
    chain = path + [path[0]] if closed else path
    P = X[chain]
    lengths = np.linalg.norm(np.diff(P, axis=0), axis=1)
    s_nodes = np.concatenate([[0.0], np.cumsum(lengths)])
    s = np.full(len(X), np.nan)
    s[path] = s_nodes[: len(path)]
    inner = np.flatnonzero(np.isnan(s))
    if len(inner):  # nodes inside the lines (quadratic elements): their projection on the nearest line
        A, D = P[:-1], np.diff(P, axis=0)
        t = np.clip(np.einsum("nkd,kd->nk", X[inner, None, :] - A[None], D) / np.maximum(lengths**2, 1e-300), 0, 1)
        dist = np.linalg.norm(X[inner, None, :] - (A[None] + t[..., None] * D[None]), axis=2)
        k = np.argmin(dist, axis=1)
        s[inner] = s_nodes[k] + t[np.arange(len(inner)), k] * lengths[k]
    return s

"""One global numbering for the dofs of parts on several meshes (:class:`DofLayout`)."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from .. import _dolfinx


class DofLayout:
    """One global numbering for the dofs of models on different meshes.

    A node is identified by (node source, input node number): the meshes read
    from one gmsh model (or built from one array of points with the same
    ``node_source``) share the nodes they have in common, which become one
    node of the system with one set of dofs (those of the model with most: a solid's
    node shared with a beam or shell has its translations and their rotations). A shared node is owned by the
    rank that owns it in the first model holding it; nodes are numbered rank
    by rank, so each rank owns a contiguous range of scalar dofs.

    imap: scalar IndexMap of the system (owned, then ghosts); gdofs[i]: global
    dof of every local unrolled dof (owned and ghost) of model i; local[i]:
    the same in the local numbering of ``imap``; n_owned, start: this rank's range.
    """

    def __init__(self, models: Sequence) -> None:
        comm = models[0].comm
        sources: list[str] = []
        keys = []
        for m in models:
            if m.tmesh.node_source not in sources:
                sources.append(m.tmesh.node_source)
            code = np.int64(sources.index(m.tmesh.node_source))
            keys.append((code << np.int64(40)) | m.node_keys())
        allk, allm, allr = [], [], []
        for i, (m, k) in enumerate(zip(models, keys)):
            for r, g in enumerate(comm.allgather(k[: m.V.dofmap.index_map.size_local])):
                allk.append(g)
                allm.append(np.full(len(g), i, dtype=np.int32))
                allr.append(np.full(len(g), r, dtype=np.int32))
        allk, allm, allr = np.concatenate(allk), np.concatenate(allm), np.concatenate(allr)
        order = np.lexsort((allm, allk))
        ks = allk[order]
        first = np.ones(len(order), dtype=bool)
        first[1:] = ks[1:] != ks[:-1]
        primary = order[first]
        ukeys, owner, pmodel = allk[primary], allr[primary], allm[primary]
        # a shared node has the dofs of the model with most of them (a solid's translations are the
        # first dofs of a beam's or shell's node); the others' dofs must be their leading ones
        ndofs = np.array([m.ndof for m in models], dtype=np.int64)
        ncomp = np.maximum.reduceat(ndofs[allm[order]], np.flatnonzero(first))
        for i, m in enumerate(models):
            idx = np.searchsorted(ukeys, keys[i])
            for j in np.unique(pmodel[idx]):
                a, b = sorted((m.dof_names, models[j].dof_names), key=len)
                if b[: len(a)] != a:
                    raise ValueError(f"parts of kinds {[p.kind for p in m.parts]} and "
                                     f"{[p.kind for p in models[j].parts]} share nodes but have different dofs "
                                     f"({m.dof_names} and {models[j].dof_names})")
        gorder = np.lexsort((ukeys, owner))
        gnode = np.empty(len(ukeys), dtype=np.int64)
        gnode[gorder] = np.arange(len(ukeys))
        offsets_in_order = np.concatenate([[0], np.cumsum(ncomp[gorder])])
        offset = offsets_in_order[gnode]
        per_rank = np.bincount(owner, weights=ncomp, minlength=comm.size).astype(np.int64)
        self.start = int(per_rank[: comm.rank].sum())
        self.n_owned = int(per_rank[comm.rank])
        self.size_global = int(per_rank.sum())
        self.gdofs, owners = [], []
        for i, m in enumerate(models):
            idx = np.searchsorted(ukeys, keys[i])
            self.gdofs.append((offset[idx][:, None] + np.arange(m.ndof)).ravel())
            owners.append(np.repeat(owner[idx], m.ndof))
        alld, allo = np.concatenate(self.gdofs), np.concatenate(owners)
        outside = (alld < self.start) | (alld >= self.start + self.n_owned)
        ghosts, first_at = np.unique(alld[outside], return_index=True)
        ghost_owners = allo[outside][first_at].astype(np.int32)
        self.ghosts = ghosts
        self.imap = _dolfinx.index_map(comm, self.n_owned, ghosts, ghost_owners)
        self.local = []
        for gd in self.gdofs:
            own = (gd >= self.start) & (gd < self.start + self.n_owned)
            self.local.append(np.where(own, gd - self.start,
                                       self.n_owned + np.searchsorted(ghosts, gd)).astype(np.int32))



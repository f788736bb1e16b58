"""Part models on several meshes solved as one system."""
from __future__ import annotations

import numpy as np


class Coupled:
    """Structural models on several meshes, solved as one system (:class:`dolfinx_corot.assembly.CoupledSystem`).

    Meshes of one node source (one gmsh model) share their common nodes: a
    beam along a shell's edge or across its surface moves with it, dofs for
    dofs. Models that share no node are still solved together (they interact
    through supports, loads or, later, contact).
    """

    coupled = True
    continuum = False

    def __init__(self, models: list):
        self.models = list(models)
        self.large_rotations = self.models[0].large_rotations
        _link_surfaces(self.models)

    @property
    def comm(self):
        return self.models[0].comm

    @property
    def symmetric_tangent(self) -> bool:
        return all(m.symmetric_tangent for m in self.models)

    @property
    def symmetric_at_equilibrium(self) -> bool:
        """Whether every model's tangent is symmetric, at least at equilibrium (see
        :class:`~dolfinx_corot.parts.frame.Rotations3D`)."""
        return all(m.symmetric_tangent or m.symmetric_at_equilibrium for m in self.models)

    def symmetrize_tangent(self, on: bool) -> None:
        for m in self.models:
            if not m.symmetric_tangent:
                m.symmetrize_tangent(on)

    @property
    def has_prescribed_motion(self) -> bool:
        return any(m.has_prescribed_motion for m in self.models)

    @property
    def amplitudes(self) -> list:
        out = []
        for m in self.models:
            out += [a for a in m.amplitudes if a not in out]
        return out

    def extrapolate(self, older, newer, factor: float) -> None:
        for m, o, n in zip(self.models, older, newer):
            m.extrapolate(o, n, factor)

    def combine(self, states, weights) -> None:
        for i, m in enumerate(self.models):
            m.combine([s[i] for s in states], weights)

    def checkpoint(self):
        return tuple(m.checkpoint() for m in self.models)

    def restore(self, cp) -> None:
        for m, c in zip(self.models, cp):
            m.restore(c)

    def describe(self) -> list:
        return [m.describe() for m in self.models]


def _link_surfaces(models: list) -> None:
    """Hand each part that reads them (shell triangles with drilling membranes) the linear
    membrane edges of the other meshes of its node source (quadrilaterals, constant-strain
    triangles, membranes): see :meth:`dolfinx_corot.parts.shell.Shell3D._linear_edge_flags`.
    Collective."""
    if not any(m.reads_linear_edges for m in models):
        return
    edges = [m.linear_edges() for m in models]
    for m in models:
        if m.reads_linear_edges:
            others = [e for o, e in zip(models, edges)
                      if o is not m and e is not None and o.tmesh.node_source == m.tmesh.node_source]
            m.set_foreign_linear_edges(np.unique(np.concatenate(others)) if others else None)

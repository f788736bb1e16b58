"""Follower loads on structures: pressures on shells and membranes, distributed loads on 2D beams
and bars that turn with the elements (``Scene.pressure``, ``Scene.load(..., per_length=...,
follower=True)``).

A follower load depends on the configuration, so it is not a constant load vector: it enters the
system as a contribution (:mod:`dolfinx_corot.assembly.contribution`) that adds g(λ) f(x) to the
external forces (so the residual's scale counts it as a load) and −g(λ) ∂f/∂x (the load stiffness)
to the tangent, g(λ) = λ or its amplitude, at the load factor of the residual being assembled. The element loads and their derivatives are
those of :mod:`dolfinx_corot.elements.follower`. A scene without follower loads has no such
contribution (nothing to pay).

The load stiffness is not symmetric element by element: the system factorizes its tangent by LU.
Arc-length needs ∂r/∂λ at the current configuration, and staged runs ramp constant load vectors:
both refuse follower loads (load control and displacement control follow them).
"""
from __future__ import annotations

import numpy as np

from .assembly.contribution import Contribution


class FollowerLoad:
    """One follower load on the owned cells of a structural part.

    kind: 'line2d' (intensity (q_a, q_n) per current length in element axes), 'line3d' ((q_1, q_2,
    q_3) per current length in the current element axes of 3D beams and bars), 'triangle' or
    'quad' (a pressure p along the current normal); cells: the part's owned local cells;
    amplitude: None (∝ λ) or a function of λ; condition: the load's stage item."""

    def __init__(self, model, label: str, kind: str, cells: np.ndarray, intensity, bending=None, amplitude=None,
                 condition=None):
        self.model, self.label, self.kind = model, label, kind
        self.cells = np.asarray(cells, dtype=np.int32)
        self.intensity = np.asarray(intensity, dtype=float)
        self.bending = np.zeros(len(self.cells)) if bending is None else np.asarray(bending, dtype=float)
        self.amplitude, self.condition = amplitude, condition
        # node order of the dofmap: the kernels' (a quadrilateral's nodes at (0, 0), (1, 0), (0, 1), (1, 1))
        self.blocks = model.V.dofmap.list.array.reshape(-1, model.nodes_per_cell)[self.cells]
        # 2D lines: ux, uy, rz; surfaces: ux, uy, uz; 3D lines: the translations and rotations
        self.components = list(range(6)) if kind == "line3d" else [0, 1, 2]

    def factor(self, load_factor: float) -> float:
        return load_factor if self.amplitude is None else float(self.amplitude(load_factor))

    def dofs(self, system) -> np.ndarray:
        """(cells, nodes × components) global dofs of the loaded components (−1: constrained)."""
        m = self.model
        comps = np.array(self.components)
        local = (self.blocks[:, :, None] * m.ndof + comps[None, None, :]).reshape(len(self.cells), -1)
        gd = system.global_dofs(m, local.ravel()).reshape(local.shape)
        gd[np.isin(gd, system.constrained_global_dofs())] = -1
        return gd

    def evaluate(self) -> tuple[np.ndarray, np.ndarray]:
        """(f, K) at unit factor at the current configuration (forces on the loaded components)."""
        m = self.model
        g = m.gdim
        x = m.reference[self.blocks] + m.state.x.array.reshape(-1, m.state_size)[self.blocks][:, :, :g]
        if self.kind == "line2d":
            q = np.broadcast_to(self.intensity, (len(self.cells), 2))
            from .elements import follower

            return follower.line2d(x, q, self.bending)
        if self.kind == "line3d":  # the element's current axes come from its nodal rotations
            n = len(self.cells)
            X = np.ascontiguousarray(m.reference[self.blocks])
            S = np.ascontiguousarray(m.state.x.array.reshape(-1, m.state_size)[self.blocks])
            f, K = np.empty((n, 12)), np.empty((n, 12, 12))
            m.kernels.follower_loads_all(X, S, np.ascontiguousarray(m.cell_properties(self.cells)),
                                         np.ascontiguousarray(np.broadcast_to(self.intensity, (n, 3))),
                                         np.ascontiguousarray(self.bending, dtype=float), f, K)
            return f, K
        p = np.broadcast_to(self.intensity, (len(self.cells),))
        from .elements import follower

        return (follower.triangle if self.kind == "triangle" else follower.quad)(x, p)

    def describe(self) -> dict:
        return {"on": self.label, "kind": self.kind, "intensity": self.intensity.tolist(),
                "amplitude": self.amplitude is not None}


class FollowerLoads(Contribution):
    """The follower loads of a scene as one contribution of its system."""

    name = "follower loads"
    symmetric_tangent = False
    follows_configuration = True

    def __init__(self, loads):
        self.loads = list(loads)
        self._last = []

    def bind(self, system) -> None:
        self.system = system
        self._dofs = [load.dofs(system) for load in self.loads]
        self.couplings_changed = True

    def couplings(self) -> np.ndarray:
        blocks = [d for d in self._dofs if len(d)]
        if not blocks:
            return np.zeros((0, 1), dtype=np.int64)
        width = max(b.shape[1] for b in blocks)
        return np.concatenate([np.pad(b, ((0, 0), (0, width - b.shape[1])), constant_values=-1) for b in blocks])

    def engaged(self) -> bool:
        return any(len(d) for d in self._dofs)

    def _active(self):
        for load, dofs in zip(self.loads, self._dofs):
            if len(dofs) and (load.condition is None or load.condition.exists):
                yield load, dofs

    def add_residual(self, add) -> None:
        lam = self.system.load_factor
        self._last = []
        for load, dofs in self._active():
            f, K = load.evaluate()
            c = load.factor(lam)
            self._last.append((dofs, -c * K))
            add(dofs, c * f)

    def add_tangent(self, add) -> None:
        for dofs, K in self._last:
            add(dofs, K)

    def describe(self) -> dict:
        return {"name": self.name, "loads": [load.describe() for load in self.loads]}

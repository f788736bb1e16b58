"""The user's model: parts, supports, loads, monitors, and the effects they call for.

A scene declares *what* is simulated; a driver (:mod:`dolfinx_corot.solvers`)
says how the load path is followed. Effects are opt-in: with
``large_rotations=False`` the beams are geometrically linear elements in their
initial frame and no co-rotational work is done at all.

Example::

    scene = dc.Scene(large_rotations=True)
    column = scene.add_beam(tmesh, where="column", section=dc.Rectangle(0.1, 0.1),
                            material=dc.Elastic(1e5, 0.0))
    scene.fix(column, where="base")
    scene.load(column, where="tip", force=(0.0, -1.0), moment=0.01)
    scene.monitor("tip", column, where="tip")
    result = dc.solve(scene, dc.LoadControl(steps=40))
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .io.mesh import TaggedMesh
from .materials import Elastic
from .parts import Frame2D, PartRef
from .sections import Section

KINEMATICS = ("bernoulli", "timoshenko")


@dataclass(frozen=True)
class Monitor:
    name: str
    part: PartRef
    where: str
    kind: str = "dofs"  # or "reaction"


class Scene:
    """Parts, supports, loads and monitors of one analysis.

    large_rotations: co-rotational (geometrically nonlinear) structures if
    True; geometrically linear ones if False.
    """

    def __init__(self, large_rotations: bool = True):
        self.large_rotations = bool(large_rotations)
        self._models: dict[int, Frame2D] = {}
        self.monitors: list[Monitor] = []
        self._loads = 0
        self._prescribed = 0

    # -- parts -----------------------------------------------------------------
    def _model(self, tmesh: TaggedMesh) -> Frame2D:
        if not isinstance(tmesh, TaggedMesh):
            raise TypeError(f"expected a TaggedMesh from dolfinx_corot.io.from_gmsh, got {type(tmesh).__name__}")
        key = id(tmesh)
        if key not in self._models:
            if self._models:
                raise NotImplementedError("all structural parts must share one mesh (parts on different "
                                          "meshes are coupled in a later release); put every group in one gmsh model")
            self._models[key] = Frame2D(tmesh, self.large_rotations)
        return self._models[key]

    def add_beam(self, tmesh: TaggedMesh, where: str | None = None, *, section: Section,
                 material: Elastic, kinematics: str = "bernoulli") -> PartRef:
        """Beam elements on the cells of group ``where`` (all cells if None).

        kinematics: 'bernoulli' (no shear deformation) or 'timoshenko' (shear
        area ``section.As``, shear modulus ``material.G``).
        """
        if kinematics not in KINEMATICS:
            raise ValueError(f"kinematics '{kinematics}' is not one of {KINEMATICS}")
        if not isinstance(material, Elastic):
            raise TypeError(f"beam '{where}': material must be dc.Elastic, got {type(material).__name__}")
        GAs = 0.0
        if kinematics == "timoshenko":
            if section.As <= 0.0:
                raise ValueError(f"beam '{where}': Timoshenko kinematics needs a shear area As > 0")
            GAs = material.G * section.As
        return self._model(tmesh).add_elements(where, material.E * section.A, material.E * section.I,
                                               GAs, 0.0, "beam")

    def add_truss(self, tmesh: TaggedMesh, where: str | None = None, *, area: float, material: Elastic,
                  prestress_force: float = 0.0) -> PartRef:
        """Bar (truss, anchor) elements on group ``where``; axial force only.

        prestress_force: initial axial force N0 (tension positive).
        """
        if not isinstance(material, Elastic):
            raise TypeError(f"truss '{where}': material must be dc.Elastic, got {type(material).__name__}")
        if not area > 0.0:
            raise ValueError(f"truss '{where}': area = {area} must be positive")
        return self._model(tmesh).add_elements(where, material.E * area, 0.0, 0.0, float(prestress_force), "truss")

    # -- conditions ------------------------------------------------------------
    def fix(self, part: PartRef, where: str, dofs: tuple[str, ...] | None = None) -> None:
        """Support: zero displacement/rotation of ``dofs`` (default all) at the nodes of ``where``."""
        model = part.model
        names = model.dof_names
        dofs = names if dofs is None else tuple(dofs)
        bad = [d for d in dofs if d not in names]
        if bad:
            raise ValueError(f"fix '{where}': unknown dof(s) {bad}; this part has {names}")
        model.fix(where, tuple(names.index(d) for d in dofs))

    def prescribe(self, part: PartRef, where: str, **values: float) -> None:
        """Prescribed displacement/rotation at the nodes of ``where``, scaled by the load factor.

        Example: ``scene.prescribe(beam, "tip", uy=-1.0)`` (displacement control:
        λ = 1 moves the tip by −1; read the force with :meth:`monitor_reaction`).
        """
        model = part.model
        names = model.dof_names
        bad = [d for d in values if d not in names]
        if bad or not values:
            raise ValueError(f"prescribe '{where}': give one or more of {names} as keywords; got {list(values)}")
        for dof, value in values.items():
            if not np.isfinite(value):
                raise ValueError(f"prescribe '{where}': {dof} = {value} is not finite")
            model.prescribe(where, names.index(dof), float(value))
        self._prescribed += 1

    def load(self, part: PartRef, where: str, force=(0.0, 0.0), moment: float = 0.0) -> None:
        """Dead point force (fx, fy) and moment mz at each node of ``where``, scaled by the load factor."""
        force = np.asarray(force, dtype=float)
        if force.shape != (2,) or not np.all(np.isfinite(force)) or not np.isfinite(moment):
            raise ValueError(f"load '{where}': force must be two finite numbers and moment finite; "
                             f"got force={force.tolist()}, moment={moment}")
        part.model.add_load(where, np.array([force[0], force[1], moment]))
        self._loads += 1

    def monitor(self, name: str, part: PartRef, where: str) -> None:
        """Record the dofs of the single node of group ``where`` after every step."""
        part.model.nodal_values(where)  # fails early for a missing group
        self.monitors.append(Monitor(name, part, where))

    def monitor_reaction(self, name: str, part: PartRef, where: str) -> None:
        """Record the force (sum over the nodes of ``where``) that the supports or prescribed
        displacements there exert on the structure, after every step: name_Fx, name_Fy, name_Mz."""
        part.model.tmesh.vertices(where)  # fails early for a missing group
        self.monitors.append(Monitor(name, part, where, "reaction"))

    # -- introspection -----------------------------------------------------------
    @property
    def model(self) -> Frame2D:
        if not self._models:
            raise ValueError("the scene has no parts: add a beam or a truss first")
        return next(iter(self._models.values()))

    def effects(self) -> list[str]:
        """What will be assembled, in words."""
        out = []
        for m in self._models.values():
            kinds = sorted({p.kind for p in m.parts})
            frame = "co-rotational" if self.large_rotations else "geometrically linear"
            out.append(f"{' and '.join(kinds)} elements ({frame}, 2D)")
        if self._loads:
            out.append("point loads (dead)")
        if self._prescribed:
            out.append("prescribed displacements")
        return out

    def monitor_values(self, system) -> dict[str, float]:
        """Monitored dofs and reactions at the current state (``system`` holds f_int)."""
        values = {}
        for mon in self.monitors:
            model = mon.part.model
            if mon.kind == "reaction":
                # reaction on the structure = λ f_ext − f_int at the constrained nodes
                fint = model.reaction(mon.where, system.internal_force())
                fext = model.reaction(mon.where, system.fext) * system.load_factor
                for comp, val in zip(("Fx", "Fy", "Mz"), fext - fint):
                    values[f"{mon.name}_{comp}"] = -float(val)
            else:
                for comp, val in zip(model.dof_names, model.nodal_values(mon.where)):
                    values[f"{mon.name}_{comp}"] = float(val)
        return values

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

from .contact.interface import Contact, Interface
from .contact.laws import Penalty
from .io.mesh import TaggedMesh
from .materials import Elastic
from .parts import Coupled, Part, PartRef, part_for_mesh
from .parts.base import finite_vector
from .sections import Section
from .stabilisation import Stabilisation, Stabiliser

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

    LINEAR_SOLVERS = ("auto", "direct", "iterative")

    def __init__(self, large_rotations: bool = True, linear_solver: str = "auto"):
        """linear_solver: 'auto' (CG + algebraic multigrid for a scene of continua only, MUMPS
        otherwise), 'direct' (MUMPS) or 'iterative'; PETSc options with the prefix
        ``dc_newton_`` override either (e.g. ``-dc_newton_ksp_rtol 1e-12``)."""
        if linear_solver not in self.LINEAR_SOLVERS:
            raise ValueError(f"linear_solver '{linear_solver}' is not one of {self.LINEAR_SOLVERS}")
        self.linear_solver = linear_solver
        self.large_rotations = bool(large_rotations)
        self._models: dict[int, Part] = {}
        self._coupled: Coupled | None = None
        self.monitors: list[Monitor] = []
        self._loads = 0
        self._prescribed = 0
        self.interfaces: list = []
        self.stabilisers: list[Stabiliser] = []

    # -- parts -----------------------------------------------------------------
    def _model(self, tmesh: TaggedMesh, solid_degree: int | None = None) -> Part:
        if not isinstance(tmesh, TaggedMesh):
            raise TypeError(f"expected a TaggedMesh from dolfinx_corot.io.from_gmsh, got {type(tmesh).__name__}")
        key = id(tmesh)
        if key not in self._models:
            if self._models:
                gdims = {m.gdim for m in self._models.values()}
                if gdims != {tmesh.mesh.geometry.dim}:
                    raise ValueError(f"parts of one scene live in one space: this mesh has gdim "
                                     f"{tmesh.mesh.geometry.dim}, the scene's other parts {sorted(gdims)}")
            self._coupled = None
            self._models[key] = part_for_mesh(tmesh, self.large_rotations, solid_degree)
        model = self._models[key]
        if (solid_degree is not None) != model.continuum:
            raise ValueError("a mesh carries either a solid or structural parts, not both")
        if solid_degree is not None and model.degree != solid_degree:
            raise ValueError(f"the solid on this mesh has degree {model.degree}; all its regions share it")
        return model

    def add_solid(self, tmesh: TaggedMesh, where: str | None = None, *, material: Elastic,
                  degree: int = 2) -> PartRef:
        """Large-deformation continuum (plane strain in 2D, or 3D) on the cells of group ``where``
        (all cells if None) of a mesh that fills its space; Lagrange elements of ``degree`` 1
        or 2 on triangles, quadrilaterals, tetrahedra or hexahedra.

        material: dc.SaintVenantKirchhoff or dc.NeoHookean (dc.Elastic: St Venant–Kirchhoff).
        A named region given after the whole mesh takes its cells over: that is how one
        element or a zone is weakened as an imperfection.
        """
        if not isinstance(material, Elastic):
            raise TypeError(f"solid '{where}': material must be a dc material, got {type(material).__name__}")
        return self._model(tmesh, solid_degree=int(degree)).add_region(where, material)

    def add_beam(self, tmesh: TaggedMesh, where: str | None = None, *, section: Section,
                 material: Elastic, kinematics: str = "bernoulli", orientation=(0.0, 0.0, 1.0)) -> PartRef:
        """Beam elements on the cells of group ``where`` (all cells if None).

        kinematics: 'bernoulli' (no shear deformation) or 'timoshenko' (shear
        area ``section.As``, shear modulus ``material.G``). In 3D,
        ``orientation`` is a vector whose part normal to each element is the
        local y axis (``section.Iz`` is about the local z axis, ``section.Iy``
        about y); it is ignored in 2D.
        """
        if kinematics not in KINEMATICS:
            raise ValueError(f"kinematics '{kinematics}' is not one of {KINEMATICS}")
        self._check_material("beam", where, material)
        model = self._model(tmesh)
        if kinematics == "timoshenko" and section.As <= 0.0:
            raise ValueError(f"beam '{where}': Timoshenko kinematics needs a shear area As > 0")
        return model.add_beam(where, section, material, kinematics, orientation)

    def add_shell(self, tmesh: TaggedMesh, where: str | None = None, *, thickness: float, material: Elastic,
                  membrane: str = "opt", drilling: float = 1e-2) -> PartRef:
        """Flat co-rotational shell triangles (membrane with drilling rotations + DKT bending) on
        group ``where`` of a triangle mesh in space.

        membrane: ``"opt"`` (default), Felippa's optimal ANDES triangle, whose drilling
        rotations carry real stiffness and which bends in its plane without locking; or
        ``"cst"``, the constant-strain triangle with a drilling penalty α·G·t·A, α = ``drilling``.
        """
        self._check_material("shell", where, material)
        return self._model(tmesh).add_shell(where, material.E, material.nu, float(thickness), float(drilling),
                                            membrane)

    def add_membrane(self, tmesh: TaggedMesh, where: str | None = None, *, thickness: float,
                     material: Elastic) -> PartRef:
        """Co-rotational membranes (in-plane stiffness only) on group ``where`` of a triangle
        (constant-strain triangles) or quadrilateral (bilinear Q4) mesh in space; nodes
        carried by membranes alone have their rotations fixed."""
        self._check_material("membrane", where, material)
        return self._model(tmesh).add_membrane(where, material.E, material.nu, float(thickness))

    def add_truss(self, tmesh: TaggedMesh, where: str | None = None, *, area: float, material: Elastic,
                  prestress_force: float = 0.0) -> PartRef:
        """Bar (truss, anchor) elements on group ``where``; axial force only.

        prestress_force: initial axial force N0 (tension positive).
        """
        self._check_material("truss", where, material)
        if not area > 0.0:
            raise ValueError(f"truss '{where}': area = {area} must be positive")
        return self._model(tmesh).add_truss(where, area, material, prestress_force)

    @staticmethod
    def _check_material(kind: str, where, material) -> None:
        if not isinstance(material, Elastic):
            raise TypeError(f"{kind} '{where}': material must be dc.Elastic, got {type(material).__name__}")

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

    def prescribe(self, part: PartRef, where: str, amplitude=None, **values) -> None:
        """Prescribed displacement/rotation at the nodes of ``where``: a number scaled by the load
        factor (or by ``amplitude(λ)``, a :class:`dolfinx_corot.Amplitude`), or a function
        ``motion(load_factor, stage)`` of the load factor and the construction stage (None
        outside staged analyses).

        Example: ``scene.prescribe(beam, "tip", uy=-1.0)`` (displacement control:
        λ = 1 moves the tip by −1; read the force with :meth:`monitor_reaction`);
        ``scene.prescribe(beam, "tip", uy=lambda lam, stage: -0.1 * lam**2)``.
        """
        model = part.model
        names = model.dof_names
        bad = [d for d in values if d not in names]
        if bad or not values:
            raise ValueError(f"prescribe '{where}': give one or more of {names} as keywords; got {list(values)}")
        for dof, value in values.items():
            if callable(value):
                if amplitude is not None:
                    raise ValueError(f"prescribe '{where}': {dof} is a function of the load factor already; "
                                     "an amplitude does not apply to it")
                model.prescribe(where, names.index(dof), 0.0, None, function=value)
                continue
            if not np.isfinite(value):
                raise ValueError(f"prescribe '{where}': {dof} = {value} is not finite")
            model.prescribe(where, names.index(dof), float(value), amplitude)
        self._prescribed += 1

    def load(self, part: PartRef, where: str, force=None, moment=None, amplitude=None, traction=None) -> None:
        """Dead point force and moment at each node of ``where``, scaled by the load factor λ
        or, with an ``amplitude`` (:class:`dolfinx_corot.Amplitude`), by amplitude(λ).

        2D: force (fx, fy), moment mz (a number). 3D: force (fx, fy, fz),
        moment (mx, my, mz), a fixed spatial vector. Solids: ``traction`` (per unit
        reference area, a facet group) or ``force`` at each node of the group.
        """
        model = part.model
        if traction is not None:
            model.add_traction(where, finite_vector(f"load '{where}'", "traction", traction, model.gdim), amplitude)
            self._loads += 1
        values = model.load_values(where, force, moment)
        if values is not None:
            model.add_load(where, values, amplitude)
            self._loads += 1

    def gravity(self, part: PartRef, acceleration, density: float, where: str | None = None,
                amplitude=None) -> None:
        """Body force ρ·g per unit reference volume on a solid (cells of ``where``, all if None)."""
        model = part.model
        acc = np.atleast_1d(np.asarray(acceleration, dtype=float))
        if acc.shape != (model.gdim,) or not (np.isfinite(density) and density >= 0.0):
            raise ValueError(f"gravity: acceleration must be {model.gdim} numbers and density ≥ 0")
        model.add_body_force(where, density * acc, amplitude)
        self._loads += 1

    def contact(self, slaves: tuple[PartRef, str], masters: tuple[PartRef, str], law=None,
                symmetric: bool = False, smooth: bool = True) -> list:
        """Node-to-segment contact (2D, frictionless) of the nodes of boundary group ``slaves[1]``
        of part ``slaves[0]`` against the boundary segments of ``masters``; ``symmetric`` adds
        the other direction (two-pass contact, for two deformable bodies).

        law: dc.Penalty() (default) or dc.AugmentedLagrangian(); the default penalty scales with
        the bodies' stiffness and the master segments' length.
        smooth: the master surface is the C¹ Hermite curve through its nodes (normals continuous
        from segment to segment: robust sliding over curved and deforming masters); False: the
        straight segments (slave forces shared linearly by the segment's two nodes: the patch
        test is passed exactly). Returns the interfaces made."""
        law = Penalty() if law is None else law
        made = [Interface(slaves, masters, law, smooth)]
        if symmetric:
            made.append(Interface(masters, slaves, law, smooth))
        self.interfaces += made
        return made

    def stabilise(self, part: PartRef, stiffness: float | None = None, where: str | None = None, *,
                  rotational_stiffness: float | None = None, factor: float = 1e-6, tolerance: float = 1e-9,
                  max_updates: int = 20) -> Stabiliser:
        """Weak springs to ground on the nodes of ``part`` (of its group ``where``, if given) for a body
        that is free until contact closes (a lining in a larger hole, a block above its support, a
        frictionless ring that may spin): k (u − a) on the translations (and the planar rotations of
        2D structures) with the anchor a where they were last released; after each converged
        solve the anchors follow the body and the solve is repeated while the springs
        carry more than ``tolerance`` times the load (at most ``max_updates`` times a step), so
        the converged answer is that without springs once the body is held
        (:mod:`dolfinx_corot.stabilisation`).

        stiffness: spring per node and translational dof (force per length); None: ``factor``
        times the mean diagonal entry of the part's own tangent. rotational_stiffness: likewise
        per planar rotation (moment per radian; 0: none). The work the springs absorb and their
        force relative to the load are the history columns ``stab_work``, ``stab_force``
        (end of step), ``stab_peak`` and ``stab_updates``."""
        if any(s.part == part and s.where == where for s in self.stabilisers):
            raise ValueError(f"stabilise: {part.kind} '{part.name or 'all cells'}'"
                             f"{'' if where is None else f' at {where!r}'} is stabilised already")
        made = Stabiliser(part, stiffness, where, rotational_stiffness, factor, tolerance, max_updates)
        self.stabilisers.append(made)
        return made

    def monitor(self, name: str, part: PartRef, where: str) -> None:
        """Record the dofs of the (first) node of group ``where`` after every step, as
        ``name_ux``, ``name_uy``, … In 2D ``name_rz`` is the total angle (it may exceed 2π);
        in 3D ``name_rx..rz`` is the rotation vector of the nodal rotation (norm ≤ π)."""
        part.model.nodal_values(where)  # fails early for a missing group
        self._add_monitor(Monitor(name, part, where))

    def _add_monitor(self, monitor: Monitor) -> None:
        taken = [m for m in self.monitors if m.name == monitor.name and m.kind == monitor.kind]
        if taken:
            raise ValueError(f"monitor '{monitor.name}' exists already (on group '{taken[0].where}'): give each "
                             "monitor a name of its own (its history columns carry it)")
        self.monitors.append(monitor)

    def monitor_reaction(self, name: str, part: PartRef, where: str) -> None:
        """Record the force (sum over the nodes of ``where``) that the supports or prescribed
        displacements there exert on the structure, after every step: name_Fx, name_Fy, name_Mz
        (2D) or name_Fx … name_Mz (3D)."""
        part.model.tmesh.vertices(where)  # fails early for a missing group
        self._add_monitor(Monitor(name, part, where, "reaction"))

    # -- introspection -----------------------------------------------------------
    @property
    def model(self) -> Part | Coupled:
        """The part model: one mesh's, or the parts of several meshes coupled."""
        if not self._models:
            raise ValueError("the scene has no parts: add a beam or a truss first")
        if len(self._models) == 1:
            return next(iter(self._models.values()))
        if self._coupled is None:
            self._coupled = Coupled(list(self._models.values()))
        return self._coupled

    def contributions(self) -> list:
        """The contributions the scene adds to its parts' system (contact, when it has interfaces;
        the stabilisation, when a part is stabilised): a scene without them pays nothing for them."""
        out = [Contact(self.interfaces)] if self.interfaces else []
        if self.stabilisers:
            out.append(Stabilisation(self.stabilisers))
        return out

    def effects(self) -> list[str]:
        """What will be assembled, in words."""
        out = [m.effect() for m in self._models.values()]
        if self._loads:
            out.append("dead loads")
        if self._prescribed:
            out.append("prescribed displacements")
        for itf in self.interfaces:
            d = itf.describe()
            kind = "augmented Lagrangian" if itf.law.augmented else "penalty"
            surface = "smooth master curve" if itf.smooth else "straight master segments"
            out.append(f"contact {itf.name}: {d['slave_nodes']} slave nodes on {d['master_segments']} "
                       f"segments ({kind}, penalty {itf.penalty:.3g}, {surface})")
        out += [s.effect() for s in self.stabilisers]
        return out

    def describe(self) -> dict:
        """What defines the scene (its fingerprint's content): parts with mesh sizes, a hash of the
        node coordinates, groups and materials; the contact interfaces; the stabilised parts."""
        out = {"large_rotations": self.large_rotations, "parts": [m.describe() for m in self._models.values()],
               "interfaces": [itf.describe() for itf in self.interfaces]}
        if self.stabilisers:
            out["stabilisation"] = [s.describe() for s in self.stabilisers]
        return out

    def monitor_values(self, system) -> dict[str, float]:
        """Monitored dofs and reactions at the current state (``system`` holds f_int)."""
        values = {}
        for mon in self.monitors:
            model = mon.part.model
            if mon.kind == "reaction":
                # reaction on the structure = λ f_ext − f_int at the constrained nodes
                fint = model.reaction(mon.where, system.model_array(model, system.internal_force()))
                fext = model.reaction(mon.where, system.model_array(model, system.fext_total))
                names = ("Fx", "Fy", "Mz") if model.gdim == 2 else ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
                for comp, val in zip(names, fext - fint):
                    values[f"{mon.name}_{comp}"] = -float(val)
            else:
                for comp, val in zip(model.dof_names, model.nodal_values(mon.where)):
                    values[f"{mon.name}_{comp}"] = float(val)
        return values

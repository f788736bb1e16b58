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

import numbers
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import validate
from .conditions import Condition
from .io.mesh import TaggedMesh
from .loads import FollowerLoads
from .materials import Elastic
from .parts import Coupled, Part, PartRef, part_for_mesh
from .parts.base import finite_vector
from .parts.groups import chain_coordinate
from .result import Profile
from .sections import Section
from .stabilisation import Stabilisation, Stabiliser

if TYPE_CHECKING:  # a scene without contact loads no contact modules
    from .contact.pair import ContactPair

KINEMATICS = ("bernoulli", "timoshenko")


def _on(part: PartRef, where: str) -> str:
    """'on <group> of <kind> <name>' (a condition's label)."""
    return f"on '{where}' of {part.kind}" + (f" '{part.name}'" if part.name else "")


REDUCTIONS = {
    "sum": lambda v: np.sum(v, axis=0),
    "mean": lambda v: np.mean(v, axis=0),
    "max": lambda v: np.max(v, axis=0),
    "min": lambda v: np.min(v, axis=0),
    "absmax": lambda v: v[np.argmax(np.abs(v), axis=0), np.arange(v.shape[1])],
}
"""Reductions of a group's nodal values (n, ndof) to one value per dof; ``absmax`` is the value of
largest magnitude, with its sign."""


@dataclass(frozen=True)
class Monitor:
    """What a monitor records: the dofs of group ``where`` (``kind`` 'dofs': one node, a reduction
    ``reduce`` over the nodes, or a profile of all of them ordered ``along`` the group) or the
    reaction there (``kind`` 'reaction')."""

    name: str
    part: PartRef
    where: str
    kind: str = "dofs"  # or "reaction", "contact" (part: a ContactPair, where: its side), "results"
    reduce: str | None = None
    along: object = None
    components: tuple | None = None  # "results": the components recorded (None: all)


class Scene:
    """Parts, supports, loads and monitors of one analysis.

    large_rotations: co-rotational (geometrically nonlinear) structures if
    True; geometrically linear ones if False.
    """

    LINEAR_SOLVERS = ("auto", "direct", "iterative")

    def __init__(self, large_rotations: bool = True, linear_solver: str = "auto", tangent: str = "auto"):
        """linear_solver: 'auto' (CG + algebraic multigrid for a scene of continua only, MUMPS
        otherwise), 'direct' (MUMPS) or 'iterative'; PETSc options with the prefix
        ``dc_newton_`` override either (e.g. ``-dc_newton_ksp_rtol 1e-12``).

        tangent: what Newton factorizes for 3D beams, shells and membranes, whose co-rotational
        tangent is not symmetric away from equilibrium: 'auto' (its symmetric part, by LDLᵀ,
        where the skew part vanishes at equilibrium — no applied moments, follower loads,
        contact or stabilisation, no node with exactly one rotation held — so that Newton
        keeps converging quadratically; the consistent tangent, by LU, otherwise), 'consistent'
        or 'symmetrized' (see :meth:`dolfinx_corot.assembly.System.symmetrize`)."""
        if linear_solver not in self.LINEAR_SOLVERS:
            raise ValueError(f"linear_solver '{linear_solver}' is not one of {self.LINEAR_SOLVERS}")
        validate.choice("Scene", "tangent", tangent, validate.TANGENTS)
        self.linear_solver = linear_solver
        self.tangent = tangent
        self.large_rotations = bool(large_rotations)
        self._models: dict[int, Part] = {}
        self._coupled: Coupled | None = None
        self.monitors: list[Monitor] = []
        self._groups: dict = {}
        self._loads = 0
        self._prescribed = 0
        self.interfaces: list = []
        self.pairs: list[ContactPair] = []  # what contact() returned, in order
        self.stabilisers: list[Stabiliser] = []

    # -- parts -----------------------------------------------------------------
    def _model(self, tmesh: TaggedMesh, solid_degree: int | None = None, kind: str | None = None) -> Part:
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
            self._models[key] = part_for_mesh(tmesh, self.large_rotations, solid_degree, kind)
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
        or 2 on triangles, quadrilaterals, tetrahedra or hexahedra. Degree 2 also takes gmsh's
        second-order (curved) cells. Every cell is checked here: an inverted, self-intersecting
        or degenerate cell raises dc.MeshError naming it (``dolfinx_corot.parts.cells``).

        material: dc.SaintVenantKirchhoff or dc.NeoHookean (dc.Elastic: St Venant–Kirchhoff).
        A named region given after the whole mesh takes its cells over: that is how one
        element or a zone is weakened as an imperfection.
        """
        if not isinstance(material, Elastic):
            raise TypeError(f"solid '{where}': material must be a dc material, got {type(material).__name__}")
        return self._model(tmesh, solid_degree=int(degree)).add_region(where, material)

    def add_beam(self, tmesh: TaggedMesh, where: str | None = None, *, section: Section,
                 material: Elastic, kinematics: str = "bernoulli", orientation=(0.0, 0.0, 1.0),
                 plane_strain: bool = False) -> PartRef:
        """Beam elements on the cells of group ``where`` (all cells if None).

        kinematics: 'bernoulli' (no shear deformation) or 'timoshenko' (shear
        area ``section.As``, shear modulus ``material.G``). In 3D,
        ``orientation`` is a vector whose part normal to each element is the
        local y axis (``section.Iz`` is about the local z axis, ``section.Iy``
        about y); it is ignored in 2D.
        plane_strain (2D only): the beam stands for a plate strip of unit width in plane
        strain (a tunnel lining): axial and bending stiffness take the plate modulus
        E/(1 − ν²) (section per unit width, e.g. ``dc.Rectangle(1.0, t)``); the shear
        modulus stays G.
        """
        if kinematics not in KINEMATICS:
            raise ValueError(f"kinematics '{kinematics}' is not one of {KINEMATICS}")
        self._check_material("beam", where, material)
        model = self._model(tmesh)
        if kinematics == "timoshenko" and section.As <= 0.0:
            raise ValueError(f"beam '{where}': Timoshenko kinematics needs a shear area As > 0")
        if plane_strain and model.gdim != 2:
            raise ValueError(f"beam '{where}': plane_strain is for 2D beams (a plate strip of unit width); "
                             f"this mesh is in {model.gdim}D, where a beam has a section of its own")
        ref = model.add_beam(where, section, material, kinematics, orientation, plane_strain=bool(plane_strain))
        model.set_mass(ref, material.density, section.A)
        return ref

    def add_shell(self, tmesh: TaggedMesh, where: str | None = None, *, thickness: float | None = None,
                  material=None, section=None, axis=None, membrane: str | None = None, drilling: float = 1e-2,
                  kinematics: str = "kirchhoff", shallow: bool = False) -> PartRef:
        """Flat co-rotational shells on group ``where`` of a triangle or quadrilateral mesh in space.

        The section: ``thickness`` and ``material`` (``dc.Elastic``, or ``dc.Orthotropic``, a single
        layer), or ``section=dc.Laminate([...])`` (plies from the bottom face to the top one, the
        top on the side of the element normal e₃, which follows the right-hand rule over a cell's
        nodes: orient the mesh consistently). ``axis``: the material axis 1 of orthotropic plies,
        (x, y, z) or a function of the points (n, 3) → (n, 3), projected onto each cell; a ply's
        angle is counted from it about e₃.

        Triangles: membrane with drilling rotations + DKT bending (Kirchhoff). membrane:
        ``"opt"`` (the default), Felippa's optimal ANDES triangle, whose drilling rotations carry
        real stiffness and which bends in its plane without locking; or ``"cst"``, the
        constant-strain triangle with a drilling penalty α·G·t·A, α = ``drilling``.

        Quadrilaterals (possibly warped): the bilinear membrane with incompatible modes (QM6, no
        locking in in-plane bending) and a drilling penalty ½·α·G·t∫(θz − ω)²dA (membrane
        ``"qm6"`` or None); bending by kinematics ``"kirchhoff"`` (the default), the discrete
        Kirchhoff quadrilateral (DKQ), or ``"mindlin"``, MITC4 bending and transverse shear
        (Reissner–Mindlin, shear factor 5/6, free of shear locking; for thick shells and the
        transverse shear of laminates: bilinear rotations make it stiffer than the DKQ where
        curvature changes fast on coarse meshes). A quadrilateral mesh given shells carries its
        membranes with the same element (add its shells first).

        ``shallow``: the co-rotational local law adds the membrane strain of each element's own
        bending, von Kármán's ½w,ᵢw,ⱼ of its discrete Kirchhoff slopes (as the beams' shallow-arch
        strain; :mod:`dolfinx_corot.elements.shallow_shell`): the membrane forces then act on the
        element's bending (initial-stress stiffness). It makes coarse meshes of shells that buckle
        or snap under compression far more accurate (docs/theory.md, "The shallow-shell local
        law"); a shell pulled taut around a point load on coarse cells (the pull-out) comes out
        stiffer with it. A geometrically linear analysis ignores it.
        """
        if not isinstance(shallow, (bool, np.bool_)):
            raise ValueError(f"shell '{where}': shallow = {shallow!r} must be True or False")
        section, density = self._shell_section("shell", where, thickness, material, section)
        model = self._model(tmesh, kind="shell")
        ref = model.add_shell(where, section, float(drilling), membrane, kinematics, axis, bool(shallow))
        model.set_mass(ref, density, section.thickness)
        return ref

    def add_membrane(self, tmesh: TaggedMesh, where: str | None = None, *, thickness: float | None = None,
                     material=None, section=None, axis=None) -> PartRef:
        """Co-rotational membranes (in-plane stiffness only) on group ``where`` of a triangle
        (constant-strain triangles) or quadrilateral mesh in space (bilinear Q4; on a mesh that also
        carries shells, the shell's membrane with incompatible modes); nodes carried by membranes
        alone have their rotations fixed. The section as for :meth:`add_shell` (its membrane
        stiffness A alone): an orthotropic fabric is ``material=dc.Orthotropic(...)`` with its
        warp direction as ``axis``."""
        section, density = self._shell_section("membrane", where, thickness, material, section)
        model = self._model(tmesh)
        ref = model.add_membrane(where, section, axis)
        model.set_mass(ref, density, section.thickness)
        return ref

    @staticmethod
    def _shell_section(kind: str, where, thickness, material, section):
        """(Laminate, density) of a shell or membrane from (thickness, material) or section."""
        from .materials import Orthotropic
        from .sections import Laminate

        label = f"{kind} '{where}'"
        if section is not None:
            if thickness is not None or material is not None:
                raise ValueError(f"{label}: give either section=dc.Laminate(...) or thickness and material, "
                                 "not both")
            if not isinstance(section, Laminate):
                raise TypeError(f"{label}: section must be dc.Laminate, got {type(section).__name__}")
            return section, section.density
        if thickness is None or material is None:
            raise ValueError(f"{label}: give thickness and material (or section=dc.Laminate(...))")
        if not isinstance(material, (Elastic, Orthotropic)):
            raise TypeError(f"{label}: material must be dc.Elastic or dc.Orthotropic, got {type(material).__name__}")
        if not (np.isfinite(thickness) and thickness > 0.0):
            raise ValueError(f"{label}: thickness = {thickness} must be positive")
        return Laminate.single(float(thickness), material), material.density

    def add_truss(self, tmesh: TaggedMesh, where: str | None = None, *, area: float, material: Elastic,
                  prestress_force: float = 0.0) -> PartRef:
        """Bar (truss, anchor) elements on group ``where``; axial force only.

        prestress_force: initial axial force N0 (tension positive).
        """
        self._check_material("truss", where, material)
        if not area > 0.0:
            raise ValueError(f"truss '{where}': area = {area} must be positive")
        model = self._model(tmesh)
        ref = model.add_truss(where, area, material, prestress_force)
        model.set_mass(ref, material.density, float(area))
        return ref

    @staticmethod
    def _check_material(kind: str, where, material) -> None:
        if not isinstance(material, Elastic):
            raise TypeError(f"{kind} '{where}': material must be dc.Elastic, got {type(material).__name__}")

    # -- conditions ------------------------------------------------------------
    def fix(self, part: PartRef, where: str, dofs: tuple[str, ...] | None = None) -> Condition:
        """Support: zero displacement/rotation of ``dofs`` (default all) at the nodes of ``where``.
        Returns the support as a :class:`~dolfinx_corot.conditions.Condition`, which construction
        stages may add (it then holds the nodes where they are) or remove (its reaction is released
        over the stage)."""
        model = part.model
        names = model.dof_names
        dofs = names if dofs is None else tuple(dofs)
        bad = [d for d in dofs if d not in names]
        if bad:
            raise ValueError(f"fix '{where}': unknown dof(s) {bad}; this part has {names}")
        label = f"{_on(part, where)} ({', '.join(dofs)})"
        return model.fix(where, tuple(names.index(d) for d in dofs), Condition("support", label))

    def prescribe(self, part: PartRef, where: str, amplitude=None, **values) -> Condition:
        """Prescribed displacement/rotation at the nodes of ``where``: a number scaled by the load
        factor (or by ``amplitude(λ)``, a :class:`dolfinx_corot.Amplitude`), or a function
        ``motion(load_factor, stage)`` of the load factor and the construction stage (None
        outside staged analyses).

        Example: ``scene.prescribe(beam, "tip", uy=-1.0)`` (displacement control:
        λ = 1 moves the tip by −1; read the force with :meth:`monitor_reaction`);
        ``scene.prescribe(beam, "tip", uy=lambda lam, stage: -0.1 * lam**2)``.

        Returns the motion as a :class:`~dolfinx_corot.conditions.Condition` (construction stages
        may add or remove it; in a staged run ``stage`` is the name of the stage).
        """
        model = part.model
        names = model.dof_names
        bad = [d for d in values if d not in names]
        if bad or not values:
            raise ValueError(f"prescribe '{where}': give one or more of {names} as keywords; got {list(values)}")
        condition = Condition("motion", f"{_on(part, where)} ({', '.join(values)})")
        for dof, value in values.items():
            if callable(value):
                if amplitude is not None:
                    raise ValueError(f"prescribe '{where}': {dof} is a function of the load factor already; "
                                     "an amplitude does not apply to it")
                model.prescribe(where, names.index(dof), 0.0, None, function=value, condition=condition)
                continue
            if not np.isfinite(value):
                raise ValueError(f"prescribe '{where}': {dof} = {value} is not finite")
            model.prescribe(where, names.index(dof), float(value), amplitude, condition=condition)
        self._prescribed += 1
        return condition

    def load(self, part: PartRef, where: str | None, force=None, moment=None, amplitude=None, traction=None,
             per_length=None, axes: str = "global", follower: bool = False) -> Condition:
        """Dead point force and moment at each node of ``where``, scaled by the load factor λ
        or, with an ``amplitude`` (:class:`dolfinx_corot.Amplitude`), by amplitude(λ).

        2D: force (fx, fy), moment mz (a number). 3D: force (fx, fy, fz),
        moment (mx, my, mz), a fixed spatial vector. Solids: ``traction`` (per unit
        reference area, a facet group) or ``force`` at each node of the group.

        Beams and bars: ``per_length``, a uniform load per unit length on the elements of ``part``
        (those in group ``where``; None: all), as work-equivalent nodal forces and, for beams, the
        fixed-end moments ±q l²/12 (:mod:`dolfinx_corot.elements.uniform_load`):

        * ``axes='global'`` (default): gdim components in global axes, per unit reference length,
          dead (a weight, a wind load of fixed direction);
        * ``axes='element'``: components in each element's axes (2D: along the element, then
          normal to it, e_z × t; 3D: the beam's local x, y, z), dead: fixed at the element's
          reference axes;
        * ``follower=True`` (``axes='element'``): the load turns with the element and acts per
          unit current length (a pressure on a ring or an arch: ``per_length=(0.0, -p)`` with the
          normal e_z × t pointing away from the loaded side; in 3D along the element's current
          axes, e2 and e3 turning with its nodes' rotations); its load stiffness enters the
          tangent (:mod:`dolfinx_corot.loads`).

        Shells and membranes: ``per_length``, a uniform dead load per unit reference length in
        global axes (fx, fy, fz) on edges: the lines of ``where`` if it is a group of lines of the
        mesh (a gmsh physical curve), or the part's boundary edges between the nodes of ``where``
        if it is a group of nodes. Its nodal forces are q l/2 per edge end, and on OPT triangles
        the drilling moments of their quadratic edge field (:mod:`dolfinx_corot.elements.uniform_load`),
        without which nodal forces at a free corner of OPT triangles are not a constant-stress load.

        Returns the load as a :class:`~dolfinx_corot.conditions.Condition` (construction stages
        may add it — applied over that stage — or remove it — taken off over that stage).
        """
        model = part.model
        condition = Condition("load", _on(part, where))
        if axes not in ("global", "element"):
            raise ValueError(f"load on '{where}': axes = {axes!r} is not 'global' or 'element'")
        if per_length is not None:
            if force is not None or moment is not None or traction is not None:
                raise ValueError(f"load on '{where}': give per_length alone (a distributed load), or point loads")
            n = model.gdim if (axes == "global" or model.gdim == 3) else 2
            q = finite_vector(f"load per length on '{where}'", "per_length", per_length, n)
            model.add_line_load(part, where, q, axes, bool(follower), amplitude, condition)
            self._loads += 1
            return condition
        if follower:
            raise ValueError(f"load on '{where}': follower=True is for distributed loads (per_length on beams, "
                             "scene.pressure on surfaces); point loads here are dead")
        if traction is not None:
            model.add_traction(where, finite_vector(f"load '{where}'", "traction", traction, model.gdim), amplitude,
                               condition)
            self._loads += 1
        values = model.load_values(where, force, moment)
        if values is not None:
            model.add_load(where, values, amplitude, condition)
            self._loads += 1
        return condition

    def pressure(self, part: PartRef, where: str | None = None, p: float = 0.0, *, follower: bool = True,
                 amplitude=None) -> Condition:
        """A uniform pressure p, scaled by the load factor λ (or by ``amplitude(λ)``).

        * Shells and membranes (``where``: a cell group of the part, None: all its cells): p per
          unit area along each cell's normal n, by the right-hand rule over its nodes (a closed
          surface whose cells are numbered anticlockwise seen from outside is inflated by p > 0).
        * Solids (``where``: a facet group): p per unit area pressing on the faces, along their
          inward normal (p > 0 pushes into the solid).

        follower=True (default): the pressure acts per unit current area along the current normal
        (a fluid's pressure) and its load stiffness enters the tangent (:mod:`dolfinx_corot.loads`;
        solids: p J F⁻ᵀN in the residual form); False: a dead load p n₀ per unit reference area,
        fixed at the reference normals. Follower loads are followed by load and displacement
        control; arc-length and staged runs refuse them.
        """
        if not (isinstance(p, (int, float)) and np.isfinite(p)):
            raise ValueError(f"pressure on '{where}': p = {p!r} must be a finite number")
        condition = Condition("load", _on(part, where) if where else f"pressure on {part.kind} '{part.name}'")
        part.model.add_pressure(part, where, float(p), bool(follower), amplitude, condition)
        self._loads += 1
        return condition

    def gravity(self, part: PartRef, acceleration, density: float | None = None, where: str | None = None,
                amplitude=None) -> Condition:
        """Self-weight under the gravitational acceleration g (gdim numbers), a dead load scaled by
        the load factor λ (or by ``amplitude(λ)``) like the other loads. Returns it as a
        :class:`~dolfinx_corot.conditions.Condition` that construction stages may add or remove.

        density: mass per unit volume ρ; None: the density of the part's material
        (``dc.Elastic(E, nu, density=ρ)``).

        * Solids: body force ρ·g per unit reference volume on the cells of ``where``; None:
          the part's own cells (its region, ``add_solid(mesh, "fill", …)``: only the fill; a
          part added without a region: every cell of the mesh); with density None each
          cell's material gives ρ.
        * Beams and bars: ρ·A·g per unit reference length; shells and membranes: ρ·t·g per
          unit reference area; on the elements of ``part`` (those in group ``where`` if
          given), as work-equivalent nodal loads computed from the reference geometry
          (:mod:`dolfinx_corot.elements.uniform_load`: the weight of each element shared
          by its nodes, and the fixed-end moments ±q l²/12 of beams, kept at their
          reference values under large rotation).
        """
        model = part.model
        label = f"gravity on {part.kind} '{part.name or 'all cells'}'"
        acc = finite_vector(label, "acceleration", acceleration, model.gdim)
        if density is not None:
            ok = isinstance(density, numbers.Real) and not isinstance(density, bool) and np.isfinite(density) \
                and density >= 0.0
            if not ok:
                raise ValueError(f"{label}: density = {density!r} must be a finite number ≥ 0")
            density = float(density)
        condition = model.add_gravity(part, acc, density, where, amplitude, Condition("gravity", label[len("gravity "):]))
        self._loads += 1
        return condition

    def contact(self, slaves: tuple[PartRef, str], masters: tuple[PartRef, str], law=None,
                symmetric: bool = False, smooth: bool | None = None, discretization: str = "node_to_face",
                friction=None) -> list:
        """Node-to-segment (2D) or node-to-face (3D) contact of the nodes of group
        ``slaves[1]`` of part ``slaves[0]`` against the segments or faces of ``masters``;
        ``symmetric`` adds the other direction (two-pass contact, for two deformable bodies).
        In 3D the surfaces are boundary face groups of linear solids (tetrahedra, hexahedra),
        cell groups of shells and membranes (two-sided: their faces at ±t/2 from the
        mid-surface), and, as slaves only, line groups of beams (their nodes meet faces at the
        section's outer radius, ``Section.outer``; solid–beam contact is one-pass).

        law: dc.Penalty() (default) or dc.AugmentedLagrangian(); the default penalty scales with
        the bodies' stiffness and the master segments' length.
        smooth (2D; default True): the master surface is the C¹ Hermite curve through its nodes
        (normals continuous from segment to segment: robust sliding over curved and deforming
        masters); False: the straight segments (slave forces shared linearly by the segment's two
        nodes: the patch test is passed exactly). 3D (default False): flat faces with edge and
        vertex contact; True: the faces with averaged nodal normals, each slave met along the
        normal field they interpolate (gap, normal and force continuous from face to face:
        smooth sliding over faceted curved masters; sharp features above 60° stay sharp;
        :mod:`~dolfinx_corot.contact.smooth3d`).

        discretization (3D): 'node_to_face' (default; slave nodes against master faces, every
        kind of surface) or 'mortar' (segment-to-segment between two solids' faces: the contact
        pressure integrated over the overlaps of slave and master faces, the nodal constraints
        weighted gaps; passes the patch test on non-matching faces, :mod:`~dolfinx_corot.contact.mortar`).

        friction (node-to-segment, node-to-face): None (default, frictionless) or
        dc.Coulomb(mu=...) / dc.Coulomb(friction_angle=..., cohesion=...): the shear traction
        bounded by c + μ p; each slave sticks to a material point of the master (through a
        tangential penalty) until the bound is reached, then slips; the stick points are history
        state (committed with each step, restored with a cut step or a restart;
        :func:`~dolfinx_corot.contact.kernels2d.node_to_smooth_segment_friction`,
        :func:`~dolfinx_corot.contact.kernels3d.node_to_face_friction`). In 2D a sharp convex
        vertex of the master is frictionless; in 3D faces, edges and vertices all carry friction.
        The tangent is then not symmetric (LU while the interface is engaged).

        Returns a :class:`~dolfinx_corot.contact.ContactPair`, the sequence of the interfaces made
        (one, or two when symmetric), which gives the interface pressure of both passes combined
        on either side's contact face (``pair.pressure(on="slaves")``, a beam's face at half its
        depth) and its resultant; see also :meth:`monitor_contact`."""
        from .contact.interface import Interface  # (a scene without contact loads no contact modules)
        from .contact.interface3d import Interface3D
        from .contact.laws import ContactError, Penalty
        from .contact.mortar import MortarInterface3D
        from .contact.pair import ContactPair

        law = Penalty() if law is None else law
        if discretization not in ("node_to_face", "mortar"):
            raise ValueError(f"contact: discretization = {discretization!r} must be 'node_to_face' or 'mortar'")
        if slaves[0].model.gdim == 3:
            kind, smooth = (MortarInterface3D if discretization == "mortar" else Interface3D), bool(smooth)
        elif discretization == "mortar":
            raise ContactError("contact: the mortar discretization is 3D only (in 2D, node-to-segment contact on "
                               "straight segments passes the patch test: smooth=False)")
        else:
            kind, smooth = Interface, smooth is None or bool(smooth)
        if friction is not None and kind is MortarInterface3D:
            raise ContactError(f"contact '{slaves[1]} -> {masters[1]}': friction with the mortar discretization is "
                               "not implemented: use discretization='node_to_face' for frictional contact")
        extra = {} if friction is None else {"friction": friction}
        made = [kind(slaves, masters, law, smooth, **extra)]
        if symmetric:
            made.append(kind(masters, slaves, law, smooth, **extra))
        self.interfaces += made
        self.pairs.append(ContactPair(made))
        return self.pairs[-1]

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

    def monitor(self, name: str, part: PartRef, where: str, reduce: str | None = None, along=None) -> None:
        """Record the dofs of the nodes of group ``where`` after every step.

        reduce=None: the group has one node (a point); its dofs become the history columns
        ``name_ux``, ``name_uy``, … (``name_rz`` in 2D is the total angle, which may exceed 2π; in
        3D ``name_rx..rz`` is the rotation vector of the nodal rotation, norm ≤ π). A group of
        several nodes is refused: say which value of it to record.

        reduce='sum', 'mean', 'max', 'min' or 'absmax': one value per dof over the group's nodes,
        columns ``name_ux_mean``, ``name_uy_mean``, … (each dof reduced on its own: the largest
        ux and the largest uy may be at different nodes; 'absmax' is the value of largest
        magnitude, with its sign; rotations are reduced component by component).

        reduce='profile': every node of the group, ordered along it, kept in
        ``result.profiles[name]`` (a :class:`dolfinx_corot.result.Profile`: the nodes' reference
        coordinates ``X``, their coordinate ``s`` along the group and the values per step,
        ``values`` (steps, nodes, dofs)) rather than in history columns; a settlement trough, a
        deflection line. along=None orders the nodes by the arc length along the chain of the
        group's lines (a beam, a boundary line of a 2D solid, an edge of a shell), from its end of
        smallest (x, y, z) (a closed ring in 2D: counter-clockwise from its node of smallest
        (x, y)); along='x', 'y', 'z' or a direction (gdim numbers): by that coordinate. A profile
        monitor added at a restart has NaN values for the steps before it.

        The nodes of a group are those its supports and loads act on (a facet group of a
        quadratic solid includes the mid-side nodes); each node counts once under MPI, and the
        values are the same on every rank and equal to the serial ones.
        """
        label = f"monitor '{name}'"
        if reduce is not None and reduce != "profile" and reduce not in REDUCTIONS:
            raise ValueError(f"{label}: reduce = {reduce!r} is not one of None, {', '.join(map(repr, REDUCTIONS))} "
                             "or 'profile'")
        if along is not None and reduce != "profile":
            raise ValueError(f"{label}: along orders the nodes of a profile; give reduce='profile' with it")
        group = part.model.node_group(where)  # fails early for a missing or empty group
        if reduce is None and len(group) > 1:
            raise ValueError(f"{label}: group '{where}' has {len(group)} nodes; say which value to record: "
                             f"reduce={', '.join(map(repr, REDUCTIONS))} (columns {name}_ux_mean, …) or 'profile' "
                             f"(every node, in result.profiles['{name}']), or monitor a group of one node")
        if reduce == "profile":
            chain_coordinate(group, along, f"{label} on group '{where}'")  # fails early for a group with no order
        self._add_monitor(Monitor(name, part, where, "dofs", reduce, along))
        self._groups[(name, "dofs")] = group

    def _add_monitor(self, monitor: Monitor) -> None:
        # reactions and contact monitors share the columns name_Fx, name_Fy
        taken = [m for m in self.monitors if m.name == monitor.name and (
            m.kind == monitor.kind or {m.kind, monitor.kind} == {"reaction", "contact"})]
        if taken:
            raise ValueError(f"monitor '{monitor.name}' exists already (on group '{taken[0].where}'): give each "
                             "monitor a name of its own (its history columns carry it)")
        self.monitors.append(monitor)

    def monitor_results(self, name: str, part: PartRef, where: str | None = None, reduce: str | None = None,
                        components=None) -> None:
        """Record element results (:meth:`element_results`) after every step.

        where a node group of a beam part (one node): the section forces there, averaged over
        the element ends that meet at the node (equal where no load acts on it), columns
        ``name_N``, ``name_V``, ``name_M`` (3D: ``name_N`` … ``name_Mz``). where a cell group
        (or None: all the part's elements) with reduce 'max', 'min', 'mean' or 'absmax': one
        value per component over its elements, ``name_M_absmax``, ``name_mises_max``, …
        components: the components to record (default: all of the part's, e.g. Nxx … mises_bottom
        for shells, sxx … Exy for solids)."""
        label = f"monitor_results '{name}'"
        model = part.model
        known = tuple(model.section_components) if hasattr(model, "section_components") else ()
        if not known:
            raise ValueError(f"{label}: {part.kind} parts have no element results")
        chosen = known if components is None else tuple([components] if isinstance(components, str) else components)
        unknown = [c for c in chosen if c not in known]
        if unknown:
            raise ValueError(f"{label}: {part.kind} results have no component(s) {unknown}; they have {list(known)}")
        if where is not None and model.tmesh.groups.get(where, (None,))[0] != model.tmesh.tdim:
            if model.tdim != 1:
                raise ValueError(f"{label}: group '{where}' is not a group of the part's cells; results of "
                                 f"{part.kind} parts are per cell: give a cell group and a reduction")
            group = model.node_group(where)  # fails early for a missing group
            if len(group) != 1 or reduce is not None:
                raise ValueError(f"{label}: at a node group give a group of one node and no reduction (group "
                                 f"'{where}' has {len(group)} nodes); for several elements give a line group and "
                                 f"reduce={', '.join(map(repr, REDUCTIONS))}")
            self._groups[(name, "results")] = group
        else:
            if where is not None:
                model.tmesh.cells(where)
            if reduce not in ("max", "min", "mean", "absmax"):
                raise ValueError(f"{label}: over the elements of {('group ' + repr(where)) if where else 'the part'} "
                                 f"say which value to record: reduce='max', 'min', 'mean' or 'absmax' (got {reduce!r})")
        self._add_monitor(Monitor(name, part, where, "results", reduce, components=chosen))

    def element_results(self, part: PartRef, where: str | None = None):
        """Results element by element of ``part`` (within its cell group ``where``) at the current
        state, in engineering terms (seed §1: the quantities of the rotated element frame), on
        every rank — a :class:`~dolfinx_corot.result.ElementResults`:

        * beams and bars: section forces at both ends of each element, (N, V, M) in 2D and
          (N, Vy, Vz, T, My, Mz) in 3D, in the element's current axes;
        * shells and membranes: membrane forces, moments, transverse shears per unit length,
          top and bottom stresses and their von Mises values, in the element's current frame;
        * solids: the Cauchy stress, its von Mises value and the Green–Lagrange strain at the
          centre of each cell, in global axes.

        Contact pressures are per slave node: ``pair.pressure()`` of what :meth:`contact` returned.
        Collective."""
        model = part.model
        cells = model.tmesh.cells(part.name or None)
        if where is not None:
            cells = np.intersect1d(cells, model.tmesh.cells(where)).astype(np.int32)
        label = f"{part.kind} '{part.name or 'all cells'}'" + (f" within '{where}'" if where else "")
        return model.element_results(cells, label)

    def ply_stresses(self, part: PartRef, where: str | None = None):
        """Stresses in the plies of the laminate of shells ``part`` (within its cell group
        ``where``) at the current state, on every rank — a
        :class:`~dolfinx_corot.result.ElementResults` of kind 'ply stresses': at the centre of each
        cell, at the bottom and top face of every ply (from the bottom of the laminate up), the
        stresses s11 (along the ply's fibres), s22 (across them, in the shell) and s12 in the ply's
        axes, with the height z above the mid-surface and the ply's index (classical lamination
        theory from the cell's resultants). The cells must share one section. Collective."""
        model = part.model
        if not hasattr(model, "ply_stresses"):
            raise ValueError(f"ply stresses of {part.kind} '{part.name}': they are for shells")
        cells = model.tmesh.cells(part.name or None)
        if where is not None:
            cells = np.intersect1d(cells, model.tmesh.cells(where)).astype(np.int32)
        label = f"{part.kind} '{part.name or 'all cells'}'" + (f" within '{where}'" if where else "")
        return model.ply_stresses(cells, label)

    def monitor_reaction(self, name: str, part: PartRef, where: str) -> None:
        """Record the force (sum over the nodes of ``where``) that the supports or prescribed
        displacements there exert on the structure, after every step: name_Fx, name_Fy, name_Mz
        (2D) or name_Fx … name_Mz (3D)."""
        part.model.tmesh.vertices(where)  # fails early for a missing group
        self._add_monitor(Monitor(name, part, where, "reaction"))

    def monitor_contact(self, name: str, pair: ContactPair, on: str = "slaves") -> None:
        """Record, after every step, the contact of ``pair`` (what :meth:`contact` returned) on its
        ``on`` side ('slaves' or 'masters'), both passes combined: ``name_Fx``, ``name_Fy`` the
        resultant force the other body exerts on that side, ``name_N`` the total normal force
        Σ p L and ``name_pmax`` the largest nominal pressure on the contact face."""
        from .contact.pair import ContactPair

        if not isinstance(pair, ContactPair):
            raise TypeError(f"monitor_contact '{name}': give what scene.contact returned, got {type(pair).__name__}")
        if not any(pair.interfaces[0] is itf for itf in self.interfaces):
            raise ValueError(f"monitor_contact '{name}': contact '{pair.name}' belongs to another scene")
        pair.on_slaves(on)  # fails early for a side other than 'slaves' or 'masters'
        self._add_monitor(Monitor(name, pair, on, "contact"))

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

    def contacts_holding(self, model) -> list[str]:
        """Names of the contact interfaces with a side on ``model`` (a part model): what may hold
        it besides its supports."""
        return [itf.name for itf in self.interfaces
                if itf.slave_spec[0].model is model or itf.master_spec[0].model is model]

    def contributions(self) -> list:
        """The contributions the scene adds to its parts' system (contact, when it has interfaces;
        the stabilisation, when a part is stabilised): a scene without them pays nothing for them."""
        out = []
        if self.interfaces:
            from .contact.interface import Contact

            out.append(Contact(self.interfaces))
        if self.stabilisers:
            out.append(Stabilisation(self.stabilisers))
        followers = [f for m in self._models.values() for f in m.followers]
        if followers:
            out.append(FollowerLoads(followers))
        return out

    @property
    def follower_loads(self) -> bool:
        """Whether the scene has loads that follow the configuration (pressures, follower line loads)."""
        return any(m.followers or m.has_follower_loads for m in self._models.values())

    def effects(self) -> list[str]:
        """What will be assembled, in words."""
        out = [m.effect() for m in self._models.values()]
        if self._loads:
            out.append("dead loads" if not self.follower_loads else "loads, some following the configuration")
        if self._prescribed:
            out.append("prescribed displacements")
        for itf in self.interfaces:
            d = itf.describe()
            kind = "augmented Lagrangian" if itf.law.augmented else "penalty"
            out.append(f"contact {itf.name}: {d['slave_nodes']} slave nodes on {d['master_segments']} "
                       f"{itf.FACETS} ({kind}, penalty {itf.penalty:.3g}, {itf.master_surface})")
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
        """Monitored dofs (one node, or a reduction over a group) and reactions at the current state
        (``system`` holds f_int), by history column."""
        return {col: v for values in self.monitor_values_by_name(system).values() for col, v in values.items()}

    def monitor_values_by_name(self, system) -> dict[str, dict[str, float]]:
        """:meth:`monitor_values` monitor by monitor: name → {history column: value}."""
        out = {}
        for mon in self.monitors:
            values = out.setdefault(mon.name, {})
            if mon.kind == "contact":  # part: the ContactPair, where: its side
                values.update(mon.part.monitor_values(mon.name, mon.where))
                continue
            model = mon.part.model
            if mon.kind == "results":
                if mon.reduce is None and mon.where is not None:  # section forces at one node
                    group = self._group(mon)
                    at = group.X[0] + group.values(model)[0][: model.gdim]
                    picked = self.element_results(mon.part).at(at)
                    suffix = ""
                else:
                    picked = self.element_results(mon.part, mon.where).reduce(mon.reduce)
                    suffix = f"_{mon.reduce}"
                values.update({f"{mon.name}_{c}{suffix}": picked[c] for c in mon.components})
                continue
            if mon.kind == "reaction":
                # reaction on the structure = λ f_ext − f_int at the constrained nodes
                fint = model.reaction(mon.where, system.model_array(model, system.internal_force()))
                fext = model.reaction(mon.where, system.model_array(model, system.fext_total))
                names = ("Fx", "Fy", "Mz") if model.gdim == 2 else ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
                for comp, val in zip(names, fext - fint):
                    values[f"{mon.name}_{comp}"] = -float(val)
            elif mon.reduce != "profile":
                nodal = self._group(mon).values(model)
                reduced = nodal[0] if mon.reduce is None else REDUCTIONS[mon.reduce](nodal)
                suffix = "" if mon.reduce is None else f"_{mon.reduce}"
                for comp, val in zip(model.dof_names, reduced):
                    values[f"{mon.name}_{comp}{suffix}"] = float(val)
        return out

    def _group(self, mon: Monitor):
        """The node group of a monitor (found once: a group's nodes do not change)."""
        key = (mon.name, mon.kind)
        if key not in self._groups:
            self._groups[key] = mon.part.model.node_group(mon.where)
        return self._groups[key]

    def profiles(self) -> dict:
        """Empty :class:`~dolfinx_corot.result.Profile` of every profile monitor, its nodes ordered
        along the group in the current reference configuration (at the start of a run)."""
        out = {}
        for mon in self.monitors:
            if mon.reduce == "profile":
                model = mon.part.model
                group = model.node_group(mon.where)
                self._groups[(mon.name, mon.kind)] = group
                s = chain_coordinate(group, mon.along, f"monitor '{mon.name}' on group '{mon.where}'")
                order = np.lexsort((np.arange(len(s)), s))
                along = "arc length" if mon.along is None else \
                    (mon.along if isinstance(mon.along, str) else [float(c) for c in np.ravel(mon.along)])
                out[mon.name] = Profile(mon.name, mon.where, tuple(model.dof_names), group.X[order], s[order], along,
                                        order=order)
        return out

    def profile_values(self) -> dict[str, np.ndarray]:
        """(nodes, dofs) values of every profile monitor at the current state, in the group's order
        (a :class:`~dolfinx_corot.result.Profile` puts them in its own)."""
        return {mon.name: self._group(mon).values(mon.part.model) for mon in self.monitors
                if mon.reduce == "profile"}

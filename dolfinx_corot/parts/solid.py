"""Large-deformation continuum parts: total-Lagrangian UFL forms on a DOLFINx mesh.

A :class:`Solid` holds the continuum on one mesh (plane strain in 2D, 3D):
the displacement in a vector Lagrange space of degree 1 or 2 (triangles,
quadrilaterals, tetrahedra, hexahedra), the Lamé constants per cell (DG0,
so that one region or one element can be weakened as an imperfection), and
the forms

    f_int(u; v) = ∫ P(F) : ∇v dX,     K = ∂f_int/∂u   (UFL derivative),

with P the first Piola–Kirchhoff stress of the law (``continuum.laws``), or
the small-strain stress when the scene has ``large_rotations=False``.
The mesh geometry may be of the solid's degree at most (degree 2: gmsh's
second-order, curved cells); every cell is checked at creation
(:func:`~dolfinx_corot.parts.cells.check_solid_cells`).
External loads are dead: tractions per reference area on facet groups,
body forces per reference volume, point forces at nodes. It presents the
same part protocol (:class:`dolfinx_corot.parts.base.Part`) as the structural
parts.

Reference configuration: the forms integrate over the reference positions
X' = X + w, with X the mesh and w a displacement field the solid owns
(:meth:`Solid.capture_reference`; zero at creation): ∇_{X'} u = ∇_X u (I + ∇_X w)⁻¹
and dX' = det(I + ∇_X w) dX. While w = 0 the forms are those on the mesh itself.
"""
from __future__ import annotations

import hashlib

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.la

from .. import _dolfinx, validate
from ..assembly import petsc
from ..conditions import Condition
from ..continuum.kinematics import deformation_gradient
from ..continuum.laws import first_piola, lame
from ..io.mesh import TaggedMesh
from ..materials import Elastic, NeoHookean
from ..result import ElementResults
from .base import AdditiveState, Part, PartRef, finite_vector
from .cells import check_geometry_degree, check_solid_cells
from .surface import Surface, SurfaceError, gather_surface

CELLS = ("triangle", "quadrilateral", "tetrahedron", "hexahedron")


class Solid(AdditiveState, Part):
    """A large-deformation continuum on one mesh (see the module docstring)."""

    symmetric_tangent = True  # hyperelastic, dead loads
    continuum = True
    kind_name = "solid"

    def __init__(self, tmesh: TaggedMesh, degree: int, large_rotations: bool):
        mesh = tmesh.mesh
        cell = mesh.topology.cell_name()
        if cell not in CELLS or mesh.topology.dim != mesh.geometry.dim:
            advice = (f"read the gmsh model with from_gmsh(model, gdim={mesh.topology.dim})"
                      if mesh.topology.dim > 1 else "a mesh of lines carries beams or bars (add_beam, add_truss)")
            raise ValueError(f"solids need a mesh of {CELLS} filling its space (tdim = gdim); got {cell} with "
                             f"tdim {mesh.topology.dim}, gdim {mesh.geometry.dim}: {advice}")
        if degree not in (1, 2):
            raise ValueError(f"solid: degree {degree} is not 1 or 2")
        check_geometry_degree(mesh, f"solid of degree {degree}", degree,
                              "a solid's geometry may be of its own degree at most (degree 2: straight or "
                              "curved cells; degree 1: straight cells): give degree=2, or mesh with first-order "
                              "elements (gmsh.model.mesh.setOrder(1))" if degree == 1 else
                              "solids take geometry of degree 1 or 2: mesh with gmsh.model.mesh.setOrder(2) or 1")
        check_solid_cells(tmesh, "solid mesh")
        self.tmesh = tmesh
        self.degree = degree
        self.large_rotations = bool(large_rotations)
        self.gdim = self.tdim = mesh.geometry.dim
        self.dof_names = ("ux", "uy", "uz")[: self.gdim]
        self.translations = self.state_size = self.gdim
        # Gauss rule: 2p on simplices, 2p + 1 on quadrilaterals/hexahedra ((p + 1)^d points)
        self.quadrature = 2 * degree + (0 if cell in ("triangle", "tetrahedron") else 1)
        self.V = _dolfinx.function_space(mesh, "Lagrange", degree, mesh.geometry.dim)
        self.nodes_per_cell = self.V.dofmap.dof_layout.num_dofs  # dof blocks per cell
        self.state = dolfinx.fem.Function(self.V, name="displacement")
        self._dof_coordinates = None  # the dof blocks' reference coordinates (positions)
        self.reference_shift = dolfinx.fem.Function(self.V, name="reference_shift")
        self._shifted = None
        Q = _dolfinx.function_space(mesh, "DG", 0, scalar=True)
        self.E = dolfinx.fem.Function(Q, name="E")
        self.nu = dolfinx.fem.Function(Q, name="nu")
        self.density = dolfinx.fem.Function(Q, name="density")  # of the materials (0 where not given)
        self._cell_dof = Q.dofmap.list.array
        cmap = mesh.topology.index_map(self.tdim)
        self._owner_of_cell = np.full(cmap.size_local + cmap.num_ghosts, "", dtype=object)
        self._has_density = np.zeros(cmap.size_local + cmap.num_ghosts, dtype=bool)
        self.law: type | None = None
        self._regions: list[tuple[str, str, float, float]] = []
        self._tractions: list[tuple[str, np.ndarray, object, Condition]] = []
        # pressures: (where, p, amplitude, condition); follower ones with their factor g(λ) (a Constant)
        self._dead_pressures: list[tuple[str, float, object, Condition]] = []
        self._follower_pressures: list[tuple[str, float, object, Condition, object]] = []
        self._follower_form = None
        # (where, b, × material ρ, amplitude, condition)
        self._body: list[tuple[str | None, np.ndarray, bool, object, Condition]] = []
        self._init_conditions()
        self._shifted = False
        # staged construction (dolfinx_corot.staging): which cells exist (DG0, 1/0), the shift s of
        # each cell's nodes at its activation (discontinuous, per cell) and the approach; None:
        # every cell exists and the forms are those without stages
        self.existing: dolfinx.fem.Function | None = None
        self.activation_shift: dolfinx.fem.Function | None = None
        self.activation_reference: dolfinx.fem.Function | None = None
        self.approach = "II"

    # -- building -------------------------------------------------------------
    def add_region(self, where: str | None, material: Elastic):
        label = f"solid '{where or 'all cells'}'"
        kind = type(material)
        if self.law is not None and kind is not self.law:
            raise NotImplementedError(f"{label}: one law per solid mesh ({self.law.__name__} already); "
                                      f"{kind.__name__} regions need a mesh of their own")
        cells = self.tmesh.cells(where)
        taken = self._owner_of_cell[cells]
        clash = taken[(taken != "") & (taken != label)]
        if len(clash) and where is None:
            raise ValueError(f"{label}: its cells already belong to {clash[0]}")
        # a named region may re-assign cells of the 'all cells' region (an imperfection)
        self._owner_of_cell[cells] = label
        self.E.x.array[self._cell_dof[cells]] = material.E
        self.nu.x.array[self._cell_dof[cells]] = material.nu
        self.density.x.array[self._cell_dof[cells]] = material.density or 0.0
        self._has_density[cells] = material.density is not None
        self.law = kind
        ref = PartRef(self, where or "", "solid")
        self.parts.append(ref)
        self._regions.append((label, kind.__name__, float(material.E), float(material.nu)))
        self._forms = None
        return ref

    def _materials(self) -> list:
        return self._regions

    def describe(self) -> dict:
        """The part's description, with a hash of its reference shift (a captured reference)."""
        out = super().describe()
        if self._shifted:
            shift = self.to_global(self.reference_shift.x.array)
            digest = hashlib.sha256(np.ascontiguousarray(shift).tobytes()).hexdigest() if self.comm.rank == 0 else None
            out["reference_shift"] = self.comm.bcast(digest, root=0)
        return out

    def _entities(self, where: str) -> tuple[int, np.ndarray]:
        """(dim, local entities) that locate the dofs of group ``where``: its facets when it is a
        facet group with tags (mid-side dofs included), else its vertices."""
        facets = self.tmesh.facets(where)
        if facets is not None:
            return self.tdim - 1, facets
        if self.degree > 1 and self.tmesh.groups[where][0] == self.tdim - 1:
            raise ValueError(f"group '{where}' has no facet tags (a mesh from arrays?): quadratic solids locate "
                             "boundary dofs by facets; read the mesh with from_gmsh")
        return 0, self.tmesh.vertices(where)

    def add_traction(self, where: str, traction: np.ndarray, amplitude=None,
                     condition: Condition | None = None) -> Condition:
        if self.tmesh.facets(where) is None:
            raise ValueError(f"traction on '{where}': a group of facets (dimension {self.tdim - 1}) read with "
                             "from_gmsh is needed")
        condition = condition or Condition("load", f"'{where}'")
        self._tractions.append((where, np.asarray(traction, dtype=float), amplitude, condition))
        return condition

    def add_pressure(self, part, where: str | None, p: float, follower: bool, amplitude=None,
                     condition: Condition | None = None) -> Condition:
        """A uniform pressure p on the facets of group ``where``, along their inward normal: dead (p N₀ per
        unit reference area) or following (p n per unit current area: p J F⁻ᵀN, Nanson's formula), see
        ``Scene.pressure``."""
        if where is None:
            raise ValueError("pressure on a solid: name the group of facets it acts on (where=...)")
        if self.tmesh.facets(where) is None:
            raise ValueError(f"pressure on '{where}': a group of facets (dimension {self.tdim - 1}) read with "
                             "from_gmsh is needed")
        condition = condition or Condition("load", f"pressure on '{where}'")
        if not follower:
            self._dead_pressures.append((where, p, amplitude, condition))
            return condition
        factor = dolfinx.fem.Constant(self.V.mesh, PETSc.ScalarType(0.0))
        self._follower_pressures.append((where, p, amplitude, condition, factor))
        self.has_follower_loads = True
        self.symmetric_tangent = False  # the load stiffness of a pressure on an open surface
        self._forms = None
        self._follower_form = None
        return condition

    def set_follower_factor(self, load_factor: float) -> None:
        for _, _, amplitude, condition, factor in self._follower_pressures:
            g = load_factor if amplitude is None else float(amplitude(load_factor))
            factor.value = g if condition.exists else 0.0

    def _follower_load(self, u, v):
        """The follower pressures' load as a UFL form (external force: −g p J F⁻ᵀN · v on each group)."""
        if not self._follower_pressures:
            return None
        ds = ufl.Measure("ds", domain=self.V.mesh, subdomain_data=self.tmesh.facet_tags)
        N = ufl.FacetNormal(self.V.mesh)
        if self.large_rotations:
            F = ufl.Identity(self.gdim) + self._gradient(u)
            normal = ufl.det(F) * ufl.dot(ufl.inv(F).T, N)
        else:
            normal = N
        terms = [-factor * p * ufl.inner(normal, v) * ds(self.tmesh.groups[where][1])
                 for where, p, _, _, factor in self._follower_pressures]
        return sum(terms[1:], terms[0])

    def follower_form(self):
        if self._follower_pressures and self._follower_form is None:
            self._follower_form = dolfinx.fem.form(self._follower_load(self.state, ufl.TestFunction(self.V)))
        return self._follower_form

    def add_body_force(self, where: str | None, force: np.ndarray, amplitude=None,
                       material_density: bool = False, condition: Condition | None = None) -> Condition:
        """Body force per unit reference volume on the cells of ``where`` (all if None): ``force``,
        or ρ·``force`` with the density ρ of each cell's material (``material_density``)."""
        if where is not None:
            self.tmesh.cells(where)  # fails early for a missing group
        condition = condition or Condition("load", f"body force on '{where or 'all cells'}'")
        self._body.append((where, np.asarray(force, dtype=float), bool(material_density), amplitude, condition))
        if material_density:
            self._check_density(where)
        return condition

    def add_gravity(self, part: PartRef, acceleration: np.ndarray, density: float | None, where: str | None,
                    amplitude=None, condition: Condition | None = None) -> Condition:
        """Body force ρ·g per unit reference volume on the cells of ``where``; None: the cells of
        ``part`` (its region, or all cells of the mesh for a part added without one); ``density``
        None: each cell's material's."""
        where = part.name or None if where is None else where
        condition = condition or Condition("gravity", f"on '{where or 'all cells'}'")
        return self.add_body_force(where, acceleration if density is None else density * acceleration, amplitude,
                                   material_density=density is None, condition=condition)

    def _check_density(self, where: str | None) -> None:
        """Every cell of ``where`` (all if None) has a material with a density (checked on all ranks)."""
        cells = self.tmesh.cells(where)
        cells = cells[cells < self.tmesh.mesh.topology.index_map(self.tdim).size_local]
        bad = cells[~self._has_density[cells]]
        found = self.comm.allgather(str(self._owner_of_cell[bad[0]]) if len(bad) else None)
        if any(f is not None for f in found):
            label = next(f for f in found if f is not None)
            raise ValueError(f"gravity on '{where or 'all cells'}' of the solid: {label or 'a cell without material'}"
                             " has no density; give its material one (dc.SaintVenantKirchhoff(E, nu, density=ρ)) "
                             "or pass density= to scene.gravity")

    def load_conditions(self) -> list:
        return [(amp, cond) for *_, amp, cond in self._tractions + self._body + self._point_loads
                + self._dead_pressures] + [(amp, cond) for _, _, amp, cond, _ in self._follower_pressures]

    # -- initial (K₀) stress ---------------------------------------------------------------
    initial_stress = None  # σ₀ (UFL) the cells carry at zero strain, or None

    def set_k0_stress(self, k0: float, surface: float, unit_weight: float | None = None) -> None:
        """The geostatic stress of level ground as an initial stress σ₀ carried at zero strain:
        σ_v = −γ (surface − z) along the vertical (the last axis), σ_h = K₀ σ_v along the others,
        no shear. γ: ``unit_weight``, or (None) ρ|g| of the solid's one density and the gravity
        declared on it. With that gravity σ₀ is in equilibrium at zero displacement (div σ₀ + ρg = 0,
        no traction on the surface), the supports taking σ_h on the sides."""
        label = f"K0 initial stress of solid '{self.parts[0].name if self.parts else ''}'"
        validate.positive(label, "k0", k0, allow_zero=True)
        if not np.isfinite(surface):
            raise ValueError(f"{label}: surface = {surface} must be a finite elevation")
        if unit_weight is None:
            unit_weight = self._unit_weight(label)
        validate.positive(label, "unit_weight", unit_weight)
        top = self.comm.allreduce(float(self.V.mesh.geometry.x[:, self.gdim - 1].max(initial=-np.inf)), op=MPI.MAX)
        if top > surface + 1e-9 * max(1.0, abs(surface)):
            raise ValueError(f"{label}: the mesh rises to {top:.6g}, above the ground's surface {surface:.6g} "
                             "(level ground: give the elevation of its top)")
        x = ufl.SpatialCoordinate(self.V.mesh)
        sv = -float(unit_weight) * (float(surface) - x[self.gdim - 1])
        diagonal = [float(k0) * sv] * (self.gdim - 1) + [sv]
        self.initial_stress = ufl.as_matrix([[diagonal[i] if i == j else 0.0 for j in range(self.gdim)]
                                             for i in range(self.gdim)])
        self._forms = None

    def _unit_weight(self, label: str) -> float:
        """ρ|g| of the solid's one density and its one gravity (pointing down the last axis)."""
        n = self.tmesh.mesh.topology.index_map(self.tdim).size_local
        rho = self.density.x.array[self._cell_dof[:n]]
        values = np.unique(np.concatenate(self.comm.allgather(rho)))
        gravity = [b for _, b, by_density, _, cond in self._body if by_density and cond.exists]
        if len(values) != 1 or values[0] <= 0.0 or len(gravity) != 1:
            raise ValueError(f"{label}: give unit_weight= (the solid has {len(values)} densities "
                             f"{values[:3].tolist()} and {len(gravity)} gravity load(s); the unit weight is taken "
                             "from them only for one positive density and one gravity)")
        g = gravity[0]
        if np.any(g[:-1] != 0.0) or g[-1] >= 0.0:
            raise ValueError(f"{label}: the gravity {g.tolist()} does not point down the last axis (level ground)")
        return float(values[0] * -g[-1])

    def _initial_stress_work(self, u, v):
        """The work of σ₀ on ∇v: σ₀ : ∇v at small strain; at large rotations σ₀ is a second
        Piola–Kirchhoff stress of the reference, P₀ = F σ₀ (F and the reference as in the cell's
        staged kinematics, if any)."""
        S0 = self.initial_stress
        if self.existing is None:
            if not self.large_rotations:
                return ufl.inner(S0, self._gradient(v))
            F = ufl.Identity(self.gdim) + self._gradient(u)
            return ufl.inner(ufl.dot(F, S0), self._gradient(v))
        measure, J0 = self._staged_kinematics(u)
        if not self.large_rotations:
            return ufl.inner(S0, ufl.grad(v))
        if J0 is None:
            return ufl.inner(ufl.dot(measure, S0), ufl.grad(v))
        return ufl.det(J0) * ufl.inner(ufl.dot(measure, S0), ufl.dot(ufl.grad(v), ufl.inv(J0)))

    def load_values(self, where: str, force, moment) -> np.ndarray:
        if moment is not None:
            raise ValueError(f"load '{where}': solids carry no moments")
        return None if force is None else finite_vector(f"load '{where}'", "force", force, self.gdim)

    def effect(self) -> str:
        law = self.law.__name__ if self.large_rotations else "small-strain elastic"
        kind = "plane strain" if self.gdim == 2 else "3D"
        return f"continuum ({law}, {kind}, degree {self.degree} on {self.tmesh.mesh.topology.cell_name()}s)"

    # -- reference configuration -------------------------------------------------------
    def capture_reference(self, shift: np.ndarray | None = None) -> None:
        """Take the mesh moved by ``shift`` (local array of V, owned and ghost; None: the current
        displacement) as the stress-free reference of the elements, and zero the displacement.
        At creation the reference is the mesh itself."""
        if self._shifted is None:  # the base's call at creation: the mesh
            return Part.capture_reference(self)
        values = self.state.x.array if shift is None else np.asarray(shift)
        self.reference_shift.x.array[:] += values
        self.state.x.array[:] = 0.0
        self._shifted = bool(self.comm.allreduce(bool(np.any(self.reference_shift.x.array != 0.0))))
        self.reference = self.V.tabulate_dof_coordinates()[:, : self.gdim] + \
            self.reference_shift.x.array.reshape(-1, self.gdim)
        self._forms = None

    # -- forms -----------------------------------------------------------------
    def _gradient(self, u):
        """∇u with respect to the reference positions."""
        if not self._shifted:
            return ufl.grad(u)
        return ufl.dot(ufl.grad(u), ufl.inv(ufl.Identity(self.gdim) + ufl.grad(self.reference_shift)))

    def stress(self, u):
        """First Piola–Kirchhoff stress (large rotations) or small-strain stress of u."""
        lmbda, mu = lame(self.E, self.nu)
        grad = self._gradient(u)
        if not self.large_rotations:
            eps = ufl.sym(grad)
            return lmbda * ufl.tr(eps) * ufl.Identity(self.gdim) + 2.0 * mu * eps
        F = ufl.Identity(self.gdim) + grad if self._shifted else deformation_gradient(u)
        return first_piola(self.law, F, lmbda, mu)

    # -- staged construction ----------------------------------------------------------
    def _staged_kinematics(self, u):
        """Per cell, with its activation shift s and reference shift m (module
        dolfinx_corot.staging): the small strain ε(u − s), or F with the Jacobian J₀ of the cell's
        reference over the mesh (None: the mesh): approach I F = I + ∇(u − s) on the mesh;
        approach II the reference is X + m and the current position X + m + u − s,
        F = (I + ∇m + ∇(u − s)) J₀⁻¹, J₀ = I + ∇m (m = s unless the new continuum was mapped)."""
        s, m = self.activation_shift, self.activation_reference
        I = ufl.Identity(self.gdim)
        if not self.large_rotations:
            return ufl.sym(ufl.grad(u - s)), None
        if self.approach == "I":
            return I + ufl.grad(u - s), None
        J0 = I + ufl.grad(m)
        return ufl.dot(J0 + ufl.grad(u - s), ufl.inv(J0)), J0

    def _staged_integrand(self, u, v):
        """P(F) : ∇v per cell (:meth:`_staged_kinematics`); approach II at large rotations is
        integrated over the reference X + s (det J₀ dX, ∇_{X+s} v = ∇v J₀⁻¹)."""
        lmbda, mu = lame(self.E, self.nu)
        measure, J0 = self._staged_kinematics(u)
        if not self.large_rotations:
            eps = measure
            return ufl.inner(lmbda * ufl.tr(eps) * ufl.Identity(self.gdim) + 2.0 * mu * eps, ufl.grad(v))
        P = first_piola(self.law, measure, lmbda, mu)
        if J0 is None:
            return ufl.inner(P, ufl.grad(v))
        return ufl.det(J0) * ufl.inner(P, ufl.dot(ufl.grad(v), ufl.inv(J0)))

    def start_staging(self, approach: str) -> None:
        """Existence per cell from now on (no cell exists until :meth:`set_existing`)."""
        if self._shifted:
            raise NotImplementedError("staged construction of a solid whose reference was re-captured")
        if self.existing is None:
            mesh = self.V.mesh
            self.existing = dolfinx.fem.Function(_dolfinx.function_space(mesh, "DG", 0, scalar=True), name="existing")
            cell = self.V.ufl_element().cell()
            family = "DQ" if cell.cellname() in ("quadrilateral", "hexahedron") else "DG"
            space = _dolfinx.function_space(mesh, family, self.degree, mesh.geometry.dim)
            self.activation_shift = dolfinx.fem.Function(space, name="activation_shift")
            self.activation_reference = dolfinx.fem.Function(space, name="activation_reference")
            self._forms = None
        self.approach = approach

    def is_staged(self) -> bool:
        return self.existing is not None

    def cells_existing(self) -> np.ndarray:
        """(local cells, owned and ghost) whether each exists."""
        return self.existing.x.array[self._cell_dof] > 0.5

    def set_existing(self, exists: np.ndarray, reference: np.ndarray | None = None) -> None:
        """Which local cells (owned and ghost) exist; cells that appear take the current
        displacement of their nodes as their activation shift s (strain-free) and ``reference``
        (local blocks × gdim, e.g. mapped by :meth:`map_new_cells`; None: s) as their reference
        shift m."""
        new = exists & ~self.cells_existing()
        if new.any():
            # s, m on the new cells' DG dofs = u, reference at their nodes (the same node order per cell)
            n = self.nodes_per_cell
            dg = self.activation_shift.function_space.dofmap.list.array.reshape(-1, n)[new].ravel()
            cg = self.V.dofmap.list.array.reshape(-1, n)[new].ravel()
            u = self.state.x.array.reshape(-1, self.gdim)
            self.activation_shift.x.array.reshape(-1, self.gdim)[dg] = u[cg]
            ref = u if reference is None else np.asarray(reference).reshape(-1, self.gdim)
            self.activation_reference.x.array.reshape(-1, self.gdim)[dg] = ref[cg]
        self.existing.x.array[self._cell_dof] = exists.astype(float)

    def staging_arrays(self) -> dict:
        """Activation shift s and reference shift m of every cell's nodes (staged solids)."""
        if self.existing is None:
            return {}
        n = self.nodes_per_cell
        dg = self.activation_shift.function_space.dofmap.list.array.reshape(-1, n)
        cg = self.V.dofmap.list.array.reshape(-1, n)
        values = np.concatenate([f.x.array.reshape(-1, self.gdim)[dg]
                                 for f in (self.activation_shift, self.activation_reference)], axis=2)
        return self._cells_to_global(cg, values)

    def set_staging_arrays(self, arrays: dict) -> None:
        if self.existing is None:
            return
        n, gdim = self.nodes_per_cell, self.gdim
        dg = self.activation_shift.function_space.dofmap.list.array.reshape(-1, n)
        cg = self.V.dofmap.list.array.reshape(-1, n)
        values = self._cells_from_global(cg, arrays)
        self.activation_shift.x.array.reshape(-1, gdim)[dg] = values[:, :, :gdim]
        self.activation_reference.x.array.reshape(-1, gdim)[dg] = values[:, :, gdim:]

    def map_new_cells(self, new: np.ndarray, values: np.ndarray, imposed: np.ndarray) -> np.ndarray:
        """The seed's mapping of new continuum onto the deformed configuration (§3.1.2, approach
        II): the shift w of the nodes of the local cells ``new`` solving linear elasticity with
        E = 1, ν = 0 on those cells alone, with w = ``values`` on the dofs where ``imposed``
        (both local blocks × gdim, owned and ghost). Returns w (local blocks × gdim; the imposed
        values elsewhere). Every dof of a new cell left free must be held by the imposed ones
        (a new region with no imposed node in some direction is refused)."""
        gdim, n = self.gdim, self.nodes_per_cell
        imap = self.V.dofmap.index_map
        n_owned = imap.size_local
        blocks = self.V.dofmap.list.array.reshape(-1, n)
        in_new = np.zeros(n_owned + imap.num_ghosts, dtype=bool)
        in_new[blocks[new].ravel()] = True
        flag = dolfinx.la.vector(imap)
        flag.array[:] = in_new
        flag.scatter_reverse(dolfinx.la.ScatterMode.add)
        flag.scatter_forward()
        in_new = flag.array > 0
        fixed = np.asarray(imposed, dtype=bool).reshape(-1, gdim) | ~in_new[:, None]
        Q = self.existing.function_space
        indicator = dolfinx.fem.Function(Q)
        indicator.x.array[self._cell_dof[new]] = 1.0
        indicator.x.scatter_forward()
        w, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        a = dolfinx.fem.form(indicator * ufl.inner(ufl.sym(ufl.grad(w)), ufl.sym(ufl.grad(v))) * ufl.dx)
        A = dolfinx.fem.petsc.assemble_matrix(a)
        A.assemble()
        start = imap.local_range[0] * gdim
        rows = start + np.flatnonzero(fixed[:n_owned].ravel())
        solution = petsc.solve_constrained(self.comm, A, rows,
                                           np.asarray(values, dtype=float).reshape(-1, gdim)[:n_owned].ravel())
        singular = self.comm.allreduce(solution is None, op=MPI.LOR)
        out = dolfinx.fem.Function(self.V)
        if not singular:
            out.x.array[: n_owned * gdim] = solution
            out.x.scatter_forward()
        if singular:
            raise ValueError("mapping of new continuum (approach II): the cells added are not held — no node "
                             "of them is shared with existing elements, a slave on an existing master, "
                             "supported or on a free boundary in every direction")
        return out.x.array.reshape(-1, gdim).copy()

    keeps_strains_without_displacements = True

    def reset_displacements(self) -> None:
        """Discard the displacement, keep the strains (a geostatic stage): each existing cell's
        shifts s and m become s − u and m − u, so that its strain measure (of u − s, or
        F = (I + ∇m + ∇(u − s))(I + ∇m)⁻¹) is
        unchanged while u = 0. At small strain the stresses are kept exactly; at large strain the
        existing cells are referred to X − u (the mesh is the deformed state)."""
        exists = self.cells_existing()
        n = self.nodes_per_cell
        dg = self.activation_shift.function_space.dofmap.list.array.reshape(-1, n)[exists].ravel()
        cg = self.V.dofmap.list.array.reshape(-1, n)[exists].ravel()
        u = self.state.x.array.reshape(-1, self.gdim)[cg]
        self.activation_shift.x.array.reshape(-1, self.gdim)[dg] -= u
        self.activation_reference.x.array.reshape(-1, self.gdim)[dg] -= u
        self.state.x.array[:] = 0.0

    def _result_fields(self):
        """UFL (σ (gdim, gdim) the Cauchy stress, σ_zz (plane strain; None in 3D), E the
        Green–Lagrange strain, or the small strain ε in a geometrically linear analysis) of the
        current state; staged cells by their own kinematics. The initial stress σ₀ enters σ; in
        plane strain σ_zz is that of the law alone (σ₀ has no zz component)."""
        u = self.state
        lmbda, mu = lame(self.E, self.nu)
        I = ufl.Identity(self.gdim)
        S0 = self.initial_stress
        if self.existing is not None:
            measure, _ = self._staged_kinematics(u)
        elif self.large_rotations:
            measure = I + self._gradient(u)
        else:
            measure = ufl.sym(self._gradient(u))
        if not self.large_rotations:
            sigma = lmbda * ufl.tr(measure) * I + 2.0 * mu * measure
            sigma = sigma if S0 is None else sigma + S0
            szz = lmbda * ufl.tr(measure)
            strain = measure
        else:
            F = measure
            P = first_piola(self.law, F, lmbda, mu)
            P = P if S0 is None else P + ufl.dot(F, S0)
            J = ufl.det(F)
            sigma = ufl.dot(P, F.T) / J
            strain = 0.5 * (F.T * F - I)
            # plane strain, F_zz = 1: neo-Hookean τ_zz = λ ln J; St Venant–Kirchhoff S_zz = λ tr E
            szz = lmbda * (ufl.ln(J) if issubclass(self.law, NeoHookean) else ufl.tr(strain)) / J
        return sigma, (szz if self.gdim == 2 else None), strain

    def _at_centres(self, expression, cells: np.ndarray) -> np.ndarray:
        """A UFL expression evaluated at the centre of the given local cells, (cells, size)."""
        cell = self.V.mesh.ufl_cell().cellname()
        centre = {"triangle": [[1 / 3, 1 / 3]], "quadrilateral": [[0.5, 0.5]],
                  "tetrahedron": [[0.25, 0.25, 0.25]], "hexahedron": [[0.5, 0.5, 0.5]]}[cell]
        expr = dolfinx.fem.Expression(expression, np.array(centre, dtype=float))
        return expr.eval(np.asarray(cells, dtype=np.int32)).reshape(len(cells), -1)

    def cell_stress(self) -> np.ndarray:
        """Cauchy stress at the centre of every owned cell, (cells, gdim, gdim): σ = P Fᵀ / det F
        at large rotations, the small-strain stress otherwise (non-existing cells: 0)."""
        sigma = self._result_fields()[0]
        if self.existing is not None:
            sigma = self.existing * sigma
        owned = np.arange(self.V.mesh.topology.index_map(self.tdim).size_local, dtype=np.int32)
        return self._at_centres(sigma, owned).reshape(len(owned), self.gdim, self.gdim)

    @property
    def section_components(self) -> tuple[str, ...]:
        if self.gdim == 2:
            return ("sxx", "syy", "szz", "sxy", "mises", "Exx", "Eyy", "Exy")
        return ("sxx", "syy", "szz", "sxy", "syz", "sxz", "mises", "Exx", "Eyy", "Ezz", "Exy", "Eyz", "Exz")

    def element_results(self, cells: np.ndarray | None = None, label: str = "",
                        gather: bool = True) -> ElementResults:
        """Stresses and strains at the centre of every (existing) cell, in global axes: the Cauchy
        stress σ (in plane strain with σ_zz), its von Mises value √(3/2 s:s), and the
        Green–Lagrange strain E = ½(FᵀF − I) — the small strain ε in a geometrically linear
        analysis; tensor components (Exy = ½ γxy)."""
        cells = self._result_cells(cells)
        sigma, szz, strain = self._result_fields()
        g = self.gdim
        if g == 2:
            full = ufl.as_matrix([[sigma[0, 0], sigma[0, 1], 0.0], [sigma[1, 0], sigma[1, 1], 0.0], [0.0, 0.0, szz]])
            comps = [sigma[0, 0], sigma[1, 1], szz, sigma[0, 1]]
            strains = [strain[0, 0], strain[1, 1], strain[0, 1]]
        else:
            full = sigma
            comps = [sigma[0, 0], sigma[1, 1], sigma[2, 2], sigma[0, 1], sigma[1, 2], sigma[0, 2]]
            strains = [strain[0, 0], strain[1, 1], strain[2, 2], strain[0, 1], strain[1, 2], strain[0, 2]]
        dev = full - ufl.tr(full) / 3.0 * ufl.Identity(3)
        mises = ufl.sqrt(1.5 * ufl.inner(dev, dev))
        values = self._at_centres(ufl.as_vector(comps + [mises] + strains), cells)
        x = ufl.SpatialCoordinate(self.V.mesh) + self.state
        if self._shifted:
            x = x + self.reference_shift
        centres = self._at_centres(x, cells)
        return self._gather_results("stresses", self.section_components, cells, centres[:, None, :],
                                    values[:, None, :], None, label, gather)

    def held_blocks(self) -> np.ndarray:
        if self.existing is None:
            return np.zeros(0, dtype=np.int32)
        return self._untouched_blocks(self.cells_existing())

    def _check_complete(self) -> None:
        cmap = self.tmesh.mesh.topology.index_map(self.tdim)
        missing = self.comm.allreduce(int(np.sum(self._owner_of_cell[: cmap.size_local] == "")), op=MPI.SUM)
        if missing:
            raise ValueError(f"{missing} cell(s) of the solid mesh have no material: give every cell a region "
                             "(add_solid without 'where' covers all)")
        if np.any(self.nu.x.array >= 0.5) or np.any(self.E.x.array <= 0.0):
            raise ValueError("solid: E must be positive and nu below 0.5 in every cell")

    def _compiled_forms(self):
        """(residual, tangent) of the C kernels of :mod:`dolfinx_corot.continuum.compiled`
        (the same integrals as the UFL forms, about 3 × faster), or None where they do not cover
        the forms: small strains, staged cells, initial stresses, a captured reference, follower
        pressures, or no C compiler."""
        if (not self.large_rotations or self.existing is not None or self.initial_stress is not None
                or self._shifted or self._follower_pressures):
            return None
        from ..continuum import compiled

        mesh = self.V.mesh
        try:
            residual, tangent = compiled.kernels(self.law, mesh.topology.cell_name(), self.degree,
                                                 mesh.geometry.cmap.degree, self.quadrature)
        except Exception as err:  # no compiler, no writable cache: FFCx's kernels
            import logging

            logging.getLogger(__name__).warning("compiled continuum kernels not available (%s); "
                                                "FFCx's kernels are used", err)
            return None
        w = [self.state, self.E, self.nu]
        return (_dolfinx.kernel_form(self.V, residual, 1, w, []),
                _dolfinx.kernel_form(self.V, tangent, 2, w, [], loop=True))

    def forms(self):
        if self._forms is None:
            self._check_complete()
            self._forms = self._compiled_forms()
        if self._forms is None:
            u, v, du = self.state, ufl.TestFunction(self.V), ufl.TrialFunction(self.V)
            dx = ufl.dx(metadata={"quadrature_degree": self.quadrature})
            if self.existing is not None:
                integrand = self._staged_integrand(u, v)
            else:
                integrand = ufl.inner(self.stress(u), self._gradient(v))
            if self.initial_stress is not None:
                integrand = integrand + self._initial_stress_work(u, v)
            if self.existing is not None:
                integrand = self.existing * integrand
            if self._shifted:
                integrand = ufl.det(ufl.Identity(self.gdim) + ufl.grad(self.reference_shift)) * integrand
            residual = integrand * dx
            load = self._follower_load(u, v)
            # the tangent of f_int − f_load(u): the load stiffness of follower pressures
            jacobian = ufl.derivative(residual if load is None else residual - load, u, du)
            self._forms = (dolfinx.fem.form(residual), dolfinx.fem.form(jacobian))
        return self._forms

    def _load_form(self, amplitude):
        """Linear form of the tractions (per reference area) and body forces (per reference volume)
        of one amplitude at unit factor (or None). With a reference shift w the reference measures
        are dX' = det J₀ dX and dA' = |det J₀ J₀⁻ᵀ N| dA (Nanson), J₀ = I + ∇w."""
        v = ufl.TestFunction(self.V)
        volume = area = None
        if self._shifted:
            J0 = ufl.Identity(self.gdim) + ufl.grad(self.reference_shift)
            volume = ufl.det(J0)
            area = ufl.sqrt(ufl.dot(ufl.dot(ufl.inv(J0).T, ufl.FacetNormal(self.V.mesh)),
                                    ufl.dot(ufl.inv(J0).T, ufl.FacetNormal(self.V.mesh)))) * volume
        terms = []
        if any(a is amplitude and cond.exists for *_, a, cond in self._tractions):
            ds = ufl.Measure("ds", domain=self.V.mesh, subdomain_data=self.tmesh.facet_tags)
            for where, t, amp, cond in self._tractions:
                if amp is amplitude and cond.exists:
                    tag = self.tmesh.groups[where][1]
                    term = ufl.inner(ufl.as_vector([float(c) for c in t]), v)
                    if self.existing is not None:  # on the faces of existing cells
                        term = self.existing * term
                    terms.append((term if area is None else area * term) * ds(tag))
        if any(a is amplitude and cond.exists for _, _, a, cond in self._dead_pressures):
            ds = ufl.Measure("ds", domain=self.V.mesh, subdomain_data=self.tmesh.facet_tags)
            N = ufl.FacetNormal(self.V.mesh)
            for where, p, amp, cond in self._dead_pressures:
                if amp is amplitude and cond.exists:
                    term = -p * ufl.inner(N, v)
                    if self.existing is not None:
                        term = self.existing * term
                    terms.append((term if area is None else area * term) * ds(self.tmesh.groups[where][1]))
        dx = ufl.Measure("dx", domain=self.V.mesh, subdomain_data=self.tmesh.cell_tags)
        for where, b, material_density, amp, cond in self._body:
            if amp is amplitude and cond.exists:
                measure = dx if where is None else dx(self.tmesh.groups[where][1])
                term = ufl.inner(ufl.as_vector([float(c) for c in b]), v)
                if material_density:
                    self._check_density(where)  # a region given later may have none
                    term = self.density * term
                if self.existing is not None:
                    term = self.existing * term
                    if self.large_rotations and self.approach == "II":  # per volume of the reference X + m
                        term = ufl.det(ufl.Identity(self.gdim) + ufl.grad(self.activation_reference)) * term
                terms.append((term if volume is None else volume * term) * measure)
        if not terms:
            return None
        return dolfinx.fem.form(sum(terms[1:], terms[0]))

    def _add_distributed_loads(self, b: PETSc.Vec, amplitude) -> None:
        """Add the tractions and body forces of one amplitude (None: proportional to λ) at unit factor."""
        form = self._load_form(amplitude)
        if form is not None:
            vec = dolfinx.fem.assemble_vector(form)
            vec.scatter_reverse(dolfinx.la.ScatterMode.add)
            n = self.V.dofmap.index_map.size_local * self.ndof
            with b.localForm() as bl:
                bl.array[:n] += vec.array[:n]

    def bending_blocks(self) -> np.ndarray:
        return np.zeros(self.V.dofmap.index_map.size_local + self.V.dofmap.index_map.num_ghosts, dtype=bool)

    # -- linear solver -------------------------------------------------------------
    def positions(self) -> np.ndarray:
        """The current positions x = X + u of all local dof blocks, ghosts included ((blocks,
        gdim); X: the reference, shifted where a stage mapped it)."""
        d = self.gdim
        if self._dof_coordinates is None:
            self._dof_coordinates = self.V.tabulate_dof_coordinates()[:, :d].copy()
        return self._dof_coordinates + self.reference_shift.x.array.reshape(-1, d) + self.state.x.array.reshape(-1, d)

    def patch_rotations(self, before: np.ndarray) -> np.ndarray:
        """The rotation of the material around each owned dof block from positions ``before``
        (:meth:`positions` of an earlier configuration) to the current ones: (n_owned, gdim, gdim),
        fitted to the block's patch of cells (:func:`dolfinx_corot.assembly.amg.patch_rotations`)."""
        from ..assembly.amg import patch_rotations

        cells = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)
        return patch_rotations(cells, before, self.positions(), self.V.dofmap.index_map.size_local)

    def near_nullspace_modes(self) -> list[np.ndarray]:
        """Rigid-body modes (3 in 2D, 6 in 3D) on the owned blocks of V ((n_owned, gdim) each), the
        near-nullspace of algebraic multigrid: translations, and infinitesimal rotations of the
        current configuration x = X + u (X: the reference, shifted where a stage mapped it),
        which are nearly free motions of the tangent at u."""
        n_owned = self.V.dofmap.index_map.size_local
        d = self.gdim
        x = self.positions()[:n_owned]
        modes = []
        for k in range(d):
            m = np.zeros((n_owned, d))
            m[:, k] = 1.0
            modes.append(m)
        rots = [(0, 1)] if d == 2 else [(0, 1), (1, 2), (2, 0)]
        for i, j in rots:
            m = np.zeros((n_owned, d))
            m[:, i] = -x[:, j]
            m[:, j] = x[:, i]
            modes.append(m)
        return modes

    # -- state ---------------------------------------------------------------------
    def node_keys(self) -> np.ndarray:
        """A key per local dof block (owned and ghost) for :class:`~dolfinx_corot.assembly.DofLayout`:
        the input (gmsh) node number on linear meshes, so that structures read from the same gmsh
        model share the solid's nodes; quadratic solids number their blocks apart (never shared)."""
        if self.degree == 1:
            return super().node_keys()
        imap = self.V.dofmap.index_map
        n = imap.size_local + imap.num_ghosts
        return imap.local_to_global(np.arange(n, dtype=np.int32)).astype(np.int64) + (np.int64(1) << 32)

    def _global_order(self) -> np.ndarray:
        """Rank of each owned block in a partition-independent ordering (by coordinates: the
        blocks of a quadratic solid have no input node number)."""
        n_owned = self.V.dofmap.index_map.size_local
        x = self.V.tabulate_dof_coordinates()[:n_owned]
        allx = np.concatenate(self.comm.allgather(x))
        order = np.lexsort(allx.T[::-1].round(12))
        rank_of = np.empty(len(allx), dtype=np.int64)
        rank_of[order] = np.arange(len(allx))
        offset = sum(self.comm.allgather(n_owned)[: self.comm.rank])
        return rank_of[offset: offset + n_owned]

    _global_index = _global_order

    def from_global(self, values: np.ndarray) -> np.ndarray:
        if values.shape[0] != self.V.dofmap.index_map.size_global:
            raise ValueError(f"the checkpoint holds {values.shape[0]} nodes; this solid has "
                             f"{self.V.dofmap.index_map.size_global}: it was written for another mesh")
        idx = self._global_order()
        n_owned = self.V.dofmap.index_map.size_local
        out = np.zeros((n_owned + self.V.dofmap.index_map.num_ghosts, self.ndof))
        out[:n_owned] = values[idx]
        f = dolfinx.fem.Function(self.V)
        f.x.array[:] = out.ravel()
        f.x.scatter_forward()
        return f.x.array.copy()

    # -- contact surface -------------------------------------------------------------
    def surface(self, where: str, body: str | None = None) -> Surface:
        """The boundary facets of facet group ``where`` of a linear solid, oriented out of the body:
        in 2D lines with the body on their left, in 3D faces (triangles of tetrahedra,
        quadrilaterals of hexahedra) with their nodes counter-clockwise seen from outside (the
        normal (x₂ − x₁) × (x₃ − x₁) points out of the body); its stiffness scale is the smallest
        E/(1 − ν²) of the solid. ``body`` (a cell group): a facet between a cell of ``body`` and one
        of another region is the face of the ``body`` cell (e.g. a fill's face along a structure,
        on cells excavated before the fill appears); facets with cells of the solid on both sides
        otherwise are refused."""
        if self.gdim not in (2, 3):
            return super().surface(where, body)
        kind = "node-to-segment" if self.gdim == 2 else "node-to-face"
        if self.degree != 1:
            raise SurfaceError(f"contact surface '{where}': {kind} contact needs linear solids (degree 1); this "
                               f"solid has degree {self.degree}")
        lines = "lines" if self.gdim == 2 else "faces"
        tm = self.tmesh
        facets = tm.facets(where)
        if facets is None:
            raise SurfaceError(f"contact surface '{where}' is not a group of boundary {lines} of the solid mesh "
                               f"(groups: {sorted(tm.groups)})")
        mesh = tm.mesh
        tdim = self.tdim
        mesh.topology.create_connectivity(tdim - 1, tdim)
        mesh.topology.create_connectivity(tdim - 1, 0)
        f2c, f2v = mesh.topology.connectivity(tdim - 1, tdim), mesh.topology.connectivity(tdim - 1, 0)
        c2v = mesh.topology.connectivity(tdim, 0)
        cmap = mesh.topology.index_map(tdim)
        Xdof = self.V.tabulate_dof_coordinates()[:, : self.gdim]
        in_body = None
        if body:
            in_body = np.zeros(cmap.size_local + cmap.num_ghosts, dtype=bool)
            in_body[tm.cells(body)] = True
        facet_blocks, facet_cells, inner = [], [], 0
        for f in facets:
            cells = f2c.links(f)
            if len(cells) == 2 and in_body is not None and in_body[cells].sum() == 1:
                cells = cells[in_body[cells]]
            if len(cells) != 1:
                inner += 1
                continue
            c = cells[0]
            if c >= cmap.size_local:
                continue  # the owner of the cell adds this facet
            cv = list(c2v.links(c))
            cd = self.V.dofmap.cell_dofs(c)
            nodes = np.array([cd[cv.index(v)] for v in f2v.links(f)])
            facet_blocks.append(_outward(nodes, Xdof, Xdof[cd].mean(axis=0)))
            facet_cells.append(c)
        if self.comm.allreduce(inner, op=MPI.SUM):  # raised on every rank
            side = f" (between two cells of '{body}' or of other regions)" if body else ""
            raise SurfaceError(f"contact surface '{where}': some of its {lines} lie inside the solid{side}, "
                               "not on its boundary")
        nv = {"triangle": 2, "quadrilateral": 2, "tetrahedron": 3, "hexahedron": 4}[mesh.topology.cell_name()]
        return gather_surface(self, where, np.array(facet_blocks, dtype=np.int64).reshape(-1, nv), Xdof,
                              modulus=self._contact_modulus(), cells=np.array(facet_cells, dtype=np.int32))

    def _contact_modulus(self) -> float:
        """The smallest E/(1 − ν²) of the solid's materials: the stiffness scale of a default penalty."""
        E, nu = self.E.x.array, self.nu.x.array
        return self.comm.allreduce(float(np.min(E / (1.0 - nu**2))) if len(E) else np.inf, op=MPI.MIN)


def _outward(nodes: np.ndarray, X: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """The boundary facet ``nodes`` (blocks of X) of the cell of centre ``centre`` ordered out of
    the cell: a segment (a, b) with the cell on its left; a face counter-clockwise seen from
    outside (a quadrilateral's corners first put in cyclic order around its centre)."""
    x = X[nodes]
    mid = x.mean(axis=0)
    if len(nodes) == 2:
        t = x[1] - x[0]
        return nodes if np.dot(mid - centre, [t[1], -t[0]]) >= 0.0 else nodes[::-1]
    if len(nodes) == 4:
        normal = np.cross(x[1] - x[0], x[2] - x[0])
        e1 = (x[0] - mid) / np.linalg.norm(x[0] - mid)
        e2 = np.cross(normal / np.linalg.norm(normal), e1)
        nodes = nodes[np.argsort(np.arctan2((x - mid) @ e2, (x - mid) @ e1))]
        x = X[nodes]
    return nodes if np.dot(np.cross(x[1] - x[0], x[2] - x[0]), mid - centre) >= 0.0 else nodes[::-1]

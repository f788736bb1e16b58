"""Parts: the models of beams, bars, shells, membranes and continua on DOLFINx meshes.

Every part shares one base (:class:`~.base.Part`: nodes, dofs, supports, prescribed
motion, loads, reactions, monitors, checkpoint state, reference configuration) and
answers ``part.surface(group)`` with a :class:`~.surface.Surface`. :func:`part_for_mesh`
chooses the part model a mesh carries; nothing outside this package asks for a
concrete part class.
"""
import numpy as np

from .base import Motion, Part, PartRef, global_sum, owned_dofs_of_vertices
from .cells import MeshError
from .coupled import Coupled
from .surface import Surface, SurfaceError

# part kinds come with their first use: a scene of continua alone loads neither the structures'
# modules nor numba (53 MB and 0.15 s), a scene of structures alone not the continuum's UFL forms
_LAZY = {"Solid": "solid", "Frame2D": "frame", "Frame3D": "frame", "LineFrame": "frame", "MembraneQuad": "shell", "Shell3D": "shell",
         "ShellQuad": "shell", "Surface3D": "shell"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["Coupled", "Frame2D", "Frame3D", "LineFrame", "MembraneQuad", "MeshError", "Motion", "Part", "PartRef", "Shell3D",
           "ShellQuad", "Solid", "Surface", "Surface3D", "SurfaceError", "global_sum", "owned_dofs_of_vertices", "part_for_mesh"]


def part_for_mesh(tmesh, large_rotations: bool, solid_degree: int | None = None, kind: str | None = None) -> Part:
    """The part model of a mesh: a solid (``solid_degree`` given) or the structure its cells carry
    (lines: 2D or 3D frames; triangles in space: shells and membranes; quadrilaterals in space:
    shells and membranes when ``kind`` is ``"shell"`` (the first elements asked for), membranes
    alone otherwise)."""
    mesh = tmesh.mesh
    x = mesh.geometry.x
    bad = np.flatnonzero(~np.isfinite(x).all(axis=1))
    found = mesh.comm.allgather(x[bad[0]].tolist() if len(bad) else None)
    if any(f is not None for f in found):
        raise ValueError(f"the mesh has node coordinates that are not finite, e.g. {next(f for f in found if f)}: "
                         "check the geometry (gmsh model or arrays) before building parts on it")
    if solid_degree is not None:
        from .solid import Solid

        return Solid(tmesh, solid_degree, large_rotations)
    if mesh.topology.dim == mesh.geometry.dim and mesh.topology.dim > 1:
        raise ValueError("this mesh fills its space (a continuum): use add_solid; structural parts need "
                         "lines or surfaces in space")
    if mesh.topology.dim == 2:
        from .shell import MembraneQuad, Shell3D, ShellQuad

        if mesh.topology.cell_name() == "quadrilateral":
            model = ShellQuad if kind == "shell" else MembraneQuad
        else:
            model = Shell3D
    else:
        from .frame import Frame2D, Frame3D

        model = Frame3D if mesh.geometry.dim == 3 else Frame2D
    return model(tmesh, large_rotations)

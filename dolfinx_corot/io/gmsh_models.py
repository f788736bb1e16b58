"""Small gmsh models used by demos and tests (straight members, polylines).

Each builder creates the model on rank 0 only, reads it with
:func:`dolfinx_corot.io.from_gmsh` and finalizes gmsh.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
from mpi4py import MPI

from .mesh import TaggedMesh, from_gmsh


def polyline(points: Sequence[Sequence[float]], elements_per_segment: int | Sequence[int],
             line_name: str = "beam", point_names: dict[int, str] | None = None, gdim: int = 2,
             comm: MPI.Comm = MPI.COMM_WORLD) -> TaggedMesh:
    """Polyline through ``points`` (n, 2 or 3) meshed with equal elements per segment.

    point_names: index of a point → physical-group name (default: first
    'base', last 'tip'). All segments form the cell group ``line_name``.
    """
    import gmsh

    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or len(pts) < 2:
        raise ValueError("polyline: give at least two points as an (n, 2|3) array")
    if point_names is None:
        point_names = {0: "base", len(pts) - 1: "tip"}
    nseg = len(pts) - 1
    counts = np.broadcast_to(np.asarray(elements_per_segment, dtype=int), (nseg,))
    if np.any(counts < 1):
        raise ValueError("polyline: every segment needs at least one element")
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("polyline")
        tags = [gmsh.model.geo.addPoint(*p[:3], *(0.0,) * (3 - len(p))) for p in pts]
        lines = [gmsh.model.geo.addLine(tags[i], tags[i + 1]) for i in range(nseg)]
        gmsh.model.geo.synchronize()
        for line, n in zip(lines, counts):
            gmsh.model.mesh.setTransfiniteCurve(line, int(n) + 1)
        gmsh.model.addPhysicalGroup(1, lines, 1)
        gmsh.model.setPhysicalName(1, 1, line_name)
        for k, (i, name) in enumerate(sorted(point_names.items())):
            gmsh.model.addPhysicalGroup(0, [tags[i]], 100 + k)
            gmsh.model.setPhysicalName(0, 100 + k, name)
        gmsh.model.mesh.generate(1)
    try:
        return from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=gdim, comm=comm)
    finally:
        if comm.rank == 0:
            gmsh.finalize()


def cylinder_eighth(radius: float, length: float, n_theta: int, n_x: int,
                    comm: MPI.Comm = MPI.COMM_WORLD) -> TaggedMesh:
    """One eighth of an open cylinder (axis x), structured triangles, for pull-out problems.

    x ∈ [0, length/2], θ ∈ [0, 90°] measured from the z axis towards y. Groups:
    'shell' (surface), 'mid' (edge on x = 0), 'top' (edge on y = 0), 'side'
    (edge on z = 0), points 'A' (0, 0, R), 'B' (L/2, 0, R), 'C' (L/2, R, 0).
    """
    import gmsh

    R, L = float(radius), float(length)
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        c0, c1 = g.addPoint(0, 0, 0), g.addPoint(L / 2, 0, 0)
        A, D = g.addPoint(0, 0, R), g.addPoint(0, R, 0)
        B, C = g.addPoint(L / 2, 0, R), g.addPoint(L / 2, R, 0)
        mid, free = g.addCircleArc(A, c0, D), g.addCircleArc(B, c1, C)
        top, side = g.addLine(A, B), g.addLine(D, C)
        surface = g.addSurfaceFilling([g.addCurveLoop([top, free, -side, -mid])])
        g.synchronize()
        for line, n in ((mid, n_theta), (free, n_theta), (top, n_x), (side, n_x)):
            gmsh.model.mesh.setTransfiniteCurve(line, int(n) + 1)
        gmsh.model.mesh.setTransfiniteSurface(surface)
        for dim, tags, tag, name in ((2, [surface], 1, "shell"), (1, [mid], 2, "mid"), (1, [top], 3, "top"),
                                     (1, [side], 4, "side"), (0, [A], 5, "A"), (0, [B], 6, "B"), (0, [C], 7, "C")):
            gmsh.model.addPhysicalGroup(dim, tags, tag)
            gmsh.model.setPhysicalName(dim, tag, name)
        gmsh.model.mesh.generate(2)
    try:
        return from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=3, comm=comm)
    finally:
        if comm.rank == 0:
            gmsh.finalize()

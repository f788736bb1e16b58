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

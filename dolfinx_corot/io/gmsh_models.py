"""Small models used by demos and tests (polylines, cylinders, pits and boxes).

Each gmsh builder creates the model on rank 0 only, reads it with
:func:`dolfinx_corot.io.from_gmsh` and finalizes gmsh; :func:`polyline` needs no gmsh (its
nodes are made along the line and read with :func:`dolfinx_corot.io.mesh.from_arrays`).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
from mpi4py import MPI

from .mesh import TaggedMesh, from_arrays, from_gmsh


def polyline(points: Sequence[Sequence[float]], elements_per_segment: int | Sequence[int],
             line_name: str = "beam", point_names: dict[int, str] | None = None, gdim: int = 2,
             comm: MPI.Comm = MPI.COMM_WORLD) -> TaggedMesh:
    """Polyline through ``points`` (n, 2 or 3) meshed with equal elements per segment, the nodes
    numbered along it (made from arrays: no gmsh session is needed).

    point_names: index of a point → physical-group name (default: first
    'base', last 'tip'). All segments form the cell group ``line_name``; gdim: the coordinates
    kept (points of fewer are padded with zeros).
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or len(pts) < 2:
        raise ValueError("polyline: give at least two points as an (n, 2|3) array")
    if point_names is None:
        point_names = {0: "base", len(pts) - 1: "tip"}
    nseg = len(pts) - 1
    counts = np.broadcast_to(np.asarray(elements_per_segment, dtype=int), (nseg,))
    if np.any(counts < 1):
        raise ValueError("polyline: every segment needs at least one element")
    padded = np.zeros((len(pts), max(gdim, pts.shape[1])))
    padded[:, : pts.shape[1]] = pts
    # the points of each segment but its last (the next segment's first), then the polyline's end
    nodes = [padded[i] + np.linspace(0.0, 1.0, int(n) + 1)[:-1, None] * (padded[i + 1] - padded[i])
             for i, n in enumerate(counts)]
    nodes = np.vstack(nodes + [padded[-1:]])[:, :gdim]
    first = np.r_[0, np.cumsum(counts)]  # the node of each polyline point
    cells = np.c_[np.arange(len(nodes) - 1), np.arange(1, len(nodes))]
    groups: dict[str, list] = {}
    for i, name in sorted(point_names.items()):
        groups.setdefault(name, []).append(first[i])
    return from_arrays(nodes, cells, line_name, groups, comm=comm)


def cylinder_eighth(radius: float, length: float, n_theta: int, n_x: int,
                    comm: MPI.Comm = MPI.COMM_WORLD, quads: bool = False) -> TaggedMesh:
    """One eighth of an open cylinder (axis x), structured triangles (quadrilaterals with
    ``quads``: n_theta × n_x of them), for pull-out problems.

    x ∈ [0, length/2], θ ∈ [0, 90°] measured from the z axis towards y. Groups:
    'shell' (surface), 'mid' (edge on x = 0), 'top' (edge on y = 0), 'side'
    (edge on z = 0), points 'A' (0, 0, R), 'B' (L/2, 0, R), 'C' (L/2, R, 0), 'D' (0, R, 0)
    (Sze, Liu & Lo (2004, §3.5) call D their point B).
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
        if quads:
            gmsh.model.mesh.setRecombine(2, surface)
        for dim, tags, tag, name in ((2, [surface], 1, "shell"), (1, [mid], 2, "mid"), (1, [top], 3, "top"),
                                     (1, [side], 4, "side"), (0, [A], 5, "A"), (0, [B], 6, "B"), (0, [C], 7, "C"),
                                     (0, [D], 8, "D")):
            gmsh.model.addPhysicalGroup(dim, tags, tag)
            gmsh.model.setPhysicalName(dim, tag, name)
        gmsh.model.mesh.generate(2)
    try:
        return from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=3, comm=comm)
    finally:
        if comm.rank == 0:
            gmsh.finalize()


def block_with_hole(width: float, height: float, depth: float, radius: float, size: float,
                    hole_segments: int, comm: MPI.Comm = MPI.COMM_WORLD) -> TaggedMesh:
    """A ground block [−width/2, width/2] × [−height, 0] with a circular hole of ``radius`` whose
    centre lies ``depth`` below the surface, meshed with linear triangles of about ``size``
    (``hole_segments`` equal segments on the hole). Groups: 'soil' (cells), 'cavity' (the hole's
    boundary), 'base' (y = −height), 'sides' (x = ±width/2), 'top' (y = 0)."""
    import gmsh

    if not (0.0 < radius < depth < height and 2.0 * radius < width):
        raise ValueError(f"block_with_hole: the hole (radius {radius}, centre {depth} deep) must lie inside the "
                         f"block {width} × {height}")
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        block = occ.addRectangle(-width / 2, -height, 0.0, width, height)
        hole = occ.addDisk(0.0, -depth, 0.0, radius, radius)
        (cut, _) = occ.cut([(2, block)], [(2, hole)])
        occ.synchronize()
        surface = cut[0][1]
        groups = {"cavity": [], "base": [], "sides": [], "top": []}
        for _, curve in gmsh.model.getBoundary(cut, oriented=False):
            x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(1, curve)
            tol = 1e-6 * max(width, height)  # OCC pads bounding boxes
            if abs(y0 + height) < tol and abs(y1 + height) < tol:
                groups["base"].append(curve)
            elif abs(y0) < tol and abs(y1) < tol:
                groups["top"].append(curve)
            elif abs(abs(x0) - width / 2) < tol and abs(x1 - x0) < tol:
                groups["sides"].append(curve)
            else:
                groups["cavity"].append(curve)
        gmsh.model.mesh.setSize(gmsh.model.getEntities(0), size)
        for curve in groups["cavity"]:
            gmsh.model.mesh.setTransfiniteCurve(curve, int(hole_segments) + 1)
        gmsh.model.addPhysicalGroup(2, [surface], 1)
        gmsh.model.setPhysicalName(2, 1, "soil")
        for k, (name, curves) in enumerate(groups.items()):
            gmsh.model.addPhysicalGroup(1, curves, 2 + k)
            gmsh.model.setPhysicalName(1, 2 + k, name)
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.generate(2)
    try:
        return from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    finally:
        if comm.rank == 0:
            gmsh.finalize()


def graded_block_with_hole(width: float, height: float, depth: float, radius: float, segments: int,
                           size_far: float, grading: tuple[float, float] = (0.3, 3.0),
                           comm: MPI.Comm = MPI.COMM_WORLD) -> TaggedMesh:
    """A ground block [−width/2, width/2] × [−height, 0] with a circular hole of ``radius`` whose
    centre lies ``depth`` below the surface (``segments`` equal segments, a multiple of 4), meshed
    with linear triangles of the segments' length at the hole growing to ``size_far`` between the
    distances ``grading`` from it (gmsh's Distance + Threshold fields). Groups: 'soil' (cells),
    'base', 'sides', 'surface' (y = 0) and 'cavity'."""
    import gmsh

    if not (0.0 < radius < depth < height and 2.0 * radius < width) or segments % 4:
        raise ValueError(f"graded_block_with_hole: the hole (radius {radius}, centre {depth} deep) must lie inside "
                         f"the block {width} × {height}, and segments = {segments} be a multiple of 4")
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        c = g.addPoint(0.0, -depth, 0.0)
        q = [g.addPoint(radius * np.cos(a), -depth + radius * np.sin(a), 0.0) for a in np.pi / 2 * np.arange(4)]
        arcs = [g.addCircleArc(q[i], c, q[(i + 1) % 4]) for i in range(4)]
        w = width / 2
        p = [g.addPoint(x, y, 0.0) for x, y in ((-w, -height), (w, -height), (w, 0.0), (-w, 0.0))]
        lines = [g.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
        s = g.addPlaneSurface([g.addCurveLoop(lines), g.addCurveLoop(arcs)])
        for a in arcs:
            g.mesh.setTransfiniteCurve(a, segments // 4 + 1)
        g.synchronize()
        f = gmsh.model.mesh.field
        dist = f.add("Distance")
        f.setNumbers(dist, "CurvesList", arcs)
        th = f.add("Threshold")
        for key, value in (("InField", dist), ("SizeMin", 2 * np.pi * radius / segments), ("SizeMax", size_far),
                           ("DistMin", grading[0]), ("DistMax", grading[1])):
            f.setNumber(th, key, value)
        f.setAsBackgroundMesh(th)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        for dim, tags, name in ((2, [s], "soil"), (1, [lines[0]], "base"), (1, [lines[1], lines[3]], "sides"),
                                (1, [lines[2]], "surface"), (1, arcs, "cavity")):
            gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)
        gmsh.model.mesh.generate(2)
    from .mesh import from_gmsh

    tm = from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def ring(radius: float, elements: int, centre=(0.0, 0.0), name: str = "ring",
         comm: MPI.Comm = MPI.COMM_WORLD) -> TaggedMesh:
    """A closed circle of ``elements`` straight 2D line elements through nodes on ``radius`` about
    ``centre`` (a tunnel lining, a pipe). Groups: ``name`` (cells) and the nodes 'crown' (top),
    'invert' (bottom) and 'springline' (the right end of the horizontal diameter); ``elements``
    must be a multiple of 4."""
    from .mesh import from_arrays

    if elements < 4 or elements % 4:
        raise ValueError(f"ring: elements = {elements} must be a multiple of 4 (nodes at crown, invert and "
                         "springlines)")
    t = np.arange(elements) * 2.0 * np.pi / elements
    x = np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])
    cells = np.column_stack([np.arange(elements), (np.arange(elements) + 1) % elements])
    q = elements // 4
    return from_arrays(x, cells, name, point_groups={"springline": np.array([0]), "crown": np.array([q]),
                                                      "invert": np.array([3 * q])}, comm=comm)


def box_in_pit(width: float, height: float, pit_width: float, pit_depth: float, span: float, rise: float,
               thickness: float, layers_beside: int, layers_above: int, size: float,
               comm: MPI.Comm = MPI.COMM_WORLD) -> tuple[TaggedMesh, TaggedMesh]:
    """Half of a box structure built in a pit and backfilled (symmetry plane x = 0), meshed with
    structured quadrilaterals of about ``size``; returns (solid mesh, line mesh of the same nodes).

    The ground [0, width] × [0, height] has a pit [0, pit_width/2] × [y_f, height], y_f = height −
    pit_depth. The structure's axis: a bottom slab on the pit floor y = y_f, x ∈ [0, span/2], a
    wall x = span/2 and a roof y = y_f + rise (the slab shares the floor's nodes). Its outer faces,
    half the ``thickness`` off the axis, are lines of the mesh: the cells inside them ('core':
    the structure's interior and half its thickness) are excavated with the pit and never
    refilled; the fill is the rest of the pit, in layers from the floor up to the roof's face
    (``layers_beside``) and from there to the surface (``layers_above``).

    Cell groups: 'ground', 'core', 'layer_1' … 'layer_n' (bottom up) and 'fill' (all layers).
    Line groups: 'base' (y = 0), 'sides' (x = width), 'symmetry' (x = 0), 'surface' (y = height,
    beyond the pit), 'fill_top' (y = height, over the pit), 'pit_floor' (y = y_f beside the
    structure), 'pit_wall' (x = pit_width/2), 'slab', 'frame' (wall and roof axis), 'fill_face' (the
    structure's outer face: wall and roof). Points: 'slab_centre', 'roof_centre', 'corner' (wall
    and roof), 'surface_centre'."""
    import gmsh

    b, a, t = span / 2.0, pit_width / 2.0, thickness
    y_f = height - pit_depth
    x_face, y_roof, y_face = b + t / 2.0, y_f + rise, y_f + rise + t / 2.0
    if not (0.0 < t < span and x_face < a < width and 0.0 < y_f and y_face < height):
        raise ValueError(f"box_in_pit: the structure (span {span}, rise {rise}, thickness {t}) must lie in the "
                         f"pit ({pit_width} wide, {pit_depth} deep) inside the ground {width} × {height}")
    if layers_beside < 1 or layers_above < 1:
        raise ValueError("box_in_pit: at least one layer beside the structure and one above it")
    beside = list(np.linspace(y_f, y_face, layers_beside + 1))
    above = list(np.linspace(y_face, height, layers_above + 1))
    breaks = beside[:-1] + above
    xs = [0.0, b, x_face, a, width]
    ys = sorted(set(np.round([0.0, y_roof] + breaks, 12)))
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("box_in_pit")
        geo = gmsh.model.geo
        nx, ny = len(xs), len(ys)
        pts = {(i, j): geo.addPoint(xs[i], ys[j], 0.0) for i in range(nx) for j in range(ny)}
        hor = {(i, j): geo.addLine(pts[i, j], pts[i + 1, j]) for i in range(nx - 1) for j in range(ny)}
        ver = {(i, j): geo.addLine(pts[i, j], pts[i, j + 1]) for i in range(nx) for j in range(ny - 1)}
        for (i, j), c in hor.items():
            geo.mesh.setTransfiniteCurve(c, max(1, int(round((xs[i + 1] - xs[i]) / size))) + 1)
        for (i, j), c in ver.items():
            geo.mesh.setTransfiniteCurve(c, max(1, int(round((ys[j + 1] - ys[j]) / size))) + 1)
        groups = {"ground": [], "core": []}
        layers = [[] for _ in range(len(breaks) - 1)]
        for i in range(nx - 1):
            for j in range(ny - 1):
                loop = geo.addCurveLoop([hor[i, j], ver[i + 1, j], -hor[i, j + 1], -ver[i, j]])
                sf = geo.addPlaneSurface([loop])
                geo.mesh.setTransfiniteSurface(sf)
                geo.mesh.setRecombine(2, sf)
                xm, ym = 0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1])
                if xm > a or ym < y_f:
                    groups["ground"].append(sf)
                elif xm < x_face and ym < y_face:
                    groups["core"].append(sf)
                else:
                    layers[int(np.searchsorted(breaks, ym)) - 1].append(sf)
        geo.synchronize()
        x_at, y_at = (lambda v: xs.index(v)), (lambda v: int(np.argmin(np.abs(np.array(ys) - v))))
        j_f, j_roof, j_face, j_top = y_at(y_f), y_at(y_roof), y_at(y_face), ny - 1
        lines = {
            "base": [hor[i, 0] for i in range(nx - 1)],
            "sides": [ver[nx - 1, j] for j in range(ny - 1)],
            "symmetry": [ver[0, j] for j in range(ny - 1)],
            "surface": [hor[i, j_top] for i in range(x_at(a), nx - 1)],
            "fill_top": [hor[i, j_top] for i in range(x_at(a))],
            "pit_floor": [hor[x_at(x_face), j_f]],
            "pit_wall": [ver[x_at(a), j] for j in range(j_f, ny - 1)],
            "slab": [hor[0, j_f]],
            "frame": [ver[x_at(b), j] for j in range(j_f, j_roof)] + [hor[0, j_roof]],
            "fill_face": [ver[x_at(x_face), j] for j in range(j_f, j_face)] + [hor[0, j_face], hor[1, j_face]],
        }
        named = {name: (2, tags) for name, tags in groups.items()}
        named.update({f"layer_{k + 1}": (2, tags) for k, tags in enumerate(layers)})
        named.update({name: (1, tags) for name, tags in lines.items()})
        named.update({"slab_centre": (0, [pts[0, j_f]]), "roof_centre": (0, [pts[0, j_roof]]),
                      "corner": (0, [pts[x_at(b), j_roof]]), "surface_centre": (0, [pts[0, j_top]])})
        for name, (dim, tags) in named.items():
            tag = gmsh.model.addPhysicalGroup(dim, list(tags))
            gmsh.model.setPhysicalName(dim, tag, name)
        gmsh.model.mesh.generate(2)
    try:
        model = gmsh.model if comm.rank == 0 else None
        solid = from_gmsh(model, 2, comm=comm)
        lines_mesh = from_gmsh(model, 2, comm=comm, dim=1)
    finally:
        if comm.rank == 0:
            gmsh.finalize()
    solid.add_cell_group("fill", lambda x: (x[0] < a) & (x[1] > y_f) & ~((x[0] < x_face) & (x[1] < y_face)))
    return solid, lines_mesh

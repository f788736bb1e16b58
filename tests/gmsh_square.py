"""A gmsh model shared by the tests of mixed triangle and quadrilateral surfaces."""
import contextlib


@contextlib.contextmanager
def half_recombined_square(comm, nodes, groups):
    """The unit square in the plane z = 0 meshed by gmsh (transfinite): triangles on x < 1/2,
    recombined quadrilaterals on x > 1/2. Its lines: 0 (0, 0)–(½, 0), 1 (½, 0)–(1, 0), 2 x = 1,
    3 (1, 1)–(½, 1), 4 (½, 1)–(0, 1), 5 x = 0, 6 the middle x = ½. ``nodes(i)``: the nodes on
    line i; ``groups``: (name, lines) physical groups of lines, besides the surface group
    'plate'. Yields the gmsh model on rank 0 (None elsewhere) and finalizes gmsh afterwards."""
    import gmsh

    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        p = [g.addPoint(x, y, 0) for x, y in ((0, 0), (0.5, 0), (1, 0), (1, 1), (0.5, 1), (0, 1))]
        lines = [g.addLine(p[i], p[(i + 1) % 6]) for i in range(6)]
        lines.append(g.addLine(p[1], p[4]))
        left = g.addPlaneSurface([g.addCurveLoop([lines[0], lines[6], lines[4], lines[5]])])
        right = g.addPlaneSurface([g.addCurveLoop([lines[1], lines[2], lines[3], -lines[6]])])
        g.synchronize()
        for i, c in enumerate(lines):
            gmsh.model.mesh.setTransfiniteCurve(c, nodes(i))
        for s in (left, right):
            gmsh.model.mesh.setTransfiniteSurface(s)
        gmsh.model.mesh.setRecombine(2, right)
        gmsh.model.addPhysicalGroup(2, [left, right], 1)
        gmsh.model.setPhysicalName(2, 1, "plate")
        for tag, (name, which) in enumerate(groups, start=2):
            gmsh.model.addPhysicalGroup(1, [lines[i] for i in which], tag)
            gmsh.model.setPhysicalName(1, tag, name)
        gmsh.model.mesh.generate(2)
    try:
        yield gmsh.model if comm.rank == 0 else None
    finally:
        if comm.rank == 0:
            gmsh.finalize()

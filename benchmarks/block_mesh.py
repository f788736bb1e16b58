"""The SVK block's structured mesh, shared by its peer benchmarks (``block_calculix.py``,
``block_kratos.py``) in plain Python (Kratos's own Python may have no numpy): nodes numbered from
1, x fastest, n_x × n_y × n_z trilinear hexahedra counter-clockwise from the bottom face, and the
tributary areas that turn a uniform traction on the end face x = L into nodal forces."""

L, E, NU, LOAD, STEPS = 10.0, 1e5, 0.3, 75.0, 5


def node(n, i, j, k):
    """The number of node (i, j, k) of the (n_x + 1) × (n_y + 1) × (n_z + 1) grid."""
    nx, ny, _ = n
    return 1 + i + (nx + 1) * (j + (ny + 1) * k)


def coordinates(n):
    """(number, x, y, z) of every node: the block [0, L] × [0, 1] × [0, 1]."""
    nx, ny, nz = n
    return [(node(n, i, j, k), L * i / nx, j / ny, k / nz)
            for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]


def hexahedra(n):
    """The eight node numbers of each hexahedron, in the element numbering (from 1)."""
    nx, ny, nz = n
    return [[node(n, i, j, k), node(n, i + 1, j, k), node(n, i + 1, j + 1, k), node(n, i, j + 1, k),
             node(n, i, j, k + 1), node(n, i + 1, j, k + 1), node(n, i + 1, j + 1, k + 1), node(n, i, j + 1, k + 1)]
            for k in range(nz) for j in range(ny) for i in range(nx)]


def clamped(n):
    """The nodes of the face x = 0."""
    _, ny, nz = n
    return [node(n, 0, j, k) for k in range(nz + 1) for j in range(ny + 1)]


def end_loads(n):
    """(node, F_y) on the face x = L: the load −LOAD spread uniformly (the bilinear grid's tributary areas)."""
    nx, ny, nz = n
    return [(node(n, nx, j, k), -LOAD * (0.5 if j in (0, ny) else 1.0) / ny * (0.5 if k in (0, nz) else 1.0) / nz)
            for k in range(nz + 1) for j in range(ny + 1)]


def tip(n):
    """The node at the end face's centre, or 0 where n_y or n_z is odd (no node there)."""
    nx, ny, nz = n
    return node(n, nx, ny // 2, nz // 2) if ny % 2 == 0 and nz % 2 == 0 else 0

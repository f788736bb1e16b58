"""3D contact against a smoothed master surface (averaged nodal normals, Nagata patches, the slave
met along the interpolated normal field): the kernel's tangent against central differences of its
force, linear and angular momentum of a pair, continuity from face to face, the flat case, the
accuracy of the surface on a sphere, sharp features. References: Nagata, Comput. Aided Geom. Des.
22 (2005) 327 (the patch reproduces a circular arc to O(θ⁴)); the flat node-to-face kernel."""
import numpy as np
import pytest

from dolfinx_corot.contact import kernels3d as k3
from dolfinx_corot.contact import smooth3d as s3

EPS, AREA = 100.0, 0.7


def _cap(quad: bool, R: float = 3.0, n: int = 4, h: float = 0.5, seed: int | None = None):
    """Nodes (n², 3) on the sphere of radius R through the origin (centre (0, 0, −R)), a grid of
    spacing h in x and y, and its faces (quadrilaterals, or each split in two triangles),
    counter-clockwise seen from above (normals out of the sphere); ``seed``: nodes shaken by h/20."""
    s = np.arange(n) * h - (n - 1) * h / 2
    X = np.array([[x, y, np.sqrt(R * R - x * x - y * y) - R] for y in s for x in s])
    if seed is not None:
        X += np.random.default_rng(seed).normal(0.0, h / 20, X.shape)
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i
            faces += [[a, b, c, d]] if quad else [[a, b, c], [a, c, d]]
    return X, np.array(faces)


def _pair(X, F, face: int, slave):
    """The kernel's inputs for a slave against face ``face``: (x (1 + W, 3), k, rows, star, nstar, ext)."""
    ext, star, nstar = s3.build_stencils(X, F, np.radians(60.0))
    x = np.empty((1 + ext.shape[1], 3))
    rows = s3._gather(np.asarray(slave, float)[None, :], X, ext, 0, face, x)
    return x, F.shape[1], rows, star[face], nstar[face], ext[face]


def _evaluate(x, k, rows, star, nstar, lam=0.0, side=0.0, offset=0.0, tangent=False):
    m = 3 * len(x)
    f, K = np.zeros(m), np.zeros((m, m))
    g, xi, eta = s3.node_to_smooth_face(x, k, rows, star, nstar, side, offset, lam, EPS, AREA, tangent, f, K)
    return g, f, K


def _centre(X, F, face):
    return X[F[face]].mean(axis=0)


@pytest.mark.parametrize("quad", [False, True])
@pytest.mark.parametrize("where", ["inside", "near_edge", "near_vertex"])
@pytest.mark.parametrize("lam, side, offset", [(0.0, 0.0, 0.0), (3.0, 0.0, 0.0), (0.0, 1.0, 0.2), (0.0, -1.0, 0.2)])
def test_tangent_is_the_derivative_of_the_force_and_the_pair_conserves_momentum(quad, where, lam, side, offset):
    """K = ∂f/∂x by central differences (h = 1e-6: 1e-7 of the largest entry) over the slave and the
    whole stencil (the face's nodes and the nodes of the faces around them, through the nodal
    normals), on a shaken spherical cap, penetrating, with an augmented-Lagrangian multiplier and
    on either side of a two-sided master with a shell's offset; the pair's forces sum to zero and
    so does their moment (1e-13 of the force × the stencil's size). K is not symmetric (the force
    is not an energy's gradient)."""
    X, F = _cap(quad, seed=3)
    face = 4 if quad else 9
    c = _centre(X, F, face)
    a, b = X[F[face, 0]], X[F[face, 1]]
    slave = {"inside": c, "near_edge": 0.5 * (a + b) + 0.01 * (c - 0.5 * (a + b)),
             "near_vertex": a + 0.02 * (c - a)}[where]
    normal = np.array([0.0, 0.0, 1.0])
    depth = {0.0: -0.02, 1.0: 0.17, -1.0: -0.15}[side]
    x, k, rows, star, nstar, _ = _pair(X, F, face, slave + depth * normal)
    g, f, K = _evaluate(x, k, rows, star, nstar, lam, side, offset, tangent=True)
    assert lam - EPS * g > 0.0
    m = 3 * (1 + rows)
    fd = np.zeros((len(f), m))
    for j in range(m):
        xp, xm = x.copy(), x.copy()
        xp.flat[j] += 1e-6
        xm.flat[j] -= 1e-6
        fd[:, j] = (_evaluate(xp, k, rows, star, nstar, lam, side, offset)[1] -
                    _evaluate(xm, k, rows, star, nstar, lam, side, offset)[1]) / 2e-6
    assert np.abs(K[:, :m] - fd).max() < 1e-7 * np.abs(K).max()
    assert np.abs(K[:m, :m] - K[:m, :m].T).max() > 1e-3 * np.abs(K).max()
    fr = f.reshape(-1, 3)[: 1 + rows]
    assert np.abs(fr.sum(axis=0)).max() < 1e-13 * np.abs(f).max()
    assert np.abs(np.cross(x[: 1 + rows] - x[0], fr).sum(axis=0)).max() < 1e-13 * np.abs(f).max() * 2.0
    # pushed out of the master: along the normal field, outwards (up), on its side
    assert np.sign(side or 1.0) * fr[0, 2] < 0.0


@pytest.mark.parametrize("quad", [False, True])
@pytest.mark.parametrize("seed", range(6))
def test_a_nearly_flat_rough_master_keeps_a_smooth_force(quad, seed):
    """A flat grid whose nodes are shaken by 1e-3 of the face size out of plane (a deformed flat
    face: nodal normals nearly parallel, edges not normal to them). Each edge's curvature
    coefficient stays below |d||Δ|/|v|² (here under 1e-2 of the edge), and the force's tangent
    matches central differences (h = 1e-7) to 1e-7 over the stencil: Nagata's in-plane term,
    singular as the normals turn parallel, reached 25 times the edge there and made the contact
    point jump under perturbations of 1e-6 (the assembled tangent missed by 1.6e-5)."""
    X, F = _cap(quad, R=1e9)
    X[:, 2] += np.random.default_rng(seed).uniform(-5e-4, 5e-4, len(X))
    face = 4 if quad else 9
    x, k, rows, star, nstar, _ = _pair(X, F, face, _centre(X, F, face) + [0.03, -0.02, -0.01])
    nn, c = np.zeros((k, 3)), np.zeros(3)
    s3.nodal_normals(x, k, star, nstar, nn)
    for a in range(k):
        s3._edge_curvature(x, nn, a, (a + 1) % k, c)
        assert np.linalg.norm(c) < 1e-2 * np.linalg.norm(x[1 + (a + 1) % k] - x[1 + a])
    g, f, K = _evaluate(x, k, rows, star, nstar, lam=0.5, tangent=True)
    m = 3 * (1 + rows)
    fd = np.zeros((len(f), m))
    for j in range(m):
        xp, xm = x.copy(), x.copy()
        xp.flat[j] += 1e-7
        xm.flat[j] -= 1e-7
        fd[:, j] = (_evaluate(xp, k, rows, star, nstar, lam=0.5)[1] -
                    _evaluate(xm, k, rows, star, nstar, lam=0.5)[1]) / 2e-7
    assert np.abs(K[:, :m] - fd).max() < 1e-7 * np.abs(K).max()


@pytest.mark.parametrize("quad", [False, True])
def test_gap_normal_and_force_are_continuous_from_face_to_face(quad):
    """A slave at a fixed depth under a spherical cap moved across the edge shared by two faces:
    evaluated against either face at the edge, the gap agrees to 1e-13, the slave's force to 1e-12
    of its size and the master nodes' shares to 1e-4 (the flat kernels' normals differ by the
    faces' angle there, 4–8°); along a path across the edge the gap changes by no more than the
    path's steps allow (no jump)."""
    X, F = _cap(quad)
    ext, star, nstar = s3.build_stencils(X, F, np.radians(60.0))
    A, B = (3, 4) if quad else (8, 11)  # two faces sharing an edge (of two cells of the grid)
    shared = np.intersect1d(F[A], F[B])
    assert len(shared) == 2
    # the slave: 0.02 inside the patch at the edge's middle, along the normal field there
    x, k, rows, st, ns, _ = _pair(X, F, A, X[0])
    corners = (np.column_stack([k3.QUAD_XI, k3.QUAD_ETA]) if quad else np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
    xi, eta = corners[[list(F[A]).index(v) for v in shared]].mean(axis=0)
    nn, xc, t1, t2 = np.zeros((k, 3)), np.zeros(3), np.zeros(3), np.zeros(3)
    s3.nodal_normals(x, k, st, ns, nn)
    s3.surface(x, k, nn, xi, eta, xc, t1, t2)
    N, dN = np.zeros(k), np.zeros((k, 2))
    k3.shape(k, xi, eta, N, dN)
    mid = xc - 0.02 * (N @ nn) / np.linalg.norm(N @ nn)
    forces = []
    for face in (A, B):
        x, k, rows, st, ns, e = _pair(X, F, face, mid)
        g, f, _ = _evaluate(x, k, rows, st, ns)
        out = np.zeros((len(X) + 1, 3))
        out[0] = f[:3]
        for j, v in enumerate(e):
            if v >= 0:
                out[1 + v] += f[3 + 3 * j: 6 + 3 * j]
        forces.append((g, out))
    assert forces[0][0] == pytest.approx(forces[1][0], abs=1e-13)
    scale = np.abs(forces[0][1]).max()
    assert np.abs(forces[0][1][0] - forces[1][1][0]).max() < 1e-12 * scale  # the slave's
    # the master nodes' shares: where the line along the normal from the curved edge meets each
    # flat face (weights that give the face nodes' forces the slave's moment; 8.7e-6 measured)
    assert np.abs(forces[0][1] - forces[1][1]).max() < 1e-4 * scale
    # the flat faces' normals at the edge: 8° apart
    nA, nB = (np.cross(X[F[f, 1]] - X[F[f, 0]], X[F[f, 2]] - X[F[f, 0]]) for f in (A, B))
    angle = np.degrees(np.arccos(nA @ nB / np.linalg.norm(nA) / np.linalg.norm(nB)))
    assert angle > 4.0
    # a path across the edge: each slave against the face its point falls on
    direction = np.cross(X[shared[1]] - X[shared[0]], [0.0, 0.0, 1.0])
    direction /= np.linalg.norm(direction)
    gaps = []
    for s in np.linspace(-0.05, 0.05, 41):
        best = None
        for face in (A, B):
            xs, xm = (mid + s * direction)[None, :], X
            xi, eta, dist, ok = np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1, dtype=bool)
            s3.smooth_on_faces(xs, xm, ext, np.full(len(F), F.shape[1]), star, nstar, np.zeros(1, dtype=np.int64),
                               np.array([face]), xi, eta, dist, ok)
            inside = k3.inside(F.shape[1], xi[0], eta[0], 1e-9)
            if ok[0] and inside:
                best = dist[0]
        gaps.append(best)
    assert None not in gaps
    assert np.abs(np.diff(gaps)).max() < 0.3 * 0.1 / 40  # |Δg| ≤ 0.3 × the step: no jump


@pytest.mark.parametrize("quad", [False, True])
def test_on_a_flat_surface_the_smoothed_kernel_is_the_flat_one(quad):
    """All nodal normals equal the faces': the Nagata coefficients vanish, the normal field is the
    face normal, and gap and force equal the flat node-to-face kernel's (1e-13)."""
    X, F = _cap(quad, R=1e9)
    X[:, 2] = 0.0
    face = 4 if quad else 9
    slave = _centre(X, F, face) + np.array([0.07, -0.03, -0.01])
    x, k, rows, star, nstar, _ = _pair(X, F, face, slave)
    g, f, _ = _evaluate(x, k, rows, star, nstar)
    flat = np.vstack([slave, X[F[face]]])
    ff, KK = np.zeros(3 * (1 + k)), np.zeros((3 * (1 + k), 3 * (1 + k)))
    gf = k3.node_to_face(flat, k, 0, 0, 0.0, 0.0, 0.0, EPS, AREA, False, ff, KK)
    assert g == pytest.approx(gf, abs=1e-13)
    assert np.abs(f[: 3 * (1 + k)] - ff).max() < 1e-13 * np.abs(ff).max()
    assert np.abs(f[3 * (1 + k):]).max() == 0.0


@pytest.mark.parametrize("quad", [False, True])
def test_the_nagata_surface_of_a_faceted_sphere_lies_near_the_sphere(quad):
    """Points of a sphere (R = 3) above the centre of a face (spacing h = 0.5, faces turned by 10°)
    are at a gap below 1/20 of the flat faces' (the chord's sagitta, h²/8R ≈ 0.01 at an edge's
    midpoint; the Nagata patch reproduces circular arcs to fourth order), on the faces whose nodes
    have their full ring of faces (at the border of a surface a node's normal averages one side)."""
    R = 3.0
    X, F = _cap(quad, R=R, n=6)
    inner = np.all(np.bincount(F.ravel())[F] == (4 if quad else 6), axis=1)
    assert inner.sum() >= 4
    for face in np.flatnonzero(inner):
        c = _centre(X, F, face)
        on = (c + np.array([0.0, 0.0, R])) / np.linalg.norm(c + np.array([0.0, 0.0, R])) * R - np.array([0, 0, R])
        x, k, rows, star, nstar, _ = _pair(X, F, face, on)
        g, _, _ = _evaluate(x, k, rows, star, nstar)
        flat = k3.node_to_face(np.vstack([on, X[F[face]]]), k, 0, 0, 0.0, 0.0, 0.0, EPS, AREA, False,
                               np.zeros(3 * (1 + k)), np.zeros((3 * (1 + k), 3 * (1 + k))))
        assert flat > 0.004
        assert abs(g) < flat / 20


def test_a_sharp_feature_keeps_its_own_normals():
    """Two faces of a cube's corner (90° apart, beyond the 60° smoothing angle): each face's nodal
    normals are its own, and a slave near the shared edge meets either face along that face's
    normal (as the flat kernel)."""
    X = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1, 0, -1], [1, 1, -1]], float)
    F = np.array([[0, 1, 2, 3], [1, 4, 5, 2]])  # the top (normal +z) and the side x = 1 (normal +x)
    ext, star, nstar = s3.build_stencils(X, F, np.radians(60.0))
    assert np.all(nstar == 1)
    slave = np.array([0.9, 0.5, -0.01])
    x, k, rows, st, ns, _ = _pair(X, F, 0, slave)
    g, f, _ = _evaluate(x, k, rows, st, ns)
    assert g == pytest.approx(-0.01, abs=1e-14)
    assert np.abs(f[:3] / np.linalg.norm(f[:3]) - [0.0, 0.0, -1.0]).max() < 1e-14

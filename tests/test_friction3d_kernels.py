"""3D Coulomb friction kernels: a slave against a flat triangle or warped bilinear quadrilateral (on
the face, at an edge, at a vertex, one- and two-sided masters) and against a smoothed (Nagata)
face. References: the tangent against central differences of the force (in stick and in slip,
with cohesion); Coulomb's cone |t| = c + μ p in slip (radial return, Wriggers 2006 §5.2); the
frictionless kernels for μ = c = 0 and for a slave without slip; frame indifference (a rigid
rotation of the pair rotates its forces); the return map's stick point (ε_T s = t)."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dolfinx_corot.contact import kernels3d as k3
from dolfinx_corot.contact import smooth3d as s3
from test_smooth3d import _cap

EPS, AREA, EPS_T = 100.0, 0.7, 80.0


def _face(k: int, rng) -> np.ndarray:
    face = (np.array([[0, 0, 0], [1, 0, 0.1], [0.1, 1, -0.1]], float) if k == 3 else
            np.array([[0, 0, 0], [1, 0, 0.1], [1.1, 1, 0.0], [0, 0.9, -0.1]], float))  # warped quad
    return face + rng.normal(0.0, 0.02, face.shape)


# slaves: inside the face (penetrating), beyond an edge, beyond a vertex (as test_contact3d_kernels)
CASES = [(0, 0, [0.3, 0.35, -0.02]), (1, 0, [0.5, -0.2, -0.03]), (1, 1, [0.9, 0.6, -0.05]),
         (2, 1, [1.3, -0.2, -0.05]), (2, 0, [-0.2, -0.2, -0.01])]


def _flat(x, k, mode, which, xi0, mu=0.3, cohesion=0.0, lam=0.0, side=0.0, tangent=False, attach=0, y=None,
          offset=None, lam_t=(0.0, 0.0, 0.0)):
    m = 3 * (1 + k)
    f, K, t, n = np.zeros(m), np.zeros((m, m)), np.zeros(3), np.zeros(3)
    xi0 = np.array(xi0, float)
    y = np.zeros(3) if y is None else np.asarray(y, float)
    offset = (0.4 if side else 0.0) if offset is None else offset
    g, p, slipping = k3.node_to_face_friction(x, k, mode, which, side, offset, lam, EPS, AREA, EPS_T, mu, cohesion,
                                              attach, y, xi0, np.array(lam_t, float), tangent, f, K, t, n)
    return dict(g=g, p=p, slipping=slipping, f=f, K=K, t=t, n=n, xi0=xi0)


def _fd(fun, x, h=1e-7):
    """Central differences (m, m) of the force fun(x) over the entries of x."""
    cols = []
    for j in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp.flat[j] += h
        xm.flat[j] -= h
        cols.append((fun(xp) - fun(xm)) / (2 * h))
    return np.array(cols).T


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("mode, which, slave", CASES)
@pytest.mark.parametrize("dxi0, cohesion, side, lam_t", [((0.001, -0.0008), 0.0, 0.0, (0, 0, 0)),   # stick
                                                         ((0.001, -0.0008), 0.0, 0.0, (0.2, -0.1, 0.1)),  # λ_T
                                                         ((0.2, 0.1), 0.0, 0.0, (0, 0, 0)),        # slip
                                                         ((0.2, 0.1), 0.0, 0.0, (-1.0, 0.5, 0.3)),  # slip, λ_T
                                                         ((-0.1, 0.25), 0.4, 0.0, (0, 0, 0)),      # cohesion
                                                         ((0.2, -0.1), 0.0, 1.0, (0.5, 0.5, 0))])  # two-sided
def test_the_tangent_is_the_derivative_of_the_force_in_stick_and_slip(k, mode, which, slave, dxi0, cohesion, side,
                                                                      lam_t):
    """K = ∂f/∂x by central differences (h = 1e-7: 1e-6 of the largest entry) at faces, edges and
    vertices of a triangle and a warped quadrilateral, with and without a tangential multiplier
    λ_T (its convected basis turns with the face: in the tangent); the pair's forces sum to
    zero; in slip the traction lies on Coulomb's cone (|t| = c + μ p to 1e-13) along the slip,
    and K is not symmetric."""
    rng = np.random.default_rng(5)
    x = np.vstack([slave, _face(k, rng)])
    if side:  # a shell's mid-surface: the slave 0.03 above it, its contact face at 0.4 (as test_contact3d_kernels)
        x[0, 2] = 0.03
    offset_lam = 3.0 if side else 0.0
    base = _flat(x, k, mode, which, (0.0, 0.0), attach=1, y=x[0], side=side, lam=offset_lam)
    xi0 = base["xi0"] + np.array(dxi0)
    r = _flat(x, k, mode, which, xi0, cohesion=cohesion, side=side, lam=offset_lam, tangent=True, lam_t=lam_t)
    assert r["p"] > 0.0
    if np.abs(dxi0).max() < 0.01:
        assert not r["slipping"]
    elastic = _flat(x, k, mode, which, xi0, mu=1e9, side=side, lam=offset_lam, lam_t=lam_t)["t"]
    assert r["slipping"] == (np.linalg.norm(elastic) > cohesion + 0.3 * r["p"])
    fd = _fd(lambda y: _flat(y, k, mode, which, xi0, cohesion=cohesion, side=side, lam=offset_lam,
                             lam_t=lam_t)["f"], x)
    assert np.abs(r["K"] - fd).max() < 1e-6 * np.abs(r["K"]).max()
    assert np.abs(r["f"].reshape(-1, 3).sum(axis=0)).max() < 1e-13 * np.abs(r["f"]).max()
    assert abs(r["t"] @ r["n"]) < 1e-13 * EPS_T  # (round-off of s = r₀ − (r₀·n) n, |r₀| ~ 1)
    if r["slipping"]:
        assert np.linalg.norm(r["t"]) == pytest.approx(cohesion + 0.3 * r["p"], rel=1e-13)
        assert np.abs(r["K"] - r["K"].T).max() > 1e-3 * np.abs(r["K"]).max()


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("mode, which, slave", CASES)
def test_without_slip_or_friction_the_kernel_is_the_frictionless_one(k, mode, which, slave):
    """A slave attached where it is (the line along the normal through it meets the face at its
    contact point: no slip) and a slave far from its stick point with μ = c = 0 have the
    frictionless force and tangent (1e-13)."""
    x = np.vstack([slave, _face(k, np.random.default_rng(5))])
    m = 3 * (1 + k)
    f0, K0 = np.zeros(m), np.zeros((m, m))
    k3.node_to_face(x, k, mode, which, 0.0, 0.0, 0.0, EPS, AREA, True, f0, K0)
    attached = _flat(x, k, mode, which, (0.0, 0.0), attach=1, y=x[0], tangent=True)
    assert np.linalg.norm(attached["t"]) < 1e-12
    free = _flat(x, k, mode, which, attached["xi0"] + 0.3, mu=0.0, tangent=True)
    for r in (attached, free):
        assert np.abs(r["f"] - f0).max() < 1e-13 * np.abs(f0).max()
    # with no slip the tangent differs by the stick stiffness only (A ε_T in the tangent plane)
    assert np.abs(free["K"] - K0).max() < 1e-13 * np.abs(K0).max()


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("mode, which, slave", CASES[:3])
def test_a_rigid_rotation_of_the_pair_rotates_its_forces(k, mode, which, slave):
    """Frame indifference: the pair turned by 2.3 rad about a skew axis and moved has its forces
    and traction turned with it, the same pressure and the same stick/slip state (1e-12), with
    and without a tangential multiplier (held on the face's convected basis)."""
    x = np.vstack([slave, _face(k, np.random.default_rng(5))])
    Rm = Rotation.from_rotvec(2.3 * np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])).as_matrix()
    y = x @ Rm.T + np.array([3.0, -1.0, 2.0])
    for dxi0, lam_t in (((0.004, 0.002), (0, 0, 0)), ((0.2, -0.1), (0, 0, 0)), ((0.004, 0.002), (0.1, -0.05, 0.1)),
                        ((0.0, 0.0), (2.0, 1.0, -0.5))):
        xi0 = _flat(x, k, mode, which, (0, 0), attach=1, y=x[0])["xi0"] + dxi0
        a, b = _flat(x, k, mode, which, xi0, lam_t=lam_t), _flat(y, k, mode, which, xi0, lam_t=lam_t)
        assert a["slipping"] == b["slipping"] and b["p"] == pytest.approx(a["p"], rel=1e-12)
        assert np.abs(b["f"].reshape(-1, 3) - a["f"].reshape(-1, 3) @ Rm.T).max() < 1e-12 * np.abs(a["f"]).max()
        # (a traction of 0.016 where λ_T and ε_T s nearly cancel: round-off of terms ~0.1)
        assert np.abs(b["t"] - Rm @ a["t"]).max() < 1e-12 * max(np.linalg.norm(a["t"]), 0.1)


def _slipping_pair(k, mode, which, slave):
    """(x, ξ₀, the kernel's result, the face as a one-face surface) of a slave that slips: its
    stick point 0.3 from it in the tangent plane."""
    x = np.vstack([slave, _face(k, np.random.default_rng(5))])
    n = _flat(x, k, mode, which, (0, 0), attach=1, y=x[0])["n"]
    w = np.cross(n, [0.3, 0.8, 0.5])
    xi0 = _flat(x, k, mode, which, (0, 0), attach=1, y=x[0] + 0.3 * w / np.linalg.norm(w))["xi0"]
    r = _flat(x, k, mode, which, xi0)
    assert r["slipping"]
    faces = np.hstack([np.arange(k)[None, :], np.zeros((1, 4 - k), dtype=np.int64)]).astype(np.int64)
    return x, xi0, r, faces


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("mode, which, slave", CASES)
def test_the_return_maps_stick_point_carries_the_traction(k, mode, which, slave):
    """After a slip the new stick point (the line along n through x_s − t/ε_T meets the face:
    :func:`attach_on_faces`) gives the elastic slip ε_T s = t at the same configuration (1e-12):
    the slave sits on the cone's rim, and a reversal starts elastic."""
    x, xi0, r, faces = _slipping_pair(k, mode, which, slave)
    new = xi0[None, :].copy()
    k3.attach_on_faces(x[1:], faces, np.array([k]), np.array([0]), (x[0] - r["t"] / EPS_T)[None, :],
                       r["n"][None, :], new)
    s = _flat(x, k, mode, which, new[0], mu=1e9)  # no cap: the elastic traction
    assert not s["slipping"]
    assert np.abs(s["t"] - r["t"]).max() < 1e-12 * np.linalg.norm(r["t"])
    point = np.zeros((1, 3))
    k3.face_points(x[1:], faces, np.array([k]), np.array([0]), new, point)
    assert np.linalg.norm(np.cross(x[0] - r["t"] / EPS_T - point[0], r["n"])) < 1e-12


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("mode, which, slave", CASES)
def test_a_multiplier_on_the_convected_basis_carries_the_traction(k, mode, which, slave):
    """The augmented Lagrangian's update of a slipping slave (attached under itself, λ_T = t as
    components on the face's convected basis (a₁, a₂, a₁ × a₂) at the new stick point, with
    :func:`face_frames`; at an edge or a vertex t is not in the face's plane): evaluated there,
    the slave carries the same traction and force (1e-12), without elastic slip."""
    x, xi0, r, faces = _slipping_pair(k, mode, which, slave)
    under = _flat(x, k, mode, which, (0, 0), attach=1, y=x[0])["xi0"]
    a1, a2 = np.zeros((1, 3)), np.zeros((1, 3))
    k3.face_frames(x[1:], faces, np.array([k]), np.array([0]), under[None, :], np.zeros((1, 3)), a1, a2)
    A = np.vstack([a1, a2, np.cross(a1, a2)])
    lam_t = np.linalg.solve(A.T, r["t"])
    back = _flat(x, k, mode, which, under, lam_t=lam_t)
    assert np.abs(back["t"] - r["t"]).max() < 1e-12 * np.linalg.norm(r["t"])
    assert np.abs(back["f"] - r["f"]).max() < 1e-12 * np.abs(r["f"]).max()


# -- the smoothed master --------------------------------------------------------------------------
def _smooth(x, k, rows, star, nstar, xi0, mu=0.3, cohesion=0.0, side=0.0, lam=0.0, tangent=False, attach=0,
            y=None, lam_t=(0.0, 0.0, 0.0)):
    m = 3 * len(x)
    f, K, t, n = np.zeros(m), np.zeros((m, m)), np.zeros(3), np.zeros(3)
    xi0 = np.array(xi0, float)
    y = np.zeros(3) if y is None else np.asarray(y, float)
    g, p, slipping = s3.node_to_smooth_face_friction(x, k, rows, star, nstar, side, 0.0 if not side else 0.2, lam,
                                                     EPS, AREA, EPS_T, mu, cohesion, attach, y, xi0,
                                                     np.array(lam_t, float), tangent, f, K, t, n)
    return dict(g=g, p=p, slipping=slipping, f=f, K=K, t=t, n=n, xi0=xi0)


@pytest.mark.parametrize("quad", [False, True])
@pytest.mark.parametrize("where", ["inside", "near_edge"])
@pytest.mark.parametrize("dxi0, cohesion, side", [((0.003, 0.002), 0.0, 0.0), ((0.15, -0.1), 0.0, 0.0),
                                                  ((0.1, 0.2), 0.5, 0.0), ((-0.15, 0.1), 0.0, 1.0)])
@pytest.mark.parametrize("lam_t", [(0.0, 0.0, 0.0), (0.3, -0.2, 0.2)])
def test_smoothed_master_tangent_in_stick_and_slip(quad, where, dxi0, cohesion, side, lam_t):
    """On a shaken spherical cap's Nagata patches: K = ∂f/∂x over the slave and the stencil by
    central differences (1e-6); forces in balance; in slip |t| = c + μ p (1e-13), t ⟂ ν; a slave
    attached where it is has no traction and the frictionless smoothed kernel's force (1e-13);
    with and without a tangential multiplier on the patch's basis at the stick point."""
    X, F = _cap(quad, seed=3)
    face = 4 if quad else 9
    ext, star, nstar = s3.build_stencils(X, F, np.radians(60.0))
    c = X[F[face]].mean(axis=0)
    a, b = X[F[face, 0]], X[F[face, 1]]
    slave = {"inside": c, "near_edge": 0.5 * (a + b) + 0.01 * (c - 0.5 * (a + b))}[where]
    slave = slave + (np.array([0, 0, 0.17]) if side else np.array([0, 0, -0.02]))
    x = np.empty((1 + ext.shape[1], 3))
    rows = s3._gather(slave[None, :], X, ext, 0, face, x)
    k = F.shape[1]
    base = _smooth(x, k, rows, star[face], nstar[face], (0, 0), attach=1, y=x[0], side=side)
    assert np.linalg.norm(base["t"]) < 1e-12
    m = 3 * (1 + rows)
    f0, K0 = np.zeros(3 * len(x)), np.zeros((3 * len(x), 3 * len(x)))
    s3.node_to_smooth_face(x, k, rows, star[face], nstar[face], side, 0.0 if not side else 0.2, 0.0, EPS, AREA,
                           False, f0, K0)
    assert np.abs(base["f"] - f0).max() < 1e-13 * np.abs(f0).max()
    xi0 = base["xi0"] + dxi0
    r = _smooth(x, k, rows, star[face], nstar[face], xi0, cohesion=cohesion, side=side, tangent=True, lam_t=lam_t)
    assert r["slipping"] == (np.abs(dxi0).max() > 0.01) and r["p"] > 0.0
    fd = _fd(lambda y: _smooth(y, k, rows, star[face], nstar[face], xi0, cohesion=cohesion, side=side,
                               lam_t=lam_t)["f"][:m], x[: 1 + rows])
    assert np.abs(r["K"][:m, :m] - fd).max() < 1e-6 * np.abs(r["K"]).max()
    assert np.abs(r["f"].reshape(-1, 3).sum(axis=0)).max() < 1e-13 * np.abs(r["f"]).max()
    assert abs(r["t"] @ r["n"]) < 1e-13 * EPS_T  # (round-off of s = r₀ − (r₀·n) n, |r₀| ~ 1)
    if r["slipping"]:
        assert np.linalg.norm(r["t"]) == pytest.approx(cohesion + 0.3 * r["p"], rel=1e-13)
    # the return map's stick point carries the traction (ε_T s = t)
    if r["slipping"] and not any(lam_t):
        new = xi0[None, :].copy()
        s3.attach_on_patches(X, ext, np.array([k] * len(F)), star, nstar, np.array([face]),
                             (x[0] - r["t"] / EPS_T)[None, :], r["n"][None, :], new)
        back = _smooth(x, k, rows, star[face], nstar[face], new[0], mu=1e9, side=side)
        assert np.abs(back["t"] - r["t"]).max() < 1e-11 * np.linalg.norm(r["t"])

"""The shallow-shell term of the co-rotational shells' local law (elements/shallow_shell.py): the
mean membrane strain of an element's own bending against exact integrals and Crisfield's
shallow-arch strain, and what it leaves alone (the tangent at rest, linear analysis). Its
tangents are tested with the elements' (test_kernels_shell3d.py, test_shell_quad.py); the
limit load it gives coarse meshes of a cap, in demos/hinged_sphere.py."""
import numpy as np
import pytest
from numpy.polynomial.legendre import leggauss

from dolfinx_corot.elements import shallow_shell as ss
from dolfinx_corot.elements import shell_quad as lq
from dolfinx_corot.elements import shell_triangle as lt
from dolfinx_corot.kernels import shell3d as k3
from dolfinx_corot.kernels import shell_quad as kq


def _eta(d, sdata, nnode):
    return ss._eta(d, sdata, nnode)[0]


def _exact_mean(points, weights, grad):
    """(½ w,x², ½ w,y², w,x w,y) averaged with the given quadrature."""
    acc = np.zeros(3)
    for (x, y), wt in zip(points, weights):
        gx, gy = grad(x, y)
        acc += wt * np.array([0.5 * gx * gx, 0.5 * gy * gy, gx * gy])
    return acc / np.sum(weights)


def test_triangle_mean_strain_is_exact_for_a_quadratic_deflection():
    """A quadratic w vanishing at the corners (w = Σ c L_i L_j): the DKT's slopes are its gradient,
    and η̄ equals the exact mean of (½w,x², ½w,y², w,x w,y) over the triangle (1e-12)."""
    xy = np.array([[0.1, -0.2], [1.3, 0.1], [0.4, 0.9]])
    sdata = np.empty(ss.size(3))
    lt.shallow_data(xy, lt.isotropic_props(1.0, 0.3, 0.1, 1e-2, True, True, shallow=True), sdata)
    T = np.array([np.ones(3), xy[:, 0], xy[:, 1]])
    dL = np.linalg.inv(T)[:, 1:]  # ∂L_i/∂(x, y)
    c = np.random.default_rng(3).normal(size=3)

    def grad(x, y):
        L = np.linalg.solve(T, [1.0, x, y])
        return (c[0] * (dL[0] * L[1] + L[0] * dL[1]) + c[1] * (dL[1] * L[2] + L[1] * dL[2])
                + c[2] * (dL[2] * L[0] + L[2] * dL[0]))

    d = np.zeros(18)
    for a in range(3):
        gx, gy = grad(*xy[a])
        d[6 * a + 3], d[6 * a + 4] = gy, -gx  # θx = w,y, θy = −w,x
    g, w = leggauss(8)
    g, w = 0.5 * (g + 1), 0.5 * w
    J = np.c_[xy[1] - xy[0], xy[2] - xy[0]]
    pts = [xy[0] + J @ [g[i], g[j] * (1 - g[i])] for i in range(8) for j in range(8)]
    wts = [w[i] * w[j] * (1 - g[i]) for i in range(8) for j in range(8)]
    np.testing.assert_allclose(_eta(d, sdata, 3), _exact_mean(pts, wts, grad), rtol=1e-12, atol=1e-14)


def test_quadrilateral_mean_strain_is_exact_for_a_quadratic_deflection():
    """A quadratic w vanishing at the four corners of a distorted quadrilateral: η̄ of the DKQ's
    slopes equals the exact mean over the cell (1e-12)."""
    xq = np.array([[-1.0, -0.8, 0.0], [1.2, -1.0, 0.0], [0.9, 1.1, 0.0], [-1.1, 0.7, 0.0]])
    sdata = np.empty(ss.size(4))
    lq.shallow_data(xq, lq.isotropic_props(1.0, 0.3, 0.1, 1e-2, shallow=True), sdata)
    M = np.array([[1, x, y, x * x, x * y, y * y] for x, y, _ in xq])
    a = np.random.default_rng(4).normal(size=2) @ np.linalg.svd(M)[2][4:]  # w(corners) = 0

    def grad(x, y):
        return a[1] + 2 * a[3] * x + a[4] * y, a[2] + a[4] * x + 2 * a[5] * y

    d = np.zeros(24)
    for k in range(4):
        gx, gy = grad(*xq[k, :2])
        d[6 * k + 3], d[6 * k + 4] = gy, -gx
    g, w = leggauss(8)
    xy = np.ascontiguousarray(xq[:, :2])
    pts, wts = [], []
    for i in range(8):
        for j in range(8):
            N, _, _, det = lq.shape(xy, g[i], g[j])
            pts.append(N @ xy)
            wts.append(w[i] * w[j] * det)
    np.testing.assert_allclose(_eta(d, sdata, 4), _exact_mean(pts, wts, grad), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("th1, th2", [(0.1, -0.1), (0.1, 0.1), (0.2, -0.05), (0.0, 0.3)])
def test_a_strip_bent_in_one_direction_has_crisfields_shallow_arch_strain(th1, th2):
    """A rectangle l × b whose ends x = ∓l/2 turn by θ₁, θ₂ about y (no deflection at the
    corners): its edges deflect as the cubics of a beam, and η̄_xx is the beams' shallow-arch
    strain (2θ₁² − θ₁θ₂ + 2θ₂²)/30 (Crisfield 1991, §7.2.1), η̄_yy = η̄_xy = 0 (1e-13)."""
    l, b = 2.0, 0.7
    xq = np.array([[-l / 2, -b / 2, 0], [l / 2, -b / 2, 0], [l / 2, b / 2, 0], [-l / 2, b / 2, 0]])
    sdata = np.empty(ss.size(4))
    lq.shallow_data(xq, lq.isotropic_props(1.0, 0.3, 0.1, 1e-2, shallow=True), sdata)
    d = np.zeros(24)
    for k, th in enumerate((th1, th2, th2, th1)):
        d[6 * k + 4] = th
    np.testing.assert_allclose(_eta(d, sdata, 4), [(2 * th1**2 - th1 * th2 + 2 * th2**2) / 30, 0, 0],
                               atol=1e-13)


def test_the_term_is_second_order_and_absent_from_a_linear_analysis():
    """At rest the tangent with the shallow-shell term is the linear law's (the term is quadratic
    in the element's bending), and a geometrically linear analysis ignores it: equal to 1e-12
    for triangles and quadrilaterals."""
    rng = np.random.default_rng(7)
    tri = (k3, 3, lambda s: lt.isotropic_props(2.1e4, 0.3, 0.05, 1e-2, True, True, shallow=s))
    quad = (kq, 4, lambda s: lq.isotropic_props(2.1e4, 0.3, 0.05, 1e-2, shallow=s))
    for kern, n, props in (tri, quad):
        X = np.array([[0.0, 0.0, 0.0], [1.1, 0.1, 0.05], [-0.1, 0.9, 0.1], [1.0, 1.0, 0.0]])[:n]
        rest = np.zeros((n, 7))
        rest[:, 3] = 1.0
        moved = rest.copy()
        moved[:, :3] = 0.05 * rng.normal(size=(n, 3))
        for large, S in ((True, rest), (False, moved)):
            out = []
            for s in (False, True):
                f, K = np.empty(6 * n), np.empty((6 * n, 6 * n))
                kern.evaluate(X, S, props(s), large, f, K)
                out.append((f, K))
            np.testing.assert_allclose(out[1][1], out[0][1], atol=1e-12 * np.abs(out[0][1]).max())
            np.testing.assert_allclose(out[1][0], out[0][0], atol=1e-12 * max(np.abs(out[0][0]).max(), 1.0))


def test_bending_under_membrane_force_adds_the_initial_stress_work():
    """A quadrilateral stretched by ε along x and then bent as the strip above: its end moments
    gain the initial-stress part N l b (4θ₁ − θ₂)/30 of the shallow-arch beam (N = the membrane
    force per length, EA → A11 b), to 1e-10 of the bending moment."""
    l, b, th1, th2, eps = 2.0, 0.7, 1e-3, -2e-3, 1e-3
    xq = np.array([[-l / 2, -b / 2, 0], [l / 2, -b / 2, 0], [l / 2, b / 2, 0], [-l / 2, b / 2, 0]])
    props = lq.isotropic_props(2.1e4, 0.0, 0.05, 1e-2, shallow=True)  # ν = 0: a beam
    sdata = np.empty(ss.size(4))
    lq.shallow_data(xq, props, sdata)
    K = np.empty((24, 24))
    lq.local_stiffness(xq, props, K)
    d = np.zeros(24)
    for k in range(4):
        d[6 * k] = eps * xq[k, 0]
        d[6 * k + 4] = (th1, th2, th2, th1)[k]
    f = np.empty(24)
    ss.force(d, K, sdata, 4, f)
    N = 2.1e4 * 0.05 * (eps + (2 * th1**2 - th1 * th2 + 2 * th2**2) / 30)  # per unit width
    m1 = f[4] + f[6 * 3 + 4]  # the moments of the end x = −l/2
    m_lin = (K @ d)[4] + (K @ d)[6 * 3 + 4]
    np.testing.assert_allclose(m1 - m_lin, N * l * b * (4 * th1 - th2) / 30, rtol=1e-10)


def test_a_shallow_switch_that_is_not_a_boolean_is_refused():
    """``add_shell(..., shallow=...)`` takes True or False; anything else is refused naming the
    shells' group."""
    import dolfinx_corot as dc
    from dolfinx_corot.io.mesh import from_arrays

    pts = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    tm = from_arrays(pts, np.array([[0, 1, 2]]), "plate")
    sc = dc.Scene(large_rotations=True)
    with pytest.raises(ValueError, match="shell 'plate': shallow = 'yes' must be True or False"):
        sc.add_shell(tm, "plate", thickness=0.1, material=dc.Elastic(1.0, 0.3), shallow="yes")

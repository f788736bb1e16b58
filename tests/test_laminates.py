"""Orthotropic and laminated shell sections: lamination theory against its closed forms, the
material axis, a simply supported cross-ply plate against Navier's solution, an unsymmetric
laminate's membrane–bending coupling, and an orthotropic strip in large-deflection cylindrical
bending against the closed form of a strip with immovable edges."""
import numpy as np
import pytest
from scipy.optimize import brentq

import dolfinx_corot as dc
from dolfinx_corot.io.mesh import from_arrays
from dolfinx_corot.parts.base import PartRef
from dolfinx_corot.sections import turned_stiffness

# graphite–epoxy plies as in Pagano (1970) and Reddy (2004, §5.2): E1/E2 = 25
E2 = 1.0e4
GR = dc.Orthotropic(E1=25 * E2, E2=E2, G12=0.5 * E2, nu12=0.25, G13=0.5 * E2, G23=0.2 * E2)


def cross_ply(t, angles):
    return dc.Laminate([dc.Ply(t / len(angles), a, GR) for a in angles])


def _Q():
    nu21 = 0.25 / 25
    d = 1 - 0.25 * nu21
    return np.array([[25 * E2 / d, 0.25 * E2 / d, 0], [0.25 * E2 / d, E2 / d, 0], [0, 0, 0.5 * E2]])


def test_lamination_theory_closed_forms():
    """[0/90]s of four equal plies: A = t(Q11 + Q22)/2 on the diagonal, D11 = (7Q11 + Q22)t³/96,
    D22 = (Q11 + 7Q22)t³/96, B = 0; [0/90]: B11 = −B22 = (Q22 − Q11)t²/8; the quasi-isotropic
    [0/45/−45/90]s has an isotropic A (A11 = A22, A16 = 0, A66 = (A11 − A12)/2) at every
    angle; a ply's turned stiffness from the closed form equals the turned tensor (Jones 1999)."""
    t = 0.1
    Q = _Q()
    A, B, D, S = cross_ply(t, (0, 90, 90, 0)).matrices(0.0)
    np.testing.assert_allclose(np.diag(A[0])[:2], t * (Q[0, 0] + Q[1, 1]) / 2, rtol=1e-13)
    np.testing.assert_allclose(D[0][0, 0], (7 * Q[0, 0] + Q[1, 1]) * t**3 / 96, rtol=1e-13)
    np.testing.assert_allclose(D[0][1, 1], (Q[0, 0] + 7 * Q[1, 1]) * t**3 / 96, rtol=1e-13)
    assert np.abs(B).max() < 1e-12 * np.abs(A).max() * t
    np.testing.assert_allclose(S[0], 5 / 6 * t * np.diag([(0.5 + 0.2) / 2 * E2] * 2), rtol=1e-13, atol=1e-12 * S[0].max())
    B2 = cross_ply(t, (0, 90)).matrices(0.0)[1][0]
    np.testing.assert_allclose([B2[0, 0], B2[1, 1]], [(Q[1, 1] - Q[0, 0]) * t**2 / 8, (Q[0, 0] - Q[1, 1]) * t**2 / 8],
                               rtol=1e-13)
    quasi = cross_ply(t, (0, 45, -45, 90, 90, -45, 45, 0))
    for phi in (0.0, 0.4, 1.3):
        A = quasi.matrices(phi)[0][0]
        assert abs(A[0, 0] - A[1, 1]) < 1e-12 * A[0, 0] and abs(A[0, 2]) < 1e-12 * A[0, 0]
        assert A[2, 2] == pytest.approx((A[0, 0] - A[0, 1]) / 2, rel=1e-12)
    from dolfinx_corot.sections import _turn_tensor
    theta = np.array([0.3, 1.1, -0.7, 2.0])
    np.testing.assert_allclose(turned_stiffness(Q, theta), _turn_tensor(Q, theta), atol=1e-12 * Q.max())


def _plate(a, b, nx, ny, kind, comm=None):
    """A rectangle a × b of nx × ny cells (quadrilaterals, or each cut into two triangles) in the
    plane z = 0; point groups 'edge', 'centre', 'corner' and its neighbours 'x1', 'y1'."""
    X, Y = np.meshgrid(np.linspace(0, a, nx + 1), np.linspace(0, b, ny + 1), indexing="ij")
    pts = np.c_[X.ravel(), Y.ravel(), np.zeros(X.size)]
    idx = lambda i, j: i * (ny + 1) + j  # noqa: E731
    cells = []
    for i in range(nx):
        for j in range(ny):
            q = [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)]
            cells += [q] if kind == "quad" else [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    edge = np.flatnonzero((X.ravel() % a == 0) | (Y.ravel() % b == 0) | np.isclose(X.ravel(), a)
                          | np.isclose(Y.ravel(), b))
    groups = {"edge": edge, "centre": [idx(nx // 2, ny // 2)], "corner": [0], "x1": [idx(nx, 0)], "y1": [idx(0, ny)]}
    kw = {} if comm is None else {"comm": comm}
    return from_arrays(pts, np.array(cells), "plate", groups, **kw)


def navier_centre(D, a, b, q, terms=199):
    """Centre deflection of a simply supported specially orthotropic plate (B = 0, D16 = D26 = 0)
    under a uniform pressure q (Navier's double series; Reddy 2004, eq. 5.2.8)."""
    w = 0.0
    for m in range(1, terms + 1, 2):
        for n in range(1, terms + 1, 2):
            qmn = 16 * q / (np.pi**2 * m * n)
            den = np.pi**4 * (D[0, 0] * (m / a)**4 + 2 * (D[0, 1] + 2 * D[2, 2]) * (m / a)**2 * (n / b)**2
                              + D[1, 1] * (n / b)**4)
            w += qmn / den * np.sin(m * np.pi / 2) * np.sin(n * np.pi / 2)
    return w


@pytest.mark.parametrize("kind", ["quad", "triangle"])
def test_cross_ply_plate_against_navier(kind):
    """A simply supported [0/90/90/0] plate a × 2a, a/t = 100, uniform pressure, geometrically
    linear: the centre deflection within 1 % of Navier's solution with the fibres of the outer
    plies along x, and again with the material axis along y (the solution with D11 and D22
    swapped: the axis reaches every cell). 16 × 32 cells."""
    a, b, t, q = 1.0, 2.0, 0.01, 1e-3
    lam = cross_ply(t, (0, 90, 90, 0))
    for axis, turn in (((1.0, 0.0, 0.0), 0.0), ((0.0, 1.0, 0.0), np.pi / 2)):
        D = lam.matrices(turn)[2][0]
        w_ref = navier_centre(D, a, b, q)
        sc = dc.Scene(large_rotations=False)
        p = sc.add_shell(_plate(a, b, 16, 32, kind), "plate", section=lam, axis=axis)
        sc.fix(p, "edge", dofs=("uz",))
        sc.fix(p, "corner", dofs=("ux", "uy", "rz"))
        sc.fix(p, "x1", dofs=("uy",))
        sc.pressure(p, None, q)
        sc.monitor("w", p, "centre")
        w = dc.solve(sc, dc.LoadControl(steps=1), quiet=True).history.column("w_uz")[-1]
        assert abs(w) == pytest.approx(w_ref, rel=1e-2), (axis, w, w_ref)


@pytest.mark.parametrize("kind", ["quad", "triangle"])
def test_unsymmetric_laminate_curls_under_membrane_force(kind):
    """A free [0/90] plate (held only against rigid motion) under a uniform edge tension Nx: its
    mid-surface strains and curvatures are (ε, κ) = [A B; B D]⁻¹(N, 0) (lamination theory), so
    w = −(κx x² + κy y² + κxy xy)/2 about the held corner; exact on any mesh (constant strain
    and curvature lie in the elements' spaces): 1e-6. Triangles with the CST membrane: nodal
    forces at a free corner are not the OPT's consistent load of a uniform edge traction (which
    carries drilling moments there, from its α_b lumping), so OPT meshes are exact only under
    displacement or consistent loads: a load per length on the edges, ``scene.load(...,
    per_length=...)`` (theory.md; tests/test_loads.py)."""
    a, t, Nx = 1.0, 0.01, 1.0
    lam = cross_ply(t, (0, 90))
    A, B, D, _ = (m[0] for m in lam.matrices(0.0))
    eps_kap = np.linalg.solve(np.block([[A, B], [B, D]]), np.r_[Nx, 0, 0, 0, 0, 0])
    kx, ky, kxy = eps_kap[3:]
    nx = 4
    tm = _plate(a, a, nx, nx, kind)
    sc = dc.Scene(large_rotations=False)
    p = sc.add_shell(tm, "plate", section=lam, axis=(1.0, 0.0, 0.0), membrane="cst" if kind == "triangle" else None)
    sc.fix(p, "corner", dofs=("ux", "uy", "uz"))
    sc.fix(p, "x1", dofs=("uy", "uz"))
    sc.fix(p, "y1", dofs=("uz",))
    # the edge x = a pulled and x = 0 held back by Nx: nodal forces of a uniform line load
    Xn, _ = p.model.nodes()
    for x_edge, sign in ((a, 1.0), (0.0, -1.0)):
        for j, y in enumerate(np.linspace(0, a, nx + 1)):
            name = f"e{int(x_edge)}_{j}"
            node = int(np.argmin(np.linalg.norm(Xn[:, :2] - [x_edge, y], axis=1)))
            tm.add_point_group(name, [[x_edge, y, 0.0]])
            share = 0.5 if j in (0, nx) else 1.0
            sc.load(p, name, force=(sign * Nx * a / nx * share, 0.0, 0.0))
    sc.monitor("w", p, "centre")
    row = dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    X, u = p.model.nodes()
    x, y = X[:, 0], X[:, 1]
    w_exact = -(kx * x * x + ky * y * y + kxy * x * y) / 2
    # the supports fix w at (0, 0), (a, 0), (0, a): remove the plane through them from the exact field
    plane = w_exact[np.argmin(np.hypot(x - a, y))] * x / a + w_exact[np.argmin(np.hypot(x, y - a))] * y / a
    np.testing.assert_allclose(u[:, 2], w_exact - plane, atol=1e-6 * np.abs(w_exact).max())
    assert row.totals["cuts"] == 0


def _strip_closed_form(q, l, D, A):
    """Centre deflection of a strip of span l with immovable simply supported edges under a uniform
    pressure q, in cylindrical bending (von Kármán): D w'''' − S w'' = q with the membrane force S
    from S l / A = ½∫w'² dx; u² = S l²/(4D) (Timoshenko & Woinowsky-Krieger 1959, §3)."""
    x = np.linspace(0.0, l, 4001)

    def w_of(u):
        return (q * l**4 / (16 * u**4 * D) * (np.cosh(u * (1 - 2 * x / l)) / np.cosh(u) - 1)
                + q * l**2 * x * (l - x) / (8 * u**2 * D))

    def mismatch(u):
        w = w_of(u)
        slope = np.gradient(w, x)
        stretch = 0.5 * np.sum(0.5 * (slope[1:] ** 2 + slope[:-1] ** 2) * np.diff(x))
        return 4 * u * u * D / l**2 * l / A - stretch

    u = brentq(mismatch, 1e-3, 50.0)
    return float(w_of(u)[len(x) // 2]), u


@pytest.mark.parametrize("kind", ["quad", "triangle"])
def test_orthotropic_strip_in_large_deflection_cylindrical_bending(kind):
    """A [0/90/0] strip of span l = 1, t = 0.01, edges x = 0, l held (immovable simple supports),
    plane strain across (uy, rx, rz held), under a uniform pressure up to a centre deflection of
    5.2 thicknesses (fibres along the span) and 2.4 (a second run, across it), where the membrane
    force carries most of the load (u = 11 and 12): the centre deflection at every step within
    1 % of the von Kármán closed form with D11 and A11 (measured +0.48 % and +0.13 % on quadrilaterals,
    +0.52 % and +0.14 % on triangles, 32 cells along the span; on 16: +0.57 %, +0.22 %: the rest
    is von Kármán's approximation of the exact kinematics at rotations of 0.15 rad)."""
    l, t = 1.0, 0.01
    lam = dc.Laminate([dc.Ply(t / 4, 0, GR), dc.Ply(t / 2, 90, GR), dc.Ply(t / 4, 0, GR)])
    nx = 32
    for axis, turn, q_end in (((1.0, 0.0, 0.0), 0.0, 4.0), ((0.0, 1.0, 0.0), np.pi / 2, 0.4)):
        A, _, D, _ = (m[0] for m in lam.matrices(turn))
        sc = dc.Scene()
        p = sc.add_shell(_plate(l, l / nx, nx, 1, kind), "plate", section=lam, axis=axis)
        tm = p.model.tmesh
        tm.add_point_group("ends", [[0, 0, 0], [0, l / nx, 0], [l, 0, 0], [l, l / nx, 0]])
        sc.fix(p, "ends", dofs=("ux", "uz"))
        sc.fix(p, "plate", dofs=("uy", "rx", "rz"))
        sc.pressure(p, None, q_end)
        sc.monitor("w", p, "centre")
        res = dc.solve(sc, dc.LoadControl(steps=8), quiet=True)
        lam_f = np.array(res.history.column("load_factor"))
        w = np.abs(np.array(res.history.column("w_uz")))
        ref = np.array([_strip_closed_form(f * q_end, l, D[0, 0], A[0, 0])[0] for f in lam_f])
        np.testing.assert_allclose(w, ref, rtol=1e-2)
        assert ref[-1] > 2.0 * t


def test_the_readme_laminate_example_runs_and_bends_as_a_laminated_strip():
    """The README's laminated cantilever plate (quasi-isotropic carbon lay-up, tip load), run as
    written: its tip deflection lies between those of a strip with the plate stiffness D11 and
    the beam stiffness 1/(D⁻¹)11 per unit width, P L³/(3 b D) (Euler–Bernoulli; the 3 % tip
    rotation changes it by less than 0.1 %); its largest fibre stress is in an outer 0° ply."""
    import contextlib
    import io
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    code = re.search(r"```python\n(.*?)```", text[text.index("A laminated cantilever plate of"):], re.S).group(1)
    out = io.StringIO()
    space = {}
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), space)
    w = space["result"].history.column("tip_uz_mean")[-1]
    assert out.getvalue().startswith("tip deflection")
    D = space["layup"].matrices(0.0)[2][0]
    P, L, b = 10.0, space["L"], space["b"]
    stiff, soft = P * L**3 / (3 * b * D[0, 0]), P * L**3 / (3 * b / np.linalg.inv(D)[0, 0])
    assert stiff < w < soft
    # bending: the fibre stress is largest in the outer 0° plies, at the root
    plies = space["plies"]
    k = np.unravel_index(np.argmax(np.abs(plies["s11"])), plies["s11"].shape)
    assert plies["ply"][k] in (0, 7) and out.getvalue().splitlines()[1].startswith("largest fibre stress")


@pytest.mark.parametrize("kind", ["quad", "triangle", "quad_with_shells"])
def test_orthotropic_membrane_in_uniaxial_tension_off_its_axes(kind):
    """A square membrane of an orthotropic fabric (warp at 30° from x, E1/E2 = 25) pulled by a
    uniform edge tension Nx: its mid-surface strains are A⁻¹(Nx, 0, 0) with A turned by 30°
    (shear coupling included), exactly on any mesh (constant strain), geometrically linear:
    1e-8. On triangles (CST), quadrilaterals (Q4), and quadrilaterals of a mesh that also
    carries shells (the shell's membrane)."""
    a, t, Nx, nx = 1.0, 0.01, 1.0, 4
    angle = np.radians(30.0)
    axis = (np.cos(angle), np.sin(angle), 0.0)
    fabric = dc.Orthotropic(E1=25 * E2, E2=E2, G12=0.5 * E2, nu12=0.25)
    A = dc.Laminate.single(t, fabric).matrices(angle)[0][0]
    exx, eyy, gxy = np.linalg.solve(A, [Nx, 0.0, 0.0])
    tm = _plate(a, a, nx, nx, "triangle" if kind == "triangle" else "quad")
    sc = dc.Scene(large_rotations=False)
    if kind == "quad_with_shells":  # a shell on one cell makes the mesh a four-node shell part
        tm.add_cell_group("corner_cell", lambda x: (x[0] < a / nx) & (x[1] < a / nx))
        tm.add_cell_group("rest", lambda x: ~((x[0] < a / nx) & (x[1] < a / nx)))
        sc.add_shell(tm, "corner_cell", thickness=t, material=fabric, axis=axis)
        p = sc.add_membrane(tm, "rest", thickness=t, material=fabric, axis=axis)
    else:
        p = sc.add_membrane(tm, "plate", thickness=t, material=fabric, axis=axis)
    sc.fix(p, "plate", dofs=("uz",))  # a flat membrane has no stiffness out of its plane
    sc.fix(p, "corner", dofs=("ux", "uy"))
    sc.fix(p, "y1", dofs=("ux",))
    for x_edge, sign in ((a, 1.0), (0.0, -1.0)):
        for j, y in enumerate(np.linspace(0, a, nx + 1)):
            name = f"e{int(x_edge)}_{j}"
            tm.add_point_group(name, [[x_edge, y, 0.0]])
            sc.load(p, name, force=(sign * Nx * a / nx * (0.5 if j in (0, nx) else 1.0), 0.0, 0.0))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    X, u = p.model.nodes()
    x, y = X[:, 0], X[:, 1]
    # u = εx x + (γ/2 − ω) y, v = εy y + (γ/2 + ω) x; the rigid rotation ω is set by u(0, a) = 0
    omega = 0.5 * gxy
    np.testing.assert_allclose(u[:, 0], exx * x + (0.5 * gxy - omega) * y, atol=1e-8 * exx * a)
    np.testing.assert_allclose(u[:, 1], eyy * y + (0.5 * gxy + omega) * x, atol=1e-8 * exx * a)


def test_bad_sections_are_named():
    """An orthotropic section without a material axis, an axis normal to the shell, a section given
    together with a thickness, and a ply of an unknown material: each a clear error naming the part."""
    tm = _plate(1.0, 1.0, 2, 2, "quad")
    lam = cross_ply(0.01, (0, 90, 90, 0))
    with pytest.raises(ValueError, match="shell 'plate'.*orthotropic plies: give the material axis"):
        dc.Scene().add_shell(tm, "plate", section=lam)
    with pytest.raises(ValueError, match="shell 'plate'.*material axis is normal to 4 cell"):
        dc.Scene().add_shell(tm, "plate", section=lam, axis=(0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="membrane 'plate': give either section=dc.Laminate"):
        dc.Scene().add_membrane(tm, "plate", thickness=0.01, section=lam)
    with pytest.raises(TypeError, match="Ply: material must be dc.Orthotropic or dc.Elastic"):
        dc.Ply(0.01, 0.0, "steel")
    with pytest.raises(ValueError, match="Orthotropic: nu12 = 6.0 makes the layer unstable"):
        dc.Orthotropic(E1=1.0, E2=1.0, G12=0.5, nu12=6.0)


def _stretched_and_bent(kind, lam, N, M, axis=(1.0, 0.0, 0.0)):
    """A free square plate of ``lam`` (2 × 2 cells) held against rigid motion, under edge loads N
    (x = 0 and 1) and end moments M per length about y on the same edges (their nodal shares):
    a uniform state of resultants (Nxx, Mxx) = (N, M) in every cell (geometrically linear)."""
    tm = _plate(1.0, 1.0, 2, 2, kind)
    sc = dc.Scene(large_rotations=False)
    p = sc.add_shell(tm, "plate", section=lam, axis=axis, membrane="cst" if kind == "triangle" else None)
    sc.fix(p, "corner", dofs=("ux", "uy", "uz"))
    sc.fix(p, "x1", dofs=("uy", "uz"))
    sc.fix(p, "y1", dofs=("uz",))
    for x_edge, sign in ((1.0, 1.0), (0.0, -1.0)):
        for j, y in enumerate((0.0, 0.5, 1.0)):
            tm.add_point_group(f"e{int(x_edge)}_{j}", [[x_edge, y, 0.0]])
            share = 0.25 if j != 1 else 0.5
            sc.load(p, f"e{int(x_edge)}_{j}", force=(sign * N * share, 0.0, 0.0), moment=(0.0, sign * M * share, 0.0))
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    return sc, p


@pytest.mark.parametrize("kind", ["quad", "triangle"])
@pytest.mark.parametrize("angles", [(0, 90, 90, 0), (45, -45, -45, 45), (0, 90)])
def test_ply_stresses_follow_lamination_theory(kind, angles):
    """Stresses in the plies of a laminate under a membrane force Nxx = 1 and a moment Mxx = 10⁻³
    per length (a free plate, every cell in the same state): in each ply's axes, at the bottom
    and top of each ply, those of classical lamination theory (Jones 1999, §4.2–4.3): (ε, κ) =
    [A B; B D]⁻¹(N, M), σ_xy = Q̄ₖ(ε + zκ), σ₁₂ = T(θₖ)σ_xy — for the symmetric cross-ply
    [0/90]s, the angle-ply [45/−45]s (shear in the plies' axes) and the unsymmetric [0/90] (B ≠ 0),
    to 1e-8 of the largest; through the thickness they add up to N and M (1e-10)."""
    t, N, M = 0.01, 1.0, 1e-3
    lam = cross_ply(t, angles)
    sc, p = _stretched_and_bent(kind, lam, N, M)
    r = sc.ply_stresses(p)
    assert r.values.shape == (len(r.cells), 2 * len(angles), 5)
    A, B, D, _ = (m[0] for m in lam.matrices(0.0))
    eps_kap = np.linalg.solve(np.block([[A, B], [B, D]]), [N, 0, 0, M, 0, 0])
    z = -t / 2 + np.arange(len(angles) + 1) * t / len(angles)
    for k, angle in enumerate(angles):
        th = np.radians(angle)
        c, s = np.cos(th), np.sin(th)
        T = np.array([[c * c, s * s, 2 * c * s], [s * s, c * c, -2 * c * s], [-c * s, c * s, c * c - s * s]])
        Qbar = turned_stiffness(lam.plies[k].stiffness()[0], np.array([th]))[0]
        for side, height in enumerate((z[k], z[k + 1])):
            expected = T @ Qbar @ (eps_kap[:3] + height * eps_kap[3:])
            got = r.values[:, 2 * k + side, :3]
            np.testing.assert_allclose(got, np.broadcast_to(expected, got.shape), atol=1e-8 * 1e3 * N / t)
            np.testing.assert_allclose(r.values[:, 2 * k + side, 3:], [[height, k]] * len(r.cells), atol=1e-15)
    # through the thickness (linear in z in each ply): σx integrates to N, σx·z to M
    sx = []
    for k, angle in enumerate(angles):
        th = np.radians(angle)
        c, s = np.cos(th), np.sin(th)
        s11, s22, s12 = (r.values[0, 2 * k:2 * k + 2, j] for j in range(3))
        sx.append(c * c * s11 + s * s * s22 - 2 * c * s * s12)  # back to x
    h = t / len(angles)
    Nx = sum(0.5 * h * (a + b) for a, b in sx)
    Mx = sum(h / 6 * (a * (2 * z[k] + z[k + 1]) + b * (z[k] + 2 * z[k + 1])) for k, (a, b) in enumerate(sx))
    assert Nx == pytest.approx(N, rel=1e-10) and Mx == pytest.approx(M, rel=1e-8)


def test_ply_stresses_of_one_isotropic_layer_are_the_face_stresses():
    """One isotropic layer: its ply stresses at the faces are the element results' face stresses
    σ = N/t ± 6M/t² (1e-10)."""
    t = 0.01
    lam = dc.Laminate.single(t, dc.Elastic(2e5, 0.3))
    sc, p = _stretched_and_bent("quad", lam, 1.0, 1e-3, axis=None)
    plies, faces = sc.ply_stresses(p), sc.element_results(p)
    np.testing.assert_allclose(plies["s11"][:, 0], faces["sxx_bottom"][:, 0], rtol=1e-10)
    np.testing.assert_allclose(plies["s11"][:, 1], faces["sxx_top"][:, 0], rtol=1e-10)
    np.testing.assert_allclose(plies["s22"][:, 1], faces["syy_top"][:, 0], atol=1e-10 * abs(faces["sxx_top"]).max())


def test_ply_stresses_are_refused_for_membranes_and_mixed_sections():
    """Membranes have no plies to report (N/t), and cells of two sections need a group each."""
    tm = _plate(1.0, 1.0, 2, 2, "triangle")
    tm.add_cell_group("left", lambda x: x[0] < 0.5)
    tm.add_cell_group("right", lambda x: x[0] > 0.5)
    sc = dc.Scene(large_rotations=False)
    thin, thick = cross_ply(0.01, (0, 90, 90, 0)), cross_ply(0.02, (0, 90, 90, 0))
    left = sc.add_shell(tm, "left", section=thin, axis=(1.0, 0.0, 0.0))
    sc.add_shell(tm, "right", section=thick, axis=(1.0, 0.0, 0.0))
    sc.fix(left, "edge")
    dc.solve(sc, dc.LoadControl(steps=1), quiet=True)
    assert sc.ply_stresses(left).values.shape[1] == 8
    both = PartRef(left.model, "plate", "shell")  # the cells of both sections
    with pytest.raises(ValueError, match="different sections"):
        sc.ply_stresses(both)
    tm2 = _plate(1.0, 1.0, 2, 2, "quad")
    sc2 = dc.Scene(large_rotations=False)
    m = sc2.add_membrane(tm2, "plate", thickness=0.01, material=dc.Elastic(1e6, 0.3))
    with pytest.raises(ValueError, match="give shells"):
        sc2.ply_stresses(m)

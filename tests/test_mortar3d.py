"""Mortar (segment-to-segment) contact in 3D: the face-pair kernel against closed forms (overlap
areas of squares, consistent nodal forces, conservation of momentum), its complex-step tangent
against central differences, and the 3D contact patch test on non-matching faces (Puso & Laursen
2004): the homogeneous uniaxial state u_z = −p z/E, u_x = ν p x/E, u_y = ν p y/E to round-off."""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.contact import mortar3d
from fd import free_part, tangent_and_fd
from test_contact3d import E, NU, P, _errors, _nodal, _patch_scene, _two_blocks

comm = MPI.COMM_WORLD
EPS = 100.0

UNIT = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])  # normal +z


def _master(corners, z):
    """A master face at height z facing down (outward −z: clockwise seen from above)."""
    return np.column_stack([np.asarray(corners, float)[::-1], np.full(len(corners), z)])


def _pair(slave, master, lam=0.0, off=0.0, band=False, tangent=True, touch=0.0):
    ks, km = len(slave), len(master)
    x = np.vstack([slave, master])
    f = np.zeros(3 * (ks + km))
    K = np.zeros((3 * (ks + km), 3 * (ks + km)))
    nodal = np.zeros((ks, 3))
    closed = mortar3d.segment_to_segment(x, ks, km, np.full(ks, lam), np.full(ks, off), EPS, touch, band, tangent,
                                         f, K, nodal)
    return f.reshape(-1, 3), K, nodal, closed


@pytest.mark.parametrize("master, area", [
    ([[0.3, 0.2], [1.5, 0.2], [1.5, 1.3], [0.3, 1.3]], 0.7 * 0.8),       # a corner overlap: 0.7 × 0.8
    ([[0.5, 0.0], [1.0, 0.5], [0.5, 1.0], [0.0, 0.5]], 0.5),             # the inscribed diamond
    ([[-1.0, -1.0], [3.0, -1.0], [-1.0, 3.0]], 1.0),                     # a triangle covering the square
])
def test_a_face_pair_integrates_the_pressure_over_the_exact_overlap(master, area):
    """A slave square (and the same square as two triangles) under a master face a depth d below
    its plane: ∫dA over the overlap is the overlap's area, the pressure ε d is uniform and the
    forces on the two sides are equal and opposite, their sum ε d × area. (To 1e-10: the clipping
    counts points within 1e-11 of an edge's length outside it as on it.)"""
    d = 0.01
    for slaves in ([UNIT], [UNIT[[0, 1, 2]], UNIT[[0, 2, 3]]]):
        total_area, total_force, gap = 0.0, np.zeros(3), 0.0
        for s in slaves:
            f, _, nodal, _ = _pair(s, _master(master, -d), tangent=False)
            ks = len(s)
            assert np.abs(f.sum(axis=0)).max() < 1e-15
            total_area += nodal[:, 1].sum()
            total_force += f[:ks].sum(axis=0)
            gap += nodal[:, 0].sum()
        assert total_area == pytest.approx(area, rel=1e-10)
        assert total_force == pytest.approx([0.0, 0.0, EPS * d * area], rel=1e-10, abs=1e-15)
        assert gap == pytest.approx(-d * area, rel=1e-10)


def test_a_uniform_pressure_gives_both_faces_their_consistent_nodal_forces():
    """A master square [¼, ¾]² inside the slave's unit square: each master node takes a quarter of
    the force, ε d/16; the slave's bilinear nodes take ∫N_A dA over the central square, also a
    quarter each by symmetry; with a multiplier λ and no penetration the pressure is λ."""
    d = 0.02
    f, _, nodal, closed = _pair(UNIT, _master([[0.25, 0.25], [0.75, 0.25], [0.75, 0.75], [0.25, 0.75]], -d),
                                tangent=False)
    assert closed > 0
    assert f[:4, 2] == pytest.approx(np.full(4, EPS * d / 16.0), rel=1e-10)
    assert f[4:, 2] == pytest.approx(np.full(4, -EPS * d / 16.0), rel=1e-10)
    f, _, nodal, _ = _pair(UNIT, _master([[0.25, 0.25], [0.75, 0.25], [0.75, 0.75], [0.25, 0.75]], 0.0), lam=3.0,
                           tangent=False)
    assert nodal[:, 2] == pytest.approx(3.0 * nodal[:, 1], rel=1e-12)


def _random_pair(ks, km, warp, seed):
    rng = np.random.default_rng(seed)
    slave = UNIT[:ks] if ks == 4 else UNIT[[0, 1, 3]]
    corners = [[0.2, -0.1], [1.2, 0.1], [1.1, 1.2], [-0.1, 0.9]] if km == 4 else [[-0.2, 0.1], [1.1, -0.1], [0.2, 1.1]]
    master = _master(corners, -0.1)
    x = np.vstack([slave, master]) + 0.03 * rng.standard_normal((ks + km, 3))
    if warp:  # lift one corner of each quadrilateral out of its plane
        x[ks - 1, 2] += 0.1 * warp
        x[-1, 2] -= 0.1 * warp
    # a rotation of the whole pair, so that no axis is special
    q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    q *= np.sign(np.linalg.det(q))  # (a rotation, not a reflection)
    return x @ q.T


@pytest.mark.parametrize("ks, km, warp", [(3, 3, 0), (3, 4, 0), (4, 3, 0), (4, 4, 0), (4, 4, 1)])
def test_mortar_kernel_tangent_matches_finite_differences_and_conserves_momentum(ks, km, warp):
    """The pair's complex-step tangent against central differences of its forces (step 1e-7; 1e-6
    of the largest entry) for triangles and (warped) quadrilaterals on either side, rotated and
    perturbed, with multipliers; the forces sum to zero and have no moment (each point's pair of
    forces acts along the line joining the two points)."""
    x = _random_pair(ks, km, warp, seed=ks + 2 * km + warp)
    slave, master = x[:ks], x[ks:]
    f, K, nodal, closed = _pair(slave, master, lam=0.5)
    assert closed > 0 and nodal[:, 1].sum() > 0.3
    assert np.abs(f.sum(axis=0)).max() < 1e-13
    assert np.abs(np.cross(x, f).sum(axis=0)).max() < 1e-13
    h = 1e-7
    Kfd = np.zeros_like(K)
    for j in range(3 * (ks + km)):
        pm = []
        for sign in (1.0, -1.0):
            y = x.copy()
            y.flat[j] += sign * h
            pm.append(_pair(y[:ks], y[ks:], lam=0.5, tangent=False)[0].ravel())
        Kfd[:, j] = (pm[0] - pm[1]) / (2 * h)
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()


def test_faces_that_do_not_face_each_other_or_touch_only_within_the_band():
    """No contribution from a master face whose normal is not against the slave's (a face of the
    far side); a face open by less than the touch band adds no force but, with the band, the
    penalty's linearization (ε ∫ N_A N_B dA along n: positive on the slave's normal dofs)."""
    f, K, nodal, closed = _pair(UNIT, UNIT + [0.0, 0.0, -0.01])  # same orientation: not facing
    assert closed == 0 and not f.any() and not K.any() and not nodal.any()
    master = _master([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], 1e-4)
    f, K, _, closed = _pair(UNIT, master, touch=1e-3, band=True)
    assert closed == 0 and not f.any()
    assert np.all(np.diag(K)[2:12:3] > 0.0) and np.abs(K).max() == pytest.approx(EPS / 9.0, rel=1e-9)
    f, K, _, _ = _pair(UNIT, master, touch=1e-3, band=False)
    assert not f.any() and not K.any()


@pytest.mark.parametrize("symmetric", [False, True])
def test_mortar_contact_passes_the_3d_patch_test_on_non_matching_faces(symmetric):
    """The 3D contact patch test (Puso & Laursen 2004, §5.1): two blocks pressed by p through a flat
    interface meshed independently (tetrahedra of 0.26 and 0.35, faces of different sizes and
    orientations). One- and two-pass mortar contact with the augmented Lagrangian reproduce the
    homogeneous state to 1e-10 p/E (measured 1.3e-12 and 3.9e-13 after one Uzawa update), the
    resultant is P to 1e-10 (Newton's tolerance: 1e-9 of the force scale) and the interface
    pressure P at every node to 1e-9 — node-to-face
    contact stops at 8.3e-5 p/E on these meshes (test_contact3d)."""
    sc, b, pair = _patch_scene(dc.AugmentedLagrangian(gap_tolerance=1e-9), symmetric=symmetric,
                               discretization="mortar")
    row = dc.solve(sc, dc.LoadControl(steps=1)).history.rows[-1]
    assert row["cuts"] == 0 and 1 <= row["uzawa_updates"] <= 3
    assert row["c_Fz"] == pytest.approx(P, rel=1e-10)
    low, upper, shift = _errors(b)
    assert low < 1e-10 and upper < 1e-10 and np.abs(shift).max() < 1e-10 * P / E
    for side in ("slaves", "masters"):
        p = pair.pressure(side)
        assert np.abs(p.pressure - P).max() < 1e-9 * P


def test_mortar_penalty_is_exact_up_to_a_uniform_penetration():
    """With the penalty alone the mortar interface transmits a uniform pressure: the upper block is
    the homogeneous state shifted down by the penetration p/ε (the overlap measured on the current,
    laterally stretched, faces: p/(ε (1 + ν p/E)²)), to 1e-9 p/E (Newton's tolerance)."""
    sc, b, pair = _patch_scene(dc.Penalty(), symmetric=False, discretization="mortar")
    dc.solve(sc, dc.LoadControl(steps=1))
    low, upper, shift = _errors(b)
    eps = sc.interfaces[0].penalty
    assert upper < 1e-9
    assert shift[2] == pytest.approx(-P / (eps * (1.0 + NU * P / E) ** 2), rel=1e-8)


@pytest.mark.skipif(comm.size > 1, reason="dense finite differences of the assembled system: serial")
@pytest.mark.parametrize("symmetric", [False, True])
def test_assembled_mortar_tangent_matches_finite_differences(symmetric):
    """The system's tangent with mortar contact (one- and two-pass; not symmetric, solved by LU)
    against central differences of its residual at a penetrating, sheared, randomly perturbed
    state with multipliers: 1e-6 of the largest entry."""
    from dolfinx_corot.assembly import make_system

    sc, b, pair = _patch_scene(dc.AugmentedLagrangian(), symmetric, discretization="mortar")
    for itf in sc.interfaces:
        itf.multiplier[:] = 0.3 * P
    system = make_system(sc.model, contributions=sc.contributions(), solver=sc.linear_solver)
    assert not system.contributions[0].symmetric_tangent
    for itf in sc.interfaces:  # no touch band (a stiffness without a force, by design not the derivative)
        itf.closed_before = True
    model = sc.model
    X = model.V.tabulate_dof_coordinates()
    u = model.state.x.array.reshape(-1, 3)
    rng = np.random.default_rng(5)
    u[:, 2] = np.where(X[:, 2] > 0.5 - 1e-12, -0.02, 0.0)
    u[:, 0] = 0.01 * X[:, 2] ** 2
    u += rng.uniform(-1e-3, 1e-3, u.shape)
    K, Kfd = free_part(system, *tangent_and_fd(system, model.state.x.array, 1.0))
    assert np.abs(K - K.T).max() > 1e-6 * np.abs(K).max()  # (not symmetric)
    assert np.abs(K - Kfd).max() < 1e-6 * np.abs(K).max()
    system.destroy()


def test_mortar_input_is_checked_by_name():
    """Refused by name: an unknown discretization, mortar in 2D, mortar with a shell's surface."""
    from dolfinx_corot.io.gmsh_models import polyline
    from test_contact3d_structures import _plate

    tm = _two_blocks(0.5, 0.5)
    sc = dc.Scene(large_rotations=False)
    b = sc.add_solid(tm, material=dc.Elastic(E, NU), degree=1)
    with pytest.raises(ValueError, match="discretization = 'nts' must be 'node_to_face' or 'mortar'"):
        sc.contact((b, "upper_face"), (b, "lower_face"), discretization="nts")
    plate = sc.add_shell(_plate(2, 1.2, False), "plate", thickness=0.05, material=dc.Elastic(E, NU))
    with pytest.raises(dc.ContactError, match="mortar contact: the slaves 'plate' of shell 'plate' are not faces of "
                                              "a solid"):
        sc.contact((plate, "plate"), (b, "upper_face"), discretization="mortar")
    sc2 = dc.Scene(large_rotations=False)
    beam = sc2.add_beam(polyline([[0.0, 0.0], [1.0, 0.0]], 2, line_name="beam"), "beam",
                        section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(E, NU))
    with pytest.raises(dc.ContactError, match="the mortar discretization is 3D only"):
        sc2.contact((beam, "beam"), (beam, "beam"), discretization="mortar")


class _Killed(Exception):
    pass


def test_a_mortar_run_restarted_from_its_checkpoint_continues_exactly(tmp_path):
    """State contract: a two-pass mortar run killed after step 2 of 3 and restarted from its file
    (multipliers at the slave nodes, candidate face pairs of every rank) ends where the
    uninterrupted run does: the step after the restart takes the same Newton iterations, Uzawa
    updates and cuts, and the displacements agree to 1e-8 p/E (on 2 ranks each run partitions
    its own mesh, and round-off changes the first step's iterations by a few: the steps before
    the restart are the killed run's)."""
    def on_step(row):
        if row["step"] == 2:
            raise _Killed

    law = dc.AugmentedLagrangian(gap_tolerance=1e-9)
    path = comm.bcast(str(tmp_path / "mortar.npz") if comm.rank == 0 else None, root=0)
    full_scene, b_full, _ = _patch_scene(law, discretization="mortar")
    full = dc.solve(full_scene, dc.LoadControl(steps=3))
    killed_scene, _, _ = _patch_scene(law, discretization="mortar")
    with pytest.raises(_Killed):
        dc.solve(killed_scene, dc.LoadControl(steps=3), checkpoint=path, on_step=on_step)
    assert max(np.abs(itf.multiplier).max() for itf in killed_scene.interfaces) > 0.1 * P
    resumed_scene, b_resumed, _ = _patch_scene(law, discretization="mortar")
    resumed = dc.solve(resumed_scene, dc.LoadControl(steps=3), restart=path)
    for col in ("iterations", "uzawa_updates", "cuts"):
        np.testing.assert_array_equal(resumed.history.column(col)[2:], full.history.column(col)[2:], err_msg=col)
    a, b = _nodal(b_full), _nodal(b_resumed)
    assert max(np.abs(b[p] - u).max() for p, u in a.items()) < 1e-8 * P / E

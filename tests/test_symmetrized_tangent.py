"""The symmetric part of the co-rotational tangent of 3D beams and shells.

The consistent tangent with respect to spatial spins has the skew part −½ spin(m_a) on each
node's rotations, m_a the node's unbalanced moment sum (the bracket of the rotation group;
Simo & Vu-Quoc 1986; Nour-Omid & Rankin 1991). At equilibrium it vanishes on the free
rotations unless a moment is applied there or a node has exactly one rotation held. Checked
here: that formula on converged states, the cases 'auto' keeps the consistent tangent for,
and that the symmetric part follows the path of the consistent tangent (iterations, answer).
"""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.assembly import make_system
from dolfinx_corot.io.gmsh_models import cylinder_eighth
from dolfinx_corot.io.mesh import from_arrays

comm = MPI.COMM_WORLD
E, NU, L, N = 2.0e5, 0.3, 10.0, 12


def _cantilever(tangent="auto", moment=None, held=None, follower=False, large=True):
    """A straight cantilever along x (N beams, 0.2 × 0.3 section), clamped at x = 0, bent in y
    and z by a tip force (follower: by a uniform load turning with the elements) and a tip
    ``moment`` if given; with ``held``, a span pinned at x = 0 with only those rotations held
    there, its tip on rollers, loaded at mid-span."""
    x = np.linspace(0.0, L, N + 1)
    tm = from_arrays(np.c_[x, np.zeros(N + 1), np.zeros(N + 1)], np.c_[np.arange(N), np.arange(1, N + 1)],
                     "beam", {"base": np.array([0]), "tip": np.array([N]), "mid": np.array([N // 2])}, comm=comm)
    sc = dc.Scene(large_rotations=large, tangent=tangent)
    beam = sc.add_beam(tm, "beam", section=dc.Rectangle(0.2, 0.3), material=dc.Elastic(E, NU),
                       orientation=(0.0, 0.0, 1.0))
    if held is None:
        sc.fix(beam, "base")
    else:
        sc.fix(beam, "base", dofs=("ux", "uy", "uz") + held)
        sc.fix(beam, "tip", dofs=("uy", "uz"))  # a simply supported span: the base's rotations turn it
        sc.monitor_reaction("base", beam, "base")
    F = 3.0 * E * 0.2 * 0.3**3 / 12 / L**2
    if follower:  # a uniform load turning with the elements
        sc.load(beam, None, per_length=(0.0, F / L, 0.5 * F / L), axes="element", follower=True)
    elif held is None:
        sc.load(beam, "tip", force=(0.0, F, 0.5 * F))
    else:
        sc.load(beam, "mid", force=(0.0, 20 * F, 10 * F))
    if moment is not None:
        sc.load(beam, "tip", moment=moment)
    sc.monitor("tip", beam, "tip")
    sc.monitor("mid", beam, "mid")
    return sc


def _solved_skew(sc, steps=6):
    """Solve with the consistent tangent: the converged tangent's skew part on the free dofs
    (dense, serial), max |K| and the result."""
    system = make_system(sc.model, solver="direct", tangent="consistent")
    try:
        res = dc.solve(sc, dc.LoadControl(steps=steps), system=system, quiet=True)
        system.residual(1.0)
        system.jacobian()
        K = system.A.convert("dense").getDenseArray().copy()
        fixed = np.concatenate([bc.dof_indices()[0] for bc in system.bcs])
    finally:
        system.destroy()
    free = np.setdiff1d(np.arange(len(K)), fixed)
    skew = np.zeros_like(K)
    skew[np.ix_(free, free)] = 0.5 * (K - K.T)[np.ix_(free, free)]
    return skew, np.abs(K).max(), res


@pytest.mark.skipif(comm.size > 1, reason="dense tangents of the assembled system: serial")
def test_the_skew_part_is_half_the_spin_of_the_nodal_moments_at_equilibrium():
    """Converged cantilevers, consistent tangent: (a) under a tip force the skew part of K on
    the free dofs is round-off (1e-9 of K); (b) with a tip moment m as well it is −½ spin(m) on
    the tip's rotations (to 1e-8), and nothing elsewhere (1e-6 of m);
    (c) a span pinned with only rx held at its base: the reaction moment m_x couples the two
    free rotations there by ½ m_x (to 1e-8), and nothing else."""
    skew, scale, _ = _solved_skew(_cantilever())
    assert np.abs(skew).max() < 1e-9 * scale
    m = np.array([0.3, -0.2, 0.4]) * E * 0.2 * 0.3**3 / 12 / L
    skew, scale, _ = _solved_skew(_cantilever(moment=tuple(m)))
    tip = 6 * N + 3  # the tip's rotation dofs
    block = skew[tip:tip + 3, tip:tip + 3]
    spin = np.array([[0.0, -m[2], m[1]], [m[2], 0.0, -m[0]], [-m[1], m[0], 0.0]])
    assert np.allclose(block, -0.5 * spin, rtol=1e-8, atol=1e-12 * scale)
    rest = skew.copy()
    rest[tip:tip + 3, tip:tip + 3] = 0.0
    assert np.abs(rest).max() < 1e-6 * np.abs(m).max()
    sc = _cantilever(held=("rx",))
    skew, scale, res = _solved_skew(sc)
    mx = res.history.column("base_Mx")[-1]  # the reaction moment about x
    base = skew[3:6, 3:6]
    assert abs(mx) > 1e-6 * scale  # far above round-off
    assert np.allclose(np.abs(base), 0.5 * abs(mx) * np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0]]), rtol=1e-8)
    rest = skew.copy()
    rest[3:6, 3:6] = 0.0
    assert np.abs(rest).max() < 1e-6 * abs(mx)


@pytest.mark.parametrize("case, reasons", [
    ({}, []),
    ({"moment": (0.0, 0.0, 1.0)}, ["applied moments"]),
    ({"held": ("rx",)}, ["nodes with one of their three rotations held"]),
    ({"held": ("rx", "ry")}, []),
    ({"follower": True}, ["follower loads"]),
    ({"large": False, "moment": (0.0, 0.0, 1.0), "held": ("rx",)}, []),
])
def test_auto_symmetrizes_where_the_skew_part_vanishes_at_equilibrium(case, reasons):
    """'auto' asks for the symmetric part (LDLᵀ, which counts the negative eigenvalues) exactly
    where skew_at_equilibrium finds nothing (a system large enough to leave the dense path); a
    geometrically linear analysis, whose K is symmetric as it is, whatever its loads and supports
    (follower loads aside)."""
    from dolfinx_corot.assembly import petsc as petsc_layer

    limit = petsc_layer.DENSE_LIMIT
    petsc_layer.DENSE_LIMIT = 0
    try:
        sc = _cantilever(**case)
        system = make_system(sc.model, solver="direct", contributions=sc.contributions(), tangent="auto")
        try:
            assert system.skew_at_equilibrium() == reasons
            assert system.symmetrized == (not reasons)
            assert system.counts_inertia == (not reasons)
            system.residual(1.0)  # one Newton correction: a state off equilibrium
            system.jacobian()
            system.solve()
            system.update()
            system.residual(1.0)
            system.jacobian()
            assert system.A.isSymmetric(1e-10) == (not reasons)
        finally:
            system.destroy()
    finally:
        petsc_layer.DENSE_LIMIT = limit


def test_a_tangent_that_cannot_be_symmetrized_is_refused():
    """tangent='symmetrized' with follower loads (their load stiffness stays skew at equilibrium)
    is an error naming them; an unknown choice is refused by the scene."""
    sc = _cantilever(follower=True)
    with pytest.raises(ValueError, match="follower loads"):
        make_system(sc.model, solver="direct", contributions=sc.contributions(), tangent="symmetrized")
    with pytest.raises(ValueError, match="tangent"):
        dc.Scene(tangent="symmetric")


def _pullout(tangent, nt=8, nx=12, steps=30):
    """The pull-out of an open cylinder (seed §2.4.1) on a coarse mesh, to w_A = 3 in 30 steps."""
    R, Lc, t = 4.953, 10.35, 0.094
    sc = dc.Scene(tangent=tangent)
    shell = sc.add_shell(cylinder_eighth(R, Lc, nt, nx, comm=comm), "shell", thickness=t,
                         material=dc.Elastic(10.5e6, 0.3125))
    sc.fix(shell, "mid", dofs=("ux", "ry", "rz"))
    sc.fix(shell, "top", dofs=("uy", "rx", "rz"))
    sc.fix(shell, "side", dofs=("uz", "rx", "ry"))
    sc.prescribe(shell, "A", uz=3.0)
    sc.monitor_reaction("A", shell, "A")
    sc.monitor("B", shell, "B")
    system = make_system(sc.model, solver="direct", tangent=tangent)
    try:
        res = dc.solve(sc, dc.LoadControl(steps=steps), system=system, quiet=True)
        retries = system.consistent_retries
        symmetrized = system.symmetrized
    finally:
        system.destroy()
    return res, retries, symmetrized


def test_the_symmetric_part_follows_the_path_of_the_consistent_tangent():
    """The coarse pull-out, 30 steps: with the symmetric part (LDLᵀ) the same iterations as with
    the consistent tangent in every step but the one where the cylinder's edge turns hardest
    (w_A ≈ 2.5), which fails with the symmetric part and is taken again, uncut, with the
    consistent tangent; the same path to 1e-8 (P and w_B at every step), the same number of
    negative eigenvalues (none: the path is stable)."""
    sym, retries, symmetrized = _pullout("auto")
    lu, _, _ = _pullout("consistent")
    assert symmetrized and retries == 1
    assert sym.totals["cuts"] == lu.totals["cuts"] == 0
    its_s, its_c = sym.history.column("iterations"), lu.history.column("iterations")
    assert np.sum(its_s != its_c) <= 1
    for col in ("A_Fz", "B_uz"):
        a, b = sym.history.column(col), lu.history.column(col)
        assert np.abs(a - b).max() <= 1e-8 * np.abs(b).max()
    assert np.all(sym.history.column("negative_eigenvalues") == 0)
    assert np.all(lu.history.column("negative_eigenvalues") == 0)

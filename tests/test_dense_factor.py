"""The dense direct solver of small serial LU systems (LAPACK) against numpy and against MUMPS.

References: Sylvester's law of inertia (the negative eigenvalues of K are those of Bunch–Kaufman's
block-diagonal D), the sign of det K from LU; the 45° bend (Bathe & Bolourchi 1979) solved with
MUMPS, the solver the dense one stands in for.
"""
import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx_corot as dc
import dolfinx_corot.assembly.petsc as petsc_layer
from dolfinx_corot.assembly.petsc import DenseFactor
from dolfinx_corot.io.mesh import from_arrays


def _matrix(K: np.ndarray) -> PETSc.Mat:
    n = len(K)
    A = PETSc.Mat().createDense([n, n], comm=MPI.COMM_SELF)
    A.setUp()
    rows = np.arange(n, dtype=PETSc.IntType)
    A.setValues(rows, rows, K.ravel())
    A.assemble()
    return A.convert("aij")


def test_inertia_sign_and_solution_of_random_matrices():
    """Symmetric indefinite matrices (with 2 × 2 pivots, several in a row), definite ones, and
    matrices with zero diagonal entries: the count of negative eigenvalues, the sign of the
    determinant and the solution equal numpy's."""
    rng = np.random.default_rng(1)
    for trial in range(300):
        n = int(rng.integers(1, 40))
        M = rng.normal(size=(n, n))
        K = M + M.T
        if trial % 5 == 0:
            K = M @ M.T + 1e-3 * np.eye(n)
        if trial % 7 == 0:  # zero diagonal: Bunch–Kaufman must pivot in 2 × 2 blocks
            K = np.kron(np.eye((n + 1) // 2), [[0.0, 1.0], [1.0, 0.0]])[:n, :n] + 0.1 * np.diag(rng.normal(size=n))
        f = DenseFactor(_matrix(K))
        f.factorize(True)
        eigenvalues = np.linalg.eigvalsh(K)
        assert f.negative == int(np.sum(eigenvalues < 0.0)) and f.null_pivots == 0, trial
        f.factorize(False)
        assert f.sign == np.sign(np.linalg.det(K)), trial
        b = PETSc.Vec().createSeq(n)
        b.array[:] = rng.normal(size=n)
        x = b.duplicate()
        f.solve(b, x)
        assert np.linalg.norm(K @ x.array - b.array) <= 1e-9 * np.linalg.norm(K) * np.linalg.norm(x.array)


def test_band_lu_equals_the_dense_lu():
    """Band matrices (the tangents of chains numbered along them) go to LAPACK's band LU: the sign
    of the determinant, the null pivots and the solution equal numpy's and the dense LU's, with
    pivoting needed (zero diagonal entries) and without, and for unequal bandwidths."""
    rng = np.random.default_rng(3)
    banded = 0
    for trial in range(200):
        n = int(rng.integers(8, 60))
        pivoting = trial % 3 == 0  # (a zero diagonal needs a band off the diagonal to stay regular)
        kl, ku = int(rng.integers(pivoting, 4)), int(rng.integers(pivoting, 4))
        i, j = np.indices((n, n))
        K = np.where((i - j <= kl) & (j - i <= ku), rng.normal(size=(n, n)), 0.0)
        if pivoting:
            K[np.arange(0, n, 3), np.arange(0, n, 3)] = 0.0
        if not pivoting:
            K += 4.0 * np.sign(rng.normal(size=n)) * np.eye(n)  # regular, either sign on the diagonal
        elif abs(np.linalg.slogdet(K)[1]) > 100.0:
            continue  # (a zero diagonal with a narrow band may be singular)
        f, g = DenseFactor(_matrix(K)), DenseFactor(_matrix(K))
        g.band = False
        f.factorize(False)
        g.factorize(False)
        banded += f._band is not None and g._band is None
        assert f.sign == g.sign == np.sign(np.linalg.det(K)) and f.null_pivots == g.null_pivots == 0, trial
        b = PETSc.Vec().createSeq(n)
        b.array[:] = rng.normal(size=n)
        x = b.duplicate()
        f.solve(b, x)
        assert np.linalg.norm(K @ x.array - b.array) <= 1e-9 * np.linalg.norm(K) * np.linalg.norm(x.array), trial
    assert banded >= 150
    # a singular band (a free chain of three bars): one null pivot, as the dense LU finds
    chain = np.diag([1.0, 2.0, 2.0, 2.0, 2.0, 2.0, 1.0]) - np.eye(7, k=1) - np.eye(7, k=-1)
    f = DenseFactor(_matrix(chain))
    f.factorize(False)
    assert f._band == (1, 1) and f.null_pivots == 1


@pytest.mark.parametrize("scale", [1.0, 1e9])
def test_a_singular_matrix_has_a_null_pivot(scale):
    """A free bar (a rigid translation) whatever the stiffness's units: one null pivot both ways."""
    f = DenseFactor(_matrix(scale * np.array([[1.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])))
    for ldlt in (True, False):
        f.factorize(ldlt)
        assert f.null_pivots == 1


def _bend(tangent: str = "consistent"):
    """The 45° bend, 8 co-rotational 3D beams, 20 steps (54 dofs); the consistent tangent (LU) by
    default, which is what the dense path factorizes."""
    R, E, nu = 100.0, 5e7, 0.2
    phi = np.linspace(0.0, np.pi / 4, 9)
    tm = from_arrays(np.c_[R * np.sin(phi), R * (1 - np.cos(phi)), np.zeros(9)], np.c_[np.arange(8), np.arange(1, 9)],
                     "arc", {"base": np.array([0]), "tip": np.array([8])})
    sc = dc.Scene(large_rotations=True, tangent=tangent)
    arc = sc.add_beam(tm, "arc", section=dc.Section(A=1.0, I=1 / 12, Iy=1 / 12, J=0.140577),
                      material=dc.Elastic(E, nu), orientation=(0.0, 0.0, 1.0))
    sc.fix(arc, "base")
    sc.load(arc, "tip", force=(0.0, 0.0, 7 * E / 12.0 / R**2))
    sc.monitor("tip", arc, "tip")
    return dc.solve(sc, dc.LoadControl(steps=20), quiet=True)


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="the dense path is for one rank")
def test_the_dense_path_follows_the_path_of_mumps(monkeypatch):
    """The bend solved densely and by MUMPS: the same Newton iterations in every step and the
    same tip to 1e-9 of its size (round-off of two factorizations)."""
    dense = _bend()
    monkeypatch.setattr(petsc_layer, "DENSE_LIMIT", 0)
    mumps = _bend()
    assert np.array_equal(dense.history.column("iterations"), mumps.history.column("iterations"))
    tips = [np.array([r.history.column(c)[-1] for c in ("tip_ux", "tip_uy", "tip_uz")]) for r in (dense, mumps)]
    assert np.linalg.norm(tips[0] - tips[1]) <= 1e-9 * np.linalg.norm(tips[1])
    assert np.linalg.norm(tips[1] - [-23.631863, -13.637087, 53.332253]) < 0.01 * np.linalg.norm(tips[1])


def test_without_scipys_module_file_the_lapack_wrappers_come_from_scipy_linalg(monkeypatch):
    """Where SciPy keeps no ``linalg/_flapack`` file, the dense LU takes ``scipy.linalg.lapack``."""
    import glob

    from scipy.linalg import lapack

    monkeypatch.setattr(petsc_layer, "_LAPACK", [])
    monkeypatch.setattr(glob, "glob", lambda pattern: [])
    assert petsc_layer._lapack() is lapack


def test_the_lapack_wrappers_are_scipys_and_the_helpers_match_numpy():
    """The LAPACK module loaded without scipy.linalg's package is the one ``scipy.linalg.lapack``
    hands out (one instance); the C helpers' scaled matrix S A S and band storage against NumPy."""
    from scipy.linalg import lapack

    from dolfinx_corot.assembly import dense

    module = petsc_layer._lapack()
    for name in ("dgetrf", "dgetrs", "dgbtrf", "dgbtrs", "dsytrf"):
        assert getattr(module, name) is getattr(lapack, name)
    rng = np.random.default_rng(4)
    n = 9
    K = np.triu(np.tril(rng.normal(size=(n, n)), 2), -1)  # kl = 1, ku = 2
    K[3, 3] = 0.0  # a zero diagonal entry keeps scale 1
    A = _matrix(K)
    indptr, indices, values = A.getValuesCSR()
    s_expected = np.where(np.diag(K) != 0.0, 1.0 / np.sqrt(np.abs(np.where(np.diag(K) != 0.0, np.diag(K), 1.0))), 1.0)
    D = np.empty((n, n), order="F")
    s = np.empty(n)
    dense.scaled_dense(values, indptr, indices, D, s)
    assert np.allclose(s, s_expected, rtol=1e-15) and np.allclose(D, s[:, None] * K * s[None, :], rtol=1e-15)
    assert dense.bandwidths(indptr, indices) == (1, 2)
    ab = np.empty((2 * 1 + 2 + 1, n), order="F")
    dense.scaled_band(values, indptr, indices, 1, 2, ab, s)
    for i in range(n):
        for j in range(max(0, i - 1), min(n, i + 3)):
            assert ab[1 + 2 + i - j, j] == D[i, j]
    assert not ab[0].any()  # the fill's row
    with pytest.raises(ValueError, match="column-major"):
        dense.scaled_dense(values, indptr, indices, np.empty((n, n)), s)
    assert dense.lu_summary(np.array([2.0, -1e-14, -3.0]), np.array([0, 2, 2], dtype=np.int32), 1e-13) == (1, 1, 2)


class _Factor:
    """A stand-in for MUMPS's factor matrix that runs out of workspace until ICNTL(14) ≥ ``needs``."""

    def __init__(self, needs: int, code: int):
        self.icntl14, self.needs, self.code, self.solved = 20, needs, code, 0

    def getMumpsInfog(self, i):
        return self.code if i == 1 and self.icntl14 < self.needs else 0

    def getMumpsIcntl(self, i):
        return self.icntl14

    def setMumpsIcntl(self, i, value):
        assert i == 14
        self.icntl14 = value


class _KSP:
    def __init__(self, factor):
        self.factor = factor

    def getPC(self):
        return self

    def getFactorMatrix(self):
        return self.factor

    def solve(self, rhs, out):
        self.factor.solved += 1

    def getConvergedReason(self):
        return -11 if self.factor.getMumpsInfog(1) else 1


@pytest.mark.parametrize("code, needs, solves, icntl14, reason",
                         [(-9, 45, 1, 50, 1), (-9, 150, 3, 200, 1), (-8, 10_000, 4, 400, -11), (-10, 45, 0, 20, -11)])
def test_a_factorization_out_of_workspace_is_done_again_with_more(code, needs, solves, icntl14, reason):
    """MUMPS's workspace errors (INFOG(1) = −9 here) make the solver factorize again with twice the
    extra space ICNTL(14) (at least 50 %), up to four times, and keep it; other failures (−10: a
    singular matrix) are not retried, and the message names MUMPS's error."""
    from dolfinx_corot.assembly.petsc import LinearSolver

    solver = LinearSolver.__new__(LinearSolver)
    solver.A, solver.mumps = PETSc.Mat().createAIJ([1, 1], nnz=1, comm=MPI.COMM_SELF), True
    solver.A.setUp()
    solver.A.assemble()
    solver.ksp = _KSP(_Factor(needs, code))
    assert solver._mumps_retry(None, None) == reason
    assert solver.ksp.factor.solved == solves and solver.ksp.factor.icntl14 == icntl14
    assert f"MUMPS INFOG(1) = {0 if reason > 0 else code}" in solver._mumps_error()

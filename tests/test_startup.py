"""Start-up: Open MPI's settings for a process started without a launcher
(``dolfinx_corot.SINGLETON_MPI``, docs/performance.md "Start-up and a small model")."""
import os
import subprocess
import sys

import pytest
from mpi4py import MPI

import dolfinx_corot as dc

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="runs subprocesses; serial only")


def test_a_singleton_gets_the_settings_a_launched_rank_or_a_users_setting_does_not_change():
    env = {"PATH": "/usr/bin"}
    assert dc._singleton_mpi(env) == dc.SINGLETON_MPI
    assert all(env[k] == v for k, v in dc.SINGLETON_MPI.items())
    for launcher in dc.LAUNCHED_BY:  # mpirun, PMIx, PMI, Slurm
        env = {launcher: "0"}
        assert dc._singleton_mpi(env) == {} and set(env) == {launcher}
    env = {"OMPI_MCA_pml": "ucx"}  # the user's choice wins, the other setting is still made
    assert dc._singleton_mpi(env) == {"OMPI_MCA_ess_singleton_isolated": "1"}
    assert env["OMPI_MCA_pml"] == "ucx"


def _fresh(code: str, **extra) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_MCA_", "PMIX_", "PMI_", "SLURM_"))
           and k != "OMPI_COMM_WORLD_SIZE"}
    env.update(extra)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)


@serial
def test_a_fresh_process_that_imports_the_package_first_runs_mpi_and_petsc_as_an_isolated_singleton():
    """The settings take effect when the package is imported before MPI starts: MPI runs with one
    rank, PETSc works, and nothing is written to stderr."""
    out = _fresh("import os, dolfinx_corot\n"
                 "from mpi4py import MPI\n"
                 "import dolfinx\n"
                 "from petsc4py import PETSc\n"
                 "v = PETSc.Vec().createMPI(4, comm=MPI.COMM_WORLD); v.set(2.0)\n"
                 "print(MPI.COMM_WORLD.size, v.sum(), os.environ['OMPI_MCA_pml'],"
                 " os.environ['OMPI_MCA_ess_singleton_isolated'])")
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["1", "8.0", "ob1", "1"]
    assert out.stderr == ""
    # a setting of the user's is kept
    out = _fresh("import os, dolfinx_corot\nfrom mpi4py import MPI\nprint(os.environ['OMPI_MCA_pml'])",
                 OMPI_MCA_pml="ob1,cm")
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["ob1,cm"]


@serial
def test_a_scene_of_beams_in_space_is_solved_without_loading_numba():
    """The 3D beams' kernels, the nodal rotation updates, the section forces and the dense
    factorization's helpers are C (:mod:`dolfinx_corot.kernels.compiled`,
    :mod:`dolfinx_corot.assembly.dense`): a cantilever of co-rotational beams is solved and its
    section forces read in a fresh process without importing numba; its tip under a small end load
    is Euler–Bernoulli's P L³/(3 E I), the clamp's moment P L (to the load's geometric
    nonlinearity, 1e-4)."""
    out = _fresh(
        "import sys\n"
        "import numpy as np\n"
        "import dolfinx_corot as dc\n"
        "from dolfinx_corot.io.mesh import from_arrays\n"
        "n, L, E = 8, 10.0, 1e4\n"
        "x = np.linspace(0.0, L, n + 1)\n"
        "tm = from_arrays(np.c_[x, 0 * x, 0 * x], np.c_[np.arange(n), np.arange(1, n + 1)], 'axis',\n"
        "                 {'base': np.array([0]), 'tip': np.array([n])})\n"
        "sc = dc.Scene(large_rotations=True)\n"
        "beam = sc.add_beam(tm, 'axis', section=dc.Section(A=1.0, I=1 / 12, Iy=1 / 12, J=0.14),\n"
        "                   material=dc.Elastic(E, 0.3), orientation=(0.0, 0.0, 1.0))\n"
        "sc.fix(beam, 'base')\n"
        "sc.load(beam, 'tip', force=(0.0, 1e-3, 0.0))\n"
        "sc.monitor('tip', beam, 'tip')\n"
        "result = dc.solve(sc, dc.LoadControl(steps=2), quiet=True)\n"
        "moment = sc.element_results(beam)['My'][0, 0]  # e2 = z, e3 = -y: bending about e2\n"
        "print(result.history.rows[-1]['tip_uy'], moment, 'numba' in sys.modules)")
    assert out.returncode == 0, out.stderr
    tip, moment, numba_loaded = out.stdout.split()[-3:]
    assert numba_loaded == "False"
    assert float(tip) == pytest.approx(1e-3 * 10.0**3 / (3 * 1e4 / 12), rel=1e-4)
    assert abs(float(moment)) == pytest.approx(1e-3 * 10.0, rel=1e-4)  # the clamp's moment P L


@serial
def test_a_scene_of_planar_beams_is_solved_without_loading_numba():
    """A cantilever of co-rotational planar beams under an end moment 2π EI/L rolls up into a full
    circle (the tip back at the clamp, turned by 2π: the exact elastica), its bending moment that
    moment everywhere, in a fresh process without importing numba."""
    out = _fresh(
        "import sys\n"
        "import numpy as np\n"
        "import dolfinx_corot as dc\n"
        "from dolfinx_corot.io.mesh import from_arrays\n"
        "n, L, E = 10, 10.0, 1e4\n"
        "x = np.linspace(0.0, L, n + 1)\n"
        "tm = from_arrays(np.c_[x, 0 * x], np.c_[np.arange(n), np.arange(1, n + 1)], 'axis',\n"
        "                 {'base': np.array([0]), 'tip': np.array([n])})\n"
        "sc = dc.Scene(large_rotations=True)\n"
        "beam = sc.add_beam(tm, 'axis', section=dc.Section(A=1.0, I=1 / 12), material=dc.Elastic(E, 0.3))\n"
        "sc.fix(beam, 'base')\n"
        "sc.load(beam, 'tip', moment=2 * np.pi * E / 12 / L)\n"
        "sc.monitor('tip', beam, 'tip')\n"
        "row = dc.solve(sc, dc.LoadControl(steps=10), quiet=True).history.rows[-1]\n"
        "M = np.abs(sc.element_results(beam)['M'])\n"
        "print(row['tip_ux'], row['tip_uy'], row['tip_rz'], M.min(), M.max(), 'numba' in sys.modules)")
    assert out.returncode == 0, out.stderr
    ux, uy, rz, m_min, m_max, numba_loaded = out.stdout.split()[-6:]
    assert numba_loaded == "False"
    moment = 2 * 3.141592653589793 * 1e4 / 12 / 10.0
    assert float(m_min) == pytest.approx(moment, rel=1e-6) and float(m_max) == pytest.approx(moment, rel=1e-6)
    assert float(ux) == pytest.approx(-10.0, abs=1e-6) and abs(float(uy)) < 1e-6
    assert float(rz) == pytest.approx(2 * 3.141592653589793, rel=1e-9)

"""What a run shows and gives back: progress lines or a bar, quiet runs, compiler messages kept off
stderr, and the results as data (monitors by name, pandas, the history read back).

The README's first script is run as a user runs it (a fresh FFCx cache, so its elements are
compiled): it must print its progress on stdout and nothing on stderr, serially and on two ranks.
"""
import io
import logging
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.console import show_compiler_output
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.solvers.progress import Progress, progress_mode
from dolfinx_corot.staging import Stage, solve_stages

ROOT = Path(__file__).resolve().parents[1]
serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="runs subprocesses; serial only")


def _first_script() -> str:
    """The first Python block of the README's 'A first script'."""
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## A first script"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def _run_script(tmp_path, mpi: bool) -> subprocess.CompletedProcess:
    script = tmp_path / "first.py"
    script.write_text(_first_script().replace('"history.csv"', repr(str(tmp_path / "history.csv"))))
    env = {k: v for k, v in os.environ.items() if k not in ("DC_PROGRESS", "DC_COMPILER_OUTPUT")}
    env.update(XDG_CACHE_HOME=str(tmp_path / "cache"), PYTHONUNBUFFERED="1",
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cmd = [sys.executable, str(script)]
    if mpi:
        cmd = ["mpirun", "-n", "2"] + cmd
    return subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)


@serial
@pytest.mark.parametrize("mpi", [False, pytest.param(True, marks=pytest.mark.mpi)], ids=["serial", "two ranks"])
def test_the_readme_first_script_shows_its_progress_and_nothing_on_stderr(tmp_path, mpi):
    """A fresh FFCx cache: the elements are compiled (setuptools' build lines went to stderr before);
    the 40 steps are reported once (rank 0), one line each, then the totals."""
    proc = _run_script(tmp_path, mpi)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert proc.stderr == ""
    steps = re.findall(r"^step (\d+): λ = ([0-9.e+-]+), (\d+) iterations, (\d+) cuts", proc.stdout, re.M)
    assert [int(s[0]) for s in steps] == list(range(1, 41))
    assert float(steps[-1][1]) == pytest.approx(4.0, rel=1e-14)
    assert re.search(r"^done — 40 steps, \d+ Newton iterations, 0 cuts", proc.stdout, re.M)
    assert (tmp_path / "history.csv").exists()


def _column(n: int = 10):
    tmesh = polyline([[0.0, 0.0], [0.0, 1.0]], n, line_name="column")
    scene = dc.Scene(large_rotations=True)
    column = scene.add_beam(tmesh, "column", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1e5, 0.0))
    scene.fix(column, where="base")
    scene.load(column, where="tip", force=(0.0, -2.056), moment=0.02056)
    scene.monitor("tip", column, where="tip")
    scene.monitor_reaction("base", column, "base")
    scene.monitor("shape", column, "column", reduce="profile")
    return scene, column


def test_progress_lines_bar_and_quiet(capsys):
    scene, _ = _column()
    result = dc.solve(scene, dc.LoadControl(steps=3), progress="lines")
    out = capsys.readouterr().out if MPI.COMM_WORLD.rank == 0 else ""
    if MPI.COMM_WORLD.rank == 0:
        lines = out.splitlines()
        assert len(lines) == 4 and lines[0].startswith("step 1: λ = 0.333333, ")
        assert lines[-1].startswith(f"done — 3 steps, {result.totals['newton_iterations']} Newton iterations, 0 cuts")
    scene, _ = _column()
    dc.solve(scene, dc.LoadControl(steps=3), quiet=True)
    assert capsys.readouterr().out == ""
    scene, _ = _column()
    dc.solve(scene, dc.LoadControl(steps=3), progress="bar", label="column")
    out = capsys.readouterr().out
    if MPI.COMM_WORLD.rank == 0:
        assert "column: 100%" in out and "step 3: λ=1" in out
    else:
        assert out == ""  # only rank 0 reports


def test_progress_follows_cut_steps_and_arc_length():
    """The bar's position: the targets reached, a cut step counting as the part of its target it
    went; arc-length: its steps, or its load factor against ``max_load_factor``."""
    p = Progress("bar", MPI.COMM_SELF, stream=io.StringIO())
    p.expect(4)
    row = {"step": 1, "load_factor": 0.125, "iterations": 3, "cuts": 1, "wall_time": 0.1}
    p.step(row, position=0.5)
    assert p._bar.n == 0.5
    p.step({**row, "step": 2, "load_factor": 0.25, "cuts": 0}, position=1.0)
    assert p._bar.n == 1.0 and "1 cuts" in p._bar.postfix
    p.close()
    scene, _ = _column()
    seen = []
    stream = io.StringIO()

    class Spy(Progress):
        def step(self, row, position=None):
            seen.append(position)
            super().step(row, position)

    from dolfinx_corot.solvers import run as run_module
    original = run_module.Progress
    run_module.Progress = lambda mode, comm, label: Spy("lines", comm, label, stream)
    try:
        dc.solve(scene, dc.ArcLength(initial_increment=0.5, max_steps=20, max_load_factor=1.0))
    finally:
        run_module.Progress = original
    assert seen == sorted(seen) and seen[0] >= 1.0 and seen[-1] >= 20.0  # λ reached 1: the whole way


def test_progress_names_each_stage(capsys):
    tmesh = polyline([[0.0, 0.0], [1.0, 0.0]], 4, line_name="beam")
    scene = dc.Scene(large_rotations=False)
    beam = scene.add_beam(tmesh, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1e5, 0.0))
    scene.fix(beam, "base")
    load = scene.load(beam, "tip", force=(0.0, -1.0))
    solve_stages(scene, [Stage("built"), Stage("loaded", add=[load], driver=dc.LoadControl(steps=2))],
                 approach="I", progress="lines")
    out = capsys.readouterr().out
    if MPI.COMM_WORLD.rank == 0:
        assert "stage 1/2 'built': step 1: λ = 1" in out and "stage 2/2 'loaded': step 2: λ = 1" in out


def test_a_bad_progress_value_is_refused():
    with pytest.raises(ValueError, match="progress = 'loud' is not one of"):
        progress_mode("loud", False)
    assert progress_mode("bar", True) == "off" and progress_mode(None, False) in ("auto", "bar", "lines", "off")


def test_compiler_build_messages_are_dropped_unless_asked_for():
    """setuptools' distutils logs cffi's build steps at INFO on the root logger; they are dropped,
    its warnings kept; show_compiler_output lets them through."""
    root = logging.getLogger()
    seen = []
    handler = logging.Handler()
    handler.emit = lambda record: seen.append(record.getMessage())
    root.addHandler(handler)
    level = root.level
    root.setLevel(logging.DEBUG)

    def log(level_, message):
        root.handle(root.makeRecord("root", level_, "/usr/lib/python3/dist-packages/setuptools/_distutils/log.py",
                                    10, message, None, None))
    try:
        log(logging.INFO, "running build_ext")
        log(logging.WARNING, "a compiler warning")
        root.info("a user's own message")
        show_compiler_output(True)
        log(logging.INFO, "gcc -O2 ...")
    finally:
        show_compiler_output(False)
        root.removeHandler(handler)
        root.setLevel(level)
    assert seen == ["a compiler warning", "a user's own message", "gcc -O2 ..."]


def test_results_as_data(tmp_path):
    """Monitors by name (a point, a reaction, a profile), the history as a pandas DataFrame, and
    the written history read back equal."""
    pandas = pytest.importorskip("pandas")
    scene, _ = _column()
    result = dc.solve(scene, dc.LoadControl(steps=4, final=4.0), quiet=True)
    tip = result.monitor("tip")
    assert set(tip) == {"ux", "uy", "rz"}
    np.testing.assert_array_equal(tip["uy"], result.history.column("tip_uy"))
    base = result.monitor("base")
    assert set(base) == {"Fx", "Fy", "Mz"}
    np.testing.assert_allclose(base["Fy"], 2.056 * result.history.column("load_factor"), rtol=1e-9)
    assert result.monitor("shape") is result.profiles["shape"]
    with pytest.raises(KeyError, match=r"no monitor 'tops' in this result; monitors: \['base', 'shape', 'tip'\]"):
        result.monitor("tops")
    frame = result.history.to_pandas()
    assert isinstance(frame, pandas.DataFrame) and list(frame.index) == [1, 2, 3, 4]
    np.testing.assert_array_equal(frame["tip_ux"].to_numpy(), tip["ux"])
    assert frame["residuals"].iloc[0][-1] < 1e-8 * frame["residuals"].iloc[0][0]
    if MPI.COMM_WORLD.rank == 0:
        result.write(str(tmp_path))
        back = dc.History.read_csv(str(tmp_path / "history.csv"))
        assert back.rows == result.history.rows
        again = dc.Result(back)
        np.testing.assert_array_equal(again.monitor("tip")["rz"], tip["rz"])
        for name in ("residuals", "iterations", "tip_ux"):
            got, want = back.column(name), result.history.column(name)
            for g, w in zip(got, want):
                np.testing.assert_array_equal(g, w)

"""Start-up and small-model cost (a script, not a test).

Each command runs as a fresh process, the commands taking turns (``--repeats`` rounds), so that
the machine's load falls on all of them alike; the median wall time and the peak resident memory
of each are reported:

* ``import dolfinx`` — the floor every DOLFINx script pays, with Open MPI's defaults;
* ``import dolfinx, singleton MPI`` — the same with the settings the package makes for a process
  started without mpirun (``dolfinx_corot.SINGLETON_MPI``: no local daemon, the ob1 layer), when
  it is imported before MPI starts;
* ``import dolfinx_corot`` — the package itself (it imports its names on first use);
* ``dolfinx_corot.Scene`` — what a script pays before its first scene: DOLFINx and our modules;
* the 45° bend (Bathe & Bolourchi 1979; 8 co-rotational 3D beams from arrays, 20 load steps to
  the tip force of ``demos/curved_beam_3d.py``) as a whole process, and its time in the solver
  (``dc.solve``) measured inside it: the first time (the C beam kernels and the dense LU's
  helpers are loaded from the cache then, without numba) and, in another process, for the same
  scene solved again (the solver alone).

Writes output/startup_bench/{startup.json, startup.csv, startup.png}.
Usage: python benchmarks/startup.py [--repeats 7]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

BEND = """
import time
import numpy as np
import dolfinx_corot as dc
from dolfinx_corot.io.mesh import from_arrays
R, E, nu, J = 100.0, 5e7, 0.2, 0.140577
n = 8
phi = np.linspace(0.0, np.pi / 4, n + 1)
pts = np.c_[R * np.sin(phi), R * (1 - np.cos(phi)), np.zeros(n + 1)]
cells = np.c_[np.arange(n), np.arange(1, n + 1)]
tm = from_arrays(pts, cells, "arc", {"base": np.array([0]), "tip": np.array([n])})


def bend():
    sc = dc.Scene(large_rotations=True)
    arc = sc.add_beam(tm, "arc", section=dc.Section(A=1.0, I=1 / 12, Iy=1 / 12, J=J), material=dc.Elastic(E, nu),
                      orientation=(0.0, 0.0, 1.0))
    sc.fix(arc, "base")
    sc.load(arc, "tip", force=(0.0, 0.0, 7 * E / 12.0 / R**2))
    sc.monitor("tip", arc, "tip")
    t = time.perf_counter()
    result = dc.solve(sc, dc.LoadControl(steps=20), quiet=True)
    return time.perf_counter() - t, result


first, result = bend()  # with the compiled kernels' loading from the cache
again, _ = bend() if AGAIN else (float("nan"), None)  # the same scene again: the solver alone
row = result.history.rows[-1]
print("BEND", first, again, result.totals["newton_iterations"], row["tip_ux"], row["tip_uy"], row["tip_uz"])
"""

COMMANDS = {
    "import dolfinx": "import dolfinx",
    # (written out: importing the package here would hand its settings to every child)
    "import dolfinx, singleton MPI": "import os; os.environ.update({'OMPI_MCA_ess_singleton_isolated': '1', "
                                     "'OMPI_MCA_pml': 'ob1'}); import dolfinx",
    "import dolfinx_corot": "import dolfinx_corot",
    "dolfinx_corot.Scene": "import dolfinx_corot; dolfinx_corot.Scene",
    "45° bend, 8 beams, 20 steps": "AGAIN = False\n" + BEND,
}


def run(code: str) -> tuple[float, float, str]:
    """(wall seconds, peak RSS in MB, standard output) of ``python -c code`` in a fresh process."""
    t = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t
    out, err = proc.stdout.read(), proc.stderr.read()
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"failed: {code[:60]}…\n{err}")
    return wall, usage.ru_maxrss / 1024.0, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    for code in COMMANDS.values():  # warm the file-system cache and the kernels' cache once
        run(code)
    samples = {name: [] for name in COMMANDS}
    solver, steady = [], []
    for _ in range(args.repeats):
        for name, code in COMMANDS.items():
            wall, rss, out = run(code)
            samples[name].append((wall, rss))
            if out.startswith("BEND"):
                solver.append(float(out.split()[1]))
        # in a process of its own (not timed as a whole): the same scene solved twice
        fields = run("AGAIN = True\n" + BEND)[2].split()
        steady.append(float(fields[2]))
        iterations, tip = int(fields[3]), [float(v) for v in fields[4:7]]
    floor = statistics.median(w for w, _ in samples["import dolfinx"])
    rows = []
    for name, values in samples.items():
        wall = statistics.median(w for w, _ in values)
        rows.append({"what": name, "wall_s": round(wall, 4), "ratio_to_import_dolfinx": round(wall / floor, 3),
                     "peak_rss_MB": round(max(r for _, r in values), 1)})
    bend = {"in_solver_first_s": statistics.median(solver), "in_solver_again_s": statistics.median(steady),
            "newton_iterations": iterations, "ms_per_iteration_again": 1e3 * statistics.median(steady) / iterations,
            "tip": tip}
    out_dir = os.path.join(os.environ.get("DC_OUTPUT_DIR", "output"), "startup_bench")
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "startup.json"), "w") as f:
        json.dump({"repeats": args.repeats, "rows": rows, "bend": bend}, f, indent=1)
    from dolfinx_corot.io import write_rows  # (only now: the children have run)

    write_rows(os.path.join(out_dir, "startup.csv"), rows)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.5, 3.2))
    ax = fig.subplots()
    ax.barh([r["what"] for r in rows][::-1], [r["wall_s"] for r in rows][::-1], color="C0")
    ax.axvline(floor, color="0.4", ls="--", lw=0.8, label="import dolfinx")
    ax.set(xlabel="wall time of a fresh process, median [s]", title=f"start-up ({args.repeats} runs each)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "startup.png"), dpi=110)
    import numpy as np  # here: a child forked after numpy's import would count its pages
    from summary import record

    from dolfinx_corot.io import reference

    exact = reference("B2c_45deg_bend")["scaled_version"]["exact"]["Kirchhoff_JsaintVenant"]["data"][-1][4:7]
    error = np.linalg.norm(np.subtract(tip, exact)) / np.linalg.norm(exact)
    for r in rows:
        whole = r["what"].startswith("45°")
        record("45deg_bend" if whole else "start-up", r["what"], wall_s=r["wall_s"], peak_rss_MB=r["peak_rss_MB"],
               solver_s=bend["in_solver_first_s"] if whole else None,
               newton_iterations=iterations if whole else None,
               error=f"tip {error:.2e}" if whole else "",
               reference="exact Kirchhoff rod, reference/B2c_45deg_bend.json" if whole else "")
    print(f"{'':32s} {'wall (median)':>14s} {'/ import dolfinx':>17s} {'peak RSS':>10s}")
    for r in rows:
        print(f"{r['what']:32s} {r['wall_s']:12.3f} s {r['ratio_to_import_dolfinx']:17.2f} {r['peak_rss_MB']:7.0f} MB")
    print(f"45° bend in the solver: {bend['in_solver_first_s']:.4f} s the first time (the compiled kernels loaded), "
          f"{bend['in_solver_again_s']:.4f} s again; {iterations} Newton iterations, "
          f"{bend['ms_per_iteration_again']:.2f} ms each; tip displacement {tip}")


if __name__ == "__main__":
    main()

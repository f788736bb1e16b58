"""Benchmark: a block slid on a stiff base with Coulomb friction, and what friction costs a
frictionless interface.

1. The peer set-up of issue 16: an elastic block 1 × 0.5 (E = 1000, ν = 0.3, plane strain,
   St Venant–Kirchhoff, linear quadrilaterals) on a base 2 × 0.25 a thousand times stiffer,
   fixed at its bottom; the pressure p = 10 on the block's top in the first step, then the
   top moved sideways by 0.05 in ten steps (its vertical motion free); node-to-segment
   contact of the block's bottom against the base's top, augmented Lagrangian, μ = 0.3.
   Once the block slides, |ΣF_t|/|ΣF_n| of the base's reaction is μ; reported with the wall
   time, Newton iterations and dofs for two meshes (1.3k and 5.5k dofs; the peer:
   CalculiX, quadratic elements, surface-to-surface penalty, one thread: 19 s and 49 s,
   |ΣF_t|/|ΣF_n| = 0.2999998) and two predictors: each step started from the last converged
   state (the default), or from the secant extrapolation of the last two
   (``LoadControl(extrapolate=True)``), which in steady sliding starts the slaves where they slide
   to.
2. Effects on demand: the same scene without friction (the block then follows its top
   without resistance), solved by this code and by the code before friction existed
   (``--baseline REV``, a git revision; run from a temporary worktree in a child process),
   alternately, ``--repeat`` times each: the median wall times and the reactions are compared
   (target: the same time within the machine's noise, the same numbers to round-off).

Writes output/friction/friction.{json,csv,png}.
Usage: python benchmarks/friction.py [--meshes 32 16 70 35] [--baseline 6245b6d^] [--repeat 3]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

ROOT = Path(__file__).resolve().parents[1]
comm = MPI.COMM_WORLD
E, NU, PRESSURE, MU, SHIFT, STEPS = 1000.0, 0.3, 10.0, 0.3, 0.05, 11


def run(nx: int, ny: int, friction: bool, extrapolate: bool = False) -> dict:
    import dolfinx_corot as dc
    from dolfinx_corot.io.mesh import rectangles

    tm = rectangles({"base_block": (-0.5, -0.25, 2.0, 0.25, nx, 2),
                     "block": (0.0, 0.0, 1.0, 0.5, nx, ny)},
                    {"base": [("base_block", "bottom")], "base_top": [("base_block", "top")],
                     "block_bottom": [("block", "bottom")], "top": [("block", "top")]}, comm=comm)
    sc = dc.Scene(linear_solver="direct")
    block = sc.add_solid(tm, "block", material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    base = sc.add_solid(tm, "base_block", material=dc.SaintVenantKirchhoff(1000 * E, NU), degree=1)
    sc.fix(base, "base")
    pressed = dc.Amplitude(((0.0, 0.0), (1 / STEPS, 1.0), (1.0, 1.0)))
    sc.load(block, "top", traction=(0.0, -PRESSURE), amplitude=pressed)
    sc.prescribe(block, "top", amplitude=dc.Amplitude(((0.0, 0.0), (1 / STEPS, 0.0), (1.0, 1.0))), ux=SHIFT)
    kwargs = {"friction": dc.Coulomb(mu=MU)} if friction else {}
    sc.contact((block, "block_bottom"), (base, "base_top"), law=dc.AugmentedLagrangian(), **kwargs)
    sc.monitor_reaction("base", base, "base")
    t0 = time.perf_counter()
    result = dc.solve(sc, dc.LoadControl(steps=STEPS, extrapolate=extrapolate))
    wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    h = result.history
    fx, fy = h.column("base_Fx"), h.column("base_Fy")
    return {"nx": nx, "ny": ny, "friction": friction, "predictor": "secant" if extrapolate else "last state",
            "dofs": int(2 * tm.mesh.topology.index_map(0).size_global), "wall_s": wall,
            "newton_iterations": int(h.column("iterations").sum()), "cuts": int(h.column("cuts").sum()),
            "ratio": float(abs(fx[-1] / fy[-1])), "steps": [int(v) for v in h.column("iterations")],
            "uzawa": [int(v) for v in h.column("uzawa_updates")], "base_Fx": [float(v) for v in fx],
            "base_Fy": [float(v) for v in fy]}


def child(args) -> None:
    """One timed frictionless run (after a warm-up) as JSON on stdout, with whichever
    dolfinx_corot is on the path."""
    nx, ny = args.meshes[-2:]
    run(nx, ny, False)
    out = run(nx, ny, False)
    if comm.rank == 0:
        print("RESULT " + json.dumps(out))


def frictionless_against(revision: str, nx: int, ny: int, repeat: int) -> dict:
    """Median wall times and largest reaction difference of the frictionless scene, this code
    against ``revision``, run alternately in child processes."""
    work = Path(tempfile.mkdtemp(prefix="dc_baseline_"))
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(work), revision], check=True,
                   capture_output=True)
    try:
        times = {"current": [], "baseline": []}
        results = {}
        for _ in range(repeat):
            for label, path in (("current", ROOT), ("baseline", work)):
                env = dict(os.environ, PYTHONPATH=str(path), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
                proc = subprocess.run([sys.executable, __file__, "--child", "--meshes", str(nx), str(ny)], env=env,
                                      capture_output=True, text=True, check=True, cwd=str(path))
                line = next(x for x in proc.stdout.splitlines() if x.startswith("RESULT "))
                results[label] = json.loads(line[len("RESULT "):])
                times[label].append(results[label]["wall_s"])
        diff = max(np.max(np.abs(np.subtract(results["current"][k], results["baseline"][k])))
                   / np.max(np.abs(results["baseline"][k])) for k in ("base_Fx", "base_Fy"))
        return {"revision": revision, "dofs": results["current"]["dofs"], "repeat": repeat,
                "current_s": times["current"], "baseline_s": times["baseline"],
                "median_ratio": float(np.median(times["current"]) / np.median(times["baseline"])),
                "reaction_difference": float(diff),
                "newton_iterations": [results["current"]["newton_iterations"],
                                      results["baseline"]["newton_iterations"]]}
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(work)], capture_output=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", type=int, nargs="+", default=[32, 16, 70, 35])
    ap.add_argument("--baseline", default=None, help="git revision before friction, e.g. 6245b6d^")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--child", action="store_true")
    args = ap.parse_args()
    if args.child:
        return child(args)
    from dolfinx_corot.io import output_dir

    rows, histories = [], []
    run(args.meshes[0], args.meshes[1], True)  # compiles the kernels once
    for extrapolate in (False, True):
        for nx, ny in zip(args.meshes[::2], args.meshes[1::2]):
            r = run(nx, ny, True, extrapolate)
            rows.append({k: v for k, v in r.items() if not k.startswith("base_")})
            histories.append(r)
            if comm.rank == 0:
                print(f"block {nx} × {ny} ({r['predictor']} predictor): {r['dofs']} dofs, |ΣF_t|/|ΣF_n| = "
                      f"{r['ratio']:.7f} (μ = {MU}), {r['newton_iterations']} Newton its {r['steps']}, Uzawa "
                      f"{r['uzawa']}, {r['cuts']} cuts, {r['wall_s']:.2f} s")
    report = {"sliding_block": rows}
    if args.baseline is not None and comm.size == 1:
        nx, ny = args.meshes[-2:]
        report["frictionless"] = f = frictionless_against(args.baseline, nx, ny, args.repeat)
        print(f"frictionless, {f['dofs']} dofs: this code {np.median(f['current_s']):.2f} s, before friction "
              f"({f['revision']}) {np.median(f['baseline_s']):.2f} s (medians of {f['repeat']}; ratio "
              f"{f['median_ratio']:.3f}); reactions differ by {f['reaction_difference']:.1e}; Newton its "
              f"{f['newton_iterations']}")
    if comm.rank == 0:
        folder = output_dir("friction")
        with open(os.path.join(folder, "friction.json"), "w") as fh:
            json.dump(report, fh, indent=1)
        with open(os.path.join(folder, "friction.csv"), "w") as fh:
            keys = list(rows[0])
            fh.write(",".join(keys) + "\n")
            for r in rows:
                fh.write(",".join(str(r[k]) for k in keys) + "\n")
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
        for r in histories:
            ratio = np.abs(np.divide(r["base_Fx"], r["base_Fy"]))
            axes[0].plot(np.arange(1, len(ratio) + 1), ratio, "o-" if r["predictor"] == "secant" else "x:", ms=3,
                         label=f"{r['dofs']} dofs, {r['predictor']} predictor")
        axes[0].axhline(MU, color="k", lw=0.8)
        axes[0].set(xlabel="step", ylabel="|ΣF_t| / |ΣF_n| of the base", title="pressed, then pushed (line: μ)")
        axes[0].legend(fontsize=7)
        for predictor, style in (("last state", "o:"), ("secant", "o-")):
            these = [r for r in histories if r["predictor"] == predictor]
            axes[1].loglog([r["dofs"] for r in these], [r["wall_s"] for r in these], style,
                           label=f"this code, {predictor} predictor")
        axes[1].loglog([1600, 5300], [19.0, 49.0], "s--", label="CalculiX (issue 16)")
        if "frictionless" in report:
            f = report["frictionless"]
            axes[1].plot([f["dofs"]] * 2, [np.median(f["current_s"]), np.median(f["baseline_s"])], "x", ms=8,
                         label="frictionless: this code, before friction")
        axes[1].set(xlabel="dofs", ylabel="wall time of the solve [s]", title="what sliding costs")
        axes[1].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "friction.png"), dpi=110)
        plt.close(fig)


if __name__ == "__main__":
    main()

"""The peer of the 45° bend benchmark (``benchmarks/startup.py``) in OpenSees, to measure both side by
side in one sitting (issue 18: the solver's time at or below OpenSees's).

The same model: Bathe & Bolourchi's 45° bend, R = 100, 8 elastic beams (A = 1, I = 1/12,
J = 0.140577, E = 5e7, ν = 0.2) with OpenSees's co-rotational transformation, the tip force
7 E I / R² in 20 load steps, full Newton, banded solver, the residual tolerance 3e-6 (absolute),
which is about our relative 1e-9 of the load (OpenSees then takes 101 iterations, we 100).
Prints the in-solver time (``analyze``) of each of ``--repeats`` solves, the iterations and the tip.

Writes output/bend_opensees/{bend_opensees.json, bend_opensees.csv (each run's time),
bend_opensees.png (the times of the runs)}.

Needs OpenSeesPy and Matplotlib (``pip install openseespy matplotlib``, not dependencies of this
project); run it with the Python that has them, e.g. in a venv of its own:
``python benchmarks/bend_opensees.py --repeats 15``.
"""
import argparse
import csv
import json
import math
import statistics
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import openseespy.opensees as ops  # noqa: E402

OUT = Path(__file__).resolve().parent.parent / "output" / "bend_opensees"

R, E, NU, J, A, I = 100.0, 5e7, 0.2, 0.140577, 1.0, 1.0 / 12.0
N = 8


def solve(tolerance: float) -> tuple[float, int, list]:
    """(seconds in ``analyze``, Newton iterations, tip displacement) of one run from scratch."""
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i in range(N + 1):
        phi = math.pi / 4 * i / N
        ops.node(i + 1, R * math.sin(phi), R * (1 - math.cos(phi)), 0.0)
    ops.fix(1, 1, 1, 1, 1, 1, 1)
    ops.geomTransf("Corotational", 1, 0.0, 0.0, 1.0)
    for i in range(N):
        ops.element("elasticBeamColumn", i + 1, i + 1, i + 2, A, E, E / (2 * (1 + NU)), J, I, I, 1)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(N + 1, 0.0, 0.0, 7 * E * I / R**2, 0.0, 0.0, 0.0)
    ops.system("BandGeneral")
    ops.numberer("RCM")
    ops.constraints("Plain")
    ops.test("NormUnbalance", tolerance, 50)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 1.0 / 20)
    ops.analysis("Static")
    t = time.perf_counter()
    iterations = 0
    for _ in range(20):
        if ops.analyze(1) != 0:
            raise SystemExit("OpenSees did not converge")
        iterations += ops.testIter()
    return time.perf_counter() - t, iterations, [ops.nodeDisp(N + 1, d) for d in (1, 2, 3)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--tolerance", type=float, default=3e-6)
    args = parser.parse_args()
    runs = [solve(args.tolerance) for _ in range(args.repeats)]
    times = [r[0] for r in runs]
    OUT.mkdir(parents=True, exist_ok=True)
    summary = {"peer": "OpenSeesPy", "version": ops.version() if hasattr(ops, "version") else None,
               "tolerance": args.tolerance, "newton_iterations": runs[0][1], "tip": runs[0][2],
               "solver_s_median": statistics.median(times), "solver_s_least": min(times), "solver_s": times}
    (OUT / "bend_opensees.json").write_text(json.dumps(summary, indent=1))
    with open(OUT / "bend_opensees.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "solver_s", "newton_iterations"])
        w.writerows([i + 1, t, it] for i, (t, it, _) in enumerate(runs))
    fig, ax = plt.subplots(figsize=(5, 3))
    ax.plot(range(1, len(times) + 1), [1e3 * t for t in times], "o-")
    ax.set_xlabel("run")
    ax.set_ylabel("time in analyze (ms)")
    ax.set_title("OpenSees, 45° bend, 20 steps")
    fig.tight_layout()
    fig.savefig(OUT / "bend_opensees.png", dpi=100)
    plt.close(fig)
    print(f"OpenSees 45° bend: in the solver median {1e3 * statistics.median(times):.1f} ms, "
          f"least {1e3 * min(times):.1f} ms over {len(times)} runs; {runs[0][1]} Newton iterations; tip {runs[0][2]}")


if __name__ == "__main__":
    main()

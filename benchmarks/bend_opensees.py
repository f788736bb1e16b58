"""The peer of the 45° bend benchmark (``benchmarks/startup.py``) in OpenSees, to measure both side by
side in one sitting (issue 18: the solver's time at or below OpenSees's).

The same model: Bathe & Bolourchi's 45° bend, R = 100, 8 elastic beams (A = 1, I = 1/12,
J = 0.140577, E = 5e7, ν = 0.2) with OpenSees's co-rotational transformation, the tip force
7 E I / R² in 20 load steps, full Newton, banded solver, the residual tolerance 3e-6 (absolute),
which is about our relative 1e-9 of the load (OpenSees then takes 101 iterations, we 100).
Prints the in-solver time (``analyze``) of each of ``--repeats`` solves, the iterations and the tip.

Needs OpenSeesPy (``pip install openseespy``, not a dependency of this project); run it with the
Python that has it, e.g. in a venv of its own: ``python benchmarks/bend_opensees.py --repeats 15``.
"""
import argparse
import math
import statistics
import time

import openseespy.opensees as ops

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
    print(f"OpenSees 45° bend: in the solver median {1e3 * statistics.median(times):.1f} ms, "
          f"least {1e3 * min(times):.1f} ms over {len(times)} runs; {runs[0][1]} Newton iterations; tip {runs[0][2]}")


if __name__ == "__main__":
    main()

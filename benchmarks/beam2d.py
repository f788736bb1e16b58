"""Benchmark of the 2D co-rotational beam (a script, not a test).

1. Kernel throughput: internal force + consistent tangent of 10⁵ elements in
   large-rotation states, one core (numba loop over all elements), and the same
   element work done by DOLFINx's assembler through the cfunc kernels.
2. Newton iteration cost of a cantilever of 10⁴ elements (10 001 nodes,
   30 003 dofs; element length half the section depth) under a tip load that
   rotates the tip by about 1 rad, in 10 steps: time per iteration split into
   assembly (residual + tangent), linear solve (MUMPS) and update.

Writes output/beam2d_bench/{bench.json, newton_steps.csv, bench.png}.
Usage: python benchmarks/beam2d.py [--elements 10000] [--kernel-elements 100000]
"""
import argparse
import json
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.assembly import System
from dolfinx_corot.io import output_dir
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.kernels import line2d

comm = MPI.COMM_WORLD


def say(*a):
    if comm.rank == 0:
        print(*a, flush=True)


def kernel_throughput(n, repeats=5):
    rng = np.random.default_rng(0)
    X = np.zeros((n, 2, 2))
    X[:, 1, 0] = rng.uniform(0.5, 1.5, n)
    X[:, 1, 1] = rng.uniform(-0.1, 0.1, n)
    D = rng.normal(scale=0.02, size=(n, 6))
    D[:, [2, 5]] += rng.uniform(-10, 10, size=(n, 1))  # large rigid rotations
    props = np.tile([1000.0, 0.83, 0.0, 0.0], (n, 1))
    F, K = np.empty((n, 6)), np.empty((n, 6, 6))
    out = {}
    for large in (True, False):
        line2d.evaluate_all(X, D, props, large, F, K)  # compile
        t = time.perf_counter()
        for _ in range(repeats):
            line2d.evaluate_all(X, D, props, large, F, K)
        dt = (time.perf_counter() - t) / repeats
        out["corotational" if large else "linear"] = n / dt
    return out


def newton_split(nel, steps=10):
    L = 10.0
    h = 2 * L / nel
    tm = polyline([[0.0, 0.0], [L, 0.0]], nel, line_name="beam", comm=comm)
    sc = dc.Scene(large_rotations=True)
    beam = sc.add_beam(tm, "beam", section=dc.Rectangle(h, h), material=dc.Elastic(1e5))
    sc.fix(beam, "base")
    EI = 1e5 * h**4 / 12
    sc.load(beam, "tip", force=(0.0, -3.0 * EI / L**2))  # tip rotation ≈ 0.986 rad
    sc.monitor("tip", beam, "tip")
    t = time.perf_counter()
    system = System(sc.model)
    t_setup = time.perf_counter() - t
    # one residual+tangent assembly alone: element evaluations through DOLFINx
    system.residual(0.0)
    system.jacobian()
    t = time.perf_counter()
    for _ in range(5):
        system.residual(0.0)
        system.jacobian()
    t_asm = (time.perf_counter() - t) / 5
    system.timings = type(system.timings)()
    t = time.perf_counter()
    res = dc.solve(sc, dc.LoadControl(steps=steps), system=system)
    wall = time.perf_counter() - t
    iters = res.totals["newton_iterations"]
    tm_ = system.timings
    system.destroy()
    return {"elements": nel, "dofs": 3 * (nel + 1), "setup_s": t_setup, "steps": steps, "iterations": iters,
            "wall_s": wall, "per_iteration_s": wall / iters,
            "assembly_per_iteration_s": tm_.assembly / iters, "solve_per_iteration_s": tm_.solve / iters,
            "update_per_iteration_s": tm_.update / iters,
            "dolfinx_assembly_elements_per_s": 2 * nel / t_asm,
            "tip_rz": float(res.history.column("tip_rz")[-1])}, res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--elements", type=int, default=10_000)
    ap.add_argument("--kernel-elements", type=int, default=100_000)
    args = ap.parse_args()
    out = output_dir("beam2d_bench")
    data = {"ranks": comm.size}
    if comm.rank == 0:
        data["kernel_evaluations_per_s"] = kernel_throughput(args.kernel_elements)
        for k, v in data["kernel_evaluations_per_s"].items():
            say(f"kernel ({k}): {v:.3e} element evaluations (f + K) per second, one core")
    split, res = newton_split(args.elements)
    data["newton"] = split
    say(f"Newton, {split['elements']} elements ({split['dofs']} dofs), {comm.size} rank(s): "
        f"{split['iterations']} iterations in {split['wall_s']:.3f} s")
    say(f"  per iteration: {1e3 * split['per_iteration_s']:.2f} ms = assembly "
        f"{1e3 * split['assembly_per_iteration_s']:.2f} + solve {1e3 * split['solve_per_iteration_s']:.2f} "
        f"+ update {1e3 * split['update_per_iteration_s']:.3f} ms (+ convergence checks)")
    say(f"  DOLFINx assembly of the cfunc kernels: {split['dolfinx_assembly_elements_per_s']:.3e} "
        "element evaluations per second (residual + tangent)")
    from summary import peak_rss_MB, record

    rss = peak_rss_MB(comm)
    if comm.rank == 0:
        record("beam2d", f"cantilever of {split['elements']} 2D beams ({split['dofs']} dofs), 10 steps", ranks=comm.size,
               wall_s=split["wall_s"], solver_s=split["wall_s"], peak_rss_MB=rss,
               newton_iterations=split["iterations"])
        with open(os.path.join(out, "bench.json"), "w") as f:
            json.dump(data, f, indent=1)
        res.history.to_csv(os.path.join(out, "newton_steps.csv"))
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 3.5))
        parts = ["assembly", "solve", "update"]
        vals = [1e3 * split[f"{p}_per_iteration_s"] for p in parts]
        ax.bar(parts, vals, color=["C0", "C1", "C2"])
        ax.set_ylabel("ms per Newton iteration")
        ax.set_title(f"2D co-rotational beam, {split['elements']} elements, {comm.size} rank(s)")
        fig.tight_layout()
        fig.savefig(os.path.join(out, "bench.png"), dpi=120)


if __name__ == "__main__":
    main()

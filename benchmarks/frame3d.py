"""Benchmark of the 3D co-rotational beam on lattices of 10³, 10⁴ and 10⁵ elements (a script).

A cubic lattice of n×n×n cells (every grid edge a beam, 3n(n+1)² elements)
is clamped at its base and sheared by a horizontal load on its top nodes,
in 3 load steps. Reported per size: elements, dofs, Newton iterations, time
per iteration split into assembly (residual + tangent), solve (MUMPS) and
update, and the element throughput of the tangent assembly; assembly time
must grow linearly with the element count.

Writes output/frame3d_bench/{bench.csv, bench.json, bench.png}.
Usage: python benchmarks/frame3d.py [--sizes 7 15 32]
"""
import argparse
import json
import logging
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.assembly import System
from dolfinx_corot.io import from_arrays, output_dir

comm = MPI.COMM_WORLD
logging.basicConfig(level=logging.WARNING)
logging.getLogger("dolfinx_corot.solvers.control").setLevel(logging.INFO)


def say(*a):
    if comm.rank == 0:
        print(*a, flush=True)


def lattice(n, h=1.0):
    g = np.arange(n + 1) * h
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    pts = np.c_[X.ravel(), Y.ravel(), Z.ravel()]
    idx = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)
    cells = np.concatenate([np.c_[idx[:-1, :, :].ravel(), idx[1:, :, :].ravel()],
                            np.c_[idx[:, :-1, :].ravel(), idx[:, 1:, :].ravel()],
                            np.c_[idx[:, :, :-1].ravel(), idx[:, :, 1:].ravel()]])
    return from_arrays(pts, cells, "lattice", {"base": idx[:, :, 0].ravel(), "top": idx[:, :, -1].ravel()},
                       comm=comm)


def run(n):
    tm = lattice(n)
    sc = dc.Scene()
    # the orientation (1, 1, 1) is parallel to none of the grid edges
    beams = sc.add_beam(tm, "lattice", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1e5, 0.3),
                        orientation=(1.0, 1.0, 1.0))
    sc.fix(beams, "base")
    EI = 1e5 * 1e-4 / 12
    sc.load(beams, "top", force=(0.2 * EI / (n + 1) ** 2, 0.0, 0.0))
    t = time.perf_counter()
    system = System(sc.model)
    setup = time.perf_counter() - t
    system.residual(0.0)
    system.jacobian()  # compile/warm
    t = time.perf_counter()
    system.jacobian()
    t_tangent = comm.allreduce(time.perf_counter() - t, op=MPI.MAX)
    system.timings = type(system.timings)()
    t = time.perf_counter()
    res = dc.solve(sc, dc.LoadControl(steps=3), system=system)
    wall = comm.allreduce(time.perf_counter() - t, op=MPI.MAX)
    it = res.totals["newton_iterations"]
    tm_ = system.timings
    nel = 3 * n * (n + 1) ** 2
    row = {"n": n, "elements": nel, "dofs": 6 * (n + 1) ** 3, "ranks": comm.size, "setup_s": setup,
           "iterations": it, "wall_s": wall, "per_iteration_s": wall / it,
           "assembly_per_iteration_s": tm_.assembly / it, "solve_per_iteration_s": tm_.solve / it,
           "update_per_iteration_s": tm_.update / it, "tangent_assembly_s": t_tangent,
           "tangent_elements_per_s": nel / t_tangent}
    system.destroy()
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[7, 15, 32])
    args = ap.parse_args()
    out = output_dir("frame3d_bench")
    rows = []
    for n in args.sizes:
        r = run(n)
        rows.append(r)
        say(f"{r['elements']:7d} elements, {r['dofs']:7d} dofs, {comm.size} rank(s): {r['iterations']} iterations, "
            f"{r['per_iteration_s']:.3f} s/iteration = assembly {r['assembly_per_iteration_s']:.3f} + solve "
            f"{r['solve_per_iteration_s']:.3f} + update {r['update_per_iteration_s']:.4f}; tangent "
            f"{r['tangent_elements_per_s']:.3g} elements/s")
    from summary import peak_rss_MB, record

    rss = peak_rss_MB(comm)
    if comm.rank == 0:
        for r in rows:
            record("frame3d", f"{r['elements']} 3D beams, {r['dofs']} dofs, 3 steps", ranks=comm.size,
                   wall_s=r["wall_s"], solver_s=r["wall_s"],
                   peak_rss_MB=rss, newton_iterations=r["iterations"])
        cols = list(rows[0])
        np.savetxt(os.path.join(out, "bench.csv"), np.array([[r[c] for c in cols] for r in rows]), delimiter=",",
                   header=",".join(cols), comments="")
        with open(os.path.join(out, "bench.json"), "w") as f:
            json.dump(rows, f, indent=1)
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        ne = np.array([r["elements"] for r in rows])
        fig, ax = plt.subplots(figsize=(5.5, 4))
        for key, lab in (("assembly_per_iteration_s", "assembly"), ("solve_per_iteration_s", "solve (MUMPS)"),
                         ("update_per_iteration_s", "update")):
            ax.loglog(ne, [r[key] for r in rows], "o-", label=lab)
        ax.loglog(ne, rows[0]["assembly_per_iteration_s"] * ne / ne[0], "k:", lw=0.8, label="linear growth")
        ax.set_xlabel("beam elements")
        ax.set_ylabel("s per Newton iteration")
        ax.set_title(f"3D co-rotational lattice, {comm.size} rank(s)")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "bench.png"), dpi=120)


if __name__ == "__main__":
    main()

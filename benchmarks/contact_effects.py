"""Benchmark: what an idle contact interface costs (effects on demand).

Two elastic blocks (plane strain, SVK, nx × ny quadrilaterals each) side by side,
2 apart, each clamped at its base and bent by a top traction in 5 load steps:
they never come near each other. The same scene is solved without and with a
(two-pass, augmented-Lagrangian) interface between their facing sides, in
alternation, five times each; the best and the median wall times are
compared (target: at most 5 % more). Run-to-run noise on a shared 2-core
machine is ±10 %, more than the effect: the time spent inside the contact
code (search, kernels, assembly) is also measured directly, as a share of
the run.
Writes output/contact_effects/effects.{json,csv,png}.
Usage: python benchmarks/contact_effects.py [--mesh 60 60]
"""
import argparse
import json
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io import output_dir
from dolfinx_corot.io.mesh import rectangles

comm = MPI.COMM_WORLD


def blocks(nx, ny):
    return rectangles({"block0": (0.0, 0.0, 1.0, 1.0, nx, ny), "block1": (3.0, 0.0, 1.0, 1.0, nx, ny)},
                      {"base0": [("block0", "bottom")], "top0": [("block0", "top")], "inner0": [("block0", "right")],
                       "base1": [("block1", "bottom")], "top1": [("block1", "top")], "inner1": [("block1", "left")]},
                      comm=comm)


def run(nx, ny, with_contact):
    tm = blocks(nx, ny)
    sc = dc.Scene(linear_solver="direct")
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(1e3, 0.3), degree=1)
    for k in (0, 1):
        sc.fix(b, f"base{k}")
        sc.load(b, f"top{k}", traction=(5.0 if k == 0 else -5.0, 0.0))  # they bend away from each other
    if with_contact:
        sc.contact(slaves=(b, "inner0"), masters=(b, "inner1"), law=dc.AugmentedLagrangian(), symmetric=True)
    from dolfinx_corot.assembly import make_system

    t0 = time.perf_counter()
    system = make_system(sc.model, solver="direct", contributions=sc.contributions())
    res = dc.solve(sc, dc.LoadControl(steps=5), system=system)
    wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    contact = comm.allreduce(system.timings.contributions, op=MPI.MAX)
    system.destroy()
    return wall, int(res.totals["newton_iterations"]), sc.model.nodes()[1], contact


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mesh", type=int, nargs=2, default=[120, 120])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    times = {False: [], True: []}
    contact_times = []
    run(10, 10, True)  # compile/load the numba caches of the contact code once
    for _ in range(args.repeat):
        for flag in (False, True):
            wall, its, u, contact = run(*args.mesh, flag)
            times[flag].append(wall)
            if flag:
                contact_times.append(contact / wall)
            if flag:
                u_with = u
            else:
                u_without = u
    best = {k: min(v) for k, v in times.items()}
    median = {k: float(np.median(v)) for k, v in times.items()}
    data = {"mesh": args.mesh, "ranks": comm.size, "newton_iterations": its,
            "wall_without_s": best[False], "wall_with_s": best[True],
            "overhead": best[True] / best[False] - 1, "overhead_median": median[True] / median[False] - 1,
            "contact_share_of_wall": float(np.median(contact_times)),
            "all_times": {str(k): v for k, v in times.items()},
            "same_solution": bool(comm.rank != 0 or np.abs(u_with - u_without).max() == 0.0)}
    out = output_dir("contact_effects")
    from summary import peak_rss_MB, record

    rss = peak_rss_MB(comm)
    if comm.rank == 0:
        for flag, name in ((False, "without interface"), (True, "with an idle interface")):
            record("contact_effects", f"two {args.mesh[0]} × {args.mesh[1]} blocks, {name} (best of {args.repeat})",
                   ranks=comm.size, wall_s=best[flag], solver_s=best[flag], peak_rss_MB=rss, newton_iterations=its)
        print(json.dumps(data, indent=1))
        with open(os.path.join(out, "effects.json"), "w") as f:
            json.dump(data, f, indent=1)
        with open(os.path.join(out, "effects.csv"), "w") as f:
            f.write("scene,best_wall_s\n")
            f.write(f"without interface,{best[False]}\nwith idle interface,{best[True]}\n")
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(4.5, 3.5))
        ax.bar(["without\ninterface", "with idle\ninterface"], [best[False], best[True]])
        ax.set_ylabel("wall time, best of %d [s]" % args.repeat)
        ax.set_title(f"overhead {100 * data['overhead']:+.1f} % (best), "
                     f"{100 * data['overhead_median']:+.1f} % (median)", fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "effects.png"), dpi=110)
        plt.close(fig)


if __name__ == "__main__":
    main()

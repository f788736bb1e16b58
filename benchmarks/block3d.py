"""Benchmark: St Venant–Kirchhoff cantilever block in 3D (a script).

L = 10, 1 × 1 section, E = 1e5, ν = 0.3, clamped at x = 0, a transverse dead
traction on the end face with resultant 75, in 5 load steps; trilinear
hexahedra n_x × n_y × n_z (default 150 × 15 × 15: 116 736 dofs).
Reports the total time, Newton iterations, the split per iteration into
assembly / linear solve (preconditioner set-up included) and the peak
memory; writes output/block3d/bench_<mesh>_p<degree>_np<ranks>.{json,csv,png}
(summary, per-step history, tip deflection and time split).
Usage: python benchmarks/block3d.py [--mesh 150 15 15] [--degree 1] [--solver iterative|direct] [--rtol 1e-9]
"""
import argparse
import json
import os
import resource
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.assembly import make_system
from dolfinx_corot.io import output_dir
from dolfinx_corot.io.mesh import box

comm = MPI.COMM_WORLD


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mesh", type=int, nargs=3, default=[150, 15, 15])
    ap.add_argument("--degree", type=int, default=1)
    ap.add_argument("--solver", default="iterative")
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--forcing", action=argparse.BooleanOptionalAction, default=True,
                    help="inexact Newton (Eisenstat-Walker linear tolerances)")
    ap.add_argument("--extrapolate", action=argparse.BooleanOptionalAction, default=True,
                    help="secant predictor from the last two converged steps")
    ap.add_argument("--rtol", type=float, default=dc.NewtonOptions().rtol,
                    help="Newton's residual tolerance (relative to the force scale)")
    args = ap.parse_args()
    t0 = time.perf_counter()
    tm = box((10.0, 1.0, 1.0), args.mesh)
    scene = dc.Scene(linear_solver=args.solver)
    b = scene.add_solid(tm, material=dc.SaintVenantKirchhoff(1e5, 0.3), degree=args.degree)
    scene.fix(b, "x0")
    scene.load(b, "x1", traction=(0.0, -75.0, 0.0))
    has_tip = args.mesh[1] % 2 == 0 and args.mesh[2] % 2 == 0  # a node at the centre of the end face
    if has_tip:
        tm.add_point_group("tip", [(10.0, 0.5, 0.5)])
        scene.monitor("tip", b, "tip")
    system = make_system(scene.model, solver=args.solver)
    t_setup = time.perf_counter() - t0
    res = dc.solve(scene, dc.LoadControl(steps=args.steps, extrapolate=args.extrapolate,
                                                  newton=dc.NewtonOptions(forcing=args.forcing, rtol=args.rtol)),
                   system=system)
    wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    X, u = scene.model.nodes()
    tip = np.argmin(np.linalg.norm(X - np.array([10.0, 0.5, 0.5]), axis=1))
    tm_ = system.timings
    it = res.totals["newton_iterations"]
    ksp_its = system.linear.ksp.getIterationNumber()
    rss = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, op=MPI.SUM)
    data = {"mesh": args.mesh, "degree": args.degree, "solver": args.solver, "ranks": comm.size,
            "dofs": int(scene.model.V.dofmap.index_map.size_global * 3), "steps": len(res.history),
            "newton_iterations": it, "forcing": args.forcing, "extrapolate": args.extrapolate, "rtol": args.rtol,
            "block_operator": system.linear.operator is not None,
            "amg_builds": system.amg_builds + 1, "amg_corotations": system.amg_corotations,
            "krylov_iterations": system.krylov_iterations, "fallback_solves": system.fallback_solves, "wall_s": wall, "setup_s": t_setup, "assembly_s": tm_.assembly,
            "solve_s": tm_.solve, "assembly_per_iteration_s": tm_.assembly / it, "solve_per_iteration_s": tm_.solve / it,
            "last_krylov_iterations": ksp_its, "peak_rss_MB_all_ranks": rss,
            "tip_displacement": u[tip].tolist()}
    system.destroy()
    out = output_dir("block3d")  # collective
    if comm.rank == 0:
        from summary import record

        record("block3d", f"{data['dofs']} dofs, SVK, {data['steps']} steps", ranks=comm.size, wall_s=wall,
               solver_s=wall - t_setup, peak_rss_MB=rss, newton_iterations=it)
        print(json.dumps(data, indent=1))
        tol = "" if args.rtol == dc.NewtonOptions().rtol else f"_rtol{args.rtol:g}"
        stem = os.path.join(out, f"bench_{'x'.join(map(str, args.mesh))}_p{args.degree}_np{comm.size}{tol}")
        with open(stem + ".json", "w") as f:
            json.dump(data, f, indent=1)
        res.history.to_csv(stem + ".csv")
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(9, 3.5))
        lam = res.history.column("load_factor")
        if has_tip:
            ax.plot(lam, -res.history.column("tip_uy"), "o-")
            ax.set_ylabel("tip deflection")
        else:
            ax.plot(lam, res.history.column("iterations"), "o-")
            ax.set_ylabel("Newton iterations")
        ax.set_xlabel("load factor")
        ax2.bar(["assembly", "solve", "other"], [data["assembly_s"], data["solve_s"],
                                                 wall - data["assembly_s"] - data["solve_s"]])
        ax2.set_ylabel("s")
        ax2.set_title(f"{data['dofs']} dofs, {comm.size} rank(s): {wall:.1f} s")
        fig.tight_layout()
        fig.savefig(stem + ".png", dpi=110)
        plt.close(fig)


if __name__ == "__main__":
    main()

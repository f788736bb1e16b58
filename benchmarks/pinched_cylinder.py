"""Benchmark: the pinched cylinder with rigid end diaphragms, load drops along a displacement-driven
path (a script, not a test).

Sze, Liu & Lo (2004), Popular benchmark problems for geometric nonlinear analysis of shells,
*Finite Elem. Anal. Des.* 40, 1551–1569: R = 100, L = 200, t = 1, E = 3·10⁴, ν = 0.3, two
opposite radial point loads P at mid-length. An octant (x from the loaded section to a
diaphragm, θ over a quarter circle), structured shell triangles n_θ × n_x, symmetry on the
three planes, the diaphragm holding the end section's radial and circumferential motion; the
loaded point driven inwards to w = 80 (the loaded points meet at w = R), P = 4 × its reaction.

Along this path P grows; a step where P falls while w grows is a load drop. On coarse meshes
the section under the load folds into a crease about 3t wide that a row of flat triangles
cannot carry between its nodes: the crease stays on a node row, then hops to the next, and each
hop is a drop (arc length shows them as snap-backs of the discrete model). The script lists,
per mesh: the drops (count, count above 1 %, largest), where the run ended, P at w = 40, 60, 80,
Newton iterations and wall time; writes output/pinched_cylinder_bench/{bench.json, curves.csv,
curves.png}.
With --quads the same grids carry four-node shells (discrete Kirchhoff quadrilaterals).
Usage: python benchmarks/pinched_cylinder.py [--meshes 10x10 24x24 40x16] [--steps 80] [--w-max 80]
       [--tangent auto|consistent] [--rtol 1e-9] [--quads]
"""
import argparse
import json
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io import output_dir, write_rows
from dolfinx_corot.io.mesh import from_arrays

comm = MPI.COMM_WORLD
R, L, T, E, NU = 100.0, 200.0, 1.0, 3.0e4, 0.3


def octant(n_theta: int, n_x: int, quads: bool = False):
    """Nodes on the octant x ∈ [0, L/2], θ ∈ [0, π/2] (from the loaded point (0, 0, R) towards y),
    right-diagonal triangles (or the quadrilaterals of the grid), and the node groups of the
    conditions."""
    th = np.linspace(0.0, 0.5 * np.pi, n_theta + 1)
    xs = np.linspace(0.0, 0.5 * L, n_x + 1)
    TH, XS = np.meshgrid(th, xs, indexing="ij")
    points = np.c_[XS.ravel(), R * np.sin(TH.ravel()), R * np.cos(TH.ravel())]
    node = np.arange(len(points)).reshape(n_theta + 1, n_x + 1)
    a, b, c, d = node[:-1, :-1].ravel(), node[:-1, 1:].ravel(), node[1:, 1:].ravel(), node[1:, :-1].ravel()
    cells = np.c_[a, b, c, d] if quads else np.r_[np.c_[a, b, c], np.c_[a, c, d]]
    groups = {"mid": node[:, 0], "top": node[0, :], "side": node[-1, :], "end": node[:, -1], "A": node[:1, 0]}
    return points, cells, groups


def load_drops(P: np.ndarray) -> np.ndarray:
    """Relative falls (P_{k−1} − P_k)/P_{k−1} of the steps where P falls (w grows at every step)."""
    before = np.r_[0.0, P[:-1]]
    fall = before - P
    return fall[fall > 0.0] / before[fall > 0.0]


def run(n_theta: int, n_x: int, steps: int, w_max: float, tangent: str = "auto", rtol: float = 1e-9,
        quads: bool = False) -> dict:
    scene = dc.Scene(tangent=tangent)
    points, cells, groups = octant(n_theta, n_x, quads)
    shell = scene.add_shell(from_arrays(points, cells, "shell", groups, comm=comm), "shell",
                            thickness=T, material=dc.Elastic(E, NU))
    scene.fix(shell, "mid", dofs=("ux", "ry", "rz"))   # plane x = 0
    scene.fix(shell, "top", dofs=("uy", "rx", "rz"))   # plane y = 0
    scene.fix(shell, "side", dofs=("uz", "rx", "ry"))  # plane z = 0
    scene.fix(shell, "end", dofs=("uy", "uz"))         # the diaphragm
    scene.prescribe(shell, "A", uz=-w_max)
    scene.monitor_reaction("A", shell, "A")
    started = time.perf_counter()
    ended = "w_max"
    try:
        res = dc.solve(scene, dc.LoadControl(steps=steps, at_critical_point="continue",
                                             newton=dc.NewtonOptions(rtol=rtol)), quiet=True)
    except dc.ConvergenceError as err:  # the converged steps are kept
        res, ended = err.result, " ".join(str(err).split())[:160]
    wall = comm.allreduce(time.perf_counter() - started, op=MPI.MAX)
    P = -4.0 * res.history.column("A_Fz")
    w = w_max * res.history.column("load_factor")
    falls = load_drops(P)
    return {"mesh": f"{n_theta}x{n_x}" + (" quadrilaterals" if quads else ""), "steps_done": len(P), "w_end": float(w[-1]), "ended": ended,
            "drops": int(len(falls)), "drops_over_1pc": int(np.sum(falls > 0.01)),
            "largest_drop_pc": float(100.0 * falls.max()) if len(falls) else 0.0,
            **{f"P_at_w{int(x)}": float(np.interp(x, w, P)) if w[-1] >= x else None for x in (40, 60, 80)},
            "newton_iterations": int(res.totals["newton_iterations"]), "cuts": int(res.totals["cuts"]),
            "wall_s": wall, "w": w.tolist(), "P": P.tolist()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", nargs="+", default=["10x10", "24x24", "40x16"], help="n_theta x n_x")
    ap.add_argument("--steps", type=int, default=80)
    ap.add_argument("--w-max", type=float, default=80.0)
    ap.add_argument("--tangent", default="auto", help="auto, consistent or symmetrized")
    ap.add_argument("--rtol", type=float, default=1e-9, help="Newton's residual tolerance")
    ap.add_argument("--quads", action="store_true", help="four-node shells on the same grids")
    args = ap.parse_args()
    out = output_dir("pinched_cylinder_bench")
    rows = []
    for mesh in args.meshes:
        n_theta, n_x = (int(v) for v in mesh.split("x"))
        r = run(n_theta, n_x, args.steps, args.w_max, args.tangent, args.rtol, args.quads)
        rows.append(r)
        if comm.rank == 0:
            print(f"{r['mesh']:>6}: {r['drops']} drops ({r['drops_over_1pc']} over 1 %, largest "
                  f"{r['largest_drop_pc']:.1f} %), ended at w = {r['w_end']:.1f} ({r['ended']}); P at w = 40/60/80: "
                  + " / ".join("—" if r[k] is None else f"{r[k]:.0f}" for k in ("P_at_w40", "P_at_w60", "P_at_w80"))
                  + f"; {r['newton_iterations']} iterations, {r['wall_s']:.1f} s", flush=True)
    if comm.rank != 0:
        return
    with open(os.path.join(out, "bench.json"), "w") as f:
        json.dump({"steps": args.steps, "w_max": args.w_max,
                   "runs": [{k: v for k, v in r.items() if k not in ("w", "P")} for r in rows]}, f, indent=1)
    write_rows(os.path.join(out, "curves.csv"),
               [{"mesh": r["mesh"], "w": w, "P": P} for r in rows for w, P in zip(r["w"], r["P"])])
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for r in rows:
        ax.plot(r["w"], r["P"], ".-", ms=3, label=f"{r['mesh']}: {r['drops']} drops")
    ax.set_xlabel("deflection under the load w")
    ax.set_ylabel("pinching force P")
    ax.set_title("Pinched cylinder, displacement-driven")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "curves.png"), dpi=120)


if __name__ == "__main__":
    main()

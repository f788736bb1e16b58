"""Benchmark: Newton iterations of a tunnel lining in soft ground against mesh refinement.

A lining (ring of 2D beams, axis radius 1, depth 0.2, E = 3·10⁶) sits in a
circular hole (radius 1.1, centre 3 below the surface) of a soil block 10 × 7
(neo-Hookean, E = 1000, ν = 0.3; base clamped, sides on rollers). The soil's
own weight (unit weight 20) and a surcharge of 50 on its surface are applied
in 4 load steps; the soil settles by about 0.33 around the lining and carries
it down (symmetric augmented-Lagrangian contact, smooth master curves; the
lining's crown and invert are held horizontally, which stops its free spin).
Meshes k = 1, 2, 4, 8: 32k hole segments, 24k lining elements, the soil
refined towards the hole.

Each contact node moves by several master segments in a step while staying
in contact: a cap on each node's correction (half a master segment) makes
Newton crawl, a cap on the motion relative to its master does not.
Writes output/lining_soft_ground/iterations.{json,csv,png}.
Usage: python benchmarks/lining_soft_ground.py [--meshes 1 2 4 8]
"""
import argparse
import json
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io import output_dir, write_rows
from dolfinx_corot.io.gmsh_models import graded_block_with_hole

comm = MPI.COMM_WORLD
R, H, CENTRE = 1.0, 0.2, 3.0  # lining axis radius and depth; depth of its centre
WIDTH, DEPTH = 10.0, 7.0      # soil block


def soil_mesh(segments: int):
    """The soil block [−5, 5] × [−7, 0] with the hole (radius R + H/2, ``segments`` equal segments),
    groups soil, base, sides, surface, cavity; elements 2π(R + H/2)/segments at the hole, 0.6 far off."""
    return graded_block_with_hole(WIDTH, DEPTH, CENTRE, R + H / 2, segments, 0.6, comm=comm)


def lining_mesh(n: int):
    a = 2 * np.pi * np.arange(n) / n - np.pi / 2  # node 0 at the invert
    X = np.column_stack([R * np.cos(a), -CENTRE + R * np.sin(a)])
    return dc.io.mesh.from_arrays(X, np.column_stack([np.arange(n), (np.arange(n) + 1) % n]), "lining",
                                  point_groups={"invert": np.array([0]), "crown": np.array([n // 2]),
                                                "axis_nodes": np.array([0, n // 2])}, comm=comm)


def scene(k: int):
    sc = dc.Scene()
    soil = sc.add_solid(soil_mesh(32 * k), material=dc.NeoHookean(1.0e3, 0.3), degree=1)
    lining = sc.add_beam(lining_mesh(24 * k), section=dc.Rectangle(1.0, H), material=dc.Elastic(3.0e6, 0.2))
    sc.fix(soil, "base")
    sc.fix(soil, "sides", dofs=("ux",))
    sc.fix(lining, "axis_nodes", dofs=("ux",))
    sc.gravity(soil, (0.0, -1.0), 20.0)
    sc.load(soil, "surface", traction=(0.0, -50.0))
    sc.monitor("invert", lining, "invert")
    sc.monitor_reaction("base", soil, "base")
    sc.contact(slaves=(lining, "lining"), masters=(soil, "cavity"), law=dc.AugmentedLagrangian(), symmetric=True)
    return sc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", type=int, nargs="+", default=[1, 2, 4, 8])
    args = ap.parse_args()
    rows = []
    for k in args.meshes:
        sc = scene(k)
        t0 = time.perf_counter()
        res = dc.solve(sc, dc.LoadControl(steps=4))
        wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
        h = res.history
        rows.append({"k": k, "hole_segments": 32 * k, "lining_elements": 24 * k,
                     "newton_iterations": int(h.column("iterations").sum()),
                     "per_step": " ".join(str(int(i)) for i in h.column("iterations")),
                     "cuts": int(h.column("cuts").sum()), "invert_settlement": -float(h.column("invert_uy")[-1]),
                     "base_Fy": float(h.column("base_Fy")[-1]), "wall_s": wall})
        if comm.rank == 0:
            print(json.dumps(rows[-1]), flush=True)
    out = output_dir("lining_soft_ground")
    from summary import peak_rss_MB, record

    rss = peak_rss_MB(comm)
    if comm.rank == 0:
        for r in rows:
            record("lining_soft_ground", f"{r['hole_segments']} hole segments, {r['lining_elements']} beams, 4 steps",
                   ranks=comm.size, wall_s=r["wall_s"], solver_s=r["wall_s"], peak_rss_MB=rss,
                   newton_iterations=r["newton_iterations"])
        write_rows(f"{out}/iterations.csv", rows)
        with open(f"{out}/iterations.json", "w") as fh:
            json.dump({"ranks": comm.size, "rows": rows}, fh, indent=1)
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 3.5))
        ax.plot([r["hole_segments"] for r in rows], [r["newton_iterations"] for r in rows], "o-")
        ax.set(xscale="log", xlabel="hole segments", ylabel="Newton iterations (4 steps)",
               title="lining in soft ground")
        fig.tight_layout()
        fig.savefig(f"{out}/iterations.png", dpi=120)
        plt.close(fig)


if __name__ == "__main__":
    main()

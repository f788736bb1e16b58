"""Hertz line contact of two equal elastic bodies, the peer comparison's set-up (a script, not a test).

Plane strain: an elastic half cylinder of radius R = 8 (its flat face up) on an elastic block
16 wide and 8 deep, both E = 2·10⁵, ν = 0.3, small strain; half model (symmetry on x = 0), the
block's bottom clamped, the cylinder's flat top driven down by a prescribed displacement of 0.1
in 4 steps. The contact: the cylinder's arc against the block's top, two-pass (symmetric), the
augmented Lagrangian. Hertz for two equal cylinders-on-flat bodies: E* = E / (2 (1 − ν²)),
a = √(4FR / (π E*)), p₀ = 2F / (π a), F = twice the half model's reaction. The half-width and
the peak pressure of the computed contact are those of Hertz's ellipse p² = p₀² (1 − x²/a²)
fitted to the nodal pressures (both passes combined); each is compared with Hertz's value at
the computed F. Three meshes (size h near the contact point, growing to R/8 away from it).

Writes output/hertz_same/{hertz_same.json, hertz_same.csv, hertz_same.png}.
Usage: python benchmarks/hertz_same.py [--sizes 0.2 0.1 0.05]
"""
import argparse
import json
import os
import resource
import time

import gmsh
import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.closed_forms import hertz_ellipse_fit
from dolfinx_corot.io import write_rows
from dolfinx_corot.io.mesh import name_groups, size_field

comm = MPI.COMM_WORLD
R, DEPTH, E, NU, PUSH = 8.0, 8.0, 2.0e5, 0.3, 0.1


def mesh(h: float):
    """Quarter disc (centre (0, R), touching the block at the origin) on the block [0, R] × [−DEPTH, 0];
    size h within 2 of the contact point on both bodies, R/8 beyond 6."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        c, b, a = g.addPoint(0, R, 0), g.addPoint(0, 0, 0), g.addPoint(R, R, 0)
        arc, top, axis = g.addCircleArc(b, c, a), g.addLine(a, c), g.addLine(c, b)
        cyl = g.addPlaneSurface([g.addCurveLoop([arc, top, axis])])
        f = [g.addPoint(x, y, 0) for x, y in ((0, 0), (R, 0), (R, -DEPTH), (0, -DEPTH))]
        ftop, fright, fbase, faxis = (g.addLine(f[i], f[(i + 1) % 4]) for i in range(4))
        block = g.addPlaneSurface([g.addCurveLoop([ftop, fright, fbase, faxis])])
        g.synchronize()
        field = gmsh.model.mesh.field
        field.add("Distance", 1)
        field.setNumbers(1, "PointsList", [b, f[0]])
        field.add("Threshold", 2)
        field.setNumber(2, "InField", 1)
        for key, value in (("SizeMin", h), ("SizeMax", R / 8), ("DistMin", 2.0), ("DistMax", 6.0)):
            field.setNumber(2, key, value)
        size_field(2)
        name_groups({"cylinder": (2, [cyl]), "block": (2, [block]), "arc": (1, [arc]), "load": (1, [top]),
                     "axis": (1, [axis, faxis]), "block_top": (1, [ftop]), "base": (1, [fbase])})
        gmsh.model.mesh.generate(2)
    tm = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def run(h: float, steps: int = 4) -> dict:
    t0 = time.perf_counter()
    tm = mesh(h)
    sc = dc.Scene(large_rotations=False)
    body = sc.add_solid(tm, material=dc.Elastic(E, NU), degree=1)
    sc.fix(body, "base")
    sc.fix(body, "axis", dofs=("ux",))
    sc.prescribe(body, "load", uy=-PUSH)
    sc.monitor_reaction("load", body, "load")
    pair = sc.contact(slaves=(body, "arc"), masters=(body, "block_top"), symmetric=True,
                      law=dc.AugmentedLagrangian(gap_tolerance=1e-4))
    t1 = time.perf_counter()
    res = dc.solve(sc, dc.LoadControl(steps=steps), quiet=True)
    t2 = time.perf_counter()
    F = 2.0 * abs(res.history.column("load_Fy")[-1])
    star = E / (2.0 * (1.0 - NU**2))
    a = np.sqrt(4.0 * F * R / (np.pi * star))
    p0 = 2.0 * F / (np.pi * a)
    side = pair.pressure("masters")  # on the block's top (both passes combined)
    p0_fe, a_fe = hertz_ellipse_fit(side.x[:, 0], side.pressure)
    cells = comm.allreduce(tm.mesh.topology.index_map(2).size_local)
    return {"h": h, "cells": cells, "F": F, "a_hertz": a, "p0_hertz": p0, "a": a_fe, "p0": p0_fe,
            "a_error": a_fe / a - 1.0, "p0_error": p0_fe / p0 - 1.0, "a_over_h": a / h,
            "newton_iterations": int(res.totals["newton_iterations"]), "cuts": int(res.totals["cuts"]),
            "wall_s": t2 - t0, "solve_s": t2 - t1, "setup_s": t1 - t0,
            "peak_rss_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=float, nargs="+", default=[0.2, 0.1, 0.05])
    args = parser.parse_args()
    rows = [run(h) for h in args.sizes]
    if comm.rank == 0:
        from summary import record

        for r in rows:
            record("hertz_same", f"h = {r['h']:g}", ranks=comm.size, wall_s=r["wall_s"], solver_s=r["solve_s"],
                   peak_rss_MB=r["peak_rss_MB"], newton_iterations=r["newton_iterations"],
                   error=f"p0 {r['p0_error']:+.2%}, a {r['a_error']:+.2%}", reference="Hertz, E* = E/(2(1 − ν²))")
        out = os.path.join(os.environ.get("DC_OUTPUT_DIR", "output"), "hertz_same")
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, "hertz_same.json"), "w") as f:
            json.dump({"ranks": comm.size, "rows": rows}, f, indent=1)
        write_rows(os.path.join(out, "hertz_same.csv"), rows)
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6, 4))
        ax = fig.subplots()
        for key, mark in (("p0_error", "o-"), ("a_error", "s--")):
            ax.loglog([r["wall_s"] for r in rows], [abs(r[key]) for r in rows], mark, label=f"|{key.split('_')[0]} error|")
        for r in rows:
            ax.annotate(f"h = {r['h']:g}", (r["wall_s"], abs(r["p0_error"])), fontsize=7)
        ax.axhline(0.01, color="0.5", ls=":", lw=0.8, label="1 %")
        ax.set(xlabel="wall time of the whole run [s]", ylabel="relative error against Hertz",
               title="Hertz, two equal elastic bodies")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "hertz_same.png"), dpi=110)
        for r in rows:
            print(f"h = {r['h']:5.3f} ({r['cells']:6d} cells, a/h = {r['a_over_h']:5.1f}): F = {r['F']:9.2f}, "
                  f"p0 {r['p0']:9.2f} ({r['p0_error']:+.2%} of Hertz), a {r['a']:.4f} ({r['a_error']:+.2%}); "
                  f"{r['newton_iterations']} Newton its, {r['cuts']} cuts; {r['wall_s']:.2f} s "
                  f"(solve {r['solve_s']:.2f} s), {r['peak_rss_MB']:.0f} MB")


if __name__ == "__main__":
    main()

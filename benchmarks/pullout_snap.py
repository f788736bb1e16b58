"""The pull-out's snap (seed §2.4.1): its limit point converged over meshes of both shell families
(a script, not a test).

The open cylinder of ``demos/cylinder_pullout.py`` (Sze, Liu & Lo 2004, §3.5), driven by the
radial displacement w_A of the load point, in steps of 0.1 to w_A = 2.3, then of ``--dw``
(0.0025) to 2.6, where the pulled section snaps flat. Along the driven path the force P rises to
a maximum near w_A = 2.49 and falls a little before the band stiffens: a limit point of the
shell under point load. Per mesh and family: the local maxima of P(w_A), the limit load, where
it lies, the fall of P after it (to the valley) and, where a mesh shows no maximum, where the
path is flattest and its least slope dP/dw_A. The limit load and the fall are extrapolated from
the two finest meshes of each family as h² (h = 1/n_θ).

Measured (steps of 0.0025; OPT triangles / DKQ quadrilaterals on the same nodes):

| n_θ × n_x | OPT: P_max, fall | quadrilaterals: P_max, fall |
|---|---|---|
| 8 × 12 | 19 976, 2.34 % | none (flattest at 21 702, dP/dw_A 19 400) |
| 12 × 18 | 20 403, 1.81 % | none (21 056, dP/dw_A 5 350) |
| 16 × 24 | 20 581, 1.16 % | 20 882, 0.005 % |
| 24 × 36 | 20 693, 0.65 % | 20 807, 0.15 % |
| 48 × 72 | 20 758, 0.40 % | 20 787, 0.26 % |
| h² extrapolation | 20 779, 0.32 % | 20 780, 0.30 % |

Writes output/pullout_snap/{snap.json, snap.csv, snap.png}.
Usage: python benchmarks/pullout_snap.py [--meshes 8 12 12 18 16 24 24 36 48 72] [--dw 0.0025]
"""
import argparse
import json
import os
import sys

import numpy as np
from mpi4py import MPI

from dolfinx_corot.io import output_dir, write_rows

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "demos"))
import cylinder_pullout as demo  # noqa: E402  (the demo's geometry, material and measures)

comm = MPI.COMM_WORLD
FAMILIES = {"opt": "triangles (OPT + DKT)", "qm6": "quadrilaterals (DKQ)"}


def path(n_theta, n_x, membrane, dw, w_max=2.6):
    """(P, w_A) along the driven path (the demo's scene, driven to ``w_max``), the wall time and
    the Newton iterations."""
    steps = np.r_[np.arange(1, 24) * 0.1, np.arange(2.3 + dw, w_max + 0.5 * dw, dw)]
    curve, res, wall = demo.pullout(n_theta, n_x, w_max=w_max, membrane=membrane, w_steps=steps)
    return curve, wall, res.totals["newton_iterations"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", type=int, nargs="+", default=[8, 12, 12, 18, 16, 24, 24, 36, 48, 72],
                    help="pairs n_theta n_x")
    ap.add_argument("--dw", type=float, default=0.0025, help="step of w_A across the snap")
    args = ap.parse_args()
    meshes = list(zip(args.meshes[::2], args.meshes[1::2]))
    rows, curves = [], {}
    for membrane in FAMILIES:
        for n_theta, n_x in meshes:
            curve, wall, its = path(n_theta, n_x, membrane, args.dw)
            point = demo.snap_point(curve)
            maxima, p_max, w_max, fall, least = (point[k] for k in ("maxima", "P", "wA", "fall", "least_slope"))
            rows.append({"family": membrane, "n_theta": n_theta, "n_x": n_x, "maxima": maxima, "P_max": p_max,
                         "wA_at_P_max": w_max, "fall": fall, "least_slope": least, "wall_s": wall,
                         "iterations": its})
            curves[(membrane, n_theta)] = (curve[:, 1], curve[:, 0])
            if comm.rank == 0:
                what = (f"P_max {p_max:.1f} at w_A {w_max:.4f}, fall {100 * fall:.3f} %" if maxima
                        else f"no maximum; flattest at P {p_max:.1f}, w_A {w_max:.4f}, dP/dw_A {least:.0f}")
                print(f"{FAMILIES[membrane]:>24s} {n_theta:2d} x {n_x:2d}: {what}; {wall:.1f} s, {its} iterations",
                      flush=True)
    extrapolated = {}
    for membrane in FAMILIES:
        (a, b) = [r for r in rows if r["family"] == membrane][-2:]
        q = (b["n_theta"] / a["n_theta"]) ** 2
        extrapolated[membrane] = {key: b[key] + (b[key] - a[key]) / (q - 1.0) for key in ("P_max", "fall")}
    out = output_dir("pullout_snap")  # collective
    if comm.rank == 0:
        for membrane, e in extrapolated.items():
            print(f"{FAMILIES[membrane]:>24s}, extrapolated as h²: P_max {e['P_max']:.0f}, fall {100 * e['fall']:.2f} %")
        with open(os.path.join(out, "snap.json"), "w") as f:
            json.dump({"dw": args.dw, "rows": rows, "extrapolated": extrapolated}, f, indent=1)
        write_rows(os.path.join(out, "snap.csv"), rows)
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        for (membrane, n_theta), (w, P) in curves.items():
            m = (w > 2.40) & (w < 2.60)
            ax.plot(w[m], P[m], "-" if membrane == "opt" else "--", label=f"{FAMILIES[membrane]}, {n_theta} cells")
        ax.set(xlabel="$w_A$", ylabel="P", title="Pull-out: the snap's limit point (1/8 model)")
        ax.legend(fontsize=7)
        fig.savefig(os.path.join(out, "snap.png"), dpi=120, bbox_inches="tight")


if __name__ == "__main__":
    main()

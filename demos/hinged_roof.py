# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # A hinged cylindrical roof snaps through (Sabir & Lock; Sze, Liu & Lo 2004, §3.8)
#
# The shallow roof of Sabir & Lock (1972), as tabulated by Sze, Liu & Lo (2004, §3.8, the
# isotropic roof of thickness 12.7): a cylindrical panel of radius $R = 2540$, length
# $L = 508$ along its axis and opening angle $2\theta = 0.2$ rad, rise 12.7 at the crown;
# $t = 12.7$, $E = 3102.75$, $\nu = 0.3$. The straight edges are hinged (translations
# fixed, rotations free), the curved edges free. A point force $P$ at the centre C pushes the
# roof down: the force rises to a maximum, falls as the roof snaps through, and rises steeply
# once the roof hangs inverted. The central deflection $W_C$ is prescribed (displacement
# control), so the whole path is followed, its limit point included, without arc length.
#
# One quarter is modelled (symmetry on the planes through C), meshed in code as a structured
# grid of flat co-rotational triangles (OPT membrane, DKT bending) and the same grid of
# four-node shells (incompatible-mode membrane, DKQ bending): the same nodes, $n \times n$
# squares on the quarter.
#
# Reference: the load–deflection table of Sze, Liu & Lo (2004), P/P_max against −W_C with
# P_max = 3000 (the whole roof), from ABAQUS S4R on a fine mesh. Checked: the limit load and
# the valley after the snap (both refined by a parabola through the points around them, ours
# and the table's alike), the distance of the table's points from our path up to the valley,
# and the deflection where the inverted roof carries P = 3000.

# %%
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io import from_arrays
from dolfinx_corot.result import limit_load, path_distance

comm = MPI.COMM_WORLD
R, L, THETA, t, E, nu = 2540.0, 508.0, 0.1, 12.7, 3102.75, 0.3
P_MAX = 3000.0  # the table's P_max
W_END = 30.0    # the prescribed central deflection at the end of the path
SZE = "Sze, Liu & Lo (2004), §3.8: hinged cylindrical roof, t = 12.7, isotropic (ABAQUS S4R)"
# Sze, Liu & Lo (2004), the isotropic roof of thickness 12.7: (P/P_max, −W_C)
TABLE = np.array([
    [0.0000, 0.000], [0.0877, 0.693], [0.1980, 1.638], [0.3473, 3.087], [0.4686, 4.477],
    [0.5647, 5.802], [0.6381, 7.057], [0.6908, 8.237], [0.7246, 9.339], [0.7412, 10.358],
    [0.7421, 11.293], [0.7286, 12.141], [0.7023, 12.903], [0.6649, 13.583], [0.6182, 14.188],
    [0.5643, 14.728], [0.5055, 15.217], [0.4442, 15.676], [0.3830, 16.125], [0.3245, 16.590],
    [0.2717, 17.094], [0.2272, 17.657], [0.1940, 18.299], [0.1750, 19.028], [0.1729, 19.852],
    [0.1905, 20.771], [0.2303, 21.780], [0.2950, 22.875], [0.3871, 24.049], [0.4443, 24.663],
    [0.5093, 25.293], [0.5826, 25.940], [0.6644, 26.601], [0.7551, 27.276], [0.8549, 27.964],
    [0.9643, 28.663], [1.0835, 29.374]])
W_REF, P_REF = TABLE[:, 1], P_MAX * TABLE[:, 0]
SZE_LAMINATE = ("Sze, Liu & Lo (2004), §3.8: hinged cylindrical roof, t = 12.7, laminate [0/90/0] "
                "(E1 = 3300, E2 = 1100, G = 660, ν12 = 0.25; ABAQUS S4R)")
# the same roof as a laminate [0/90/0] of three equal plies, 0° along the axis: (P/P_max, −W_C)
TABLE_LAMINATE = np.array([
    [0.0000, 0.000], [0.0546, 0.807], [0.1245, 1.956], [0.1938, 3.281], [0.2494, 4.548],
    [0.2925, 5.753], [0.3244, 6.892], [0.3459, 7.961], [0.3582, 8.959], [0.3618, 9.884],
    [0.3577, 10.735], [0.3464, 11.516], [0.3288, 12.227], [0.3057, 12.872], [0.2778, 13.458],
    [0.2461, 13.990], [0.2115, 14.477], [0.1749, 14.928], [0.0999, 15.774], [0.0638, 16.199],
    [0.0303, 16.648], [0.0007, 17.141], [-0.0236, 17.692], [-0.0411, 18.317], [-0.0504, 19.024],
    [-0.0503, 19.817], [-0.0394, 20.698], [-0.0165, 21.663], [0.0194, 22.707], [0.0697, 23.824],
    [0.1354, 25.005], [0.2178, 26.244], [0.3181, 27.533], [0.4374, 28.864], [0.5769, 30.229],
    [0.7374, 31.622], [1.0192, 33.748]])
PLY = dc.Orthotropic(E1=3300.0, E2=1100.0, G12=660.0, nu12=0.25, G13=660.0, G23=660.0)


def quarter_roof(n, quads=False):
    """The quarter x ∈ [0, L/2], φ ∈ [0, θ] (C at x = 0, φ = 0), n × n squares."""
    xs, phis = np.linspace(0.0, L / 2, n + 1), np.linspace(0.0, THETA, n + 1)
    pts = np.array([(x, R * np.sin(p), R * np.cos(p)) for p in phis for x in xs])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)  # [φ, x]
    a0, a1, b0, b1 = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    cells = np.c_[a0, a1, b1, b0] if quads else np.concatenate([np.c_[a0, a1, b1], np.c_[a0, b1, b0]])
    groups = {"mid": idx[:, 0], "crown": idx[0, :], "hinged": idx[-1, :], "C": [0]}
    return from_arrays(pts, cells, "roof", groups, comm=comm)


def roof(n, quads=False, steps=60, laminate=False, w_end=W_END, demo=None):
    """(W_C, P) from the unloaded state (the whole roof's force), the result and the wall time;
    ``laminate``: three equal plies [0/90/0], 0° along the roof's axis; with ``demo``, the
    quarter at W_C = 7.5, 15, 22.5 and 30 in ``roof_shapes.png``."""
    scene = dc.Scene(large_rotations=True)
    if laminate:
        section = dc.Laminate([dc.Ply(t / 3, angle, PLY) for angle in (0.0, 90.0, 0.0)])
        shell = scene.add_shell(quarter_roof(n, quads), "roof", section=section, axis=(1.0, 0.0, 0.0))
    else:
        shell = scene.add_shell(quarter_roof(n, quads), "roof", thickness=t, material=dc.Elastic(E, nu))
    scene.fix(shell, "mid", dofs=("ux", "ry", "rz"))     # plane x = 0
    scene.fix(shell, "crown", dofs=("uy", "rx", "rz"))   # plane y = 0
    scene.fix(shell, "hinged", dofs=("ux", "uy", "uz"))  # the straight edge: hinged
    scene.prescribe(shell, "C", uz=-w_end)
    scene.monitor_reaction("C", shell, "C")
    shots = dc.plot.Snapshots(scene, at=(0.25, 0.5, 0.75, 1.0)) if demo is not None else None
    res, wall = timed(dc.solve, scene, dc.LoadControl(steps=steps), on_step=shots)
    if demo is not None:  # the last state first: the views share the first one's camera
        demo.picture(shots.states, "roof_shapes.png", field="displacement", layout="grid", columns=2,
                     window_size=(1200, 900), title=f"Hinged roof ({n} x {n} quarter)")
    w = np.r_[0.0, w_end * res.history.column("load_factor")]
    P = np.r_[0.0, -4.0 * res.history.column("C_Fz")]  # four quarters
    return w, P, res, wall


def extrema(w, P):
    """(limit load, valley after the snap, deflection where P = P_max on the inverted branch)."""
    peak = limit_load(P, w)
    k = int(np.flatnonzero(np.diff(P) < 0)[0])
    valley = -limit_load(-P[k:], w[k:])
    rising = w > w[k + int(np.argmin(P[k:]))]
    return peak, valley, float(np.interp(P_MAX, P[rising], w[rising]))


PEAK_REF, VALLEY_REF, W3000_REF = extrema(W_REF, P_REF)
LAMINATE_REF = extrema(TABLE_LAMINATE[:, 1], P_MAX * TABLE_LAMINATE[:, 0])


def path_error(w, P):
    """Largest distance of the table's points up to the valley from our path, with W_C scaled by
    its value at the table's valley and P by the table's limit load (the descending branch is
    steep: a distance, not a difference of P at equal W_C)."""
    w_scale = W_REF[np.argmin(np.where(W_REF > 15.0, P_REF, np.inf))]
    table = np.c_[W_REF, P_REF][W_REF <= 20.0]
    return float(path_distance(np.c_[w, P], table, [w_scale, PEAK_REF]).max())


# %% [markdown]
# ## Three meshes of each family

# %%
def three_meshes(demo, quads=False):
    rows, curves = [], {}
    family = "quadrilaterals" if quads else "triangles"
    meshes = [4, 8, 16] if demo.ci else [8, 16, 32]
    for n in meshes:
        w, P, res, wall = roof(n, quads, demo=demo if quads and n == meshes[-1] else None)
        peak, valley, w3000 = extrema(w, P)
        curves[n] = (w, P)
        rows.append((n, peak, valley, w3000, path_error(w, P), wall, res.totals["newton_iterations"],
                     res.totals["cuts"], int(np.sum((P[1:-1] > P[:-2]) & (P[1:-1] > P[2:]))),
                     int(np.sum((P[1:-1] < P[:-2]) & (P[1:-1] < P[2:])))))
        demo.say(f"{family:>14s} {n:2d} x {n:2d}: P_max = {peak:.1f} ({100 * (peak / PEAK_REF - 1):+.2f} %), "
                 f"valley {valley:.1f} ({100 * (valley / VALLEY_REF - 1):+.2f} %), W_C at P = 3000 {w3000:.3f} "
                 f"({100 * (w3000 / W3000_REF - 1):+.2f} %), path {100 * rows[-1][4]:.2f} %, {wall:.1f} s, "
                 f"{res.totals['newton_iterations']} iterations, {res.totals['cuts']} cuts")
    rows = np.array(rows)
    demo.table(f"mesh_convergence_{family}.csv", rows,
               ["n", "P_max", "P_valley", "W_C_at_3000", "path_error", "wall_s", "iterations", "cuts",
                "maxima", "minima"])
    return rows, curves


def plot(demo, tri, quad):
    fig, ax = demo.figure(figsize=(6.4, 4.4))
    ax.plot(W_REF, P_REF, "ks", ms=4, mfc="none", label="Sze, Liu & Lo (2004)")
    for (curves, family, style) in ((tri, "triangles", "-"), (quad, "quadrilaterals", "--")):
        for n, (w, P) in curves.items():
            ax.plot(w, P, style, lw=1.2, label=f"{family}, {n}×{n} (quarter)")
    ax.set(xlabel="central deflection $-W_C$", ylabel="central force P (whole roof)",
           title="Hinged cylindrical roof, t = 12.7: snap-through")
    ax.legend(fontsize=7)
    demo.save(fig, "hinged_roof.png")


# %% [markdown]
# ## The roof as a laminate
#
# Sze, Liu & Lo also tabulate the same roof as a cross-ply laminate [0/90/0] (three equal
# plies, 0° along the axis; $E_1 = 3300$, $E_2 = 1100$, $G_{12} = G_{13} = G_{23} = 660$,
# $\nu_{12} = 0.25$; lamination theory, `dc.Laminate`). It is much softer: the limit load is
# about a third of the isotropic roof's, and after the snap the force turns negative (the
# roof pulls the load point) before the inverted roof takes load again.

# %%
def laminated_roof(demo):
    """(family, n, P_max, valley, W_C at P = 3000, wall) on one mesh of each family."""
    n = 8 if demo.ci else 16
    rows = []
    for quads in (False, True):
        w, P, res, wall = roof(n, quads, steps=69, laminate=True, w_end=34.5)
        peak, valley, w3000 = extrema(w, P)
        rows.append((float(quads), n, peak, valley, w3000, wall))
        demo.say(f"laminate [0/90/0], {'quadrilaterals' if quads else 'triangles'} {n} x {n}: P_max = {peak:.1f} "
                 f"({100 * (peak / LAMINATE_REF[0] - 1):+.2f} %), valley {valley:.1f} (table {LAMINATE_REF[1]:.1f}), "
                 f"W_C at P = 3000 {w3000:.3f} ({100 * (w3000 / LAMINATE_REF[2] - 1):+.2f} %), {wall:.1f} s, "
                 f"{res.totals['cuts']} cuts")
    rows = np.array(rows)
    demo.table("laminate.csv", rows, ["quadrilaterals", "n", "P_max", "P_valley", "W_C_at_3000", "wall_s"])
    return rows


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("hinged_roof")
    demo.say(f"Sze's table: limit load {PEAK_REF:.1f}, valley {VALLEY_REF:.1f}, W_C at P = 3000 {W3000_REF:.3f}")
    tri, tri_curves = three_meshes(demo)
    quad, quad_curves = three_meshes(demo, quads=True)
    plot(demo, tri_curves, quad_curves)
    laminated = laminated_roof(demo)
    for rows, label in ((tri, "triangles (OPT + DKT)"), (quad, "quadrilaterals (DKQ)")):
        demo.work_precision(rows[:, 0].astype(int), rows[:, 1] / PEAK_REF - 1.0, rows[:, 5], series=label,
                            quantity="limit load (squares along an edge of the quarter)", reference=SZE)
    demo.record(triangles=tri[:, 1:5], quadrilaterals=quad[:, 1:5])
    w, P = list(quad_curves.values())[-1]
    demo.record(load_factor=w / W_END, W_C=w, P=P)
    solver = "solver acceptance (no published value)"
    for rows, family in ((tri, "triangles"), (quad, "quadrilaterals")):
        demo.check(f"{family}: limit load on the finest mesh", rows[-1, 1], PEAK_REF, rtol=0.005, reference=SZE)
        demo.check(f"{family}: valley after the snap on the finest mesh", rows[-1, 2], VALLEY_REF, rtol=0.025,
                   reference=SZE)
        demo.check(f"{family}: path up to the valley, largest distance of the table's points (W_C / W_valley, "
                   "P / P_limit), finest mesh", rows[-1, 4], bound=0.01, reference=SZE)
        demo.check(f"{family}: W_C where the inverted roof carries P = 3000, finest mesh", rows[-1, 3], W3000_REF,
                   rtol=0.01, reference=SZE)
        demo.check(f"{family}: local maxima and minima of P along the driven path, every mesh (the limit point "
                   "and the valley alone)", rows[:, 8:10], 1, reference="the roof's one snap: no spurious load drop")
        demo.check(f"{family}: cut load steps, every mesh", rows[:, 7], bound=0, reference=solver)
        d1, d2 = abs(rows[1, 1] - rows[0, 1]), abs(rows[2, 1] - rows[1, 1])
        demo.check(f"{family}: change of the limit load on the last refinement / on the first", d2 / d1, bound=0.5,
                   reference="self-convergence (the table itself is a converged S4R solution)")
    for row in laminated:
        family = "quadrilaterals" if row[0] else "triangles"
        demo.check(f"laminate, {family}: limit load", row[2], LAMINATE_REF[0], rtol=0.01, reference=SZE_LAMINATE)
        demo.check(f"laminate, {family}: valley (negative: the roof pulls) / limit load",
                   (row[3] - LAMINATE_REF[1]) / LAMINATE_REF[0], 0.0, atol=0.01, reference=SZE_LAMINATE)
        demo.check(f"laminate, {family}: W_C where the inverted roof carries P = 3000", row[4], LAMINATE_REF[2],
                   rtol=0.01, reference=SZE_LAMINATE)
    demo.record(laminate=laminated[:, 2:5])
    demo.check("quadrilaterals / triangles: error of the limit load on the coarsest mesh (the same nodes)",
               abs(quad[0, 1] / PEAK_REF - 1.0) / abs(tri[0, 1] / PEAK_REF - 1.0), bound=1.0, reference=SZE)
    demo.check("quadrilaterals / triangles: path error on the coarsest mesh (the same nodes)",
               quad[0, 4] / tri[0, 4], bound=1.0, reference=SZE)
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Euler buckling of a continuum column in plane strain
#
# Seed §2.5.1: a column $L = 10$ m long and $H = 1$ m deep, $E = 10^5$ kPa,
# $\nu = 0$, plane strain (per metre), clamped at $x = 0$, is compressed by
# an imposed horizontal displacement of the node at mid-depth of its free
# end; the force is the reaction there. One element has its modulus halved
# (the imperfection; on fine meshes the elements filling a 0.25 m × 0.25 m
# block): the bottom element at the free end, where it shifts
# the stiffness centre of the loaded section (an eccentricity that makes
# the column bend from the start) without softening the column where its
# bending moment is large (a weak element at the clamp lowers the buckling
# load itself by a few per cent on coarse meshes).
#
# Reference (`B4_continuum_euler_buckling.json`): the bifurcation load of
# the St Venant–Kirchhoff continuum is 203.77 kN/m (quadratic elements,
# converged; beam theory gives 205.6 with Euler, 204.6 with the shear
# correction), and beyond it the column follows the inextensible elastica
# within about 0.5 % once the force is normalised by that load. We estimate
# the critical load from each computed curve by that normalisation: on the
# part of the path where the tip has moved sideways by 0.25–0.37 L (where
# the imperfection no longer matters), F(w) divided by the elastica's
# F/F_cr at the same w, averaged. The elastica of the cantilever in closed
# form: F/F_cr = (2K(k)/π)², w/L = 2k/K(k), K the complete elliptic integral
# of the first kind, k = sin(α/2) with α the tip rotation.
#
# The study is also a work-precision diagram: the error of that estimate
# against the reference and the wall time, for linear and quadratic
# quadrilaterals. Quadratic ones (Q9) are within 0.3 % on a 10 × 2 mesh.
# Linear ones (Q4) need 16 elements through the depth: on the 80 × 8 mesh
# the column stays on the straight, unstable path far past the bifurcation
# (the "overshoot" column of the CSV: the largest force before the tip has
# moved by 0.05 L, here many times the critical load), and Newton has no
# reason to leave an equilibrium it has found; on 160 × 16 it bends at the
# bifurcation. Following the stable branch in such cases needs the LDLᵀ
# inertia to detect the bifurcation and switch branches, which the drivers
# do not do yet.

# %%
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.closed_forms import cantilever_elastica_force_ratio
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io import reference

comm = MPI.COMM_WORLD
B4 = "B4 St Venant–Kirchhoff bifurcation load 203.77 kN/m (reference/B4_continuum_euler_buckling.json)"
ref = reference("B4_continuum_euler_buckling")
p = ref["problem"]
L, H, E = p["L"], p["H"], p["E"]
P_ref = ref["continuum_numerical"]["plane_strain_extrapolated"]["P_exact_bifurcation"]
elastica = np.array(ref["postbuckling_elastica"]["data"])  # F/Fcr, w/L, shortening/L, rotation

# %% [markdown]
# ## The column as a structured gmsh rectangle of quadrilaterals

# %%
from dolfinx_corot.io.mesh import rectangles  # noqa: E402


def column(nx: int, ny: int):
    tm = rectangles({"column": (0.0, 0.0, L, H, nx, ny)}, {"clamp": [("column", "left")]}, comm=comm)
    # the imperfection: the bottom corner block at the free end, one element of the
    # coarsest mesh (at least 0.25 m × 0.25 m, so that it does not vanish on fine meshes)
    a, b = max(L / nx, 0.25), max(H / ny, 0.25)
    tm.add_cell_group("weak", lambda x: (x[0] > L - a) & (x[1] < b))
    tm.add_point_group("tip", [(L, H / 2)])
    return tm


# %% [markdown]
# ## Displacement-driven compression
# The end node is pushed by up to 1 m. The column buckles when the push
# reaches about F_cr L/EA = 0.02 m, so the first 0.04 m are taken in steps of
# 0.5 mm (larger first steps carry Newton past the bifurcation onto the
# unstable straight path), the rest in steps of 40 mm. The linear solver
# is MUMPS LDLᵀ here rather than the CG + algebraic multigrid chosen by
# default for continua: past the bifurcation the tangent of the coarsest
# meshes is nearly singular and CG with GAMG stalls, and the LDLᵀ inertia
# shows that the path followed is stable (no negative pivot).
#
# `euler_continuum_2d_shapes.png` draws the Q9 40 × 4 column (the recorded run) pushed by
# 0.2, 0.4, 0.6 and 1 m over its initial outline, coloured by $|u|$.

# %%
SHORTENING = 1.0
LOAD_FACTORS = list(np.r_[np.linspace(0.0, 0.04, 81)[1:], np.linspace(0.04, SHORTENING, 25)[1:]] / SHORTENING)


def compress(tm, degree: int, clamp: str, picture=None):
    """The column of mesh ``tm`` (cell group "weak", point group "tip"), clamped on ``clamp`` and
    pushed at "tip": (scene, result, wall time). ``picture``: (demo, file name, options of
    ``demo.picture``) to draw the column at a push of 0.2, 0.4, 0.6 and 1 m."""
    scene = dc.Scene(large_rotations=True, linear_solver="direct")
    col = scene.add_solid(tm, material=dc.SaintVenantKirchhoff(E, 0.0), degree=degree)
    scene.add_solid(tm, "weak", material=dc.SaintVenantKirchhoff(0.5 * E, 0.0), degree=degree)
    scene.fix(col, clamp)
    scene.prescribe(col, "tip", ux=-SHORTENING)
    scene.monitor("tip", col, "tip")
    scene.monitor_reaction("tip", col, "tip")
    # the path is traced through and past buckling on purpose: critical points are recorded
    # (result.critical_points), not a reason to stop
    shots = dc.plot.Snapshots(scene, at=np.array([0.2, 0.4, 0.6, 1.0]) / SHORTENING) if picture else None
    res, wall = timed(dc.solve, scene, dc.LoadControl(load_factors=LOAD_FACTORS, at_critical_point="continue"),
                      on_step=shots)
    if picture:
        demo, filename, options = picture
        demo.picture(shots.states, filename, **options)
    return scene, res, wall


elastica_ratio = cantilever_elastica_force_ratio


def critical_load(res):
    """F / (F/F_cr)_elastica(w) averaged over 0.25 ≤ w/L ≤ 0.37."""
    F = -res.history.column("tip_Fx")
    w = np.abs(res.history.column("tip_uy")) / L
    m = (w >= 0.25) & (w <= 0.37)
    if not np.any(m):
        return float("nan"), 0
    return float(np.mean([f / elastica_ratio(x) for f, x in zip(F[m], w[m])])), int(np.sum(m))


# %% [markdown]
# ## Meshes: linear and quadratic quadrilaterals

# %%
def work_precision(demo):
    """One row per mesh (critical load, its error, overshoot, time, iterations), the curves, and the
    Newton residuals of a mid-path step on the last mesh."""
    studies = [(10, 2, 2), (20, 2, 2), (40, 4, 2), (80, 8, 1), (160, 16, 1), (320, 32, 1)]
    if demo.ci:
        studies = [(10, 2, 2), (20, 2, 2), (40, 4, 2), (80, 8, 1), (160, 16, 1)]
    rows, curves = [], {}
    for nx, ny, degree in studies:
        picture = None
        if (nx, ny, degree) == (40, 4, 2):  # the recorded mesh: its picture
            picture = (demo, "euler_continuum_2d_shapes.png",
                       dict(field="displacement", layout="overlay", title=f"Q9 {nx} x {ny}: push 0.2, 0.4, 0.6, 1 m"))
        scene, res, wall = compress(column(nx, ny), degree, "clamp", picture)
        Pcr, npts = critical_load(res)
        err = (Pcr - P_ref) / P_ref
        h = res.history
        F_path, w_path = -h.column("tip_Fx"), np.abs(h.column("tip_uy")) / L
        overshoot = float(F_path[w_path < 0.05].max() / P_ref - 1.0)
        rows.append({"nx": nx, "ny": ny, "degree": degree, "dofs": 2 * ((degree * nx + 1) * (degree * ny + 1)),
                     "P_cr": Pcr, "error": err, "overshoot": overshoot, "wall_s": wall,
                     "newton_iterations": res.totals["newton_iterations"],
                     "cuts": res.totals["cuts"], "max_iterations": int(h.column("iterations").max())})
        curves[(nx, ny, degree)] = (np.abs(h.column("tip_uy")), -h.column("tip_Fx"), -h.column("tip_ux"))
        demo.say(f"Q{degree} {nx:3d} x {ny:2d}: P_cr = {Pcr:8.3f} kN/m ({100 * err:+.2f} % against {P_ref:.2f}; "
                 f"{npts} points; overshoot {100 * overshoot:+.1f} %), {wall:5.1f} s, "
                 f"{res.totals['newton_iterations']} iterations, "
                 f"at most {rows[-1]['max_iterations']} per step, {res.totals['cuts']} cuts")
    demo.say("effects:", scene.effects())
    residuals = [float(r) for r in res.history.rows[len(res.history) // 2]["residuals"].split()]
    demo.say("Newton residuals of a mid-path step:", " ".join(f"{r:.1e}" for r in residuals),
             "(observed orders", ", ".join(f"{np.log(c / b) / np.log(b / a):.2f}"
                                           for a, b, c in zip(residuals, residuals[1:], residuals[2:])) + ")")
    demo.table("work_precision.csv", rows)
    demo.work_precision([r["dofs"] for r in rows], [r["error"] for r in rows], [r["wall_s"] for r in rows],
                        reference=B4, quantity="critical load, plane strain (dofs)")
    return rows, curves, residuals


def plot(demo, rows, curves):
    fig, (ax, ax2) = demo.figure(1, 2, figsize=(11, 4.2))
    for key, (w, F, _) in curves.items():
        ax.plot(w / L, F, "-", lw=1, label=f"Q{key[2]} {key[0]}×{key[1]}")
    ws = np.linspace(0.0, 0.6, 61)
    ax.plot(ws, [P_ref * elastica_ratio(max(x, 1e-9)) for x in ws], "k--", lw=1, label="elastica × 203.77")
    for name, val in (("Euler", ref["beam_theory"]["P_Euler"]), ("continuum bifurcation", P_ref)):
        ax.axhline(val, color="grey", lw=0.6, ls=":")
        ax.text(0.02, val + 0.5, f"{name} {val:.1f}", fontsize=7)
    ax.set(xlabel="lateral tip deflection w / L", ylabel="F (kN/m)", ylim=(0, 1.15 * P_ref),
           title="Euler continuum, plane strain")
    ax.legend(fontsize=7)
    for degree, marker in ((1, "s-"), (2, "o-")):
        rr = [r for r in rows if r["degree"] == degree]
        ax2.loglog([r["wall_s"] for r in rr], [abs(r["error"]) for r in rr], marker, label=f"Q{degree}")
        for r in rr:
            ax2.annotate(f"{r['nx']}×{r['ny']}", (r["wall_s"], abs(r["error"])), fontsize=7)
    ax2.set(xlabel="wall time (s)", ylabel="|P_cr − 203.77| / 203.77", title="What accuracy costs")
    ax2.legend(fontsize=8)
    demo.save(fig, "euler_continuum_2d.png")
    w, F, _ = curves[(40, 4, 2)]
    demo.record(load_factor=LOAD_FACTORS[: len(F)], F=F, w=w)


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("euler_continuum_2d")
    # the closed form against the tabulated elastica of the reference
    demo.check("closed-form elastica F/F_cr at the first tabulated deflections",
               [elastica_ratio(w) for r, w in elastica[1:6, :2]], elastica[1:6, 0], atol=2e-3,
               reference="B4 tabulated post-buckling elastica (reference/B4_continuum_euler_buckling.json)")
    rows, curves, residuals = work_precision(demo)
    plot(demo, rows, curves)
    q2 = [r for r in rows if r["degree"] == 2]
    q1 = [r for r in rows if r["degree"] == 1]
    demo.check("Q9: relative error of the critical load, every mesh (within 0.5 %)", [r["error"] for r in q2],
               bound=(-0.005, 0.005), reference=B4)
    demo.check("Q9: change of P_cr on the last refinement / change from the coarsest (converging)",
               abs(q2[-1]["P_cr"] - q2[-2]["P_cr"]) / abs(q2[-2]["P_cr"] - q2[0]["P_cr"]), bound=1.0,
               reference="self-convergence (no published value)")
    demo.check(f"Q4 {q1[-1]['nx']} x {q1[-1]['ny']}: overshoot of the straight path (it bends)",
               q1[-1]["overshoot"], bound=0.01, reference=B4)
    demo.check(f"Q4 {q1[-1]['nx']} x {q1[-1]['ny']}: relative error of the critical load", q1[-1]["error"],
               bound=(-0.005, 0.005), reference=B4)
    demo.check("Q9: failed load steps, every mesh", [r["cuts"] for r in q2], 0,
               reference="solver acceptance (no published value)")
    demo.check("Q9: overshoot of the straight path, every mesh (it bends at the bifurcation)",
               [r["overshoot"] for r in q2], bound=0.01, reference=B4)
    orders = [np.log(c / b) / np.log(b / a) for a, b, c in zip(residuals, residuals[1:], residuals[2:])]
    demo.check("Newton: largest observed rate of convergence, a mid-path step", max(orders), bound=(1.6, None),
               reference="Newton's method: quadratic convergence")
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

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
import json
import logging
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.closed_forms import cantilever_elastica_force_ratio
from dolfinx_corot.io import output_dir, reference

comm = MPI.COMM_WORLD
logging.basicConfig(level=logging.WARNING)
out = output_dir("euler_continuum_2d")
ref = reference("B4_continuum_euler_buckling")
p = ref["problem"]
L, H, E = p["L"], p["H"], p["E"]
P_ref = ref["continuum_numerical"]["plane_strain_extrapolated"]["P_exact_bifurcation"]
elastica = np.array(ref["postbuckling_elastica"]["data"])  # F/Fcr, w/L, shortening/L, rotation
CI = os.environ.get("CI") == "true"


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)


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

# %%
SHORTENING = 1.0
LOAD_FACTORS = list(np.r_[np.linspace(0.0, 0.04, 81)[1:], np.linspace(0.04, SHORTENING, 25)[1:]] / SHORTENING)


def run(nx: int, ny: int, degree: int):
    tm = column(nx, ny)
    scene = dc.Scene(large_rotations=True, linear_solver="direct")
    col = scene.add_solid(tm, material=dc.SaintVenantKirchhoff(E, 0.0), degree=degree)
    scene.add_solid(tm, "weak", material=dc.SaintVenantKirchhoff(0.5 * E, 0.0), degree=degree)
    scene.fix(col, "clamp")
    scene.prescribe(col, "tip", ux=-SHORTENING)
    scene.monitor("tip", col, "tip")
    scene.monitor_reaction("tip", col, "tip")
    t0 = time.perf_counter()
    res = dc.solve(scene, dc.LoadControl(load_factors=LOAD_FACTORS))
    wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    return scene, res, wall


elastica_ratio = cantilever_elastica_force_ratio


# the closed form against the tabulated elastica of the reference
assert all(abs(elastica_ratio(w) - r) < 2e-3 for r, w in elastica[1:6, :2])


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
studies = [(10, 2, 2), (20, 2, 2), (40, 4, 2), (80, 8, 1), (160, 16, 1), (320, 32, 1)]
if CI:
    studies = [(10, 2, 2), (20, 2, 2), (40, 4, 2), (80, 8, 1), (160, 16, 1)]
rows, curves = [], {}
for nx, ny, degree in studies:
    scene, res, wall = run(nx, ny, degree)
    Pcr, npts = critical_load(res)
    err = (Pcr - P_ref) / P_ref
    h = res.history
    F_path, w_path = -h.column("tip_Fx"), np.abs(h.column("tip_uy")) / L
    overshoot = float(F_path[w_path < 0.05].max() / P_ref - 1.0)
    rows.append({"nx": nx, "ny": ny, "degree": degree, "dofs": 2 * ((degree * nx + 1) * (degree * ny + 1)),
                 "P_cr": Pcr, "error": err, "overshoot": overshoot, "wall_s": wall, "newton_iterations": res.totals["newton_iterations"],
                 "cuts": res.totals["cuts"], "max_iterations": int(h.column("iterations").max())})
    curves[(nx, ny, degree)] = (np.abs(h.column("tip_uy")), -h.column("tip_Fx"), -h.column("tip_ux"))
    say(f"Q{degree} {nx:3d} x {ny:2d}: P_cr = {Pcr:8.3f} kN/m ({100 * err:+.2f} % against {P_ref:.2f}; "
        f"{npts} points; overshoot {100 * overshoot:+.1f} %), {wall:5.1f} s, {res.totals['newton_iterations']} iterations, "
        f"at most {rows[-1]['max_iterations']} per step, {res.totals['cuts']} cuts")
say("effects:", scene.effects())
residuals = [float(r) for r in res.history.rows[len(res.history) // 2]["residuals"].split()]
say("Newton residuals of a mid-path step:", " ".join(f"{r:.1e}" for r in residuals),
    "(observed orders", ", ".join(f"{np.log(c / b) / np.log(b / a):.2f}"
                                  for a, b, c in zip(residuals, residuals[1:], residuals[2:])) + ")")

if comm.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(os.path.join(out, "work_precision.csv"), "w") as f:
        f.write(",".join(rows[0]) + "\n")
        for r in rows:
            f.write(",".join(str(v) for v in r.values()) + "\n")
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for key, (w, F, _) in curves.items():
        ax.plot(w / L, F, "-", lw=1, label=f"Q{key[2]} {key[0]}×{key[1]}")
    ws = np.linspace(0.0, 0.6, 61)
    ax.plot(ws, [P_ref * elastica_ratio(max(x, 1e-9)) for x in ws], "k--", lw=1, label="elastica × 203.77")
    for name, val in (("Euler", ref["beam_theory"]["P_Euler"]), ("continuum bifurcation", P_ref)):
        ax.axhline(val, color="grey", lw=0.6, ls=":")
        ax.text(0.02, val + 0.5, f"{name} {val:.1f}", fontsize=7)
    ax.set_xlabel("lateral tip deflection w / L")
    ax.set_ylabel("F (kN/m)")
    ax.set_ylim(0, 1.15 * P_ref)
    ax.legend(fontsize=7)
    ax.set_title("Euler continuum, plane strain")
    for degree, marker in ((1, "s-"), (2, "o-")):
        rr = [r for r in rows if r["degree"] == degree]
        ax2.loglog([r["wall_s"] for r in rr], [abs(r["error"]) for r in rr], marker, label=f"Q{degree}")
        for r in rr:
            ax2.annotate(f"{r['nx']}×{r['ny']}", (r["wall_s"], abs(r["error"])), fontsize=7)
    ax2.set_xlabel("wall time (s)")
    ax2.set_ylabel("|P_cr − 203.77| / 203.77")
    ax2.legend(fontsize=8)
    ax2.set_title("What accuracy costs")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "euler_continuum_2d.png"), dpi=120)
    plt.close(fig)
    w, F, _ = curves[(40, 4, 2)]
    with open(os.path.join(out, "tip_values.json"), "w") as f:
        json.dump({"load_factor": LOAD_FACTORS[: len(F)], "F": F.tolist(), "w": w.tolist(), "ranks": comm.size}, f)

# %% [markdown]
# ## Verification

# %%
q2 = [r for r in rows if r["degree"] == 2]
q1 = [r for r in rows if r["degree"] == 1]
assert all(abs(r["error"]) < 0.005 for r in q2), q2  # quadratic elements within 0.5 % of 203.77 on every mesh
assert abs(q2[-1]["P_cr"] - q2[-2]["P_cr"]) < abs(q2[-2]["P_cr"] - q2[0]["P_cr"])  # and converging
assert q1[-1]["overshoot"] < 0.01 and abs(q1[-1]["error"]) < 0.005, q1[-1]  # Q4 on 160 × 16 bends and agrees
assert all(r["cuts"] == 0 and r["overshoot"] < 0.01 for r in q2)  # Q2 bends at the bifurcation
orders = [np.log(c / b) / np.log(b / a) for a, b, c in zip(residuals, residuals[1:], residuals[2:])]
assert max(orders) > 1.6, (residuals, orders)  # Newton's asymptotic rate is quadratic
say("euler_continuum_2d: verified")

# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Euler column: eccentric compression far into the post-buckling range
#
# Seed §2.3.1 (Z_Soil report 070303, "Euler2D"). A cantilever column of length
# $L = 1$ m, square section $b = h = 0.1$ m, $E = 10^5$ kPa, $\nu = 0$, is
# clamped at its base and loaded at its free tip by a dead compressive force
# $N$ and a dead moment $M = N e$ with eccentricity $e = 0.01$ m. $N$ grows
# from 0 to $4N_{cr}$, $N_{cr} = \pi^2 EI/(2L)^2 = 2.056$ kN. The mesh is the
# seed's: 10 equal two-node beam elements.
#
# The elements are co-rotational Bernoulli beams with the shallow-arch local
# law (Crisfield 1991, §7.2.1), so we compare with the *extensible Bernoulli*
# elastica ($EA = 1000$ kN) from `reference/B1_elastica_eccentric_compression.json`,
# an independent shooting solution of the rod equations.

# %%
import json
import logging
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io import output_dir, reference
from dolfinx_corot.io.gmsh_models import polyline

comm = MPI.COMM_WORLD
rank = comm.rank
logging.basicConfig(level=logging.WARNING)
out = output_dir("euler_beam_2d")
here = os.path.dirname(os.path.abspath(__file__))


def say(*args):
    if rank == 0:
        print(*args, flush=True)


# %% [markdown]
# ## Problem data and the reference solution

# %%
ref = reference("B1_elastica_eccentric_compression")
p = ref["problem"]
L, b, h, E, nu = p["L"], p["b"], p["h"], p["E"], p["nu"]
e = 0.01
Ncr = p["N_crit_euler"]
exact = np.array(ref["curves"][f"extensible_bernoulli__e={e}"]["data"])  # N/Ncr, N, M, ux, uy, phi, M_base
say(f"N_cr = {Ncr:.5f} kN, e = {e} m, EA = {p['EA']:.0f} kN, EI = {p['EI']:.5f} kN m^2")

# %% [markdown]
# ## Mesh: a gmsh file with named physical groups
#
# `meshes/euler_column_2d.geo` defines the column (curve group `column`) and
# the points `base` and `tip`. gmsh runs on rank 0; `dc.from_gmsh` distributes
# the mesh and keeps the group names.

# %%
import gmsh  # noqa: E402

if rank == 0:
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(os.path.join(here, "..", "meshes", "euler_column_2d.geo"))
    gmsh.model.mesh.generate(1)
tmesh = dc.from_gmsh(gmsh.model if rank == 0 else None, gdim=2, comm=comm)
if rank == 0:
    gmsh.finalize()

# %% [markdown]
# ## Scene: one beam part, a clamped base, a tip load scaled by the load factor
#
# The reference load is $N_{cr}$ downwards with the moment $N_{cr}e$; the load
# factor $\lambda = N/N_{cr}$ runs from 0 to 4 in steps of 0.1 (the reference
# points).

# %%
def build_scene(tmesh, large_rotations=True, kinematics="bernoulli"):
    scene = dc.Scene(large_rotations=large_rotations)
    column = scene.add_beam(tmesh, "column", section=dc.Rectangle(b, h), material=dc.Elastic(E, nu),
                            kinematics=kinematics)
    scene.fix(column, where="base")
    scene.load(column, where="tip", force=(0.0, -Ncr), moment=Ncr * e)
    scene.monitor("tip", column, where="tip")
    return scene


scene = build_scene(tmesh)
say("effects:", scene.effects())
shapes = {}


def snapshot(row):
    """Keep the deformed column at a few load levels for the plot."""
    if any(abs(row["load_factor"] - v) < 1e-9 for v in (1.0, 1.5, 2.0, 3.0, 4.0)):
        X, state = scene.model.nodes()
        order = np.argsort(X[:, 1])
        shapes[round(row["load_factor"], 3)] = (X + state[:, :2])[order]


t0 = time.perf_counter()
result = dc.solve(scene, dc.LoadControl(steps=40, final=4.0), on_step=snapshot)
wall = time.perf_counter() - t0
hist = result.history
if rank == 0:
    result.write(out)
say(f"{len(hist)} steps, {result.totals['newton_iterations']} Newton iterations, {wall:.2f} s")

# %% [markdown]
# ## Newton convergence
#
# Residual norms of a step in the post-buckling range: the number of correct
# digits doubles at each iteration.

# %%
lam = hist.column("load_factor")
iters = hist.column("iterations")
k = int(np.argmin(np.abs(lam - 3.0)))
say(f"step at N/Ncr = {lam[k]:.1f}: |r| = {hist.rows[k]['residuals']}")
res = [float(x) for x in hist.rows[k]["residuals"].split()]
rates = [np.log(res[i + 1] / res[i]) / np.log(res[i] / res[i - 1]) for i in range(1, len(res) - 1)
         if res[i + 1] > 1e-14 * res[0]]

# %% [markdown]
# ## Comparison with the exact elastica

# %%
ux, uy, rz = hist.column("tip_ux"), hist.column("tip_uy"), hist.column("tip_rz")
ex = {round(r[0], 6): r for r in exact}
rows = np.array([[lam[i], ux[i], uy[i], rz[i], *ex[round(lam[i], 6)][3:6]] for i in range(len(lam))
                 if round(lam[i], 6) in ex])
post = rows[:, 0] >= 1.5 - 1e-9
err_ux = np.max(np.abs(rows[post, 1] - rows[post, 4]) / np.abs(rows[post, 4]))
err_uy = np.max(np.abs(rows[post, 2] - rows[post, 5]) / np.abs(rows[post, 5]))
err_rz = np.max(np.abs(rows[post, 3] - rows[post, 6]) / np.abs(rows[post, 6]))
say(f"max relative error for N/Ncr in [1.5, 4]: ux {err_ux:.2e}, uy {err_uy:.2e}, rotation {err_rz:.2e}")
say(f"at N = 4 Ncr: ux = {ux[-1]:.6f} (exact {rows[-1, 4]:.6f}), uy = {uy[-1]:.6f} "
    f"(exact {rows[-1, 5]:.6f}), rotation = {rz[-1]:.6f} (exact {rows[-1, 6]:.6f})")

if rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(14, 4.4))
    for name, col, fe, c in (("$u_x$", 3, ux, "C0"), ("$u_y$", 4, uy, "C1"), ("$\\varphi$", 5, rz, "C2")):
        ax[0].plot(exact[:, col], exact[:, 0], "-", color=c, lw=1.2, label=f"{name} exact elastica")
        ax[0].plot(fe, lam, "o", color=c, ms=3.5, label=f"{name} 10 co-rotational beams")
    ax[0].axhline(1.0, color="0.6", lw=0.8, ls="--")
    ax[0].set_xlabel("tip displacement [m], rotation [rad]")
    ax[0].set_ylabel("$N/N_{cr}$")
    ax[0].set_title(f"Euler column, e = {e} m")
    ax[0].legend(fontsize=7)
    ax[1].plot([0, 0], [0, L], "k--", lw=0.8, label="initial")
    for lf, xy in shapes.items():
        ax[1].plot(xy[:, 0], xy[:, 1], "o-", ms=3, label=f"N = {lf:g} $N_{{cr}}$")
    ax[1].set_aspect("equal")
    ax[1].set_title("deformed column")
    ax[1].legend(fontsize=7)
    ax[2].plot(lam, iters, "s-", ms=3)
    ax[2].set_xlabel("$N/N_{cr}$")
    ax[2].set_ylabel("Newton iterations per step")
    ax[2].set_title("Load control, 40 steps")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "euler_beam_2d.png"), dpi=120)
    plt.close(fig)
    with open(os.path.join(out, "tip_values.json"), "w") as f:
        json.dump({"load_factor": lam.tolist(), "ux": ux.tolist(), "uy": uy.tolist(), "rz": rz.tolist(),
                   "ranks": comm.size}, f)

# %% [markdown]
# ## Timoshenko kinematics against the Reissner rod
#
# The same column with shear deformation ($GA_s = 5/6\,GA = 416.7$ kN) is
# compared with the extensible, shearable (Reissner) rod of the reference.

# %%
timo = dc.solve(build_scene(tmesh, kinematics="timoshenko"), dc.LoadControl(steps=40, final=4.0))
exact_r = {round(r[0], 6): r for r in ref["curves"][f"reissner_extensible_shear__e={e}"]["data"]}
lt = timo.history.column("load_factor")
sel = [i for i in range(len(lt)) if lt[i] >= 1.5 - 1e-9 and round(lt[i], 6) in exact_r]
err_timo = max(max(abs(timo.history.column(c)[i] - exact_r[round(lt[i], 6)][k]) / abs(exact_r[round(lt[i], 6)][k])
                   for c, k in (("tip_ux", 3), ("tip_uy", 4), ("tip_rz", 5))) for i in sel)
say(f"Timoshenko beams vs Reissner rod, N/Ncr in [1.5, 4]: max relative error {err_timo:.2e}")

# %% [markdown]
# ## What accuracy costs: error against wall time as the mesh is refined
#
# The same analysis with 2 to 32 elements (the `polyline` mesh builder);
# error = largest relative error of the tip displacement for $N/N_{cr} \in [1.5, 4]$.
# Under `CI=true` the study stops at 16 elements.

# %%
counts = [2, 4, 8, 16] if os.environ.get("CI") == "true" else [2, 4, 8, 16, 32]
study = []
for n in counts:
    tm = polyline([[0.0, 0.0], [0.0, L]], n, line_name="column", comm=comm)
    sc = build_scene(tm)
    t0 = time.perf_counter()
    r = dc.solve(sc, dc.LoadControl(steps=40, final=4.0))
    dt = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    lm = r.history.column("load_factor")
    sel = [i for i in range(len(lm)) if lm[i] >= 1.5 - 1e-9 and round(lm[i], 6) in ex]
    eu = max(max(abs(r.history.column("tip_ux")[i] - ex[round(lm[i], 6)][3]) / abs(ex[round(lm[i], 6)][3]),
                 abs(r.history.column("tip_uy")[i] - ex[round(lm[i], 6)][4]) / abs(ex[round(lm[i], 6)][4]))
             for i in sel)
    study.append((n, eu, dt, r.totals["newton_iterations"]))
    say(f"{n:3d} elements: error {eu:.2e}, {dt:.3f} s, {r.totals['newton_iterations']} Newton iterations")
study = np.array(study)
order = np.log(study[-2, 1] / study[-1, 1]) / np.log(study[-1, 0] / study[-2, 0])
say(f"observed order of convergence between the two finest meshes: {order:.2f}")
if rank == 0:
    np.savetxt(os.path.join(out, "work_precision.csv"), study, delimiter=",",
               header="elements,max_rel_error,wall_time_s,newton_iterations", comments="")
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.loglog(study[:, 2], study[:, 1], "o-")
    for n, err, dt, _ in study:
        ax.annotate(f"{int(n)}", (dt, err), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.set_xlabel("wall time [s] (40 load steps)")
    ax.set_ylabel("max relative tip error, $N/N_{cr}\\in[1.5,4]$")
    ax.set_title("Euler column: work-precision (elements labelled)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "work_precision.png"), dpi=120)
    plt.close(fig)

# %% [markdown]
# ## Verification

# %%
assert err_ux < 5e-3 and err_uy < 5e-3, (err_ux, err_uy)  # acceptance: 0.5 %
assert err_ux < 2e-4 and err_uy < 2e-4 and err_rz < 2e-4  # what this element achieves
assert err_timo < 5e-4, err_timo
assert np.all(iters[lam >= 1.5 - 1e-9] <= 6), iters
assert max(rates) > 1.8, rates  # quadratic convergence
assert order > 1.8, order  # (at least) second-order convergence in the element size
say("euler_beam_2d: verified")

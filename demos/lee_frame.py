# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Lee's frame: snap-through and snap-back by arc-length
#
# Lee, Manuel & Rossow (1968); Schweizerhof & Wriggers (1986). Two members of
# length $L = 120$ meet at a rigid corner; both far ends are pinned. A vertical
# load $P$ acts on the horizontal member, 24 from the corner. $E = 720$,
# $A = 6$, $I = 2$. The equilibrium path has a load maximum (snap-through),
# turns back in displacement (snap-back) and passes a load minimum below zero
# before stiffening. The published limit load is $PL^2/EI \approx 18.5$.
#
# Load control stops at the first limit point; the arc-length method
# (Crisfield's cylindrical constraint, predictor direction from the sign of
# $\det\mathbf K$ counted by the LDLᵀ factorization) follows the whole path.
# The load factor is $\lambda = PL^2/EI$.

# %%
import json
import logging
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io import output_dir
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.result import limit_load

comm = MPI.COMM_WORLD
logging.basicConfig(level=logging.WARNING)
out = output_dir("lee_frame")
L, E, A, I = 120.0, 720.0, 6.0, 2.0
P_ref = 18.5  # published limit load PL²/EI


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)


def lee_frame(n):
    """Frame with 10n elements on the column, 2n + 8n on the beam (node at the load)."""
    tmesh = polyline([[0.0, 0.0], [0.0, L], [24.0, L], [L, L]], [10 * n, 2 * n, 8 * n], line_name="frame",
                     point_names={0: "A", 2: "load", 3: "B"}, comm=comm)
    scene = dc.Scene(large_rotations=True)
    frame = scene.add_beam(tmesh, "frame", section=dc.Section(A=A, I=I), material=dc.Elastic(E))
    scene.fix(frame, "A", dofs=("ux", "uy"))
    scene.fix(frame, "B", dofs=("ux", "uy"))
    scene.load(frame, "load", force=(0.0, -E * I / L**2))  # λ = P L²/EI
    scene.monitor("P", frame, "load")
    return scene


# %% [markdown]
# ## The path with 20 elements

# %%
scene = lee_frame(1)
shapes = {}


def snapshot(row):
    X, state = scene.model.nodes()
    order = np.argsort(X[:, 1] + X[:, 0])  # along the frame: up the column, then along the beam
    shapes[row["step"]] = ((X + state[:, :2])[order], row["load_factor"])


driver = dc.ArcLength(initial_increment=0.5, desired_iterations=4, max_steps=400,
                      stop=lambda row: row["P_uy"] < -100.0)
t0 = time.perf_counter()
result = dc.solve(scene, driver, on_step=snapshot)
wall = time.perf_counter() - t0
hist = result.history
if comm.rank == 0:
    result.write(out)
lam, u, v = hist.column("load_factor"), hist.column("P_ux"), hist.column("P_uy")
lam0, u0, v0 = np.r_[0.0, lam], np.r_[0.0, u], np.r_[0.0, v]
P_max = limit_load(lam0, u0, v0)  # the first maximum, refined by a parabola along the path
P_min = limit_load(lam0, u0, v0, kind="min", first=False)
iters = hist.column("iterations")
say(f"{len(hist)} arc-length steps, {result.totals['newton_iterations']} iterations, "
    f"{result.totals['cuts']} cuts, {wall:.2f} s; iterations per step {int(iters.min())}-{int(iters.max())}")
say(f"limit loads: P_max L²/EI = {P_max:.4f} (published {P_ref}), P_min L²/EI = {P_min:.4f}")

# %% [markdown]
# ## Mesh convergence of the limit load

# %%
study = []
for n in ([1, 2] if os.environ.get("CI") == "true" else [1, 2, 4]):
    sc = lee_frame(n)
    t0 = time.perf_counter()
    r = dc.solve(sc, driver)
    dt = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    lm = np.r_[0.0, r.history.column("load_factor")]
    uu, vv = np.r_[0.0, r.history.column("P_ux")], np.r_[0.0, r.history.column("P_uy")]
    pm = limit_load(lm, uu, vv)
    study.append((20 * n, pm, limit_load(lm, uu, vv, kind="min", first=False), dt, r.totals["cuts"]))
    say(f"{20 * n:3d} elements: P_max L²/EI = {pm:.4f}, P_min L²/EI = {study[-1][2]:.4f}, "
        f"{dt:.2f} s, {r.totals['cuts']} cuts")
study = np.array(study)

if comm.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    np.savetxt(os.path.join(out, "mesh_convergence.csv"), study, delimiter=",",
               header="elements,P_max_L2_over_EI,P_min_L2_over_EI,wall_time_s,cuts", comments="")
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.5))
    ax[0].plot(-v0, lam0, "o-", ms=2.5, label="$-v$ (down) at the load")
    ax[0].plot(u0, lam0, "s-", ms=2.5, label="$u$ at the load")
    ax[0].axhline(P_ref, color="0.5", ls="--", lw=0.8, label="published limit 18.5")
    ax[0].set_xlabel("displacement")
    ax[0].set_ylabel("$PL^2/EI$")
    ax[0].set_ylim(-15, 30)
    ax[0].legend(fontsize=8)
    ax[0].set_title("Lee's frame: equilibrium path (20 elements)")
    picks = [k for k in sorted(shapes)][:: max(1, len(shapes) // 6)]
    ax[1].plot([0, 0, L], [0, L, L], "k--", lw=0.8)
    for k in picks:
        xy, lf = shapes[k]
        ax[1].plot(*xy.T, ".-", ms=3, lw=1, label=f"λ = {lf:.2f}")
    ax[1].set_aspect("equal")
    ax[1].legend(fontsize=7)
    ax[1].set_title("deformed shapes")
    ax[2].plot(np.arange(1, len(iters) + 1), iters, "s-", ms=3)
    ax[2].set_xlabel("arc-length step")
    ax[2].set_ylabel("Newton iterations")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "lee_frame.png"), dpi=120)
    plt.close(fig)
    with open(os.path.join(out, "tip_values.json"), "w") as f:
        json.dump({"load_factor": lam.tolist(), "ux": u.tolist(), "uy": v.tolist(),
                   "rz": hist.column("P_rz").tolist(), "ranks": comm.size}, f)

# %% [markdown]
# ## Verification

# %%
assert abs(P_max - P_ref) / P_ref < 0.01, P_max  # published limit load within 1 %
assert result.totals["cuts"] == 0 and np.all(study[:, 4] == 0)  # no failed arc-length step
assert iters.max() <= 6, iters.max()
assert P_min < -9.0 and lam[-1] > 10.0  # passed the load minimum and came back up
assert np.ptp(study[:, 1]) / P_ref < 2e-3  # limit load converged in the mesh
say("lee_frame: verified")

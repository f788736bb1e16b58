# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Williams' toggle frame: snap-through of a shallow clamped frame
#
# Williams (1964) tested a shallow toggle: two straight members of horizontal
# projection $a = 12.943$ in rising $H = 0.386$ in to an apex, both far ends
# clamped, a vertical load $P$ at the apex; section $0.753 \times 0.243$ in,
# $E = 10.3\cdot10^6$ psi. Under load control the apex would jump at the
# limit load; the arc-length method follows the frame through it, across the
# unstable branch where the load falls, and onto the stiffening branch beyond.
#
# The limit load is checked for convergence on four meshes (2 to 16 elements
# per member); the reference is the extrapolated value of that sequence.

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
out = output_dir("toggle_frame")
a, H, E = 12.943, 0.386, 10.3e6
section = dc.Rectangle(0.753, 0.243)


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)


def toggle(n):
    tmesh = polyline([[-a, 0.0], [0.0, H], [a, 0.0]], n, line_name="toggle",
                     point_names={0: "left", 1: "apex", 2: "right"}, comm=comm)
    scene = dc.Scene(large_rotations=True)
    frame = scene.add_beam(tmesh, "toggle", section=section, material=dc.Elastic(E))
    scene.fix(frame, "left")
    scene.fix(frame, "right")
    scene.load(frame, "apex", force=(0.0, -1.0))  # λ = P in lb
    scene.monitor("apex", frame, "apex")
    return scene


driver = dc.ArcLength(initial_increment=1.0, max_growth=1.0, max_steps=400,
                      stop=lambda row: -row["apex_uy"] > 2.5 * H)

# %% [markdown]
# ## Path with 8 elements per member

# %%
scene = toggle(8)
t0 = time.perf_counter()
result = dc.solve(scene, driver)
wall = time.perf_counter() - t0
hist = result.history
if comm.rank == 0:
    result.write(out)
P = np.r_[0.0, hist.column("load_factor")]
v = np.r_[0.0, -hist.column("apex_uy")]
u = np.r_[0.0, hist.column("apex_ux")]
P_lim = limit_load(P, v, u)
iters = hist.column("iterations")
say(f"{len(hist)} steps, {result.totals['newton_iterations']} iterations, {result.totals['cuts']} cuts, "
    f"{wall:.2f} s; iterations per step {int(iters.min())}-{int(iters.max())}")
k = int(np.flatnonzero(np.diff(P) < 0)[0])  # the first point past the maximum
P_valley = P[k:].min()
say(f"limit load {P_lim:.3f} lb at an apex deflection of {v[k]:.3f} in; the load then falls to "
    f"{P_valley:.2f} lb before the inverted frame stiffens")

# %% [markdown]
# ## Mesh convergence of the limit load

# %%
study = []
for n in (2, 4, 8, 16):
    sc = toggle(n)
    t0 = time.perf_counter()
    r = dc.solve(sc, driver)
    dt = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    pl = limit_load(np.r_[0.0, r.history.column("load_factor")], np.r_[0.0, -r.history.column("apex_uy")],
                    np.r_[0.0, r.history.column("apex_ux")])
    study.append((n, pl, dt, r.totals["cuts"], r.history.column("iterations").max()))
study = np.array(study)
# Richardson extrapolation with the observed order
order = np.log(abs(study[1, 1] - study[2, 1]) / abs(study[2, 1] - study[3, 1])) / np.log(2.0)
P_ref = study[3, 1] + (study[3, 1] - study[2, 1]) / (2**order - 1)
for n, pl, dt, cuts, it in study:
    say(f"{int(n):3d} elements per member: P_lim = {pl:.4f} lb (error {abs(pl - P_ref) / P_ref:.1e}), "
        f"{dt:.2f} s, {int(cuts)} cuts")
say(f"extrapolated limit load {P_ref:.4f} lb (observed order {order:.2f})")

if comm.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    np.savetxt(os.path.join(out, "mesh_convergence.csv"), study, delimiter=",",
               header="elements_per_member,limit_load_lb,wall_time_s,cuts,max_iterations", comments="")
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    ax[0].plot(v, P, "o-", ms=3)
    ax[0].axhline(P_lim, color="0.6", ls="--", lw=0.8, label=f"limit load {P_lim:.2f} lb")
    ax[0].set_xlabel("apex deflection [in]")
    ax[0].set_ylabel("P [lb]")
    ax[0].set_title("Williams' toggle, arc-length (8 + 8 elements)")
    ax[0].legend(fontsize=8)
    ax[1].loglog(study[:, 0], np.abs(study[:, 1] - P_ref) / P_ref, "o-")
    ax[1].set_xlabel("elements per member")
    ax[1].set_ylabel("relative error of the limit load")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "toggle_frame.png"), dpi=120)
    plt.close(fig)
    with open(os.path.join(out, "tip_values.json"), "w") as f:
        json.dump({"load_factor": P.tolist(), "v": v.tolist(), "ranks": comm.size}, f)

# %% [markdown]
# ## Verification

# %%
assert result.totals["cuts"] == 0 and np.all(study[:, 3] == 0)  # no failed arc-length step
assert iters.max() <= 6
assert P_valley < 0.95 * P_lim and P[-1] > P_lim and v[-1] > 2.5 * H  # through the snap
assert abs(study[2, 1] - P_ref) / P_ref < 2e-3 and abs(study[3, 1] - P_ref) / P_ref < 5e-4
assert order > 1.5  # the limit load converges at the element's order
say("toggle_frame: verified")

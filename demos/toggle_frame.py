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
# per member); the reference is the extrapolated value of that sequence
# (self-convergence: Williams' measured curve is not checked here).

# %%
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.result import limit_load

comm = MPI.COMM_WORLD
SELF = "self-convergence: Richardson extrapolation of the four meshes (no published value)"
a, H, E = 12.943, 0.386, 10.3e6
section = dc.Rectangle(0.753, 0.243)


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
#
# `toggle_shapes.png` draws the frame at every 70th arc-length step, coloured by $|u|$ with the
# displacements magnified ten times (the frame is shallow): near the limit load, at the flat
# frame in the valley of the load, and twice on the stiffening inverted branch.

# %%
def path(demo):
    """The arc-length run on 8 + 8 elements: (result, P, v) from the unloaded state, the limit load
    and the valley after it."""
    scene = toggle(8)
    shots = dc.plot.Snapshots(scene, every=70)  # PyVista states: 4 along the path
    result, wall = timed(dc.solve, scene, driver, on_step=shots)
    hist = result.history
    demo.write_result(result)
    demo.picture(shots, "toggle_shapes.png", field="displacement", scale=10.0, window_size=(1400, 700),
                 title="Toggle frame: arc-length steps 70, 140, 210, 280 (P = 33.3, 31.3, 48.7, 131 lb), "
                       "displacements ×10")
    P = np.r_[0.0, hist.column("load_factor")]
    v = np.r_[0.0, -hist.column("apex_uy")]
    u = np.r_[0.0, hist.column("apex_ux")]
    P_lim = limit_load(P, v, u)
    iters = hist.column("iterations")
    demo.say(f"{len(hist)} steps, {result.totals['newton_iterations']} iterations, {result.totals['cuts']} cuts, "
             f"{wall:.2f} s; iterations per step {int(iters.min())}-{int(iters.max())}")
    k = int(np.flatnonzero(np.diff(P) < 0)[0])  # the first point past the maximum
    P_valley = P[k:].min()
    demo.say(f"limit load {P_lim:.3f} lb at an apex deflection of {v[k]:.3f} in; the load then falls to "
             f"{P_valley:.2f} lb before the inverted frame stiffens")
    demo.record(load_factor=P, v=v)
    return result, P, v, P_lim, P_valley


# %% [markdown]
# ## Mesh convergence of the limit load

# %%
def mesh_convergence(demo):
    """(elements per member, limit load, wall time, cuts, most iterations) per mesh; the
    extrapolated limit load and the observed order."""
    study = []
    for n in (2, 4, 8, 16):
        sc = toggle(n)
        r, dt = timed(dc.solve, sc, driver)
        pl = limit_load(np.r_[0.0, r.history.column("load_factor")], np.r_[0.0, -r.history.column("apex_uy")],
                        np.r_[0.0, r.history.column("apex_ux")])
        study.append((n, pl, dt, r.totals["cuts"], r.history.column("iterations").max()))
    study = np.array(study)
    # Richardson extrapolation with the observed order
    order = np.log(abs(study[1, 1] - study[2, 1]) / abs(study[2, 1] - study[3, 1])) / np.log(2.0)
    P_ref = study[3, 1] + (study[3, 1] - study[2, 1]) / (2**order - 1)
    for n, pl, dt, cuts, it in study:
        demo.say(f"{int(n):3d} elements per member: P_lim = {pl:.4f} lb (error {abs(pl - P_ref) / P_ref:.1e}), "
                 f"{dt:.2f} s, {int(cuts)} cuts")
    demo.say(f"extrapolated limit load {P_ref:.4f} lb (observed order {order:.2f})")
    demo.table("mesh_convergence.csv", study,
               ["elements_per_member", "limit_load_lb", "wall_time_s", "cuts", "max_iterations"])
    demo.work_precision(2 * study[:, 0].astype(int), np.abs(study[:, 1] - P_ref) / P_ref, study[:, 2],
                        quantity="limit load (elements)", reference=SELF)
    return study, P_ref, order


def plot(demo, P, v, P_lim, study, P_ref):
    fig, ax = demo.figure(1, 2, figsize=(11, 4.2))
    ax[0].plot(v, P, "o-", ms=3)
    ax[0].axhline(P_lim, color="0.6", ls="--", lw=0.8, label=f"limit load {P_lim:.2f} lb")
    ax[0].set_xlabel("apex deflection [in]")
    ax[0].set_ylabel("P [lb]")
    ax[0].set_title("Williams' toggle, arc-length (8 + 8 elements)")
    ax[0].legend(fontsize=8)
    ax[1].loglog(study[:, 0], np.abs(study[:, 1] - P_ref) / P_ref, "o-")
    ax[1].set_xlabel("elements per member")
    ax[1].set_ylabel("relative error of the limit load")
    demo.save(fig, "toggle_frame.png")


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("toggle_frame")
    result, P, v, P_lim, P_valley = path(demo)
    study, P_ref, order = mesh_convergence(demo)
    plot(demo, P, v, P_lim, study, P_ref)
    solver = "solver acceptance (no published value)"
    demo.check("failed arc-length steps, every mesh", [result.totals["cuts"], *study[:, 3]], 0, reference=solver)
    demo.check("Newton iterations per step", result.history.column("iterations").max(), bound=6, reference=solver)
    demo.check("valley after the limit point / limit load (through the snap)", P_valley / P_lim,
               bound=(None, 0.95), reference="the snap-through of the toggle (Williams 1964); the bound is ours")
    demo.check("last load / limit load (onto the stiffening branch)", P[-1] / P_lim, bound=(1.0, None),
               reference="the snap-through of the toggle (Williams 1964)")
    demo.check("last apex deflection / H", v[-1] / H, bound=(2.5, None),
               reference="the run's stop criterion (deflection 2.5 H)")
    demo.check("limit load, 8 elements per member (within 2e-3)", study[2, 1], P_ref, rtol=2e-3, reference=SELF)
    demo.check("limit load, 16 elements per member (within 5e-4)", study[3, 1], P_ref, rtol=5e-4, reference=SELF)
    demo.check("observed order of convergence of the limit load", order, bound=(1.5, None), reference=SELF)
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

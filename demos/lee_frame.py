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
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.result import limit_load

comm = MPI.COMM_WORLD
L, E, A, I = 120.0, 720.0, 6.0, 2.0
P_ref = 18.5  # published limit load PL²/EI


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


driver = dc.ArcLength(initial_increment=0.5, desired_iterations=4, max_steps=400,
                      stop=lambda row: row["P_uy"] < -100.0)

# %% [markdown]
# ## The path with 20 elements
#
# `lee_frame_shapes.png` draws the frame at every 20th arc-length step, coloured by $|u|$:
# before the load maximum ($\lambda$ = 15.7), on the snap-back (12.8), near the load minimum
# (−9.4) and as the path comes back up (14.4).

# %%
def path(demo):
    """The arc-length run on 20 elements, its deformed shapes, and the limit loads (max, min)."""
    scene = lee_frame(1)
    shapes = {}
    pictures = dc.plot.Snapshots(scene, every=20)  # PyVista states: 4 along the path

    def snapshot(row):
        X, state = scene.model.nodes()
        order = np.argsort(X[:, 1] + X[:, 0])  # along the frame: up the column, then along the beam
        shapes[row["step"]] = ((X + state[:, :2])[order], row["load_factor"])
        pictures(row)

    result, wall = timed(dc.solve, scene, driver, on_step=snapshot)
    demo.picture(pictures, "lee_frame_shapes.png", field="displacement", window_size=(1100, 800),
                 title="Lee frame: arc-length steps 20, 40, 60, 80 (λ = 15.7, 12.8, −9.4, 14.4)")
    hist = result.history
    demo.write_result(result)
    lam, u, v = hist.column("load_factor"), hist.column("P_ux"), hist.column("P_uy")
    lam0, u0, v0 = np.r_[0.0, lam], np.r_[0.0, u], np.r_[0.0, v]
    P_max = limit_load(lam0, u0, v0)  # the first maximum, refined by a parabola along the path
    P_min = limit_load(lam0, u0, v0, kind="min", first=False)
    iters = hist.column("iterations")
    demo.say(f"{len(hist)} arc-length steps, {result.totals['newton_iterations']} iterations, "
             f"{result.totals['cuts']} cuts, {wall:.2f} s; iterations per step {int(iters.min())}-{int(iters.max())}")
    demo.say(f"limit loads: P_max L²/EI = {P_max:.4f} (published {P_ref}), P_min L²/EI = {P_min:.4f}")
    demo.record(load_factor=lam, ux=u, uy=v, rz=hist.column("P_rz"))
    return result, shapes, P_max, P_min


# %% [markdown]
# ## Mesh convergence of the limit load

# %%
def mesh_convergence(demo):
    """(elements, P_max L²/EI, P_min L²/EI, wall time, cuts) per mesh."""
    study = []
    for n in ([1, 2] if demo.ci else [1, 2, 4]):
        sc = lee_frame(n)
        r, dt = timed(dc.solve, sc, driver)
        lm = np.r_[0.0, r.history.column("load_factor")]
        uu, vv = np.r_[0.0, r.history.column("P_ux")], np.r_[0.0, r.history.column("P_uy")]
        pm = limit_load(lm, uu, vv)
        study.append((20 * n, pm, limit_load(lm, uu, vv, kind="min", first=False), dt, r.totals["cuts"]))
        demo.say(f"{20 * n:3d} elements: P_max L²/EI = {pm:.4f}, P_min L²/EI = {study[-1][2]:.4f}, "
                 f"{dt:.2f} s, {r.totals['cuts']} cuts")
    study = np.array(study)
    demo.table("mesh_convergence.csv", study,
               ["elements", "P_max_L2_over_EI", "P_min_L2_over_EI", "wall_time_s", "cuts"])
    demo.work_precision_to_finest(study[:, 0].astype(int), study[:, 1], study[:, 3], quantity="limit load (elements)")
    return study


def plot(demo, hist, shapes):
    lam0, u0, v0 = (np.r_[0.0, hist.column(c)] for c in ("load_factor", "P_ux", "P_uy"))
    iters = hist.column("iterations")
    fig, ax = demo.figure(1, 3, figsize=(15, 4.5))
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
    demo.save(fig, "lee_frame.png")


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("lee_frame")
    result, shapes, P_max, P_min = path(demo)
    study = mesh_convergence(demo)
    hist = result.history
    plot(demo, hist, shapes)
    demo.check("limit load P_max L²/EI, 20 elements (within 1 %)", P_max, P_ref, rtol=0.01,
               reference="published limit load PL²/EI ≈ 18.5 (Lee, Manuel & Rossow 1968; Schweizerhof & "
                         "Wriggers 1986)")
    demo.check("failed arc-length steps, every mesh", [result.totals["cuts"], *study[:, 4]], 0,
               reference="solver acceptance (no published value)")
    demo.check("Newton iterations per step", hist.column("iterations").max(), bound=6,
               reference="solver acceptance (no published value)")
    demo.check("load minimum P_min L²/EI (the path passes it)", P_min, bound=(None, -9.0),
               reference="path shape as published: a load minimum below zero (Schweizerhof & Wriggers "
                         "1986); the bound −9 is ours")
    demo.check("last load factor (the path comes back up)", hist.column("load_factor")[-1], bound=(10.0, None),
               reference="path shape as published: stiffening after the load minimum (Schweizerhof & "
                         "Wriggers 1986); the bound 10 is ours")
    demo.check("spread of P_max L²/EI over the meshes / 18.5 (limit load converged in the mesh)",
               np.ptp(study[:, 1]) / P_ref, bound=2e-3, reference="self-convergence (no published value)")
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # A shallow space-truss dome snaps through
#
# Six bars join an apex at height $h = 5$ to supports on a circle of radius
# $R = 50$ ($EA = 10^6$). A vertical load $P$ at the apex pushes the dome flat,
# through, and into its inverted position: the load–deflection curve has a
# maximum, goes negative, and rises again. Load control stops at the maximum;
# the arc-length method follows the whole path.
#
# With one free node and symmetric loading the exact equilibrium is known in
# closed form: with $w$ the downward apex displacement,
# $\ell = \sqrt{R^2 + (h - w)^2}$, $N = EA(\ell - \ell_0)/\ell_0$,
#
# $$P(w) = -6\,N\,\frac{h - w}{\ell},$$
#
# so every point of the computed path can be checked, and the limit loads are
# $\pm\max P$ of this curve. The bars are 3D co-rotational bars (axial force
# only; nodal rotations have no stiffness and are fixed automatically).

# %%
import json
import logging
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io import output_dir

comm = MPI.COMM_WORLD
logging.basicConfig(level=logging.WARNING)
out = output_dir("truss_dome_3d")
R, h, EA, nbars = 50.0, 5.0, 1e6, 6


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)


def P_exact(w):
    l0 = np.hypot(R, h)
    l = np.hypot(R, h - w)
    return -nbars * EA * (l - l0) / l0 * (h - w) / l


w_fine = np.linspace(0.0, 2.2 * h, 22001)
P_max = P_exact(w_fine[w_fine <= h]).max()  # the snap-through load
P_min = P_exact(w_fine[w_fine >= h]).min()  # and the load of the inverted dome's snap back
say(f"exact limit loads: P_max = {P_max:.3f}, P_min = {P_min:.3f}")

# %% [markdown]
# ## The dome as a gmsh model: six bars, named apex and supports

# %%
import gmsh  # noqa: E402

if comm.rank == 0:
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    apex = gmsh.model.geo.addPoint(0.0, 0.0, h)
    feet = [gmsh.model.geo.addPoint(R * np.cos(t), R * np.sin(t), 0.0)
            for t in np.arange(nbars) * 2 * np.pi / nbars]
    bars = [gmsh.model.geo.addLine(apex, f) for f in feet]
    gmsh.model.geo.synchronize()
    for bar in bars:
        gmsh.model.mesh.setTransfiniteCurve(bar, 2)  # one bar element per member
    gmsh.model.addPhysicalGroup(1, bars, 1)
    gmsh.model.setPhysicalName(1, 1, "bars")
    gmsh.model.addPhysicalGroup(0, [apex], 2)
    gmsh.model.setPhysicalName(0, 2, "apex")
    gmsh.model.addPhysicalGroup(0, feet, 3)
    gmsh.model.setPhysicalName(0, 3, "supports")
    gmsh.model.mesh.generate(1)
tmesh = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=3, comm=comm)
if comm.rank == 0:
    gmsh.finalize()

scene = dc.Scene(large_rotations=True)
truss = scene.add_truss(tmesh, "bars", area=1.0, material=dc.Elastic(EA))
scene.fix(truss, "supports", dofs=("ux", "uy", "uz"))
scene.load(truss, "apex", force=(0.0, 0.0, -1.0))  # λ = P
scene.monitor("apex", truss, "apex")
say("effects:", scene.effects())

# %% [markdown]
# ## Arc-length through the snap

# %%
t0 = time.perf_counter()
result = dc.solve(scene, dc.ArcLength(initial_increment=100.0, max_growth=1.0, max_steps=400,
                                      stop=lambda row: -row["apex_uz"] > 2.1 * h))
wall = time.perf_counter() - t0
hist = result.history
if comm.rank == 0:
    result.write(out)
P = hist.column("load_factor")
w = -hist.column("apex_uz")
err = np.abs(P - P_exact(w)) / P_max
lateral = np.abs(np.c_[hist.column("apex_ux"), hist.column("apex_uy")]).max()
say(f"{len(hist)} steps, {result.totals['newton_iterations']} iterations, {result.totals['cuts']} cuts, "
    f"{wall:.2f} s; iterations per step {int(hist.column('iterations').min())}-"
    f"{int(hist.column('iterations').max())}")
say(f"largest deviation from the exact path: {err.max():.1e} P_max; lateral apex motion {lateral:.1e}")
P_top = P[w <= h].max()
P_bottom = P[w >= h].min()
say(f"computed limit loads (largest sampled points): {P_top:.3f} and {P_bottom:.3f} "
    f"(exact {P_max:.3f}, {P_min:.3f})")

if comm.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.2))
    ax.plot(w_fine, P_exact(w_fine), "k-", lw=0.8, label="exact")
    ax.plot(w, P, "o", ms=3, label="arc-length, 3D co-rotational bars")
    ax.axhline(0.0, color="0.7", lw=0.6)
    ax.set_xlabel("apex deflection w")
    ax.set_ylabel("apex load P")
    ax.set_title("Shallow space-truss dome: snap-through")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "truss_dome_3d.png"), dpi=120)
    plt.close(fig)
    with open(os.path.join(out, "tip_values.json"), "w") as f:
        json.dump({"load_factor": P.tolist(), "w": w.tolist(), "ranks": comm.size}, f)

# %% [markdown]
# ## Verification

# %%
assert err.max() < 1e-8, err.max()  # every point on the exact path
assert lateral < 1e-10
assert result.totals["cuts"] == 0 and hist.column("iterations").max() <= 6
assert P_top > 0.999 * P_max and P_bottom < 0.999 * P_min and w[-1] > 2 * h  # through both limit points
say("truss_dome_3d: verified")

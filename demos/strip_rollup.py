# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # A plate strip rolled into a full circle by an end moment (co-rotational shells)
#
# The shell version of B2a (Sze, Liu & Lo 2004, test 3.2): a strip $L = 12$,
# $b = 1$, $t = 0.1$, $E = 1.2\cdot10^6$, $\nu = 0$, clamped at $x = 0$,
# carries an end moment about its width axis. With $EI = Ebt^3/12 = 100$ the
# moment $M = 2\pi EI/L$ closes a full circle, and every intermediate tip
# position is known in closed form. The mesh is 16 × 1 squares, each split
# into two flat co-rotational triangles (CST membrane with drilling rotations,
# DKT bending), 6 dofs per node.

# %%
import json
import logging
import os
import time

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io import output_dir, reference

comm = MPI.COMM_WORLD
logging.basicConfig(level=logging.WARNING)
out = output_dir("strip_rollup")


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)


p = reference("B2a_cantilever_end_moment")["problem"]
L, b, t, E = p["L"], p["b"], p["h"], p["E"]
EI = E * b * t**3 / 12
nx = 16

# %% [markdown]
# ## The strip as a structured gmsh surface with named edges

# %%
import gmsh  # noqa: E402

if comm.rank == 0:
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    pts = [gmsh.model.geo.addPoint(*c) for c in ((0, 0, 0), (L, 0, 0), (L, b, 0), (0, b, 0))]
    lines = [gmsh.model.geo.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
    surface = gmsh.model.geo.addPlaneSurface([gmsh.model.geo.addCurveLoop(lines)])
    for line, n in zip(lines, (nx, 1, nx, 1)):
        gmsh.model.geo.mesh.setTransfiniteCurve(line, n + 1)
    gmsh.model.geo.mesh.setTransfiniteSurface(surface)
    gmsh.model.geo.synchronize()
    for dim, tags, tag, name in ((2, [surface], 1, "strip"), (1, [lines[3]], 2, "clamp"), (1, [lines[1]], 3, "tip")):
        gmsh.model.addPhysicalGroup(dim, tags, tag)
        gmsh.model.setPhysicalName(dim, tag, name)
    gmsh.model.mesh.generate(2)
tmesh = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=3, comm=comm)
if comm.rank == 0:
    gmsh.finalize()

scene = dc.Scene(large_rotations=True)
strip = scene.add_shell(tmesh, "strip", thickness=t, material=dc.Elastic(E, 0.0))
scene.fix(strip, "clamp")
# the tip edge has two nodes: each takes half of the moment (about −y bends the strip up, +z)
scene.load(strip, "tip", moment=(0.0, -np.pi * EI / L, 0.0))
scene.monitor("tip", strip, "tip")
say("effects:", scene.effects())

# %% [markdown]
# ## Thirty load steps to the full circle

# %%
t0 = time.perf_counter()
with dc.io.FieldWriter(scene, os.path.join(out, "strip.xdmf")) as writer:
    result = dc.solve(scene, dc.LoadControl(steps=30), on_step=writer)
wall = time.perf_counter() - t0
hist = result.history
if comm.rank == 0:
    result.write(out)
lam = hist.column("load_factor")
phi = 2 * np.pi * lam
u, w = hist.column("tip_ux"), hist.column("tip_uz")
u_ex, w_ex = L * (np.sin(phi) / phi - 1), L * (1 - np.cos(phi)) / phi
err = np.hypot(u - u_ex, w - w_ex) / L
say(f"{len(hist)} steps, {result.totals['newton_iterations']} Newton iterations, {wall:.2f} s")
say(f"full circle: tip ({u[-1]:+.5f}, {w[-1]:+.5f}) against (−12, 0): error {err[-1]:.1e} L; "
    f"largest error on the path {err.max():.1e} L")
say(f"residuals of the last step: {hist.rows[-1]['residuals']}")

if comm.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(lam, u / L, "o", ms=4, label="$u_{tip}/L$, 32 shell triangles")
    ax.plot(lam, w / L, "s", ms=4, label="$w_{tip}/L$")
    s = np.linspace(1e-6, 1.0, 200)
    ax.plot(s, (np.sin(2 * np.pi * s) / (2 * np.pi * s) - 1), "k-", lw=0.8, label="closed form")
    ax.plot(s, (1 - np.cos(2 * np.pi * s)) / (2 * np.pi * s), "k-", lw=0.8)
    ax.set_xlabel("$M/(2\\pi EI/L)$")
    ax.legend(fontsize=8)
    ax.set_title("Strip roll-up, co-rotational flat shells")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "strip_rollup.png"), dpi=120)
    plt.close(fig)
    with open(os.path.join(out, "tip_values.json"), "w") as f:
        json.dump({"load_factor": lam.tolist(), "ux": u.tolist(), "uz": w.tolist(), "ranks": comm.size}, f)

# %% [markdown]
# ## Verification

# %%
assert err[-1] < 1e-3, err[-1]  # acceptance: full circle within 1e-3 L on a modest mesh
assert err.max() < 2e-3, err.max()
assert result.totals["cuts"] == 0
say("strip_rollup: verified")

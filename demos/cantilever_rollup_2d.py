# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Cantilever rolled up by an end moment: one full circle, then two turns
#
# A cantilever of length $L = 12$, $b = 1$, $h = 0.1$, $E = 1.2\cdot10^6$,
# $\nu = 0$ ($EI = 100$) carries a dead end moment $M$. Every section carries
# the same bending moment, so the beam bends into a circular arc of radius
# $EI/M$ (closed form B2a, `reference/B2a_cantilever_end_moment.json`):
#
# $$\varphi_{tip} = \frac{ML}{EI},\qquad u_{tip} = L\Bigl(\frac{\sin\varphi}{\varphi}-1\Bigr),\qquad
#   w_{tip} = L\,\frac{1-\cos\varphi}{\varphi}.$$
#
# $M = 2\pi EI/L$ closes a full circle (the tip returns to the clamp) and
# $M = 4\pi EI/L$ winds the beam twice around it. A 2D co-rotational element
# that computes its local rotations as plain differences of angles fails once
# the tip rotation passes $\pi$; ours reduces them through sines and cosines
# while the nodal angles grow without bound, so the tip angle reads $4\pi$ at
# the end.

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
logging.basicConfig(level=logging.WARNING)
out = output_dir("cantilever_rollup_2d")


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)


ref = reference("B2a_cantilever_end_moment")
p = ref["problem"]
L, b, h, E = p["L"], p["b"], p["h"], p["E"]
EI = E * b * h**3 / 12
M1 = 2 * np.pi * EI / L  # one full circle


def closed_form(M):
    phi = M * L / EI
    return L * (np.sin(phi) / phi - 1.0), L * (1.0 - np.cos(phi)) / phi, phi


# %% [markdown]
# ## Scene: 10 beam elements along x, clamped at x = 0, moment at x = L

# %%
tmesh = polyline([[0.0, 0.0], [L, 0.0]], 10, line_name="strip", comm=comm)
scene = dc.Scene(large_rotations=True)
strip = scene.add_beam(tmesh, "strip", section=dc.Rectangle(b, h), material=dc.Elastic(E, 0.0))
scene.fix(strip, "base")
scene.load(strip, "tip", moment=M1)  # load factor 1 = full circle, 2 = two turns
scene.monitor("tip", strip, "tip")

shapes = {}


def snapshot(row):
    lf = row["load_factor"]
    if any(abs(lf - v) < 1e-9 for v in (0.25, 0.5, 0.75, 1.0, 1.5, 2.0)):
        X, state = scene.model.nodes()
        order = np.argsort(X[:, 0])
        shapes[round(lf, 3)] = (X + state[:, :2])[order]


steps = 40  # 20 steps per turn: 18 degrees of tip rotation per step
t0 = time.perf_counter()
result = dc.solve(scene, dc.LoadControl(steps=steps, final=2.0), on_step=snapshot)
wall = time.perf_counter() - t0
hist = result.history
if comm.rank == 0:
    result.write(out)
say(f"{len(hist)} steps, {result.totals['newton_iterations']} Newton iterations, "
    f"{result.totals['cuts']} cuts, {wall:.2f} s")

# %% [markdown]
# ## Tip against the closed form at every step

# %%
lam = hist.column("load_factor")
u, w, phi = hist.column("tip_ux"), hist.column("tip_uy"), hist.column("tip_rz")
exact = np.array([closed_form(lf * M1) for lf in lam])
pos_err = np.hypot(u - exact[:, 0], w - exact[:, 1]) / L
i1 = int(np.argmin(np.abs(lam - 1.0)))
i2 = len(lam) - 1
say(f"full circle: tip ({u[i1]:+.3e}, {w[i1]:+.3e}) + L·(1, 0), rotation {phi[i1] / np.pi:.12f} π, "
    f"tip error {pos_err[i1]:.1e} L")
say(f"two turns:   tip ({u[i2]:+.3e}, {w[i2]:+.3e}) + L·(1, 0), rotation {phi[i2] / np.pi:.12f} π, "
    f"tip error {pos_err[i2]:.1e} L")
say(f"largest tip error along the path: {pos_err.max():.2e} L; Newton iterations per step: "
    f"{int(hist.column('iterations').min())}-{int(hist.column('iterations').max())}")

if comm.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.6))
    for lf, xy in shapes.items():
        ax[0].plot(xy[:, 0], xy[:, 1], "o-", ms=3, label=f"M = {lf:g}·2πEI/L")
    t = np.linspace(0, 2, 400)
    cf = np.array([closed_form(max(x, 1e-9) * M1) for x in t])
    ax[0].plot(L + cf[:, 0], cf[:, 1], "k:", lw=0.8, label="exact tip path")
    ax[0].set_aspect("equal")
    ax[0].set_title("Roll-up, 10 co-rotational beams")
    ax[0].legend(fontsize=7, loc="upper right")
    ax[1].plot(lam, u / L, "o", ms=3, label="$u_{tip}/L$ FE")
    ax[1].plot(lam, w / L, "s", ms=3, label="$w_{tip}/L$ FE")
    ax[1].plot(t, cf[:, 0] / L, "k-", lw=0.8, label="closed form")
    ax[1].plot(t, cf[:, 1] / L, "k-", lw=0.8)
    ax[1].set_xlabel("$M/(2\\pi EI/L)$")
    ax[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "cantilever_rollup_2d.png"), dpi=120)
    plt.close(fig)
    with open(os.path.join(out, "tip_values.json"), "w") as f:
        json.dump({"load_factor": lam.tolist(), "ux": u.tolist(), "uy": w.tolist(), "rz": phi.tolist(),
                   "ranks": comm.size}, f)

# %% [markdown]
# ## Verification

# %%
assert abs(lam[i1] - 1.0) < 1e-12 and abs(lam[i2] - 2.0) < 1e-12
assert pos_err[i1] < 1e-6, pos_err[i1]  # full circle: the tip is back at the clamp
assert pos_err[i2] < 1e-6, pos_err[i2]  # two turns
assert abs(phi[i1] - 2 * np.pi) < 1e-9 and abs(phi[i2] - 4 * np.pi) < 1e-9
assert pos_err.max() < 1e-3, pos_err.max()  # along the whole path (chord effect of 10 elements)
assert hist.column("iterations").max() <= 6
say("cantilever_rollup_2d: verified")

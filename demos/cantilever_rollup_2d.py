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
# the end. The section forces (`scene.monitor_results`: the largest and
# smallest over every element end, in the element's rotated axes) show the
# equilibrium itself: every section carries $M$ and no force, at every turn
# (measured: to 6·10⁻¹² M).

# %%
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io import reference
from dolfinx_corot.io.gmsh_models import polyline

comm = MPI.COMM_WORLD
B2A = "closed form B2a, circular arc of radius EI/M (reference/B2a_cantilever_end_moment.json)"

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
def rollup(demo):
    """Two turns in 40 load steps; the history and the deformed beam at a few load levels."""
    tmesh = polyline([[0.0, 0.0], [L, 0.0]], 10, line_name="strip", comm=comm)
    scene = dc.Scene(large_rotations=True)
    strip = scene.add_beam(tmesh, "strip", section=dc.Rectangle(b, h), material=dc.Elastic(E, 0.0))
    scene.fix(strip, "base")
    scene.load(strip, "tip", moment=M1)  # load factor 1 = full circle, 2 = two turns
    scene.monitor("tip", strip, "tip")
    # the section forces of every element end, largest and smallest: the applied moment everywhere
    scene.monitor_results("moment", strip, None, reduce="max", components="M")
    scene.monitor_results("least", strip, None, reduce="min", components=("N", "V", "M"))
    scene.monitor_results("force", strip, None, reduce="absmax", components=("N", "V"))

    shapes = {}
    pictures = dc.plot.Snapshots(scene, at=(0.25, 0.5, 1.0, 1.5, 2.0))  # PyVista states

    def snapshot(row):
        lf = row["load_factor"]
        if any(abs(lf - v) < 1e-9 for v in (0.25, 0.5, 0.75, 1.0, 1.5, 2.0)):
            X, state = scene.model.nodes()
            order = np.argsort(X[:, 0])
            shapes[round(lf, 3)] = (X + state[:, :2])[order]
        pictures(row)

    steps = 40  # 20 steps per turn: 18 degrees of tip rotation per step
    result, wall = timed(dc.solve, scene, dc.LoadControl(steps=steps, final=2.0), on_step=snapshot)
    demo.write_result(result)
    demo.say(f"{len(result.history)} steps, {result.totals['newton_iterations']} Newton iterations, "
             f"{result.totals['cuts']} cuts, {wall:.2f} s")
    demo.picture(pictures, "rollup_shapes.png", field="rotation", title="M = 0.25, 0.5, 1, 1.5, 2 × 2πEI/L")
    return result.history, shapes


# %% [markdown]
# ## Tip against the closed form at every step

# %%
def tip_errors(demo, hist, shapes):
    """Tip position error / L at every step; the indices of the full circle and of two turns."""
    lam = hist.column("load_factor")
    u, w, phi = hist.column("tip_ux"), hist.column("tip_uy"), hist.column("tip_rz")
    exact = np.array([closed_form(lf * M1) for lf in lam])
    pos_err = np.hypot(u - exact[:, 0], w - exact[:, 1]) / L
    i1 = int(np.argmin(np.abs(lam - 1.0)))
    i2 = len(lam) - 1
    demo.say(f"full circle: tip ({u[i1]:+.3e}, {w[i1]:+.3e}) + L·(1, 0), rotation {phi[i1] / np.pi:.12f} π, "
             f"tip error {pos_err[i1]:.1e} L")
    demo.say(f"two turns:   tip ({u[i2]:+.3e}, {w[i2]:+.3e}) + L·(1, 0), rotation {phi[i2] / np.pi:.12f} π, "
             f"tip error {pos_err[i2]:.1e} L")
    demo.say(f"largest tip error along the path: {pos_err.max():.2e} L; Newton iterations per step: "
             f"{int(hist.column('iterations').min())}-{int(hist.column('iterations').max())}")

    fig, ax = demo.figure(1, 2, figsize=(11, 4.6))
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
    demo.save(fig, "cantilever_rollup_2d.png")
    demo.record(load_factor=lam, ux=u, uy=w, rz=phi)
    return pos_err, i1, i2


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("cantilever_rollup_2d")
    hist, shapes = rollup(demo)
    pos_err, i1, i2 = tip_errors(demo, hist, shapes)
    lam, phi = hist.column("load_factor"), hist.column("tip_rz")
    demo.check("load factors of the full circle and of two turns", [lam[i1], lam[i2]], [1.0, 2.0], atol=1e-12,
               reference="the load path (40 equal steps to 2)")
    demo.check("tip error / L, full circle (the tip is back at the clamp)", pos_err[i1], bound=1e-6,
               reference=B2A)
    demo.check("tip error / L, two turns", pos_err[i2], bound=1e-6, reference=B2A)
    demo.check("tip rotation at one and two turns", [phi[i1], phi[i2]], [2 * np.pi, 4 * np.pi], atol=1e-9,
               reference=B2A + ": φ = ML/EI")
    demo.check("largest tip error / L along the path (chord effect of 10 elements)", pos_err.max(), bound=1e-3,
               reference=B2A)
    applied = lam * M1
    spread = np.maximum(np.abs(hist.column("moment_M_max") - applied), np.abs(hist.column("least_M_min") - applied))
    demo.say(f"section moments: within {spread.max() / M1:.1e} M of the applied moment at every step; |N|, |V| ≤ "
             f"{max(np.abs(hist.column('force_N_absmax')).max(), np.abs(hist.column('force_V_absmax')).max()):.1e}")
    demo.check("section moment of every element end / applied moment, at one and two turns",
               [hist.column(c)[i] / applied[i] for i in (i1, i2) for c in ("moment_M_max", "least_M_min")], 1.0,
               rtol=1e-9, reference="equilibrium of the part beyond any section: it carries the end moment alone")
    demo.check("largest |section moment − applied moment| / M1 along the path", spread.max() / M1, bound=1e-9,
               reference="equilibrium of the part beyond any section")
    demo.check("largest |N|, |V| along the path / (M1/L)",
               max(np.abs(hist.column("force_N_absmax")).max(), np.abs(hist.column("force_V_absmax")).max()) / (M1 / L),
               bound=1e-9, reference="equilibrium: a pure end moment carries no force")
    demo.check("Newton iterations per step", hist.column("iterations").max(), bound=6,
               reference="solver acceptance (no published value)")
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

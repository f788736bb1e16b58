# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # The 45° bend: a curved cantilever loaded out of its plane
#
# Seed §2.3.2 (Bathe & Bolourchi 1979; Litewka & Wriggers). A circular arc of
# radius $R = 100$ spanning 45° in the x–y plane (tangent +x at the clamp,
# centre (0, R, 0)), square section 1×1, $E = 5\cdot10^7$, $\nu = 0.2$, carries a
# dead tip force $F = 7EI/R^2 = 2916.7$ along +z. Eight straight co-rotational
# Bernoulli beams. The reference is the exact Kirchhoff rod (inextensible,
# unshearable) with the Saint-Venant torsion constant $J = 0.140577$, from
# `reference/B2c_45deg_bend.json` (scaled version).

# %%
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io import reference
from dolfinx_corot.io.gmsh_models import polyline

comm = MPI.COMM_WORLD
B2C = "B2c exact Kirchhoff rod, Saint-Venant J (reference/B2c_45deg_bend.json, scaled version)"

ref = reference("B2c_45deg_bend")
scaled = ref["scaled_version"]
exact = np.array(scaled["exact"]["Kirchhoff_JsaintVenant"]["data"])  # P, x, y, z, ux, uy, uz
ex = exact[1:, 4:7]
R, E, nu = 100.0, 5e7, 0.2
J = scaled["exact"]["Kirchhoff_JsaintVenant"]["props"]["J"]
EI = E / 12.0
F = 7 * EI / R**2


def bend(n):
    phi = np.linspace(0.0, np.pi / 4, n + 1)
    pts = np.c_[R * np.sin(phi), R * (1 - np.cos(phi)), np.zeros(n + 1)]
    tmesh = polyline(pts, 1, line_name="arc", gdim=3, comm=comm)
    scene = dc.Scene(large_rotations=True)
    arc = scene.add_beam(tmesh, "arc", section=dc.Section(A=1.0, I=1 / 12, Iy=1 / 12, J=J),
                         material=dc.Elastic(E, nu), orientation=(0.0, 0.0, 1.0))
    scene.fix(arc, "base")
    scene.load(arc, "tip", force=(0.0, 0.0, F))
    scene.monitor("tip", arc, "tip")
    return scene


# %% [markdown]
# ## Eight elements, ten load steps (fields for ParaView in `bend.xdmf`)
#
# `bend_shapes.png` draws the bend at 20, 40, 60, 80 and 100 % of the tip force over
# its initial arc (grey), coloured by $|u|$: the tip rises out of the plane of the arc (z up).

# %%
def eight_elements(demo):
    """The history of the 8-element bend and the relative tip error at every step."""
    scene = bend(8)
    shots = dc.plot.Snapshots(scene, at=(0.2, 0.4, 0.6, 0.8, 1.0))  # for the PyVista picture
    # the deformed bend at every step, for ParaView (Warp By Vector on "displacement")
    with dc.io.FieldWriter(scene, demo.path("bend.xdmf")) as writer:
        def on_step(row):
            writer(row)
            shots(row)

        result, wall = timed(dc.solve, scene, dc.LoadControl(steps=10), on_step=on_step)
    demo.picture(shots, "bend_shapes.png", field="displacement",
                 title="45° bend: F = 0.2, 0.4, 0.6, 0.8, 1 × 7EI/R²",
                 camera=[(120.0, -220.0, 160.0), (35.0, 10.0, 25.0), (0.0, 0.0, 1.0)])
    hist = result.history
    demo.write_result(result)
    u = np.c_[hist.column("tip_ux"), hist.column("tip_uy"), hist.column("tip_uz")]
    err = np.linalg.norm(u - ex, axis=1) / np.linalg.norm(ex, axis=1)
    demo.say(f"{len(hist)} steps, {result.totals['newton_iterations']} Newton iterations, {wall:.2f} s")
    demo.say(f"tip displacement at F: ({u[-1, 0]:.3f}, {u[-1, 1]:.3f}, {u[-1, 2]:.3f}); exact rod "
             f"({ex[-1, 0]:.3f}, {ex[-1, 1]:.3f}, {ex[-1, 2]:.3f}); relative error {err[-1]:.2e}")
    demo.say(f"as the seed lists it (|uy|, ux, uz): ({abs(u[-1, 1]):.1f}, {u[-1, 0]:.1f}, {u[-1, 2]:.1f}); "
             "seed reference (13.5, -23.6, 54.0), Z_Soil (13.5, -23.6, 53.3)")
    demo.record(load_factor=hist.column("load_factor"), ux=u[:, 0], uy=u[:, 1], uz=u[:, 2])
    return hist, err


# %% [markdown]
# ## Accuracy against time: 4 to 32 elements

# %%
def work_precision(demo, hist):
    """(elements, tip error at F, wall time, Newton iterations) per mesh; the plot."""
    study = []
    for n in ([4, 8, 16] if demo.ci else [4, 8, 16, 32]):
        sc = bend(n)
        r, dt = timed(dc.solve, sc, dc.LoadControl(steps=10))
        un = np.array([r.history.column(c)[-1] for c in ("tip_ux", "tip_uy", "tip_uz")])
        e = np.linalg.norm(un - ex[-1]) / np.linalg.norm(ex[-1])
        study.append((n, e, dt, r.totals["newton_iterations"]))
        demo.say(f"{n:3d} elements: tip error {e:.2e}, {dt:.2f} s, {r.totals['newton_iterations']} iterations")
    study = np.array(study)

    demo.table("work_precision.csv", study, ["elements", "tip_rel_error", "wall_time_s", "newton_iterations"])
    demo.work_precision(study[:, 0].astype(int), study[:, 1], study[:, 2], reference=B2C,
                        quantity="tip displacement (elements)")
    fig, ax = demo.figure(1, 2, figsize=(11, 4.2))
    lam = hist.column("load_factor")
    for k, (name, c) in enumerate((("$u_x$", "tip_ux"), ("$u_y$", "tip_uy"), ("$u_z$", "tip_uz"))):
        ax[0].plot(exact[:, 0], exact[:, 4 + k], "k-", lw=0.8)
        ax[0].plot(lam * F, hist.column(c), "o", ms=4, label=f"{name}, 8 co-rotational beams")
    ax[0].set_xlabel("tip force F")
    ax[0].set_ylabel("tip displacement")
    ax[0].set_title("45° bend (lines: exact Kirchhoff rod)")
    ax[0].legend(fontsize=8)
    ax[1].loglog(study[:, 2], study[:, 1], "o-")
    for n, e, dt, _ in study:
        ax[1].annotate(f"{int(n)}", (dt, e), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax[1].set_xlabel("wall time [s] (10 load steps)")
    ax[1].set_ylabel("relative tip error at F")
    ax[1].set_title("work-precision (elements labelled)")
    demo.save(fig, "curved_beam_3d.png")
    return study


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("curved_beam_3d")
    demo.say(f"F = 7EI/R² = {F:.1f}, J = {J}")
    hist, err = eight_elements(demo)
    study = work_precision(demo, hist)
    demo.check("relative tip error, 8 elements, every load step (acceptance 1 %)", err.max(), bound=0.01,
               reference=B2C)
    demo.check("Newton iterations per step", hist.column("iterations").max(), bound=6,
               reference="solver acceptance (no published value)")
    demo.check("tip error at F, finest mesh / coarsest mesh (refinement converges to the rod)",
               study[-1, 1] / study[0, 1], bound=0.1, reference=B2C)
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

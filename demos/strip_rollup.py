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
# into two flat co-rotational triangles (OPT membrane with drilling rotations,
# DKT bending), 6 dofs per node. The same squares as four-node shells
# (incompatible-mode membrane, discrete Kirchhoff quadrilateral) and both
# families on 8, 16 and 32 squares show what accuracy costs.

# %%
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io import reference

comm = MPI.COMM_WORLD
B2A = "closed form B2a (reference/B2a_cantilever_end_moment.json)"

p = reference("B2a_cantilever_end_moment")["problem"]
L, b, t, E = p["L"], p["b"], p["h"], p["E"]
EI = E * b * t**3 / 12
nx = 16


def tip_closed_form(lam):
    """(u, w) of the tip under M = λ·2πEI/L: the closed form B2a with φ = 2πλ."""
    phi = 2 * np.pi * lam
    return L * (np.sin(phi) / phi - 1), L * (1 - np.cos(phi)) / phi


def plot_tip(ax, lam, u, w, label, exact_label):
    """u/L and w/L of the tip against λ (``label``: the FE model), with the closed form."""
    ax.plot(lam, u / L, "o", ms=4, label=label)
    ax.plot(lam, w / L, "s", ms=4, label="$w_{tip}/L$")
    s = np.linspace(1e-6, 1.0, 200)
    u_ex, w_ex = tip_closed_form(s)
    ax.plot(s, u_ex / L, "k-", lw=0.8, label=exact_label)
    ax.plot(s, w_ex / L, "k-", lw=0.8)
    ax.legend(fontsize=8)


# %% [markdown]
# ## The strip as a structured gmsh surface with named edges

# %%
import gmsh  # noqa: E402


def strip_scene(demo, nx=nx, quads=False):
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        pts = [gmsh.model.geo.addPoint(*c) for c in ((0, 0, 0), (L, 0, 0), (L, b, 0), (0, b, 0))]
        lines = [gmsh.model.geo.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
        surface = gmsh.model.geo.addPlaneSurface([gmsh.model.geo.addCurveLoop(lines)])
        for line, n in zip(lines, (nx, 1, nx, 1)):
            gmsh.model.geo.mesh.setTransfiniteCurve(line, n + 1)
        gmsh.model.geo.mesh.setTransfiniteSurface(surface)
        if quads:
            gmsh.model.geo.mesh.setRecombine(2, surface)
        gmsh.model.geo.synchronize()
        for dim, tags, tag, name in ((2, [surface], 1, "strip"), (1, [lines[3]], 2, "clamp"),
                                     (1, [lines[1]], 3, "tip")):
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
    scene.monitor("tip", strip, "tip", reduce="mean")  # the two tip nodes move alike: their mean
    if demo is not None:
        demo.say("effects:", scene.effects())
    return scene


def tip_errors(result):
    """(load factors, tip error / L per step) against the closed form."""
    hist = result.history
    lam = hist.column("load_factor")
    u_ex, w_ex = tip_closed_form(lam)
    return lam, np.hypot(hist.column("tip_ux_mean") - u_ex, hist.column("tip_uz_mean") - w_ex) / L


# %% [markdown]
# ## Thirty load steps to the full circle
#
# `strip_shapes.png` draws the strip at $M$ = 0.27, 0.5, 0.77 and 1 × $2\pi EI/L$ over its
# flat outline, coloured by the angle of the nodal rotations (between 0 and π, so the tip of the
# closed circle is back at 0).

# %%
def full_circle(demo, scene):
    """The run (fields in strip.xdmf) and the tip error / L at every step."""
    shots = dc.plot.Snapshots(scene, at=(0.25, 0.5, 0.75, 1.0))  # for the PyVista picture
    with dc.io.FieldWriter(scene, demo.path("strip.xdmf")) as writer:
        def on_step(row):
            writer(row)
            shots(row)

        result, wall = timed(dc.solve, scene, dc.LoadControl(steps=30), on_step=on_step)
    hist = result.history
    demo.write_result(result)
    demo.picture(shots, "strip_shapes.png", field="rotation", layout="overlay", window_size=(1100, 800),
                 camera=[(6.0, -40.0, 12.0), (6.0, 0.5, 2.0), (0.0, 0.0, 1.0)],
                 title="Strip roll-up: M = 0.27, 0.5, 0.77, 1 × 2πEI/L")
    lam = hist.column("load_factor")
    u, w = hist.column("tip_ux_mean"), hist.column("tip_uz_mean")
    u_ex, w_ex = tip_closed_form(lam)
    err = np.hypot(u - u_ex, w - w_ex) / L
    demo.say(f"{len(hist)} steps, {result.totals['newton_iterations']} Newton iterations, {wall:.2f} s")
    demo.say(f"full circle: tip ({u[-1]:+.5f}, {w[-1]:+.5f}) against (−12, 0): error {err[-1]:.1e} L; "
             f"largest error on the path {err.max():.1e} L")
    demo.say(f"residuals of the last step: {hist.rows[-1]['residuals']}")

    fig, ax = demo.figure(figsize=(6, 4))
    plot_tip(ax, lam, u, w, "$u_{tip}/L$, 32 shell triangles", "closed form")
    ax.set(xlabel="$M/(2\\pi EI/L)$", title="Strip roll-up, co-rotational flat shells")
    demo.save(fig, "strip_rollup.png")
    demo.record(load_factor=lam, ux=u, uz=w)
    return result, err


# %% [markdown]
# ## Triangles and quadrilaterals on 8, 16 and 32 squares
#
# The tip error at the full circle and the largest along the path, the wall time and the Newton
# iterations of each run.

# %%
def families(demo):
    rows = []
    for quads in (False, True):
        for n in (8, 16, 32):
            result, wall = timed(dc.solve, strip_scene(None, n, quads), dc.LoadControl(steps=30), quiet=True)
            _, err = tip_errors(result)
            rows.append({"quads": int(quads), "squares": n, "nodes": 2 * (n + 1), "error_end_L": err[-1],
                         "error_max_L": err.max(), "wall_s": wall,
                         "newton_iterations": result.totals["newton_iterations"], "cuts": result.totals["cuts"]})
            demo.say(f"{'quadrilaterals' if quads else 'triangles':>14s} {n:2d} squares: tip error {err[-1]:.1e} L "
                     f"at the full circle, {err.max():.1e} L at most; {result.totals['newton_iterations']} "
                     f"iterations, {wall:.2f} s")
    demo.table("families.csv", rows)
    for quads, label in ((0, "triangles (OPT + DKT)"), (1, "quadrilaterals (DKQ)")):
        part = [r for r in rows if r["quads"] == quads]
        demo.work_precision([r["nodes"] for r in part], [r["error_max_L"] for r in part],
                            [r["wall_s"] for r in part], quantity="largest tip error / L on the path (nodes)",
                            reference=B2A, series=label)
    return rows


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("strip_rollup")
    result, err = full_circle(demo, strip_scene(demo))
    rows = families(demo)
    demo.record(quad_error_max_L=[r["error_max_L"] for r in rows if r["quads"]])
    tri = [r for r in rows if not r["quads"]]
    quad = [r for r in rows if r["quads"]]
    demo.check("quadrilaterals: tip error / L at the full circle, 8, 16, 32 squares", [r["error_end_L"] for r in quad],
               bound=1e-6, reference=B2A)
    demo.check("quadrilaterals: largest tip error / L on the path, 8, 16, 32 squares",
               [r["error_max_L"] for r in quad], bound=[5e-3, 2e-3, 1e-3], reference=B2A)
    demo.check("largest tip error on the path, quadrilaterals / triangles on the same nodes",
               [q["error_max_L"] / t["error_max_L"] for q, t in zip(quad, tri)], bound=1.05, reference=B2A)
    demo.check("failed load steps of the six runs", sum(r["cuts"] for r in rows), 0,
               reference="solver acceptance (no published value)")
    demo.check("tip error / L at the full circle (acceptance on a modest mesh)", err[-1], bound=1e-3,
               reference=B2A)
    demo.check("largest tip error / L along the path", err.max(), bound=2e-3, reference=B2A)
    demo.check("failed load steps", result.totals["cuts"], 0, reference="solver acceptance (no published value)")
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

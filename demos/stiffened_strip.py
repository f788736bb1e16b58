# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---
# %% [markdown]
# # A stiffened strip rolled into a circle: shells and beams sharing nodes
#
# The plate strip of `strip_rollup` ($L = 12$, $b = 1$, $t = 0.1$,
# $E = 1.2\cdot10^6$, $\nu = 0$, $EI_s = Ebt^3/12 = 100$) gets a stiffener
# along its centre line: a beam of circular section whose axis lies in the
# mid-surface, with $EI_b = 100$ as well. One gmsh model holds both: the
# surface's triangles and the centre line's segments, which share their
# nodes. The shell is read as one mesh (`from_gmsh(model, 3)`) and the lines
# as another (`from_gmsh(model, 3, dim=1)`); the scene couples the two
# through the common gmsh node numbers, so the beam's nodes *are* shell nodes.
#
# With the stiffener in the mid-surface and $\nu = 0$ the section acts as one
# with $EI = EI_s + EI_b = 200$: the end moment $M = 2\pi EI/L$ closes a full
# circle, and each intermediate tip position is the closed form of B2a.
# Without the coupling the same moment would roll the strip twice around and
# leave the beam behind. The closed form and its plot are those of
# `strip_rollup.py` beside this demo (the strip's $L$ is the same). The strip
# is meshed with triangles and, in a second set of runs, with quadrilaterals
# (gmsh's recombination of the same squares): the beam shares the nodes of
# either.

# %%
import json
import logging

import numpy as np
from mpi4py import MPI
from strip_rollup import plot_tip, tip_closed_form

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io import reference

comm = MPI.COMM_WORLD
B2A = "closed form B2a with EI = EI_s + EI_b (reference/B2a_cantilever_end_moment.json)"

p = reference("B2a_cantilever_end_moment")["problem"]
L, b, t, E = p["L"], p["b"], p["h"], p["E"]
EI_s = E * b * t**3 / 12
EI_b = EI_s
d = (64 * EI_b / (np.pi * E)) ** 0.25        # diameter of a circle of second moment EI_b / E
EI = EI_s + EI_b
meshes = (16, 32, 64)
STEPS = 24

# %% [markdown]
# ## One gmsh model: two half-strips meeting on the centre line
# %%
import gmsh  # noqa: E402


def strip_meshes(nx: int, quads: bool = False):
    """(shell mesh, beam mesh) of one gmsh model: nx × 2 squares, each cut into two triangles
    (or kept whole with ``quads``), and the nx segments of the centre line, which are edges of
    those cells."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        geo = gmsh.model.geo
        c = [(0, 0), (L, 0), (L, b / 2), (0, b / 2), (L, b), (0, b)]
        P = [geo.addPoint(x, y, 0.0) for x, y in c]
        bottom, tip1, centre, root1 = (geo.addLine(P[0], P[1]), geo.addLine(P[1], P[2]),
                                       geo.addLine(P[3], P[2]), geo.addLine(P[3], P[0]))
        tip2, top, root2 = geo.addLine(P[2], P[4]), geo.addLine(P[4], P[5]), geo.addLine(P[5], P[3])
        s1 = geo.addPlaneSurface([geo.addCurveLoop([bottom, tip1, -centre, root1])])
        s2 = geo.addPlaneSurface([geo.addCurveLoop([centre, tip2, top, root2])])
        for line in (bottom, centre, top):
            geo.mesh.setTransfiniteCurve(line, nx + 1)
        for line in (tip1, root1, tip2, root2):
            geo.mesh.setTransfiniteCurve(line, 2)
        geo.mesh.setTransfiniteSurface(s1)
        geo.mesh.setTransfiniteSurface(s2)
        if quads:
            geo.mesh.setRecombine(2, s1)
            geo.mesh.setRecombine(2, s2)
        geo.synchronize()
        groups = ((2, [s1, s2], "strip"), (1, [centre], "stiffener"), (1, [root1, root2], "clamp"),
                  (1, [tip1, tip2], "tip"), (0, [P[2]], "tip_centre"))
        for k, (dim, tags, name) in enumerate(groups, start=1):
            gmsh.model.addPhysicalGroup(dim, tags, k)
            gmsh.model.setPhysicalName(dim, k, name)
        gmsh.model.mesh.generate(2)
    model = gmsh.model if comm.rank == 0 else None
    shell_mesh = dc.from_gmsh(model, gdim=3, comm=comm)
    beam_mesh = dc.from_gmsh(model, gdim=3, comm=comm, dim=1)
    if comm.rank == 0:
        gmsh.finalize()
    return shell_mesh, beam_mesh


# %% [markdown]
# ## The scene: shell, beam, clamp, end moment
# The strip's end moment per unit width is $M_s/b$ with $M_s = 2\pi EI_s/L$;
# with two elements across the width the consistent nodal moments are
# $M_s/4, M_s/2, M_s/4$; the stiffener's share $M_b = 2\pi EI_b/L$ acts at the
# centre node. The clamp is given on the shell; the beam's root node is the
# same node.
# %%
M_s, M_b = 2 * np.pi * EI_s / L, 2 * np.pi * EI_b / L


def rollup(demo, nx: int, quads: bool = False):
    shell_mesh, beam_mesh = strip_meshes(nx, quads)
    scene = dc.Scene(large_rotations=True)
    strip = scene.add_shell(shell_mesh, "strip", thickness=t, material=dc.Elastic(E, 0.0))
    stiffener = scene.add_beam(beam_mesh, "stiffener", section=dc.Circle(d), material=dc.Elastic(E, 0.0),
                               orientation=(0.0, 1.0, 0.0))
    scene.fix(strip, "clamp")
    scene.load(strip, "tip", moment=(0.0, -M_s / 4, 0.0))
    scene.load(stiffener, "tip_centre", moment=(0.0, -(M_s / 4 + M_b), 0.0))
    scene.monitor("tip", stiffener, "tip_centre")
    scene.monitor("edge", strip, "tip", reduce="profile")  # every node of the tip edge
    if nx == meshes[0] and not quads:
        demo.say("effects:", scene.effects())
    if nx != meshes[-1] or quads:
        return timed(dc.solve, scene, dc.LoadControl(steps=STEPS))
    shots = dc.plot.Snapshots(scene, at=(0.25, 0.5, 0.75, 1.0))  # the finest mesh: a picture
    result, wall = timed(dc.solve, scene, dc.LoadControl(steps=STEPS), on_step=shots)
    demo.picture(shots, "stiffened_strip_shapes.png", field="rotation", layout="overlay", window_size=(1100, 800),
                 camera=[(6.0, -40.0, 12.0), (6.0, 0.5, 2.0), (0.0, 0.0, 1.0)],
                 title=f"Stiffened strip ({nx} x 2): M = 0.25, 0.5, 0.75, 1 × 2πEI/L")
    return result, wall


# %% [markdown]
# ## Twenty-four load steps to the full circle, on three meshes
# `stiffened_strip_shapes.png` draws the strip and its stiffener (a tube along the centre
# line) on the finest mesh at a quarter, half, three quarters and all of the moment, coloured
# by the angle of the nodal rotations (between 0 and π: back to 0 at the closed circle).
#
# The beam measures its axial strain along its cubic (the shallow-arch law
# that makes lone beams accurate), the flat shell along its chords; coupled,
# the two disagree by $O(\varphi_e^2)$ per element of turn $\varphi_e$, which
# puts a small self-equilibrated axial force in the stiffener whose moment
# changes the turn. The disagreement vanishes as $h^4$, which the three
# meshes show.
# %%
def three_meshes(demo, quads: bool = False):
    """One row per mesh (tip and path errors, section warp, Newton iterations, cuts, time), the
    finest mesh's history, and the observed orders of the tip error; triangles or quadrilaterals."""
    rows = []
    family = "quadrilaterals" if quads else "triangles"
    for nx in meshes:
        result, wall = rollup(demo, nx, quads)
        hist = result.history
        u, w = hist.column("tip_ux"), hist.column("tip_uz")
        u_ex, w_ex = tip_closed_form(hist.column("load_factor"))
        err = np.hypot(u - u_ex, w - w_ex) / L
        edge = result.profiles["edge"]  # (steps, nodes) per dof: the edge nodes off the centre node
        edge_gap = np.hypot(edge.column("ux") - u[:, None], edge.column("uz") - w[:, None]).max(axis=1) / L
        rows.append({"nx": nx, "tip_error_L": float(err[-1]), "path_error_L": float(err.max()),
                     "section_warp_L": float(edge_gap.max()),
                     "newton_iterations": result.totals["newton_iterations"],
                     "cuts": result.totals["cuts"], "wall_time_s": wall})
        demo.say(f"{family:>14s} {nx:3d} x 2 squares: {len(hist)} steps, {result.totals['newton_iterations']} Newton iterations, "
                 f"{wall:.2f} s; full circle: tip ({u[-1]:+.5f}, {w[-1]:+.5f}), error {err[-1]:.1e} L "
                 f"(path {err.max():.1e} L); edge node off the centre node's section {edge_gap.max():.1e} L")
        demo.write_result(result, f"{'quad_' if quads else ''}nx{nx}")
    rates = [np.log2(a["tip_error_L"] / b["tip_error_L"]) for a, b in zip(rows, rows[1:])]
    demo.say(f"{family}: observed orders of the tip error:", ", ".join(f"{r:.2f}" for r in rates))
    demo.table(f"convergence{'_quadrilaterals' if quads else ''}.csv", rows)
    demo.work_precision([3 * (r["nx"] + 1) for r in rows], [r["tip_error_L"] for r in rows],
                        [r["wall_time_s"] for r in rows], quantity="tip position at the full circle (shell nodes)",
                        reference=B2A, series="triangles (OPT + DKT)" if not quads else "quadrilaterals (DKQ)")
    if demo.rank == 0:
        with open(demo.path(f"convergence{'_quadrilaterals' if quads else ''}.json"), "w") as f:
            json.dump(rows, f, indent=1)
    return rows, hist, rates


def plot(demo, rows, hist):
    lam, u, w = hist.column("load_factor"), hist.column("tip_ux"), hist.column("tip_uz")
    fig, (ax, ax2) = demo.figure(1, 2, figsize=(10, 4))
    plot_tip(ax, lam, u, w, f"$u_{{tip}}/L$, shell + beam, {meshes[-1]}×2", "closed form, $EI_s + EI_b$")
    ax.set(xlabel="$M/(2\\pi (EI_s + EI_b)/L)$", title="Stiffened strip: shells and a beam sharing nodes")
    ax2.loglog([r["nx"] for r in rows], [r["tip_error_L"] for r in rows], "o-", label="tip error / L, full circle")
    n = np.array(meshes, dtype=float)
    ax2.loglog(n, rows[0]["tip_error_L"] * (n / n[0]) ** -4, "k--", lw=0.8, label="$h^4$")
    ax2.set_xlabel("elements along the strip")
    ax2.legend(fontsize=8)
    demo.save(fig, "stiffened_strip.png")
    demo.record(load_factor=lam, ux=u, uz=w)


# %% [markdown]
# ## Verification
# %%
def main() -> dict:
    demo = Demo("stiffened_strip")
    rows, hist, rates = three_meshes(demo)
    quad_rows, _, quad_rates = three_meshes(demo, quads=True)
    plot(demo, rows, hist)
    demo.record(quad_tip_error_L=[r["tip_error_L"] for r in quad_rows])
    for rs, rt, family in ((rows, rates, "triangles"), (quad_rows, quad_rates, "quadrilaterals")):
        warp = [r["section_warp_L"] for r in rs]
        demo.check(f"{family}: tip error / L at the full circle, {meshes[-1]} x 2 squares", rs[-1]["tip_error_L"],
                   bound=1e-3, reference=B2A)
        demo.check(f"{family}: observed orders of the tip error", rt, bound=(3.5, None),
                   reference=B2A + ": h⁴ convergence expected of the beam–shell strain mismatch")
        demo.check(f"{family}: edge node off the centre node's section / L, every mesh", warp, bound=5e-3,
                   reference="plane sections of the coupled strip (B2a kinematics)")
        demo.check(f"{family}: decrease of that warp from mesh to mesh", np.diff(warp), bound=(None, 0.0),
                   reference="self-convergence (no published value)")
        demo.check(f"{family}: failed load steps, every mesh", [r["cuts"] for r in rs], 0,
                   reference="solver acceptance (no published value)")
    demo.check("tip error at the full circle, quadrilaterals / triangles on the same nodes, every mesh",
               [q["tip_error_L"] / t["tip_error_L"] for q, t in zip(quad_rows, rows)], bound=1.05, reference=B2A)
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

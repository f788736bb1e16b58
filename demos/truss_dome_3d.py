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
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed

comm = MPI.COMM_WORLD
EXACT = "closed-form equilibrium path P(w) of the symmetric dome (in this demo)"
R, h, EA, nbars = 50.0, 5.0, 1e6, 6


def P_exact(w):
    l0 = np.hypot(R, h)
    l = np.hypot(R, h - w)
    return -nbars * EA * (l - l0) / l0 * (h - w) / l


w_fine = np.linspace(0.0, 2.2 * h, 22001)
P_max = P_exact(w_fine[w_fine <= h]).max()  # the snap-through load
P_min = P_exact(w_fine[w_fine >= h]).min()  # and the load of the inverted dome's snap back

# %% [markdown]
# ## The dome as a gmsh model: six bars, named apex and supports

# %%
import gmsh  # noqa: E402


def dome(demo):
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
    demo.say("effects:", scene.effects())
    return scene


# %% [markdown]
# ## Arc-length through the snap
#
# `dome_shapes.png` shows the dome from the side at every 30th arc-length step (apex
# deflection $w$ = 2.5, 5.1, 7.6 and 10.1: past the load maximum, flat, near the load minimum,
# inverted), coloured by $|u|$, the displacements drawn three times their size.

# %%
def snap_through(demo, scene):
    """The arc-length run: (result, P, w, deviation from the exact path / P_max, lateral motion)."""
    driver = dc.ArcLength(initial_increment=100.0, max_growth=1.0, max_steps=400,
                          stop=lambda row: -row["apex_uz"] > 2.1 * h)
    shots = dc.plot.Snapshots(scene, every=30)  # PyVista states: 4 along the path
    result, wall = timed(dc.solve, scene, driver, on_step=shots)
    hist = result.history
    demo.write_result(result)
    demo.picture(shots, "dome_shapes.png", field="displacement", scale=3.0, window_size=(1400, 700),
                 camera=[(0.0, -300.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)],
                 title="Truss dome seen from the side: arc-length steps 30, 60, 90, 120 (w = 2.5, 5.1, 7.6, 10.1), "
                       "displacements ×3")
    P = hist.column("load_factor")
    w = -hist.column("apex_uz")
    err = np.abs(P - P_exact(w)) / P_max
    lateral = np.abs(np.c_[hist.column("apex_ux"), hist.column("apex_uy")]).max()
    demo.say(f"{len(hist)} steps, {result.totals['newton_iterations']} iterations, {result.totals['cuts']} cuts, "
             f"{wall:.2f} s; iterations per step {int(hist.column('iterations').min())}-"
             f"{int(hist.column('iterations').max())}")
    demo.say(f"largest deviation from the exact path: {err.max():.1e} P_max; lateral apex motion {lateral:.1e}")
    demo.say(f"computed limit loads (largest sampled points): {P[w <= h].max():.3f} and {P[w >= h].min():.3f} "
             f"(exact {P_max:.3f}, {P_min:.3f})")

    fig, ax = demo.figure(figsize=(6, 4.2))
    ax.plot(w_fine, P_exact(w_fine), "k-", lw=0.8, label="exact")
    ax.plot(w, P, "o", ms=3, label="arc-length, 3D co-rotational bars")
    ax.axhline(0.0, color="0.7", lw=0.6)
    ax.set_xlabel("apex deflection w")
    ax.set_ylabel("apex load P")
    ax.set_title("Shallow space-truss dome: snap-through")
    ax.legend(fontsize=8)
    demo.save(fig, "truss_dome_3d.png")
    demo.record(load_factor=P, w=w)
    return result, P, w, err, lateral


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("truss_dome_3d")
    demo.say(f"exact limit loads: P_max = {P_max:.3f}, P_min = {P_min:.3f}")
    result, P, w, err, lateral = snap_through(demo, dome(demo))
    demo.check("deviation of every path point from the exact path / P_max", err.max(), bound=1e-8,
               reference=EXACT)
    demo.check("lateral apex motion", lateral, bound=1e-10, reference="symmetry of the dome: none")
    demo.check("failed arc-length steps", result.totals["cuts"], 0, reference="solver acceptance (no published value)")
    demo.check("Newton iterations per step", result.history.column("iterations").max(), bound=6,
               reference="solver acceptance (no published value)")
    demo.check("largest sampled load before w = h / P_max (through the snap-through point)",
               P[w <= h].max() / P_max, bound=(0.999, None), reference=EXACT)
    demo.check("smallest sampled load after w = h / P_min (through the snap-back point)",
               P[w >= h].min() / P_min, bound=(0.999, None), reference=EXACT)
    demo.check("last apex deflection / h", w[-1] / h, bound=(2.0, None),
               reference="the run's stop criterion (deflection 2.1 h)")
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

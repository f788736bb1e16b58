# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Euler column: eccentric compression far into the post-buckling range
#
# Seed §2.3.1 (Z_Soil report 070303, "Euler2D"). A cantilever column of length
# $L = 1$ m, square section $b = h = 0.1$ m, $E = 10^5$ kPa, $\nu = 0$, is
# clamped at its base and loaded at its free tip by a dead compressive force
# $N$ and a dead moment $M = N e$ with eccentricity $e = 0.01$ m. $N$ grows
# from 0 to $4N_{cr}$, $N_{cr} = \pi^2 EI/(2L)^2 = 2.056$ kN. The mesh is the
# seed's: 10 equal two-node beam elements.
#
# The elements are co-rotational Bernoulli beams with the shallow-arch local
# law (Crisfield 1991, §7.2.1), so we compare with the *extensible Bernoulli*
# elastica ($EA = 1000$ kN) from `reference/B1_elastica_eccentric_compression.json`,
# an independent shooting solution of the rod equations.

# %%
import logging
import os

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io import reference
from dolfinx_corot.io.gmsh_models import polyline

comm = MPI.COMM_WORLD
here = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else os.getcwd()  # a notebook: demos/
B1 = "B1 exact extensible Bernoulli elastica, e = 0.01 m (reference/B1_elastica_eccentric_compression.json)"

# %% [markdown]
# ## Problem data and the reference solution

# %%
ref = reference("B1_elastica_eccentric_compression")
p = ref["problem"]
L, b, h, E, nu = p["L"], p["b"], p["h"], p["E"], p["nu"]
e = 0.01
Ncr = p["N_crit_euler"]
exact = np.array(ref["curves"][f"extensible_bernoulli__e={e}"]["data"])  # N/Ncr, N, M, ux, uy, phi, M_base
ex = {round(r[0], 6): r for r in exact}

# %% [markdown]
# ## Mesh: a gmsh file with named physical groups
#
# `meshes/euler_column_2d.geo` defines the column (curve group `column`) and
# the points `base` and `tip`. gmsh runs on rank 0; `dc.from_gmsh` distributes
# the mesh and keeps the group names.

# %%
import gmsh  # noqa: E402


def column_mesh():
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(os.path.join(here, "..", "meshes", "euler_column_2d.geo"))
        gmsh.model.mesh.generate(1)
    tmesh = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tmesh


# %% [markdown]
# ## Scene: one beam part, a clamped base, a tip load scaled by the load factor
#
# The reference load is $N_{cr}$ downwards with the moment $N_{cr}e$; the load
# factor $\lambda = N/N_{cr}$ runs from 0 to 4 in steps of 0.1 (the reference
# points). `euler_beam_2d_shapes.png` draws the deformed column at
# $N/N_{cr}$ = 1, 1.5, 2, 3 and 4 over its straight initial shape, coloured by $|u|$.

# %%
def build_scene(tmesh, large_rotations=True, kinematics="bernoulli"):
    scene = dc.Scene(large_rotations=large_rotations)
    column = scene.add_beam(tmesh, "column", section=dc.Rectangle(b, h), material=dc.Elastic(E, nu),
                            kinematics=kinematics)
    scene.fix(column, where="base")
    scene.load(column, where="tip", force=(0.0, -Ncr), moment=Ncr * e)
    scene.monitor("tip", column, where="tip")
    return scene


def load_path(demo, tmesh):
    """The column under load control, 40 steps to 4 N_cr; the deformed column at a few load levels."""
    scene = build_scene(tmesh)
    demo.say("effects:", scene.effects())
    shapes = {}
    pictures = dc.plot.Snapshots(scene, at=(1.0, 1.5, 2.0, 3.0, 4.0))  # PyVista states

    def snapshot(row):
        """Keep the deformed column at a few load levels for the plots."""
        if any(abs(row["load_factor"] - v) < 1e-9 for v in (1.0, 1.5, 2.0, 3.0, 4.0)):
            X, state = scene.model.nodes()
            order = np.argsort(X[:, 1])
            shapes[round(row["load_factor"], 3)] = (X + state[:, :2])[order]
        pictures(row)

    result, wall = timed(dc.solve, scene, dc.LoadControl(steps=40, final=4.0), on_step=snapshot)
    demo.write_result(result)
    demo.say(f"{len(result.history)} steps, {result.totals['newton_iterations']} Newton iterations, {wall:.2f} s")
    demo.picture(pictures, "euler_beam_2d_shapes.png", field="displacement",
                 title="Euler column: N/N_cr = 1, 1.5, 2, 3, 4", window_size=(1000, 800))
    return result.history, shapes


# %% [markdown]
# ## Newton convergence
#
# Residual norms of a step in the post-buckling range: the number of correct
# digits doubles at each iteration.

# %%
def newton_rates(demo, hist):
    lam = hist.column("load_factor")
    k = int(np.argmin(np.abs(lam - 3.0)))
    demo.say(f"step at N/Ncr = {lam[k]:.1f}: |r| = {hist.rows[k]['residuals']}")
    res = [float(x) for x in hist.rows[k]["residuals"].split()]
    return [np.log(res[i + 1] / res[i]) / np.log(res[i] / res[i - 1]) for i in range(1, len(res) - 1)
            if res[i + 1] > 1e-14 * res[0]]


# %% [markdown]
# ## Comparison with the exact elastica

# %%
def compare_with_elastica(demo, hist, shapes):
    """Largest relative errors (ux, uy, rotation) for N/Ncr in [1.5, 4]; the plot."""
    lam, iters = hist.column("load_factor"), hist.column("iterations")
    ux, uy, rz = hist.column("tip_ux"), hist.column("tip_uy"), hist.column("tip_rz")
    rows = np.array([[lam[i], ux[i], uy[i], rz[i], *ex[round(lam[i], 6)][3:6]] for i in range(len(lam))
                     if round(lam[i], 6) in ex])
    post = rows[:, 0] >= 1.5 - 1e-9
    err_ux = np.max(np.abs(rows[post, 1] - rows[post, 4]) / np.abs(rows[post, 4]))
    err_uy = np.max(np.abs(rows[post, 2] - rows[post, 5]) / np.abs(rows[post, 5]))
    err_rz = np.max(np.abs(rows[post, 3] - rows[post, 6]) / np.abs(rows[post, 6]))
    demo.say(f"max relative error for N/Ncr in [1.5, 4]: ux {err_ux:.2e}, uy {err_uy:.2e}, rotation {err_rz:.2e}")
    demo.say(f"at N = 4 Ncr: ux = {ux[-1]:.6f} (exact {rows[-1, 4]:.6f}), uy = {uy[-1]:.6f} "
             f"(exact {rows[-1, 5]:.6f}), rotation = {rz[-1]:.6f} (exact {rows[-1, 6]:.6f})")

    fig, ax = demo.figure(1, 3, figsize=(14, 4.4))
    for name, col, fe, c in (("$u_x$", 3, ux, "C0"), ("$u_y$", 4, uy, "C1"), ("$\\varphi$", 5, rz, "C2")):
        ax[0].plot(exact[:, col], exact[:, 0], "-", color=c, lw=1.2, label=f"{name} exact elastica")
        ax[0].plot(fe, lam, "o", color=c, ms=3.5, label=f"{name} 10 co-rotational beams")
    ax[0].axhline(1.0, color="0.6", lw=0.8, ls="--")
    ax[0].set_xlabel("tip displacement [m], rotation [rad]")
    ax[0].set_ylabel("$N/N_{cr}$")
    ax[0].set_title(f"Euler column, e = {e} m")
    ax[0].legend(fontsize=7)
    ax[1].plot([0, 0], [0, L], "k--", lw=0.8, label="initial")
    for lf, xy in shapes.items():
        ax[1].plot(xy[:, 0], xy[:, 1], "o-", ms=3, label=f"N = {lf:g} $N_{{cr}}$")
    ax[1].set_aspect("equal")
    ax[1].set_title("deformed column")
    ax[1].legend(fontsize=7)
    ax[2].plot(lam, iters, "s-", ms=3)
    ax[2].set_xlabel("$N/N_{cr}$")
    ax[2].set_ylabel("Newton iterations per step")
    ax[2].set_title("Load control, 40 steps")
    demo.save(fig, "euler_beam_2d.png")
    demo.record(load_factor=lam, ux=ux, uy=uy, rz=rz)
    return err_ux, err_uy, err_rz


# %% [markdown]
# ## Timoshenko kinematics against the Reissner rod
#
# The same column with shear deformation ($GA_s = 5/6\,GA = 416.7$ kN) is
# compared with the extensible, shearable (Reissner) rod of the reference.

# %%
def timoshenko_vs_reissner(demo, tmesh):
    timo = dc.solve(build_scene(tmesh, kinematics="timoshenko"), dc.LoadControl(steps=40, final=4.0))
    exact_r = {round(r[0], 6): r for r in ref["curves"][f"reissner_extensible_shear__e={e}"]["data"]}
    lt = timo.history.column("load_factor")
    sel = [i for i in range(len(lt)) if lt[i] >= 1.5 - 1e-9 and round(lt[i], 6) in exact_r]
    err_timo = max(max(abs(timo.history.column(c)[i] - exact_r[round(lt[i], 6)][k]) / abs(exact_r[round(lt[i], 6)][k])
                       for c, k in (("tip_ux", 3), ("tip_uy", 4), ("tip_rz", 5))) for i in sel)
    demo.say(f"Timoshenko beams vs Reissner rod, N/Ncr in [1.5, 4]: max relative error {err_timo:.2e}")
    return err_timo


# %% [markdown]
# ## What accuracy costs: error against wall time as the mesh is refined
#
# The same analysis with 2 to 32 elements (the `polyline` mesh builder);
# error = largest relative error of the tip displacement for $N/N_{cr} \in [1.5, 4]$.
# Under `CI=true` the study stops at 16 elements.

# %%
def work_precision(demo):
    """Observed order of convergence between the two finest meshes."""
    counts = [2, 4, 8, 16] if demo.ci else [2, 4, 8, 16, 32]
    study = []
    for n in counts:
        tm = polyline([[0.0, 0.0], [0.0, L]], n, line_name="column", comm=comm)
        sc = build_scene(tm)
        r, dt = timed(dc.solve, sc, dc.LoadControl(steps=40, final=4.0))
        lm = r.history.column("load_factor")
        sel = [i for i in range(len(lm)) if lm[i] >= 1.5 - 1e-9 and round(lm[i], 6) in ex]
        eu = max(max(abs(r.history.column("tip_ux")[i] - ex[round(lm[i], 6)][3]) / abs(ex[round(lm[i], 6)][3]),
                     abs(r.history.column("tip_uy")[i] - ex[round(lm[i], 6)][4]) / abs(ex[round(lm[i], 6)][4]))
                 for i in sel)
        study.append((n, eu, dt, r.totals["newton_iterations"]))
        demo.say(f"{n:3d} elements: error {eu:.2e}, {dt:.3f} s, {r.totals['newton_iterations']} Newton iterations")
    study = np.array(study)
    order = np.log(study[-2, 1] / study[-1, 1]) / np.log(study[-1, 0] / study[-2, 0])
    demo.say(f"observed order of convergence between the two finest meshes: {order:.2f}")
    demo.table("work_precision.csv", study, ["elements", "max_rel_error", "wall_time_s", "newton_iterations"])
    demo.work_precision(study[:, 0].astype(int), study[:, 1], study[:, 2], reference=B1,
                        quantity="tip displacement (largest error along the path; elements)")
    fig, ax = demo.figure(figsize=(5, 4))
    ax.loglog(study[:, 2], study[:, 1], "o-")
    for n, err, dt, _ in study:
        ax.annotate(f"{int(n)}", (dt, err), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.set_xlabel("wall time [s] (40 load steps)")
    ax.set_ylabel("max relative tip error, $N/N_{cr}\\in[1.5,4]$")
    ax.set_title("Euler column: work-precision (elements labelled)")
    demo.save(fig, "work_precision.png")
    return order


# %% [markdown]
# ## Verification
#
# The tip against the exact elastica (the acceptance of 0.5 %, then what
# this element achieves), the Timoshenko column against the Reissner rod,
# Newton's quadratic convergence and the order of convergence in the
# element size.

# %%
def main() -> dict:
    demo = Demo("euler_beam_2d")
    demo.say(f"N_cr = {Ncr:.5f} kN, e = {e} m, EA = {p['EA']:.0f} kN, EI = {p['EI']:.5f} kN m^2")
    tmesh = column_mesh()
    hist, shapes = load_path(demo, tmesh)
    rates = newton_rates(demo, hist)
    err_ux, err_uy, err_rz = compare_with_elastica(demo, hist, shapes)
    err_timo = timoshenko_vs_reissner(demo, tmesh)
    order = work_precision(demo)

    lam, iters = hist.column("load_factor"), hist.column("iterations")
    demo.check("tip ux, uy: max relative error, N/Ncr in [1.5, 4] (acceptance 0.5 %)", [err_ux, err_uy],
               bound=5e-3, reference=B1)
    demo.check("tip ux, uy, rotation: max relative error, N/Ncr in [1.5, 4]", [err_ux, err_uy, err_rz],
               bound=2e-4, reference=B1)
    demo.check("Timoshenko beams: max relative tip error, N/Ncr in [1.5, 4]", err_timo, bound=5e-4,
               reference="B1 exact Reissner rod (extensible, shearable), e = 0.01 m")
    demo.check("Newton iterations per step, N/Ncr >= 1.5", iters[lam >= 1.5 - 1e-9], bound=6,
               reference="solver acceptance (no published value)")
    demo.check("Newton: largest observed rate of convergence at N/Ncr = 3", max(rates), bound=(1.8, None),
               reference="Newton's method: quadratic convergence")
    demo.check("order of convergence of the tip error in the element size", order, bound=(1.8, None),
               reference=B1 + ": second order expected")
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

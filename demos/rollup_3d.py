# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Roll-up in space, and the objectivity of the 3D co-rotational beam
#
# A cantilever ($L = 12$, $EI = 100$, the data of B2a) lies along the skew
# direction $\mathbf a = (1, 2, 2)/3$ and carries a dead end moment about a
# skew axis $\mathbf n \perp \mathbf a$. Every section bends into the same
# circle, so the tip follows the closed form
#
# $$\mathbf x_{tip} = \mathbf x_0 + L\Bigl(\frac{\sin\varphi}{\varphi}\,\mathbf a
#   + \frac{1-\cos\varphi}{\varphi}\,\mathbf n\times\mathbf a\Bigr),\qquad \varphi = ML/EI,$$
#
# up to two full turns ($M = 4\pi EI/L$). The nodal rotations are unit
# quaternions updated multiplicatively; nothing in the element knows about
# the global axes. A dead moment about a fixed axis is not conservative in
# 3D, and after about one and a half turns the symmetric part of the tangent
# takes a negative eigenvalue: the run records it in
# `result.critical_points` and, the beam being perfect, goes on along the
# circle (`at_critical_point='continue'`).
#
# Then the two properties that co-rotational 3D beams are known to lose when
# the frame is not objective:
#
# 1. rotating a loaded, deformed configuration rigidly, by up to 10 rad
#    about arbitrary axes, must rotate its internal forces and change nothing else;
# 2. a rigidly rotated, unloaded configuration must carry no internal force, so
#    that no displacement appears without load.

# %%
import logging

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot import rotations as rot
from dolfinx_corot.assembly import System
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io import reference
from dolfinx_corot.io.gmsh_models import polyline

comm = MPI.COMM_WORLD
B2A = "closed form B2a rotated onto the skew axes (reference/B2a_cantilever_end_moment.json)"
OBJECTIVITY = "objectivity: exact rotation of the internal forces (Q f, Q m), zero force without load"

p = reference("B2a_cantilever_end_moment")["problem"]
L, b, h, E = p["L"], p["b"], p["h"], p["E"]
EI = E * b * h**3 / 12
a = np.array([1.0, 2.0, 2.0]) / 3.0
n = np.cross(a, [0.0, 0.0, 1.0])
n /= np.linalg.norm(n)
x0 = np.array([0.5, -1.0, 2.0])
M1 = 2 * np.pi * EI / L


def tip_exact(lf):
    phi = lf * M1 * L / EI
    return x0 + L * (np.sin(phi) / phi * a + (1 - np.cos(phi)) / phi * np.cross(n, a))


def skew_cantilever():
    tmesh = polyline([x0, x0 + L * a], 10, line_name="strip", gdim=3, comm=comm)
    scene = dc.Scene(large_rotations=True)
    # local z = n is the bending axis of the thin section: local y = n × a
    strip = scene.add_beam(tmesh, "strip", section=dc.Rectangle(b, h), material=dc.Elastic(E, 0.0),
                           orientation=np.cross(n, a))
    scene.fix(strip, "base")
    scene.load(strip, "tip", moment=M1 * n)
    scene.monitor("tip", strip, "tip")
    return scene


# %% [markdown]
# ## Two turns in 40 load steps
#
# `rollup_3d_shapes.png` draws the beam at $M$ = 0.25, 0.5, 1, 1.5 and 2 × $2\pi EI/L$, seen
# along the moment's axis $\mathbf n$, coloured by the angle of the nodal rotations (a rotation
# vector's, between 0 and π: it returns to 0 at every full turn).

# %%
def two_turns(demo, scene, system):
    """The history, the deformed beam at every step and the state at half a turn."""
    shapes = {}
    half_turn_state = {}
    pictures = dc.plot.Snapshots(scene, at=(0.25, 0.5, 1.0, 1.5, 2.0))  # PyVista states

    def snapshot(row):
        X, state = scene.model.nodes()
        order = np.argsort(X @ a)
        shapes[round(row["load_factor"], 3)] = (X + state[:, :3])[order]
        if abs(row["load_factor"] - 0.5) < 1e-12:
            half_turn_state["x"] = scene.model.checkpoint()
        pictures(row)

    # the perfect beam stays on the circle; where the tangent loses definiteness the point is
    # recorded and load control goes on (the closed form is the path followed)
    result, wall = timed(dc.solve, scene, dc.LoadControl(steps=40, final=2.0, at_critical_point="continue"),
                         system=system, on_step=snapshot)
    hist = result.history
    demo.write_result(result)
    for cp in result.critical_points:
        demo.say(f"critical point: a {cp.kind} near λ = {cp.load_factor:.4g} (φ = {cp.load_factor * 2 * np.pi:.3g} "
                 f"rad; negative eigenvalues {cp.negative_before} → {cp.negative_after}); the perfect beam goes on "
                 "along the circle")
    demo.say(f"{len(hist)} steps, {result.totals['newton_iterations']} Newton iterations, {wall:.2f} s; "
             f"iterations per step {int(hist.column('iterations').min())}-{int(hist.column('iterations').max())}")
    # seen along the moment's axis n, the beam's axis a upwards: the circles face the camera
    demo.picture(pictures, "rollup_3d_shapes.png", field="rotation", window_size=(1000, 800),
                 camera=[tuple(x0 + 40 * n), tuple(x0), tuple(a)],
                 title="Skew roll-up, M = 0.25, 0.5, 1, 1.5, 2 × 2πEI/L (seen along n)")
    return hist, shapes, half_turn_state["x"]


def tip_errors(demo, hist):
    """Tip position error / L at every step, and the index of the full turn."""
    lam = hist.column("load_factor")
    tip = x0 + L * a + np.c_[hist.column("tip_ux"), hist.column("tip_uy"), hist.column("tip_uz")]
    exact = np.array([tip_exact(lf) for lf in lam])
    err = np.linalg.norm(tip - exact, axis=1) / L
    i1 = int(np.argmin(np.abs(lam - 1.0)))
    demo.say(f"tip error: one turn {err[i1]:.1e} L, two turns {err[-1]:.1e} L, largest on the path {err.max():.1e} L")
    return err, i1


# %% [markdown]
# ## Objectivity under large rigid rotations
#
# From the loaded half-turn state, the whole configuration is moved rigidly,
# $\mathbf x \mapsto \mathbf Q\mathbf x + \mathbf t$, $\mathbf R_i \mapsto \mathbf Q\mathbf R_i$, for
# rotations $\mathbf Q$ of 1 to 10 rad about random axes. The internal forces
# must become $\mathbf Q\mathbf f$ and $\mathbf Q\mathbf m$ at every node.

# %%
def objectivity(demo, model, system, half_turn):
    """(largest relative change of the rotated internal forces, relative internal force of the
    rigidly rotated unloaded beam)."""

    def internal_forces():
        system.residual(0.0)
        with system.internal_force().localForm() as f:
            local = f.array.copy()
        return model.to_global(local)

    def move_rigidly(state, Q, t):
        st = state.reshape(-1, 7).copy()
        X = model.V.tabulate_dof_coordinates()[: st.shape[0]]
        st[:, :3] = (X + st[:, :3]) @ Q.T + t - X
        qQ = rot.quat_from_matrix(Q)
        for i in range(st.shape[0]):
            st[i, 3:] = rot.quat_mul(qQ, st[i, 3:].copy())
        return st.ravel()

    model.restore(half_turn)
    f_ref = internal_forces()
    rng = np.random.default_rng(7)
    worst = 0.0
    for angle in (1.0, 3.0, np.pi, 6.0, 10.0):
        axis = rng.normal(size=3)
        axis = comm.bcast(axis / np.linalg.norm(axis), root=0)
        Q = rot.exp_so3(angle * axis)
        model.restore(move_rigidly(half_turn, Q, np.array([3.0, -2.0, 5.0])))
        f_new = internal_forces()
        if comm.rank == 0:
            expected = np.c_[f_ref[:, :3] @ Q.T, f_ref[:, 3:] @ Q.T]
            worst = max(worst, np.abs(f_new - expected).max() / np.abs(f_ref).max())
    worst = comm.bcast(worst, root=0)
    demo.say(f"largest change of the rotated internal forces: {worst:.1e} (relative)")

    # a rigidly rotated, unloaded structure carries no force
    zero = np.zeros_like(half_turn)
    zero.reshape(-1, 7)[:, 3] = 1.0
    model.restore(move_rigidly(zero, rot.exp_so3(10.0 * np.array([0.6, 0.0, 0.8])), np.array([1.0, 1.0, 1.0])))
    f_rigid = internal_forces()
    rigid = comm.bcast(np.abs(f_rigid).max() / np.abs(f_ref).max() if comm.rank == 0 else None, root=0)
    demo.say(f"internal force of the rigidly rotated unloaded beam: {rigid:.1e} (relative)")
    return worst, rigid


def plot(demo, hist, shapes, err):
    lam = hist.column("load_factor")
    fig, _ = demo.figure(0, figsize=(11, 4.6))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    for lf, xyz in shapes.items():
        if lf in (0.25, 0.5, 0.75, 1.0, 1.5, 2.0):
            ax.plot(*xyz.T, "o-", ms=2, label=f"M = {lf:g}·2πEI/L")
    ax.set_title("Roll-up about a skew axis")
    ax.legend(fontsize=7)
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.semilogy(lam, np.maximum(err, 1e-16), "o-", ms=3)
    ax2.set_xlabel("$M/(2\\pi EI/L)$")
    ax2.set_ylabel("tip error / L")
    ax2.set_title("10 co-rotational beams against the closed form")
    demo.save(fig, "rollup_3d.png")


# %% [markdown]
# ## Verification

# %%
def main() -> dict:
    demo = Demo("rollup_3d")
    scene = skew_cantilever()
    system = System(scene.model)
    hist, shapes, half_turn = two_turns(demo, scene, system)
    err, i1 = tip_errors(demo, hist)
    worst, rigid = objectivity(demo, scene.model, system, half_turn)
    plot(demo, hist, shapes, err)
    demo.record(load_factor=hist.column("load_factor"), ux=hist.column("tip_ux"), uy=hist.column("tip_uy"),
                uz=hist.column("tip_uz"), objectivity=worst)
    system.destroy()

    demo.check("tip error / L at one and two full turns", [err[i1], err[-1]], bound=1e-6, reference=B2A)
    demo.check("largest tip error / L along the path", err.max(), bound=1e-3, reference=B2A)
    demo.check("Newton iterations per step", hist.column("iterations").max(), bound=6,
               reference="solver acceptance (no published value)")
    demo.check("relative change of the internal forces under rigid rotations of up to 10 rad", worst,
               bound=1e-10, reference=OBJECTIVITY)
    demo.check("relative internal force of the rigidly rotated unloaded beam (no force, no displacement)",
               rigid, bound=1e-10, reference=OBJECTIVITY)
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Cattaneo–Mindlin partial slip: a cylinder pressed onto a block, then pushed sideways
#
# An elastic cylinder (radius R = 1) is pressed onto an elastic block of the
# same material (E = 1, ν = 0.3, plane strain, small strains) by a force P per
# unit length, then pushed sideways by Q < μP (μ = 0.3). Hertz gives the
# contact half-width a = √(4PR/(πE*)), E* = E/(2(1 − ν²)) for two like bodies,
# and the pressure p = p₀√(1 − x²/a²), p₀ = 2P/(πa). Cattaneo (1938) and
# Mindlin (1949) showed that the tangential load does not slide the whole
# contact: the interface sticks in a central zone |x| < c and slips at
# |x| ≥ c, where the shear traction reaches μp, with
#
#   c = a √(1 − Q/(μP)),
#   q(x) = μp₀ √(1 − x²/a²) − μp₀ (c/a) √(1 − x²/c²) in the stick zone,
#   q(x) = μp₀ √(1 − x²/a²) in the slip zones
#
# (K. L. Johnson 1985, *Contact Mechanics*, §7.2, line contact of cylinders).
# The bodies are elastically similar, so the normal and the tangential
# problems are uncoupled (Dundurs' β = 0): the pressure stays Hertz's while Q
# grows.
#
# Our data: the lower half of the cylinder on a block 4 × 2 (both meshed with
# linear triangles of size h within 1.4a of the contact point, growing to
# R/8 and R/4 at 0.6 from it), the block's bottom fixed. The cylinder's flat
# top is moved down by 0.004 in four steps (P = 0.00094, a = 0.044: a/R
# small, as Hertz's half-spaces assume), then sideways by 0.0015 in four
# steps (Q/(μP) ≈ 0.21, 0.41, 0.61, 0.81) with its rotation held; P and Q are
# the top's reactions. The arc's nodes are slaves against the block's top
# (node-to-segment, Coulomb friction; augmented Lagrangian for the pressure
# and for the shear: the tangential penalty equals the normal one, and Uzawa
# updates of the tangential multipliers remove its elastic slip, Simo &
# Laursen 1992). The stick zone is
# where the slaves do not slip; its half-width is read midway between the
# outermost sticking slave and the next slipping one on each side (so to
# ±h/2). The theory is evaluated with the a and p₀ of Hertz's ellipse fitted
# to the computed pressures (a within 0.3 % of Hertz's), so that the
# comparison measures the friction; the shear traction's error is the root
# mean square over the contact of q − q_theory, on the scale of the shear
# tractions, μp₀.
#
# Measured (h = a/10, a/20, a/40; all four Q): c within 4.0 %, 1.8 %, 3.2 %
# of the theory (a slave is h/2 = 1.4 % of c on the finest mesh); the shear
# traction's rms error 2.6–3.5 %, 2.1–2.6 %, 2.0–2.3 % of μp₀; whole runs
# 1.1, 2.6 and 9.8 s, 26–31 Uzawa updates each, no cut. The shear error
# falls slowly: what remains is the shear the pressing itself leaves
# (finite bodies are not half-spaces: up to 0.05 μp₀ at a/R = 0.11, four
# times less at a/R = 0.011) and a node-to-node scatter of the stick
# tractions where the two meshes do not match. The push steps (the stick
# zone shrinking) take 7–13 Newton iterations.
#
# The tangential penalty alone, at the same ε_T, leaves an elastic slip
# that widens the stick zone: on a/20, c is 3.2–6.1 % too large (the
# augmented Lagrangian: 0.0–1.8 %), in 2.3 s. With the penalty alone ε_T
# must be ten times larger for the same c, and then pressing to first touch
# needs 1 and 3 cut steps on the two finer meshes (20.5 s on a/40).
#
# The demo asserts c and the shear traction within 5 % on the finest mesh
# at every Q, a within 1 % of Hertz, the shear tractions' sum within 2 % of
# Q, no cut while pushing, and that the augmented Lagrangian at least
# halves the penalty's largest c error. Under CI the finest mesh is
# skipped.

# %%
import logging

import gmsh
import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.gallery import Demo, timed
from dolfinx_corot.io.mesh import name_groups, size_field

comm = MPI.COMM_WORLD
R, E, NU, MU = 1.0, 1.0, 0.3, 0.3
E_STAR = E / (2.0 * (1.0 - NU**2))  # two like bodies in plane strain
WIDTH, DEPTH = 2.0, 2.0  # the block's half-width and depth
PRESS, PUSH = 0.004, 0.0015  # the top's settlement, then its shift
PRESS_STEPS, PUSH_STEPS = 4, 4
STEPS = PRESS_STEPS + PUSH_STEPS
PRESSED = PRESS_STEPS / STEPS  # the load factor at the end of the pressing
A_HERTZ = 0.044  # about a, for the meshes' sizes
SLIP_TOLERANCE = 1e-3  # the tangential Uzawa updates' (× the mean segment); None: the penalty alone
PICTURED, SCALE = (0.25, 0.5, 0.75, 1.0), 50.0  # the pictures' load factors and displacement magnification


# %% [markdown]
# ## Geometry and meshes (gmsh)

# %%
def mesh(h: float):
    """The lower half disc (centre (0, R)) on the block [−2, 2] × [−2, 0]; size h within 0.15 of
    the contact point (0, 0), growing to R/8 (cylinder) and R/4 (block) at 0.6 from it. Groups:
    'cylinder', 'block', 'arc', 'top' (the cylinder's flat face), 'block_top', 'base'."""
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo
        centre, bottom = g.addPoint(0, R, 0), g.addPoint(0, 0, 0)
        left, right = g.addPoint(-R, R, 0), g.addPoint(R, R, 0)
        arcs = [g.addCircleArc(left, centre, bottom), g.addCircleArc(bottom, centre, right)]
        top = g.addLine(right, left)
        cylinder = g.addPlaneSurface([g.addCurveLoop([*arcs, top])])
        corners = [g.addPoint(x, y, 0) for x, y in ((-WIDTH, 0), (0, 0), (WIDTH, 0), (WIDTH, -DEPTH), (-WIDTH, -DEPTH))]
        lines = [g.addLine(corners[i], corners[(i + 1) % 5]) for i in range(5)]
        block = g.addPlaneSurface([g.addCurveLoop(lines)])
        g.synchronize()
        field = gmsh.model.mesh.field

        def graded(tag: int, point: int, far: float, surface: int, curves: list) -> None:
            """Fields tag..tag + 2: size h within 0.15 of point, ``far`` beyond 0.6, on surface only."""
            field.add("Distance", tag)
            field.setNumbers(tag, "PointsList", [point])
            field.add("Threshold", tag + 1)
            field.setNumber(tag + 1, "InField", tag)
            for key, value in (("SizeMin", h), ("SizeMax", far), ("DistMin", 1.4 * A_HERTZ), ("DistMax", 0.6)):
                field.setNumber(tag + 1, key, value)
            field.add("Restrict", tag + 2)
            field.setNumber(tag + 2, "InField", tag + 1)
            field.setNumbers(tag + 2, "SurfacesList", [surface])
            field.setNumbers(tag + 2, "CurvesList", curves)

        graded(1, bottom, R / 8, cylinder, [*arcs, top])
        graded(4, corners[1], R / 4, block, lines)
        field.add("Min", 7)
        field.setNumbers(7, "FieldsList", [3, 6])
        size_field(7)
        name_groups({"cylinder": (2, [cylinder]), "block": (2, [block]), "arc": (1, arcs), "top": (1, [top]),
                     "block_top": (1, lines[:2]), "base": (1, [lines[3]])})
        gmsh.model.mesh.generate(2)
    tm = dc.from_gmsh(gmsh.model if comm.rank == 0 else None, gdim=2, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


# %% [markdown]
# ## The contact problem
# Four steps of pressing, four of pushing; after each push, the pressures and
# the friction tractions of the slaves are kept (`Interface.pressure`,
# `Interface.friction_traction`). On the mesh a/20 the bodies are pictured half
# pressed, pressed, half pushed and pushed (`cattaneo_mindlin_shapes.png`,
# displacements × 50 coloured by their magnitude, the undeformed outline in grey):
# the cylinder flattens on the dented block, then moves sideways.

# %%
def run(h: float, slip_tolerance: float | None = SLIP_TOLERANCE, shots_at: tuple | None = None):
    """The run on the mesh of size h; ``shots_at``: load factors at which dolfinx_corot.plot.Snapshots
    keeps the scene's state (returned as ``result.shots``)."""
    tm = mesh(h)
    sc = dc.Scene(large_rotations=False)
    cylinder = sc.add_solid(tm, "cylinder", material=dc.Elastic(E, NU), degree=1)
    block = sc.add_solid(tm, "block", material=dc.Elastic(E, NU), degree=1)
    sc.fix(block, "base")
    sc.prescribe(cylinder, "top", amplitude=dc.Amplitude(((0.0, 0.0), (PRESSED, 1.0), (1.0, 1.0))), uy=-PRESS)
    sc.prescribe(cylinder, "top", amplitude=dc.Amplitude(((0.0, 0.0), (PRESSED, 0.0), (1.0, 1.0))), ux=PUSH)
    (itf,) = sc.contact((cylinder, "arc"), (block, "block_top"), law=dc.AugmentedLagrangian(gap_tolerance=1e-6),
                        friction=dc.Coulomb(mu=MU, tangential_factor=1.0, slip_tolerance=slip_tolerance))
    sc.monitor_reaction("top", cylinder, "top")
    states = []
    shots = None if shots_at is None else dc.plot.Snapshots(sc, at=shots_at)

    def on_step(row):
        if shots is not None:
            shots(row)
        X, p = itf.pressure()
        _, t, slipping = itf.friction_traction()
        if row["load_factor"] < PRESSED + 1e-9:  # pressing
            return
        # the friction on the cylinder is −t along the block's top (numbered along +x)
        states.append({"P": -row["top_Fy"], "Q": row["top_Fx"], "x": X[:, 0], "p": p, "q": -t,
                       "slipping": slipping, "length": itf.area, "iterations": int(row["iterations"]),
                       "cuts": int(row["cuts"]),
                       "load_factor": row["load_factor"]})

    result, wall = timed(dc.solve, sc, dc.LoadControl(steps=STEPS), on_step=on_step)
    result.shots = shots
    return result, states, wall


def picture(demo, shots, h: float):
    """The bodies half pressed, pressed, half pushed and pushed (``cattaneo_mindlin_shapes.png``)."""
    for state in shots.states:
        lam = state.load_factor
        press, push = PRESS * min(lam / PRESSED, 1.0), PUSH * max(lam - PRESSED, 0.0) / (1.0 - PRESSED)
        state.label = f"λ = {lam:g}: top down {press:g}, sideways {push:g}"
    demo.picture(shots, "cattaneo_mindlin_shapes.png", scale=SCALE, columns=2, window_size=(1500, 1000),
                 title=f"h = a/{A_HERTZ / h:.0f}")


def ellipse(x, p):
    """(p₀, a) of Hertz's ellipse p² = p₀²(1 − x²/a²) fitted to the nodal pressures (least squares)."""
    on = p > 0.0
    A = np.column_stack([np.ones(on.sum()), x[on] ** 2])
    (c0, c2), *_ = np.linalg.lstsq(A, p[on] ** 2, rcond=None)
    return np.sqrt(c0), np.sqrt(c0 / -c2)


def stick_half_width(x, p, slipping):
    """Half the distance between the stick zone's edges, each midway between the outermost sticking
    slave and the next slipping one; and the zone's centre."""
    order = np.argsort(x)
    x, stick = x[order], ((p > 0.0) & ~slipping)[order]
    i = np.flatnonzero(stick)
    left, right = 0.5 * (x[i[0]] + x[i[0] - 1]), 0.5 * (x[i[-1]] + x[i[-1] + 1])
    return 0.5 * (right - left), 0.5 * (right + left)


def cattaneo_mindlin(x, a, p0, c):
    """The shear traction of Cattaneo and Mindlin, μp₀ [√(1 − x²/a²) − (c/a) √(1 − x²/c²)₊]."""
    outer = MU * p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))
    return outer - MU * p0 * (c / a) * np.sqrt(np.clip(1.0 - (x / c) ** 2, 0.0, None))


def study(demo):
    """One row per mesh and push step: P, Q, a and p₀ (fitted and Hertz's), c against the theory,
    the shear traction's error; cost. Then the mesh a/20 with the tangential penalty alone."""
    sizes = (A_HERTZ / 10, A_HERTZ / 20) if demo.ci else (A_HERTZ / 10, A_HERTZ / 20, A_HERTZ / 40)
    rows, profiles = [], {}
    for h in sizes + (None,):
        alone = h is None
        h = A_HERTZ / 20 if alone else h
        pictured = not alone and h == A_HERTZ / 20  # the pictures: a/20, run in every mode
        result, states, wall = run(h, None if alone else SLIP_TOLERANCE, PICTURED if pictured else None)
        if pictured:
            picture(demo, result.shots, h)
        history = result.history
        its = history.column("iterations")
        pressing_cuts = history.column("cuts")[history.column("load_factor") < PRESSED + 1e-9].sum()
        for s in states:
            x, p, q = s["x"], s["p"], s["q"]
            on = p > 0.0
            p0, a = ellipse(x, p)
            a_hertz = np.sqrt(4.0 * s["P"] * R / (np.pi * E_STAR))
            ratio = s["Q"] / (MU * s["P"])
            c_theory = a * np.sqrt(1.0 - ratio)
            c, centre = stick_half_width(x, p, s["slipping"])
            q_theory = cattaneo_mindlin(x, a, p0, c_theory)
            w = s["length"] * on
            # errors on the scale of the shear tractions, μp₀ (their peak in the slip zones)
            rms = np.sqrt(np.sum(w * (q - q_theory) ** 2) / np.sum(w)) / (MU * p0)
            rms_own = np.sqrt(np.sum(w * (q - q_theory) ** 2) / np.sum(w * q_theory**2))
            rows.append({"h": h, "load_factor": s["load_factor"], "P": s["P"], "Q": s["Q"], "Q_over_muP": ratio, "a": a,
                         "a_hertz": a_hertz, "a_error": a / a_hertz - 1.0,
                         "p0_error": p0 / (2 * s["P"] / (np.pi * a_hertz)) - 1.0, "c": c, "c_theory": c_theory,
                         "c_error": c / c_theory - 1.0, "stick_centre": centre, "q_rms_error": rms,
                         "q_rms_error_of_rms": rms_own,
                         "q_max_error": float(np.max(np.abs(q - q_theory)[on]) / (MU * p0)),
                         "shear_balance": float(np.sum(s["length"] * q) / s["Q"] - 1.0),
                         "nodes_in_contact": int(on.sum()), "newton_iterations": s["iterations"],
                         "cuts": s["cuts"], "press_cuts": int(pressing_cuts), "wall_s": wall,
                         "method": "penalty alone" if alone else "augmented"})
            demo.say(f"{'penalty alone, ' if alone else ''}h = a/{A_HERTZ / h:.0f}, Q/(μP) = {ratio:.3f}: c = {c:.4f} (theory {c_theory:.4f}, "
                     f"{100 * (c / c_theory - 1):+.1f} %), shear traction rms error {100 * rms:.1f} % of μp₀, "
                     f"{int(on.sum())} slaves in contact, {s['iterations']} Newton its")
        demo.say(f"{'penalty alone, ' if alone else ''}h = a/{A_HERTZ / h:.0f}: a = {a:.4f} (Hertz {a_hertz:.4f}), "
                 f"{int(its.sum())} Newton its, {int(history.column('uzawa_updates').sum())} Uzawa updates, "
                 f"{int(pressing_cuts)} cut(s) while pressing, {wall:.1f} s")
        if not alone:
            profiles[h] = states
    return rows, profiles


# %% [markdown]
# ## Output: shear tractions against the theory, what accuracy costs

# %%
def plot(demo, rows, profiles):
    demo.table("cattaneo_mindlin_2d.csv", rows)
    rows = [r for r in rows if r["method"] == "augmented"]
    fig, axes = demo.figure(1, 2, figsize=(13, 4.5))
    finest = max(profiles, key=lambda h: -h)
    ax = axes[0]
    for s in profiles[finest]:
        p0, a = ellipse(s["x"], s["p"])
        ratio = s["Q"] / (MU * s["P"])
        xs = np.linspace(-a, a, 400)
        line, = ax.plot(xs / a, cattaneo_mindlin(xs, a, p0, a * np.sqrt(1 - ratio)) / (MU * p0), "-", lw=1)
        on = s["p"] > 0
        ax.plot(s["x"][on] / a, s["q"][on] / (MU * p0), "o", ms=3, color=line.get_color(),
                label=f"Q/(μP) = {ratio:.2f}")
        stick = on & ~s["slipping"]
        ax.plot(s["x"][stick] / a, s["q"][stick] / (MU * p0), ".", ms=2, color="k")
    ax.set(xlabel="x / a", ylabel="shear traction q / (μ p₀)",
           title=f"h = a/{A_HERTZ / finest:.0f} (lines: Cattaneo–Mindlin; black dots: sticking)")
    ax.legend(fontsize=7)
    ax = axes[1]
    sizes = sorted({r["h"] for r in rows}, reverse=True)
    wall = [next(r["wall_s"] for r in rows if r["h"] == h) for h in sizes]
    demo.work_precision([f"a/{A_HERTZ / h:.0f}" for h in sizes],
                        [max(abs(r["q_rms_error"]) for r in rows if r["h"] == h) for h in sizes], wall,
                        quantity="shear traction, rms / μp₀ (element size)",
                        reference="Cattaneo (1938), Mindlin (1949): q = μp₀(√(1 − x²/a²) − (c/a)√(1 − x²/c²))")
    for key, mark in (("c_error", "o-"), ("q_rms_error", "s--")):
        ax.loglog(wall, [max(abs(r[key]) for r in rows if r["h"] == h) for h in sizes], mark,
                  label=f"largest |{key}| over the four Q")
    for h, t in zip(sizes, wall):
        ax.annotate(f"a/{A_HERTZ / h:.0f}", (t, max(r["q_rms_error"] for r in rows if r["h"] == h)), fontsize=7)
    ax.set(xlabel="wall time of the whole run [s]", ylabel="error against Cattaneo–Mindlin (q: rms / μp₀)",
           title="what accuracy costs")
    ax.legend(fontsize=7)
    demo.save(fig, "cattaneo_mindlin_2d.png")
    demo.record(load_factor=[r["load_factor"] for r in rows], Q_over_muP=[r["Q_over_muP"] for r in rows],
                c=[r["c"] for r in rows],
                c_theory=[r["c_theory"] for r in rows], q_rms_error=[r["q_rms_error"] for r in rows])


# %% [markdown]
# ## Verification
# On the finest mesh, at every Q: the stick zone's half-width and the shear
# traction within 5 % of Cattaneo and Mindlin's; the contact half-width
# within 1 % of Hertz's; the interface's shear tractions sum to Q within 2 %
# (they act along the deformed block's surface); no cut on any mesh; on
# a/20, the augmented Lagrangian's largest c error at most half the
# tangential penalty's alone.

# %%
def main() -> dict:
    demo = Demo("cattaneo_mindlin_2d")
    rows, profiles = study(demo)
    plot(demo, rows, profiles)
    alone = [r for r in rows if r["method"] == "penalty alone"]
    rows = [r for r in rows if r["method"] == "augmented"]
    finest = [r for r in rows if r["h"] == min(r["h"] for r in rows)]
    same = [r for r in rows if r["h"] == alone[0]["h"]]
    theory = "Cattaneo (1938), Mindlin (1949): c = a √(1 − Q/(μP)) (Johnson 1985, §7.2)"
    demo.check("stick zone half-width c: relative error on the finest mesh, each Q", [r["c_error"] for r in finest],
               bound=(-0.05, 0.05), reference=theory)
    demo.check("shear traction: rms error over the contact / μp₀ on the finest mesh, each Q",
               [r["q_rms_error"] for r in finest], bound=0.05, reference=theory)
    demo.check("contact half-width a against Hertz, finest mesh", [r["a_error"] for r in finest],
               bound=(-0.01, 0.01), reference="Hertz: a = √(4PR/(πE*))")
    demo.check("Σ q × length / Q − 1, finest mesh", [r["shear_balance"] for r in finest], bound=(-0.02, 0.02),
               reference="equilibrium of the cylinder")
    demo.check("cut push steps (stick zone shrinking), every mesh", [r["cuts"] for r in rows], bound=0,
               reference="solver acceptance")
    demo.check("largest |c error| at a/20: augmented Lagrangian over the tangential penalty alone (ε_T = ε)",
               max(abs(r["c_error"]) for r in same) / max(abs(r["c_error"]) for r in alone), bound=0.5,
               reference=theory + "; the penalty's compliance widens the stick zone")
    return demo.finish()


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING)
    main()

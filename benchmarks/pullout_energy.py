"""Where the coarse four-node shells of the pull-out store their excess energy (a script).

The eighth of the open cylinder of ``benchmarks/pullout.py`` (Sze, Liu & Lo 2004, §3.5), driven
to w_A = 2.5 (just before the snap) in 25 steps on one grid, once with four-node shells
(QM6 membrane, DKQ bending) and once with triangles (OPT membrane, DKT bending) on the same
nodes. Under a driven displacement the stiffer model stores more strain energy, so the energy
says which strains carry the quadrilaterals' excess. For each converged state the strain energy
½ d̄ᵀ K̄ d̄ of every cell's local law is split into membrane (with the drilling term) and
bending, on the strip of cells along the loaded generator (θ < 90°/n_θ, where the section
folds) and on the rest; the QM6 membrane of the strip into ε_xx, ε_ss, their Poisson term,
the in-plane shear γ_xs and the drilling penalty (x along the axis, s around the section).
Cross-evaluation: each state is also evaluated with the other family's elements (the
quadrilaterals' cells split along either diagonal into OPT + DKT triangles, each in its own
frame), with the cell's two OPT + DKT triangles in the four-node shell's frame (the triangles'
law, the quadrilaterals' kinematics), and the OPT membrane on the triangles' state with its
drilling rotations as computed, minimised cell by cell, and set to zero.

Measured on 8 × 12 (strip / rest, 1/8 model; fine reference 32 × 48 quadrilaterals, P = 20 748,
membrane 175 / 102, bending 1684 / 598):

| state | P | evaluated with | membrane | bending |
|---|---|---|---|---|
| quadrilaterals' | 21 776 | QM6 + DKQ | 185 / 107 | 1719 / 592 |
| quadrilaterals' | | OPT + DKT (the mesh's diagonal), a frame per triangle | 281 / 149 | 1747 / 612 |
| triangles' | 19 683 | OPT + DKT, a frame per triangle | 183 / 112 | 1627 / 629 |
| triangles' | | QM6 + DKQ | 367 / 143 | 1618 / 617 |
| triangles' | | OPT + DKT, one frame per cell | 425 / 134 | 1627 / 629 |

On the same nodal values the DKQ is slightly softer than the DKT: bending is not where the
quadrilaterals are stiff. Read in one frame per cell, the triangles' state strains the strip's
membrane, with the QM6 (all of the difference in in-plane shear γ_xs: 241 against 61 on the
quadrilaterals' own state) and just as much with the triangles' own law (425 against 183): the
two triangles of a strip cell fold along their diagonal (up to 7.5° between their normals; the
quadrilaterals' cells 4.9°), and a frame spanning the cell reads
the fold's shortening of the other diagonal as in-plane shear. The family difference is the
kinematics (a frame per triangle or per cell), not a law (docs/theory.md, "One frame per cell").

Writes output/pullout_energy/{energy.json, energy.png}; the same numbers under ``mpirun -n 2``.
Usage: python benchmarks/pullout_energy.py [--mesh 8 12] [--w 2.5] [--steps 25]
"""
import argparse
import json
import os

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.corotation import frame_quad, frame_triangle
from dolfinx_corot.elements import shell_quad, shell_triangle
from dolfinx_corot.io import output_dir
from dolfinx_corot.io.gmsh_models import cylinder_eighth
from dolfinx_corot.kernels import CCW
from dolfinx_corot.kernels.spatial import nodal_states

R, L, t, E, nu = 4.953, 10.35, 0.094, 10.5e6, 0.3125
comm = MPI.COMM_WORLD
DRILLING = (5, 11, 17)  # θz of the triangle's three nodes in d̄


def solve(n_theta, n_x, quads, w, steps):
    """(P, cells' nodes (n, k, 3), nodal state by position, cells' properties) at w_A = w."""
    scene = dc.Scene()
    shell = scene.add_shell(cylinder_eighth(R, L, n_theta, n_x, quads=quads), "shell", thickness=t,
                            material=dc.Elastic(E, nu))
    scene.fix(shell, "mid", dofs=("ux", "ry", "rz"))
    scene.fix(shell, "top", dofs=("uy", "rx", "rz"))
    scene.fix(shell, "side", dofs=("uz", "rx", "ry"))
    scene.prescribe(shell, "A", uz=w)
    scene.monitor_reaction("A", shell, "A")
    res = dc.solve(scene, dc.LoadControl(steps=steps))
    part = scene.model
    cells = np.arange(part.tmesh.mesh.topology.index_map(2).size_local)
    X, S = part._element_states(cells)  # the kernels' inputs, on this rank's cells
    state = {}  # every node's state (the other family's partition differs)
    for local in comm.allgather({tuple(np.round(x, 9)): s for xc, sc in zip(X, S) for x, s in zip(xc, sc)}):
        state.update(local)
    return 4.0 * res.history.column("A_Fz")[-1], X, state, part.cell_properties(cells)


def _local(frame, X, S):
    """(R0, x̄0, d̄) of one cell: initial frame and local coordinates, the local deformation."""
    n = len(X)
    u, Rn = np.empty((n, 3)), np.empty((n, 3, 3))
    nodal_states(S, u, Rn)
    R0, xbar0 = np.empty((3, 3)), np.empty((n, 3))
    frame.initial(X, R0, xbar0)
    parts = frame.shell_parts if n == 4 else frame.parts
    return R0, xbar0, parts(X, u, Rn, R0, xbar0)[-1]


def rigid_links(xbar0):
    """W (24, 24): the flat corners' dofs from the warped nodes' (u_p = u − zθy, v_p = v + zθx),
    as in :func:`shell_quad.local_stiffness`."""
    W = np.eye(24)
    for a in range(4):
        W[6 * a, 6 * a + 4] = -xbar0[a, 2]
        W[6 * a + 1, 6 * a + 3] = xbar0[a, 2]
    return W


def quad_energy(X, S, props):
    """(membrane, bending, membrane split (ε_xx, ε_ss, Poisson, γ_xs, drilling)) of one
    four-node shell, counter-clockwise nodes X (4, 3), states S (4, 7)."""
    R0, xbar0, d = _local(frame_quad, X, S)
    K, Km = np.empty((24, 24)), np.empty((24, 24))
    shell_quad.local_stiffness(xbar0, props, K)
    membrane = props.copy()
    membrane[shell_quad.D0:shell_quad.D0 + 9] = 0.0
    membrane[shell_quad.S0:shell_quad.S0 + 4] = 0.0
    shell_quad.local_stiffness(xbar0, membrane, Km)
    em = 0.5 * d @ Km @ d
    # the membrane's strains at its 2 × 2 points, incompatible modes condensed as in the law
    W = rigid_links(xbar0)
    xy = np.ascontiguousarray(xbar0[:, :2])
    A = props[shell_quad.A0:shell_quad.A0 + 9].reshape(3, 3)
    kd = props[shell_quad.ALPHA] * A[2, 2]
    _, _, J0, det0 = shell_quad.shape(xy, 0.0, 0.0)
    Kf, points = np.zeros((28, 28)), []
    for xi, eta in shell_quad._GAUSS:
        Be, _, Bw, N, det = shell_quad._strains(xy, xi, eta, J0, det0, True)
        g = -Bw.copy()
        g[5::6][:4] += N
        Kf += det * (Be.T @ A @ Be + kd * np.outer(g, g))
        points.append((Be, g, det))
    df = W @ d
    full = np.r_[df, -np.linalg.solve(Kf[24:, 24:], Kf[24:, :24] @ df)]
    axis = R0[0, :2]  # the cylinder's axis x in the cell's initial frame
    c, s = axis / np.linalg.norm(axis)
    turn = np.array([[c * c, s * s, c * s], [s * s, c * c, -c * s], [-2 * c * s, 2 * c * s, c * c - s * s]])
    Cm = E * t / (1.0 - nu * nu)
    split = np.zeros(5)
    for Be, g, det in points:
        exx, ess, gxs = turn @ (Be @ full)
        split += 0.5 * det * np.array([Cm * exx ** 2, Cm * ess ** 2, 2 * nu * Cm * exx * ess,
                                       0.5 * Cm * (1 - nu) * gxs ** 2, kd * (g @ full) ** 2])
    return em, 0.5 * d @ K @ d - em, split


TRI = shell_triangle.isotropic_props(E, nu, t, 0.0, True, True)
TRI_MEMBRANE = TRI.copy()
TRI_MEMBRANE[shell_triangle.D0:shell_triangle.D0 + 9] = 0.0


def triangle_energy(X, S):
    """(membrane, bending, OPT membrane with the drilling rotations minimised, with them zero)
    of one OPT + DKT triangle."""
    _, xbar0, d = _local(frame_triangle, X, S)
    xy = np.ascontiguousarray(xbar0[:, :2])
    K, Km = np.empty((18, 18)), np.empty((18, 18))
    shell_triangle.local_stiffness(xy, TRI, K)
    shell_triangle.local_stiffness(xy, TRI_MEMBRANE, Km)
    rest = [i for i in range(18) if i not in DRILLING]
    d_min, d_zero = d.copy(), d.copy()
    d_min[list(DRILLING)] = np.linalg.lstsq(Km[np.ix_(DRILLING, DRILLING)], -Km[np.ix_(DRILLING, rest)] @ d[rest],
                                            rcond=None)[0]
    d_zero[list(DRILLING)] = 0.0
    em = 0.5 * d @ Km @ d
    return em, 0.5 * d @ K @ d - em, 0.5 * d_min @ Km @ d_min, 0.5 * d_zero @ Km @ d_zero


def pair_in_quad_frame_energy(X, S, halves):
    """(membrane, bending) of the cell's two OPT + DKT triangles ``halves`` taken as one element
    in the four-node shell's frame: the triangles' law, the quadrilateral's kinematics (d̄ from
    :func:`frame_quad.shell_parts`, the triangles' stiffness assembled on x̄0, rigid links for the
    initial warping as in the four-node law)."""
    _, xbar0, d = _local(frame_quad, X, S)
    K, Km, Kt = np.zeros((24, 24)), np.zeros((24, 24)), np.empty((18, 18))
    for h in halves:
        xy = np.ascontiguousarray(xbar0[h, :2])
        dofs = np.array([6 * a + k for a in h for k in range(6)])
        shell_triangle.local_stiffness(xy, TRI, Kt)
        K[np.ix_(dofs, dofs)] += Kt
        shell_triangle.local_stiffness(xy, TRI_MEMBRANE, Kt)
        Km[np.ix_(dofs, dofs)] += Kt
    W = rigid_links(xbar0)
    em = 0.5 * d @ W.T @ Km @ W @ d
    return em, 0.5 * d @ W.T @ K @ W @ d - em


def fold_angle(X, S):
    """The angle (degrees) between the current normals of the cell's triangles (0, 1, 3) and
    (1, 2, 3): how far the cell folds along its diagonal 1-3 (a warped cell shows its twist)."""
    x = X + S[:, :3]
    n1 = np.cross(x[1] - x[0], x[3] - x[0])
    n2 = np.cross(x[2] - x[1], x[3] - x[1])
    return float(np.degrees(np.arccos(np.clip(n1 @ n2 / np.linalg.norm(n1) / np.linalg.norm(n2), -1.0, 1.0))))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mesh", type=int, nargs=2, default=[8, 12])
    ap.add_argument("--w", type=float, default=2.5)
    ap.add_argument("--steps", type=int, default=25)
    args = ap.parse_args()
    n_theta, n_x = args.mesh
    P_q, X, state_q, props = solve(n_theta, n_x, True, args.w, args.steps)
    P_t, _, state_t, _ = solve(n_theta, n_x, False, args.w, args.steps)
    splits = {"diagonal 0-2": ([0, 1, 2], [0, 2, 3]), "diagonal 1-3": ([0, 1, 3], [1, 2, 3])}
    out = {"mesh": args.mesh, "w_A": args.w, "P": {"quadrilaterals": P_q, "triangles": P_t}}
    for name, state in (("quadrilaterals' state", state_q), ("triangles' state", state_t)):
        sums = {"QM6 + DKQ": np.zeros((2, 2)), **{f"OPT + DKT, {k}": np.zeros((2, 2)) for k in splits},
                "OPT + DKT, diagonal 1-3, one frame": np.zeros((2, 2))}
        qm6_split, opt_drilling, fold = np.zeros(5), np.zeros(3), 0.0
        for c in range(len(X)):
            Xc = np.ascontiguousarray(X[c][list(CCW)])
            strip = np.degrees(np.arctan2(Xc[:, 1].mean(), Xc[:, 2].mean())) < 90.0 / n_theta
            row = 0 if strip else 1
            Sc = np.array([state[tuple(np.round(x, 9))] for x in Xc])
            em, eb, split = quad_energy(Xc, Sc, props[c])
            sums["QM6 + DKQ"][row] += em, eb
            if strip:
                qm6_split += split
                fold = max(fold, fold_angle(Xc, Sc))
            sums["OPT + DKT, diagonal 1-3, one frame"][row] += pair_in_quad_frame_energy(Xc, Sc, splits["diagonal 1-3"])
            for key, halves in splits.items():
                for h in halves:
                    tri = triangle_energy(np.ascontiguousarray(Xc[h]), np.ascontiguousarray(Sc[h]))
                    sums[f"OPT + DKT, {key}"][row] += tri[:2]
                    if strip and key == "diagonal 1-3":  # the split of cylinder_eighth's triangles
                        opt_drilling += tri[0], tri[2], tri[3]
        sums = {k: comm.allreduce(v) for k, v in sums.items()}
        qm6_split, opt_drilling = comm.allreduce(qm6_split), comm.allreduce(opt_drilling)
        fold = comm.allreduce(fold, op=MPI.MAX)
        out[name] = {k: {"strip": {"membrane": v[0, 0], "bending": v[0, 1]},
                         "rest": {"membrane": v[1, 0], "bending": v[1, 1]}} for k, v in sums.items()}
        out[name]["QM6 strip membrane (exx, ess, poisson, gxs, drilling)"] = qm6_split.tolist()
        out[name]["OPT strip membrane (as computed, drilling minimised, drilling zero)"] = opt_drilling.tolist()
        out[name]["largest fold of a strip cell along its diagonal 1-3 (degrees)"] = fold
        if comm.rank:
            continue
        print(f"{name}: P = {P_q if state is state_q else P_t:.1f}")
        for k, v in sums.items():
            print(f"  {k:34s} strip: membrane {v[0, 0]:7.1f}, bending {v[0, 1]:7.1f}; "
                  f"rest: membrane {v[1, 0]:7.1f}, bending {v[1, 1]:7.1f}; total {v.sum():7.1f}")
        print("  QM6 membrane of the strip (ε_xx, ε_ss, Poisson, γ_xs, drilling):", np.round(qm6_split, 1))
        print("  OPT membrane of the strip (as computed, drilling minimised, zero):", np.round(opt_drilling, 1))
        print(f"  largest fold of a strip cell along its diagonal 1-3: {fold:.2f}°")
    out_dir = output_dir("pullout_energy")  # collective
    if comm.rank == 0:
        with open(os.path.join(out_dir, "energy.json"), "w") as f:
            json.dump(out, f, indent=1)
        plot(out, os.path.join(out_dir, "energy.png"))


def plot(out, path):
    """Bars of the strip's and the rest's membrane and bending energy, per state and evaluation."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for ax, state in zip(axes, ("quadrilaterals' state", "triangles' state")):
        names = [k for k in out[state] if isinstance(out[state][k], dict)]
        x = np.arange(len(names))
        for j, (region, part) in enumerate([(r, q) for r in ("strip", "rest") for q in ("membrane", "bending")]):
            ax.bar(x + 0.2 * (j - 1.5), [out[state][k][region][part] for k in names], 0.2, label=f"{region}, {part}")
        ax.set_xticks(x, [k.replace(", ", "\n") for k in names], fontsize=8)
        ax.set_title(f"{state}, P = {out['P'][state.split(chr(39))[0]]:.0f}", fontsize=9)
        ax.set_yscale("log")
    axes[0].set_ylabel("strain energy (1/8 model)")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=4, fontsize=8)
    fig.suptitle(f"Pull-out {out['mesh'][0]} × {out['mesh'][1]} at w_A = {out['w_A']}", fontsize=10)
    fig.tight_layout(rect=(0.0, 0.07, 1.0, 1.0))
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()

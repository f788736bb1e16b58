"""The pull-out (seed §2.4.1; Sze, Liu & Lo 2004, §3.5) in OpenSees, a peer for
``benchmarks/pullout.py`` on the same grid (a script).

The eighth of the open cylinder (R = 4.953, L = 10.35, t = 0.094, E = 10.5·10⁶, ν = 0.3125):
x ∈ [0, L/2], θ ∈ [0, 90°] from the z axis towards y, n_θ × n_x squares on the same nodes as
:func:`dolfinx_corot.io.gmsh_models.cylinder_eighth`, symmetry on x = 0 (ux, ry, rz), y = 0
(uy, rx, rz) and z = 0 (uz, rx, ry), w_A = u_z at A = (0, 0, R) driven by OpenSees's
``DisplacementControl`` in steps of at most 0.05, halved when Newton fails. Elements:
``ASDShellQ4`` and ``ASDShellT3`` with their ``-corotational`` option (the triangles on the
diagonal of ``cylinder_eighth``'s triangles), ``ElasticMembranePlateSection``. P = 4 × the load
factor at the marks w_A = 0.5, 1, 1.5, 2, 2.3, 2.4, 2.45, 2.5 (up to ``--w-max``).

Measured with OpenSees 3.7.1 on 8 × 12 (docs/theory.md, "A peer code on the same grid"): both
elements are stiffer than ours on the same nodes (ASDShellQ4 +3.4 / +5.4 / +10.3 % at
w_A = 0.5 / 1.5 / 2 against our converged 32 × 48 path; ours +0.85 / +0.93 / +1.27 %), and
Newton stops converging for both near w_A = 2 (the triangles at 1.998), before the snap near 2.49.

Writes output/pullout_opensees/{pullout_opensees.json, pullout_opensees.csv, pullout_opensees.png}.
Needs OpenSeesPy and Matplotlib (``pip install openseespy matplotlib``, not dependencies of this
project); run it with the Python that has them, e.g. in a venv of its own:
``python benchmarks/pullout_opensees.py --mesh 8 12``.
"""
import argparse
import csv
import json
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import openseespy.opensees as ops  # noqa: E402

OUT = Path(__file__).resolve().parent.parent / "output" / "pullout_opensees"
R, L, T, E, NU = 4.953, 10.35, 0.094, 10.5e6, 0.3125
MARKS = (0.5, 1.0, 1.5, 2.0, 2.3, 2.4, 2.45, 2.5)


def solve(n_theta: int, n_x: int, element: str, w_max: float) -> dict:
    """{'path': [(w_A, P)] at every converged step, 'marks': {w_A: P}, 'stopped': w_A or None}."""
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)

    def tag(i, j):
        return 1 + i + j * (n_theta + 1)

    for j in range(n_x + 1):
        for i in range(n_theta + 1):
            th = 0.5 * math.pi * i / n_theta
            ops.node(tag(i, j), 0.5 * L * j / n_x, R * math.sin(th), R * math.cos(th))
    ops.section("ElasticMembranePlateSection", 1, E, NU, T, 0.0)
    e = 1
    for j in range(n_x):
        for i in range(n_theta):
            a, b, c, d = tag(i, j), tag(i + 1, j), tag(i + 1, j + 1), tag(i, j + 1)
            if element == "ASDShellQ4":
                ops.element("ASDShellQ4", e, a, b, c, d, 1, "-corotational")
                e += 1
            else:  # cylinder_eighth's triangles share the diagonal from (i + 1, j) to (i, j + 1)
                for tri in ((a, b, d), (b, c, d)):
                    ops.element("ASDShellT3", e, *tri, 1, "-corotational")
                    e += 1
    for j in range(n_x + 1):
        for i in range(n_theta + 1):
            fix = [0] * 6
            if j == 0:
                fix[0] = fix[4] = fix[5] = 1
            if i == 0:
                fix[1] = fix[3] = fix[5] = 1
            if i == n_theta:
                fix[2] = fix[3] = fix[4] = 1
            if any(fix):
                ops.fix(tag(i, j), *fix)
    A = tag(0, 0)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(A, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
    ops.system("UmfPack")
    ops.numberer("RCM")
    ops.constraints("Plain")
    ops.test("NormUnbalance", 1e-4, 100, 0)
    ops.algorithm("Newton")
    ops.analysis("Static")
    path, marks, stopped, dw = [(0.0, 0.0)], {}, None, 0.05
    while ops.nodeDisp(A, 3) < w_max - 1e-9:
        w0 = ops.nodeDisp(A, 3)
        target = min([m for m in MARKS if m > w0 + 1e-9] + [w_max])
        ops.integrator("DisplacementControl", A, 3, min(dw, target - w0))
        if ops.analyze(1) != 0:
            dw /= 2.0
            if dw < 1e-4:
                stopped = w0
                break
            continue
        dw = min(0.05, 1.5 * dw)
        w, P = ops.nodeDisp(A, 3), 4.0 * ops.getLoadFactor(1)
        path.append((w, P))
        for m in MARKS:
            if abs(w - m) < 1e-6:
                marks[m] = P
                print(f"{element} {n_theta} x {n_x}: w_A = {w:.3f}, P = {P:.1f}", flush=True)
    if stopped is not None:
        print(f"{element} {n_theta} x {n_x}: Newton stopped converging at w_A = {stopped:.4f}", flush=True)
    return {"path": path, "marks": marks, "stopped": stopped}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mesh", type=int, nargs=2, default=[8, 12])
    ap.add_argument("--w-max", type=float, default=2.5)
    ap.add_argument("--elements", nargs="+", default=["ASDShellQ4", "ASDShellT3"])
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    runs = {el: solve(*args.mesh, el, args.w_max) for el in args.elements}
    data = {"mesh": args.mesh, "opensees": ops.version(),
            "runs": {el: {"marks": {str(k): v for k, v in r["marks"].items()}, "stopped_at_w_A": r["stopped"],
                          "path": r["path"]} for el, r in runs.items()}}
    (OUT / "pullout_opensees.json").write_text(json.dumps(data, indent=1))
    with open(OUT / "pullout_opensees.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["element", "w_A", "P"])
        for el, r in runs.items():
            w.writerows([el, *row] for row in r["path"])
    fig, ax = plt.subplots(figsize=(6, 4))
    for el, r in runs.items():
        ax.plot(*zip(*r["path"]), ".-", ms=3, label=f"{el} (co-rotational)")
    ax.set_xlabel("w_A")
    ax.set_ylabel("P")
    ax.set_title(f"Pull-out in OpenSees {ops.version()}, {args.mesh[0]} x {args.mesh[1]}", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "pullout_opensees.png", dpi=120)


if __name__ == "__main__":
    main()

"""The beams' C kernels against their numba versions, side by side in one process (a script).

``--elements`` co-rotational beams in space (default 10⁵) on a line, their nodal states set to
random large rotations (|θ| ~ 0.5 rad a component) and small displacements; the residual (the
vector kernel) and the tangent (the matrix kernel, with DOLFINx's insertion) are assembled
through DOLFINx with the C kernels of :mod:`dolfinx_corot.kernels.compiled` and with the numba
cfuncs of :mod:`dolfinx_corot.kernels.beam3d`, the two taking turns (``--repeats`` rounds,
medians). Checked: the two residuals equal bit for bit, the tangents' Frobenius norms to 1e-14.

Writes output/beam_kernels/{kernels.json, kernels.csv, kernels.png}.
Usage: python benchmarks/beam_kernels.py [--elements 100000] [--repeats 7]
"""
import argparse
import json
import os
import statistics
import time

import numpy as np

import dolfinx.fem.petsc

import dolfinx_corot as dc
from dolfinx_corot import _dolfinx
from dolfinx_corot.io import output_dir, write_rows
from dolfinx_corot.io.mesh import from_arrays
from dolfinx_corot.kernels import beam3d, compiled


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, default=100_000)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    n = args.elements
    x = np.linspace(0.0, 100.0, n + 1)
    tm = from_arrays(np.c_[x, 0 * x, 0 * x], np.c_[np.arange(n), np.arange(1, n + 1)], "axis",
                     {"base": np.array([0])})
    scene = dc.Scene(large_rotations=True)
    part = scene.add_beam(tm, "axis", section=dc.Section(A=1.0, I=1 / 12, Iy=1 / 12, J=0.14),
                          material=dc.Elastic(1e4, 0.3), orientation=(0.0, 0.0, 1.0)).model
    part.forms()  # (the form constant and the coefficients)
    rng = np.random.default_rng(0)
    states = part.state.x.array.reshape(-1, 7)
    states[:, :3] = 0.01 * rng.normal(size=(len(states), 3))
    w = 0.5 * rng.normal(size=(len(states), 3))
    angle = np.linalg.norm(w, axis=1)
    states[:, 3] = np.cos(0.5 * angle)
    states[:, 4:] = w * (np.sin(0.5 * angle) / np.where(angle > 0.0, angle, 1.0))[:, None]
    coefficients = [part.state, part.props, *part._element_constants()]
    kernels = {"C": compiled.beam3d_kernels(), "numba": (beam3d.vector_kernel, beam3d.matrix_kernel)}
    forms = {name: tuple(_dolfinx.kernel_form(part.V, k.address, rank, coefficients, [part._flag])
                         for k, rank in zip(pair, (1, 2))) for name, pair in kernels.items()}
    A = dolfinx.fem.petsc.create_matrix(forms["C"][1])
    b = dolfinx.fem.petsc.create_vector(forms["C"][0])
    times = {name: {"residual": [], "tangent": []} for name in forms}
    results = {}
    for _ in range(args.repeats):
        for name, (L, a) in forms.items():
            with b.localForm() as local:
                local.set(0.0)
            t = time.perf_counter()
            dolfinx.fem.petsc.assemble_vector(b, L)
            times[name]["residual"].append(time.perf_counter() - t)
            A.zeroEntries()
            t = time.perf_counter()
            dolfinx.fem.petsc.assemble_matrix(A, a)
            A.assemble()
            times[name]["tangent"].append(time.perf_counter() - t)
            results[name] = (b.array.copy(), A.norm())
    same_residual = bool(np.array_equal(results["C"][0], results["numba"][0]))
    tangent_norms = abs(results["C"][1] - results["numba"][1]) / results["numba"][1]
    rows = []
    for name, t in times.items():
        rows.append({"kernels": name, "elements": n, "residual_ms": 1e3 * statistics.median(t["residual"]),
                     "tangent_ms": 1e3 * statistics.median(t["tangent"]),
                     "residual_us_per_element": 1e6 * statistics.median(t["residual"]) / n,
                     "tangent_us_per_element": 1e6 * statistics.median(t["tangent"]) / n})
    ratios = {k: rows[0][k] / rows[1][k] for k in ("residual_ms", "tangent_ms")}
    out = output_dir("beam_kernels")
    with open(os.path.join(out, "kernels.json"), "w") as f:
        json.dump({"repeats": args.repeats, "rows": rows, "C_over_numba": ratios, "residuals_equal": same_residual,
                   "tangent_norms_relative_difference": tangent_norms}, f, indent=1)
    write_rows(os.path.join(out, "kernels.csv"), rows)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.0, 3.0))
    ax = fig.subplots()
    for i, (what, label) in enumerate((("residual_ms", "residual"), ("tangent_ms", "tangent + insertion"))):
        ax.bar([3 * i, 3 * i + 1], [rows[0][what], rows[1][what]], color=["C0", "C1"])
        ax.text(3 * i + 0.5, max(rows[0][what], rows[1][what]) * 1.02, label, ha="center")
    ax.set_xticks([0, 1, 3, 4], ["C", "numba", "C", "numba"])
    ax.set_ylim(0.0, 1.15 * max(r["tangent_ms"] for r in rows))
    ax.set(ylabel=f"assembly of {n} beams, median [ms]", title=f"the beams' kernels through DOLFINx ({args.repeats} rounds)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "kernels.png"), dpi=110)
    for r in rows:
        print(f"{r['kernels']:6s} residual {r['residual_ms']:7.1f} ms  tangent {r['tangent_ms']:7.1f} ms  "
              f"({r['residual_us_per_element']:.2f} / {r['tangent_us_per_element']:.2f} µs an element)")
    print(f"C / numba: residual {ratios['residual_ms']:.2f}, tangent {ratios['tangent_ms']:.2f}; residuals equal: "
          f"{same_residual}; tangent norms differ by {tangent_norms:.1e}")
    if not same_residual or tangent_norms > 1e-14:
        raise SystemExit("the C and numba kernels disagree")


if __name__ == "__main__":
    main()

"""Benchmark of the 3D contact search (a script, not a test).

For n faces = 10³, 10⁴, 10⁵, 10⁶: a master sphere of radius 1 meshed by a latitude–longitude
grid of n quadrilaterals (triangles at the poles), and n slave points at random positions on a
concentric sphere perturbed by N(0, (h/2)²) in radius (h the mean face size), so that slaves lie
on both sides of the master; boxes inflated by the margin h/2. Times the broad phase
(:func:`dolfinx_corot.contact.search3d.broad_phase_boxes`, boxes included) and the narrow phase
(closest point on each candidate face, :func:`dolfinx_corot.contact.kernels3d.closest_on_faces`),
best of ``--repeats`` after a compile run, one core; the slaves numbered randomly. The growth
exponent between sizes is printed (1: linear).

Writes output/contact_search_3d/{search_times.json, search_times.png}. Run serially.
Usage: python benchmarks/contact_search_3d.py [--sizes 1000 10000 100000 1000000] [--repeats 3]
"""
import argparse
import json
import os
import time

import numpy as np

from dolfinx_corot.contact.kernels3d import closest_on_faces
from dolfinx_corot.contact.search3d import broad_phase_boxes, face_boxes
from dolfinx_corot.io import output_dir


def sphere(n_faces: int, seed: int = 0):
    """(master nodes, faces (m, 4), nodes per face (m,), slaves, h) of the problem of size n_faces."""
    rng = np.random.default_rng(seed)
    nt = max(4, int(round(np.sqrt(n_faces / 2))))
    npnt = 2 * nt
    theta = np.linspace(0.0, np.pi, nt + 1)[1:-1]
    phi = np.linspace(0.0, 2 * np.pi, npnt + 1)[:-1]
    T, P = np.meshgrid(theta, phi, indexing="ij")
    X = np.column_stack([np.sin(T).ravel() * np.cos(P).ravel(), np.sin(T).ravel() * np.sin(P).ravel(),
                         np.cos(T).ravel()])
    X = np.vstack([X, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]])
    north, south = len(X) - 2, len(X) - 1
    idx = np.arange((nt - 1) * npnt).reshape(nt - 1, npnt)
    nxt = np.roll(idx, -1, axis=1)
    quads = np.column_stack([idx[:-1].ravel(), idx[1:].ravel(), nxt[1:].ravel(), nxt[:-1].ravel()])
    top = np.column_stack([np.full(npnt, north), idx[0], nxt[0], np.full(npnt, north)])
    bottom = np.column_stack([idx[-1], np.full(npnt, south), nxt[-1], idx[-1]])
    faces = np.vstack([quads, top, bottom])
    nodes = np.r_[np.full(len(quads), 4), np.full(2 * npnt, 3)]
    h = np.pi / nt
    m = len(faces)
    u = rng.normal(size=(m, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    slaves = u * (1.0 + rng.normal(scale=0.5 * h, size=m))[:, None]
    return X, faces, nodes, slaves, h


def best_of(fn, repeats):
    best, out = np.inf, None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10_000, 100_000, 1_000_000])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    X, faces, nodes, slaves, h = sphere(200)
    broad_phase_boxes(slaves, *face_boxes(X, faces, h))  # compile
    rows = []
    for n in args.sizes:
        X, faces, nodes, slaves, h = sphere(n)

        def broad():
            return broad_phase_boxes(slaves, *face_boxes(X, faces, 0.5 * h))

        t_broad, pairs = best_of(broad, args.repeats)
        k = len(pairs)
        xi, eta, dist, on = np.zeros(k), np.zeros(k), np.zeros(k), np.zeros(k, dtype=bool)

        def narrow():
            closest_on_faces(slaves, X, faces, nodes, pairs[:, 0], pairs[:, 1], 1e-9, xi, eta, dist, on)

        narrow()
        t_narrow, _ = best_of(narrow, args.repeats)
        found = len(np.unique(pairs[on, 0]))
        rows.append({"faces": len(faces), "slaves": len(slaves), "pairs": int(k), "broad_s": t_broad,
                     "narrow_s": t_narrow, "slaves_on_a_face": int(found)})
        print(f"{len(faces):>8} faces, {len(slaves):>8} slaves: {k:>8} candidate pairs, broad {t_broad * 1e3:8.2f} ms, "
              f"narrow {t_narrow * 1e3:8.2f} ms; {found} slaves project onto a face", flush=True)
    for a, b in zip(rows, rows[1:]):
        grow = np.log((b["broad_s"] + b["narrow_s"]) / (a["broad_s"] + a["narrow_s"])) / np.log(b["faces"] / a["faces"])
        print(f"growth exponent {a['faces']} → {b['faces']}: {grow:.2f}")
    out = output_dir("contact_search_3d")
    with open(os.path.join(out, "search_times.json"), "w") as f:
        json.dump({"repeats": args.repeats, "rows": rows}, f, indent=2)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 4))
    n = [r["faces"] for r in rows]
    ax.loglog(n, [r["broad_s"] for r in rows], "o-", label="broad phase (boxes, grid)")
    ax.loglog(n, [r["narrow_s"] for r in rows], "s-", label="narrow phase (closest points)")
    ax.loglog(n, [rows[0]["broad_s"] * x / n[0] for x in n], "k:", label="linear growth")
    ax.set_xlabel("faces = slaves")
    ax.set_ylabel("time (s), one core")
    ax.set_title("3D contact search")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "search_times.png"), dpi=120)
    print(f"wrote {out}/search_times.{{json,png}}")


if __name__ == "__main__":
    main()

"""Benchmark of the 2D node-to-segment contact search (a script, not a test).

For n = 10⁴, 10⁵, 10⁶: a master circle of radius 1 discretised by n segments
and n slave nodes at random angles on a perturbed concentric circle (radius
1 + N(0, (h/2)²), h the segment length, so slaves lie on both sides of the
master polyline), margin = h.  Times broad phase, narrow phase and both (best
of 3 after a warm-up/compile run, one core), with the slaves numbered randomly
and, for comparison, numbered along the surface as a mesh would number them.

Writes output/contact_search/{search_times.json, search_times.csv,
search_times.png}.  Run serially (output_dir calls an MPI barrier).
Usage: python benchmarks/contact_search.py [--sizes 10000 100000 1000000] [--repeats 3]
"""
import argparse
import csv
import json
import os
import time

import numpy as np

from dolfinx_corot.contact.search import broad_phase, narrow_phase
from dolfinx_corot.io import output_dir


def problem(n, seed=0):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2 * np.pi, n + 1)[:-1]
    verts = np.column_stack([np.cos(t), np.sin(t)])
    seg_a = verts
    seg_b = np.roll(verts, -1, axis=0)
    h = 2 * np.sin(np.pi / n)
    phi = rng.uniform(0.0, 2 * np.pi, n)
    r = 1.0 + rng.normal(scale=0.5 * h, size=n)
    slaves = np.column_stack([r * np.cos(phi), r * np.sin(phi)])
    return slaves, seg_a, seg_b, h


def best_of(fn, repeats):
    best = np.inf
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def run(n, repeats):
    slaves, seg_a, seg_b, h = problem(n)
    margin = h
    pairs = broad_phase(slaves, seg_a, seg_b, margin)  # warm-up / compile
    narrow_phase(slaves, seg_a, seg_b, pairs)
    t_broad, pairs = best_of(lambda: broad_phase(slaves, seg_a, seg_b, margin), repeats)
    t_narrow, (seg, xi) = best_of(lambda: narrow_phase(slaves, seg_a, seg_b, pairs), repeats)
    t_total, _ = best_of(
        lambda: narrow_phase(slaves, seg_a, seg_b, broad_phase(slaves, seg_a, seg_b, margin)),
        repeats,
    )
    # the same slaves numbered along the surface (as a mesh would number them):
    # better memory locality than the random numbering above
    ordered = slaves[np.argsort(np.arctan2(slaves[:, 1], slaves[:, 0]))]
    t_ordered, _ = best_of(
        lambda: narrow_phase(ordered, seg_a, seg_b, broad_phase(ordered, seg_a, seg_b, margin)),
        repeats,
    )
    # sanity: slaves inside the margin band found their angular segment
    phi = np.mod(np.arctan2(slaves[:, 1], slaves[:, 0]), 2 * np.pi)
    angular = np.minimum((phi / (2 * np.pi / n)).astype(np.int64), n - 1)
    found = float(np.mean(seg >= 0))
    agree = float(np.mean(seg[seg >= 0] == angular[seg >= 0]))
    return {
        "n": n,
        "margin": margin,
        "pairs": int(pairs.shape[0]),
        "pairs_per_slave": pairs.shape[0] / n,
        "found": found,
        "angular_agreement": agree,
        "broad_s": t_broad,
        "narrow_s": t_narrow,
        "total_s": t_total,
        "total_surface_numbering_s": t_ordered,
    }


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = np.array([r["n"] for r in rows], dtype=float)
    fig, ax = plt.subplots(figsize=(5.5, 4.0))
    for key, label in (("broad_s", "broad phase"), ("narrow_s", "narrow phase"),
                       ("total_s", "broad + narrow"),
                       ("total_surface_numbering_s", "broad + narrow, slaves numbered along surface")):
        ax.loglog(n, [r[key] for r in rows], "o-", label=label)
    t0 = rows[0]["total_s"]
    guide = t0 * (n * np.log(n)) / (n[0] * np.log(n[0]))
    ax.loglog(n, guide, "k--", lw=1, label=r"$\propto n \log n$")
    ax.set_xlabel("n (slave nodes = master segments)")
    ax.set_ylabel("time [s] (best of repeats)")
    ax.set_title("2D node-to-segment contact search")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10**4, 10**5, 10**6])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()

    rows = [run(n, args.repeats) for n in args.sizes]

    print(f"{'n':>9} {'pairs':>9} {'found':>6} {'broad [s]':>10} {'narrow [s]':>11} "
          f"{'total [s]':>10} {'total/(n log n) [ns]':>21} {'total, surface numbering [s]':>29}")
    for r in rows:
        per = r["total_s"] / (r["n"] * np.log(r["n"])) * 1e9
        print(f"{r['n']:>9d} {r['pairs']:>9d} {r['found']:>6.3f} {r['broad_s']:>10.4f} "
              f"{r['narrow_s']:>11.4f} {r['total_s']:>10.4f} {per:>21.2f} "
              f"{r['total_surface_numbering_s']:>29.4f}")
    for r0, r1 in zip(rows, rows[1:]):
        exponent = np.log(r1["total_s"] / r0["total_s"]) / np.log(r1["n"] / r0["n"])
        print(f"growth {r0['n']} -> {r1['n']}: time ∝ n^{exponent:.2f}")

    out = output_dir("contact_search")
    with open(os.path.join(out, "search_times.json"), "w") as f:
        json.dump({"repeats": args.repeats, "rows": rows}, f, indent=2)
    with open(os.path.join(out, "search_times.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    plot(rows, os.path.join(out, "search_times.png"))
    print(f"wrote {out}/search_times.{{json,csv,png}}")


if __name__ == "__main__":
    main()

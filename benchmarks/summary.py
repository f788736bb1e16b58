"""The benchmarks' one table: every script of ``make bench`` adds its rows here.

``record(...)`` puts one row (a benchmark, a case, a number of ranks) into
output/bench/summary.json — a row measured again replaces the old one — and rewrites
output/bench/summary.csv and output/bench/summary.md from it. Columns: wall time of the
whole run, time in the solver (``dc.solve``), peak resident memory (summed over ranks),
Newton iterations, the error against a named reference where one exists, and the peer
codes' figures measured side by side on this kind of machine where there are some
(issue 18: one thread each, one process at a time).
"""
from __future__ import annotations

import json
import os
import platform
import time

from dolfinx_corot.io import write_rows

COLUMNS = ["benchmark", "case", "ranks", "wall_s", "solver_s", "peak_rss_MB", "newton_iterations",
           "error", "reference", "peers", "measured"]

# measured side by side on this kind of machine, one thread each (issue 18)
PEERS = {
    "45deg_bend": "OpenSeesPy 0.08 s whole process (0.021 s in the solver), 36 MB; Kratos 0.14 s, 79 MB",
    "pullout": "CalculiX S4 (36 × 24) 13–14 s, w_A −1.6 %; OpenSees ShellNLDKGQ 147 s, w_A −4.4 %",
    "hertz_same": "CalculiX CPE8 (another set-up) 22–25 s",
    "block3d": "116 k dofs: Kratos (AMGCL) 78–109 s, 633 MB; CalculiX (iterative) 80–105 s, 249 MB (on a twice faster machine); here, in one sitting with ours at 13.0–13.5 s, 379 MB (session 50): CalculiX 2.20 (benchmarks/block_calculix.py) 146 s, 249 MB; Kratos 10.4 (benchmarks/block_kratos.py, AMGCL with Kratos's defaults) 136 s, 598 MB",
}


def _folder() -> str:
    path = os.path.join(os.environ.get("DC_OUTPUT_DIR", "output"), "bench")
    os.makedirs(path, exist_ok=True)
    return path


def peak_rss_MB(comm=None) -> float:
    """Peak resident memory of this process so far, summed over the ranks of ``comm`` (collective)."""
    import resource

    mine = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return mine if comm is None else comm.allreduce(mine)


def record(benchmark: str, case: str, *, wall_s: float, solver_s: float | None = None, peak_rss_MB: float,
           newton_iterations: int | None = None, error: str = "", reference: str = "", ranks: int = 1) -> None:
    """Add (or replace) the row (benchmark, case, ranks) and rewrite the table's files."""
    folder = _folder()
    path = os.path.join(folder, "summary.json")
    rows = []
    if os.path.exists(path):
        with open(path) as f:
            rows = json.load(f)["rows"]
    row = {"benchmark": benchmark, "case": case, "ranks": ranks, "wall_s": round(float(wall_s), 3),
           "solver_s": None if solver_s is None else round(float(solver_s), 3),
           "peak_rss_MB": round(float(peak_rss_MB), 1),
           "newton_iterations": None if newton_iterations is None else int(newton_iterations),
           "error": error, "reference": reference, "peers": PEERS.get(benchmark, ""),
           "measured": time.strftime("%Y-%m-%d %H:%M")}
    rows = [r for r in rows if (r["benchmark"], r["case"], r["ranks"]) != (benchmark, case, ranks)] + [row]
    rows.sort(key=lambda r: (r["benchmark"], r["case"], r["ranks"]))
    with open(path, "w") as f:
        json.dump({"machine": f"{platform.node()} ({os.cpu_count()} cores)", "rows": rows}, f, indent=1)
    write_rows(os.path.join(folder, "summary.csv"), [{c: r[c] for c in COLUMNS} for r in rows])
    with open(os.path.join(folder, "summary.md"), "w") as f:
        f.write("| benchmark | case | ranks | wall | in the solver | peak memory | Newton its | error | peers |\n")
        f.write("|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            solver = "" if r["solver_s"] is None else f"{r['solver_s']:.3g} s"
            its = "" if r["newton_iterations"] is None else str(r["newton_iterations"])
            error = f"{r['error']} ({r['reference']})" if r["error"] else ""
            f.write(f"| {r['benchmark']} | {r['case']} | {r['ranks']} | {r['wall_s']:.3g} s | {solver} | "
                    f"{r['peak_rss_MB']:.0f} MB | {its} | {error} | {r['peers']} |\n")

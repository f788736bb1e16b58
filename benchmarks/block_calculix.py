"""The peer of the SVK block benchmark (``benchmarks/block3d.py``) in CalculiX, to measure both
side by side in one sitting (issue 18: the 116 k-dof block at least 8 times faster than the peers).

The same model: a cantilever block L = 10, 1 × 1 section, E = 1e5, ν = 0.3, clamped at x = 0,
n_x × n_y × n_z trilinear hexahedra with full 2 × 2 × 2 integration (CalculiX's C3D8; a linear
elastic material under NLGEOM is St Venant–Kirchhoff there as here), a dead transverse load of
resultant 75 on the end face (as nodal forces of the uniform traction: CalculiX's distributed
loads follow the face under NLGEOM) in 5 fixed increments. The linear solver is CalculiX's
iterative one (``SOLVER=ITERATIVE CHOLESKY``: CG preconditioned by an incomplete Cholesky) or
SPOOLES (``--solver spooles``). CalculiX's own convergence criterion (residual 0.5 % of the
average force) is looser than ours; its Newton iterations are reported beside the time.

Writes output/block_calculix/block_<mesh>_<solver>.{inp, json, csv, png} and prints the JSON:
the wall time of ``ccx`` (one thread), its peak resident memory, the Newton iterations and the
tip's displacement at the end face's centre (needs even n_y and n_z); the CSV is CalculiX's
convergence history (increment, iteration, residual and correction in % of its criteria' scales),
the PNG plots it.

Needs ``ccx`` (Debian: ``apt-get install calculix-ccx``), not a dependency of this project, and
Matplotlib:
``python benchmarks/block_calculix.py --mesh 150 15 15``.
"""
import argparse
import csv
import json
import os
import re
import resource
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np

import block_mesh
from block_mesh import E, NU

OUT = Path(__file__).resolve().parent.parent / "output" / "block_calculix"


def write_input(path: Path, n: tuple[int, int, int], solver: str) -> int:
    """The input deck; returns the tip node's number (0 if the end face has no centre node)."""
    lines = ["*HEADING", "SVK cantilever block (dolfinx_corot benchmarks/block_calculix.py)", "*NODE"]
    lines += [f"{i},{x:.12g},{y:.12g},{z:.12g}" for i, x, y, z in block_mesh.coordinates(n)]
    lines.append("*ELEMENT, TYPE=C3D8, ELSET=EALL")
    lines += [f"{e}," + ",".join(map(str, c)) for e, c in enumerate(block_mesh.hexahedra(n), start=1)]
    lines.append("*NSET, NSET=FIXED")
    fixed = block_mesh.clamped(n)
    lines += [",".join(map(str, fixed[i:i + 16])) for i in range(0, len(fixed), 16)]
    tip = block_mesh.tip(n)
    lines += ["*NSET, NSET=TIP", str(tip)] if tip else []
    lines += ["*BOUNDARY", "FIXED,1,3", "*MATERIAL, NAME=SVK", "*ELASTIC", f"{E:g},{NU:g}",
              "*SOLID SECTION, ELSET=EALL, MATERIAL=SVK",
              "*STEP, NLGEOM, INC=1000",
              f"*STATIC, DIRECT, SOLVER={'ITERATIVE CHOLESKY' if solver == 'iterative' else 'SPOOLES'}",
              "0.2, 1.0", "*CLOAD"]
    lines += [f"{i},2,{f:.15g}" for i, f in block_mesh.end_loads(n)]
    if tip:
        lines += ["*NODE PRINT, NSET=TIP", "U"]
    lines += ["*END STEP", ""]
    path.write_text("\n".join(lines))
    return tip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", type=int, nargs=3, default=[150, 15, 15])
    ap.add_argument("--solver", choices=["iterative", "spooles"], default="iterative")
    args = ap.parse_args()
    ccx = shutil.which("ccx")
    if ccx is None:
        raise SystemExit("ccx not found: apt-get install calculix-ccx")
    OUT.mkdir(parents=True, exist_ok=True)
    stem = OUT / f"block_{'x'.join(map(str, args.mesh))}_{args.solver}"
    tip = write_input(stem.with_suffix(".inp"), tuple(args.mesh), args.solver)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1", CCX_NPROC_STIFFNESS="1",
               CCX_NPROC_RESULTS="1")
    t = time.perf_counter()
    run = subprocess.run([ccx, "-i", stem.name], cwd=OUT, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if run.returncode != 0 or "Job finished" not in run.stdout:
        raise SystemExit(f"ccx failed:\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}")
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    iterations = len(re.findall(r"^\s*iteration\s+\d+", run.stdout, flags=re.M))
    increments = len(re.findall(r"^\s*increment\s+\d+", run.stdout, flags=re.M))
    u = None
    if tip:
        dat = stem.with_suffix(".dat").read_text().split()
        # the last block "displacements (vx,vy,vz) for set TIP ... time 1.0": node ux uy uz
        k = len(dat) - 1 - dat[::-1].index(str(tip))
        u = [float(v) for v in dat[k + 1:k + 4]]
    data = {"peer": "CalculiX", "ccx": ccx, "mesh": args.mesh, "solver": args.solver,
            "dofs": 3 * int(np.prod(np.array(args.mesh) + 1)), "wall_s": wall, "peak_rss_MB": peak,
            "increments": increments, "newton_iterations": iterations, "tip_displacement": u}
    stem.with_suffix(".json").write_text(json.dumps(data, indent=1))
    history = _convergence(stem.with_suffix(".cvg"))
    with open(stem.with_suffix(".csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["increment", "iteration", "residual_percent", "correction_percent"])
        w.writerows(history)
    _plot(history, data, stem.with_suffix(".png"))
    print(json.dumps(data, indent=1))


def _convergence(path: Path) -> list:
    """(increment, iteration, residual %, correction %) rows of CalculiX's .cvg file."""
    rows = []
    for line in path.read_text().splitlines():
        parts = line.split()
        if len(parts) >= 7 and parts[0].isdigit():
            rows.append((int(parts[1]), int(parts[3]), float(parts[5]), float(parts[6])))
    return rows


def _plot(history: list, data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    for inc in sorted({r[0] for r in history}):
        its = [r for r in history if r[0] == inc]
        ax.semilogy([r[1] for r in its], [r[2] for r in its], "o-", label=f"increment {inc}")
    ax.set_xlabel("iteration")
    ax.set_ylabel("residual (% of CalculiX's scale)")
    ax.set_title(f"CalculiX, {data['dofs']} dofs: {data['wall_s']:.1f} s, {data['peak_rss_MB']:.0f} MB")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()

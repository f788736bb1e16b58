"""The peer of the SVK block benchmark (``benchmarks/block3d.py``) in Kratos Multiphysics, to
measure both side by side in one sitting (issue 18: the 116 k-dof block at least 8 times faster
than the peers; ``benchmarks/block_calculix.py`` is the other peer).

The same model: a cantilever block L = 10, 1 × 1 section, E = 1e5, ν = 0.3, clamped at x = 0,
n_x × n_y × n_z trilinear hexahedra (Kratos's ``TotalLagrangianElement3D8N``, 2 × 2 × 2 Gauss
points; its ``LinearElastic3DLaw`` maps the element's Green–Lagrange strain to the 2nd
Piola–Kirchhoff stress: St Venant–Kirchhoff as here), a dead transverse
load of resultant 75 on the end face as nodal forces of the uniform traction
(``PointLoadCondition3D1N``, tributary areas), in 5 equal load steps. Newton–Raphson with
Kratos's block builder; the linear solver is AMGCL with Kratos's default settings (``--amgcl``
overrides them: e.g. ``'{"smoother_type": "spai0", "krylov_type": "cg"}'``), Kratos's iterative
solver for solids, or Kratos's sparse LU (``--solver direct``).
Convergence: the residual norm below 1e-9 of the step's first (relative) or 1e-12 (absolute).

Writes output/block_kratos/block_<mesh>_<solver>.{json, csv, png} and prints the JSON: the wall
time of the analysis (set-up included, one thread), its peak resident memory, Newton iterations
and the displacement of the node at the end face's centre (needs even n_y and n_z); the CSV and
the PNG are the steps' Newton iterations and times. The mesh is ``block_mesh.py``'s, as CalculiX's.

Needs Kratos in the Python that runs it (not a dependency of this project), e.g. in a venv of its
own: ``pip install KratosMultiphysics KratosStructuralMechanicsApplication
KratosLinearSolversApplication matplotlib``, then ``OMP_NUM_THREADS=1 python benchmarks/block_kratos.py``.
"""
import argparse
import csv
import json
import os
import resource
import time
from pathlib import Path

import block_mesh
from block_mesh import E, NU, STEPS

OUT = Path(__file__).resolve().parent.parent / "output" / "block_kratos"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", type=int, nargs=3, default=[150, 15, 15])
    ap.add_argument("--solver", choices=["iterative", "direct"], default="iterative")
    ap.add_argument("--amgcl", default="{}", help="AMGCL settings (JSON) over Kratos's defaults")
    args = ap.parse_args()
    if os.environ.get("OMP_NUM_THREADS") != "1":
        raise SystemExit("run with OMP_NUM_THREADS=1 (one thread, as the other benchmarks)")
    t0 = time.perf_counter()
    import KratosMultiphysics as KM
    import KratosMultiphysics.StructuralMechanicsApplication as SMA
    from KratosMultiphysics import python_linear_solver_factory

    KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    n = tuple(args.mesh)
    model = KM.Model()
    mp = model.CreateModelPart("block")
    mp.SetBufferSize(2)
    mp.ProcessInfo[KM.DOMAIN_SIZE] = 3
    for var in (KM.DISPLACEMENT, KM.REACTION, SMA.POINT_LOAD, KM.VOLUME_ACCELERATION):
        mp.AddNodalSolutionStepVariable(var)
    for i, x, y, z in block_mesh.coordinates(n):
        mp.CreateNewNode(i, x, y, z)
    props = mp.GetProperties()[1]
    props.SetValue(KM.YOUNG_MODULUS, E)
    props.SetValue(KM.POISSON_RATIO, NU)
    props.SetValue(KM.DENSITY, 1.0)
    props.SetValue(KM.CONSTITUTIVE_LAW, SMA.LinearElastic3DLaw())
    for e, c in enumerate(block_mesh.hexahedra(n), start=1):
        mp.CreateNewElement("TotalLagrangianElement3D8N", e, c, props)
    for comp in "XYZ":
        KM.VariableUtils().AddDof(getattr(KM, f"DISPLACEMENT_{comp}"), getattr(KM, f"REACTION_{comp}"), mp)
    for i in block_mesh.clamped(n):
        for comp in "XYZ":
            mp.GetNode(i).Fix(getattr(KM, f"DISPLACEMENT_{comp}"))
    loads = []
    for c, (i, f) in enumerate(block_mesh.end_loads(n), start=1):
        mp.CreateNewCondition("PointLoadCondition3D1N", c, [i], props)
        loads.append((mp.GetNode(i), f))
    if args.solver == "iterative":
        settings = {"solver_type": "amgcl", "verbosity": 0, **json.loads(args.amgcl)}
    else:
        settings = {"solver_type": "sparse_lu"}
    linear = python_linear_solver_factory.ConstructSolver(KM.Parameters(json.dumps(settings)))
    scheme = KM.ResidualBasedIncrementalUpdateStaticScheme()
    criterion = KM.ResidualCriteria(1e-9, 1e-12)
    builder = KM.ResidualBasedBlockBuilderAndSolver(linear)
    strategy = KM.ResidualBasedNewtonRaphsonStrategy(mp, scheme, criterion, builder, 30, True, False, True)
    strategy.SetEchoLevel(0)
    strategy.Initialize()
    history = []  # (step, load factor, Newton iterations, wall time of the step)
    for step in range(1, STEPS + 1):
        t = time.perf_counter()
        lam = step / STEPS
        mp.CloneTimeStep(lam)
        mp.ProcessInfo[KM.STEP] = step
        for node, f in loads:
            node.SetSolutionStepValue(SMA.POINT_LOAD, [0.0, lam * f, 0.0])
        strategy.InitializeSolutionStep()
        strategy.Predict()
        converged = strategy.SolveSolutionStep()
        strategy.FinalizeSolutionStep()
        history.append((step, lam, mp.ProcessInfo[KM.NL_ITERATION_NUMBER], time.perf_counter() - t))
        if not converged:
            raise SystemExit(f"Kratos: step {step} did not converge")
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    tip = None
    if block_mesh.tip(n):
        u = mp.GetNode(block_mesh.tip(n)).GetSolutionStepValue(KM.DISPLACEMENT)
        tip = [u[0], u[1], u[2]]
    data = {"peer": "Kratos", "version": KM.KratosGlobals.Kernel.Version() if hasattr(KM.KratosGlobals, "Kernel")
            else "", "mesh": args.mesh, "solver": args.solver, "dofs": 3 * (n[0] + 1) * (n[1] + 1) * (n[2] + 1),
            "linear_solver": settings, "wall_s": wall, "peak_rss_MB": peak,
            "newton_iterations": sum(h[2] for h in history), "iterations_per_step": [h[2] for h in history],
            "tip_displacement": tip}
    OUT.mkdir(parents=True, exist_ok=True)
    stem = OUT / f"block_{'x'.join(map(str, args.mesh))}_{args.solver}"
    stem.with_suffix(".json").write_text(json.dumps(data, indent=1))
    with open(stem.with_suffix(".csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["step", "load_factor", "newton_iterations", "wall_time_s"])
        w.writerows(history)
    _plot(history, data, stem.with_suffix(".png"))
    print(json.dumps(data, indent=1))


def _plot(history: list, data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.bar([h[0] for h in history], [h[3] for h in history], color="tab:blue")
    for h in history:
        ax.annotate(f"{h[2]} it.", (h[0], h[3]), ha="center", va="bottom", fontsize=8)
    ax.set_xlabel("load step")
    ax.set_ylabel("wall time of the step (s)")
    ax.set_title(f"Kratos, {data['dofs']} dofs: {data['wall_s']:.1f} s, {data['peak_rss_MB']:.0f} MB")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)

if __name__ == "__main__":
    main()

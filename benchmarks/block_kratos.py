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

Writes output/block_kratos/block_<mesh>_<solver>.json and prints it: the wall time of the
analysis (set-up included, one thread), its peak resident memory, Newton iterations and the
displacement of the node at the end face's centre (needs even n_y and n_z).

Needs Kratos in the Python that runs it (not a dependency of this project), e.g. in a venv of its
own: ``pip install KratosMultiphysics KratosStructuralMechanicsApplication
KratosLinearSolversApplication``, then ``OMP_NUM_THREADS=1 python benchmarks/block_kratos.py``.
"""
import argparse
import json
import os
import resource
import time
from pathlib import Path

OUT = Path(__file__).resolve().parent.parent / "output" / "block_kratos"
L, E, NU, LOAD, STEPS = 10.0, 1e5, 0.3, 75.0, 5


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
    nx, ny, nz = args.mesh
    model = KM.Model()
    mp = model.CreateModelPart("block")
    mp.SetBufferSize(2)
    mp.ProcessInfo[KM.DOMAIN_SIZE] = 3
    for var in (KM.DISPLACEMENT, KM.REACTION, SMA.POINT_LOAD, KM.VOLUME_ACCELERATION):
        mp.AddNodalSolutionStepVariable(var)

    def node(i, j, k):
        return 1 + i + (nx + 1) * (j + (ny + 1) * k)

    for k in range(nz + 1):
        for j in range(ny + 1):
            for i in range(nx + 1):
                mp.CreateNewNode(node(i, j, k), L * i / nx, j / ny, k / nz)
    props = mp.GetProperties()[1]
    props.SetValue(KM.YOUNG_MODULUS, E)
    props.SetValue(KM.POISSON_RATIO, NU)
    props.SetValue(KM.DENSITY, 1.0)
    props.SetValue(KM.CONSTITUTIVE_LAW, SMA.LinearElastic3DLaw())
    e = 1
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                c = [node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k),
                     node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)]
                mp.CreateNewElement("TotalLagrangianElement3D8N", e, c, props)
                e += 1
    for comp in "XYZ":
        KM.VariableUtils().AddDof(getattr(KM, f"DISPLACEMENT_{comp}"), getattr(KM, f"REACTION_{comp}"), mp)
    for k in range(nz + 1):
        for j in range(ny + 1):
            n = mp.GetNode(node(0, j, k))
            for comp in "XYZ":
                n.Fix(getattr(KM, f"DISPLACEMENT_{comp}"))
    # nodal forces of a uniform traction on the bilinear end face: the tributary areas
    loads = []
    c = 1
    for k in range(nz + 1):
        for j in range(ny + 1):
            w = (0.5 if j in (0, ny) else 1.0) / ny * (0.5 if k in (0, nz) else 1.0) / nz
            nid = node(nx, j, k)
            mp.CreateNewCondition("PointLoadCondition3D1N", c, [nid], props)
            loads.append((mp.GetNode(nid), -LOAD * w))
            c += 1
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
    iterations = []
    for step in range(1, STEPS + 1):
        lam = step / STEPS
        mp.CloneTimeStep(lam)
        mp.ProcessInfo[KM.STEP] = step
        for n, f in loads:
            n.SetSolutionStepValue(SMA.POINT_LOAD, [0.0, lam * f, 0.0])
        strategy.InitializeSolutionStep()
        strategy.Predict()
        converged = strategy.SolveSolutionStep()
        strategy.FinalizeSolutionStep()
        iterations.append(mp.ProcessInfo[KM.NL_ITERATION_NUMBER])
        if not converged:
            raise SystemExit(f"Kratos: step {step} did not converge")
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    tip = None
    if ny % 2 == 0 and nz % 2 == 0:
        u = mp.GetNode(node(nx, ny // 2, nz // 2)).GetSolutionStepValue(KM.DISPLACEMENT)
        tip = [u[0], u[1], u[2]]
    data = {"peer": "Kratos", "version": KM.KratosGlobals.Kernel.Version() if hasattr(KM.KratosGlobals, "Kernel")
            else "", "mesh": args.mesh, "solver": args.solver, "dofs": 3 * (nx + 1) * (ny + 1) * (nz + 1),
            "linear_solver": settings, "wall_s": wall, "peak_rss_MB": peak, "newton_iterations": sum(iterations),
            "iterations_per_step": iterations, "tip_displacement": tip}
    OUT.mkdir(parents=True, exist_ok=True)
    stem = OUT / f"block_{'x'.join(map(str, args.mesh))}_{args.solver}"
    stem.with_suffix(".json").write_text(json.dumps(data, indent=1))
    print(json.dumps(data, indent=1))


if __name__ == "__main__":
    main()

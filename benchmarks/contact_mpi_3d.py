"""What 3D contact costs across ranks as the contact surface grows (a script, not a test).

Two slabs [0, 1]² × [0, 2h] and [0, 1]² × [2h, 4h] of tetrahedra (sizes h and 1.3 h: non-matching
faces), pressed together by a pressure on the top, two-pass penalty contact, one load step. The
slabs are two elements thick, so the surfaces (about 2/h² faces each) grow as fast as the meshes.
Every rank holds both contact surfaces whole and evaluates the slaves whose dofs it owns; per
contact evaluation the script times, summed over the two passes and taken on the slowest rank:

* ``wait``: before each gather, a barrier: how far the slowest rank lags behind (load imbalance);
* ``gather``: the surfaces' current positions (one allgather of the surface nodes' displacements);
* ``search``: the broad phase (face boxes over the whole master surface) when a slave has moved
  by half the search margin, with the allreduce that agrees on the candidate list;
* ``pairs``: closest points, choice of face, gaps, forces and tangents of this rank's slaves;
* ``evaluate``: the whole contact evaluation (the above and the bookkeeping),

and the step's wall time. Run it on one and on two ranks; each run writes
output/contact_mpi_3d/ranks<N>.json, prints a table and plots every ranks<N>.json written so far
(output/contact_mpi_3d/contact_mpi_3d.png):

    python benchmarks/contact_mpi_3d.py [--sizes 0.05 0.025 0.0125]
    mpirun -n 2 python benchmarks/contact_mpi_3d.py [--sizes ...]
"""
import argparse
import functools
import json
import os
import time

import gmsh
import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.contact.interface3d import Interface3D
from dolfinx_corot.io import output_dir
from dolfinx_corot.io.mesh import from_gmsh

comm = MPI.COMM_WORLD
E, NU, P = 100.0, 0.3, 1.0
TIMERS = {"wait": 0.0, "gather": 0.0, "search": 0.0, "pairs": 0.0, "evaluate": 0.0}
COUNT = {"evaluate": 0}


def _timed(name, method):
    @functools.wraps(method)
    def wrapper(*args, **kwargs):
        if name == "gather":  # the slower rank's lead, apart from the communication itself
            t = time.perf_counter()
            comm.barrier()
            TIMERS["wait"] += time.perf_counter() - t
        t = time.perf_counter()
        out = method(*args, **kwargs)
        TIMERS[name] += time.perf_counter() - t
        if name in COUNT:
            COUNT[name] += 1
        return out
    return wrapper


for _name, _method in (("gather", "_positions"), ("search", "_search"), ("pairs", "_pairs"),
                       ("evaluate", "evaluate")):
    setattr(Interface3D, _method, _timed(_name, getattr(Interface3D, _method)))


def slabs(h: float):
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        vols = {"lower": (occ.addBox(0, 0, 0, 1, 1, 2 * h), h),
                "upper": (occ.addBox(0, 0, 2 * h, 1, 1, 2 * h), 1.3 * h)}
        occ.synchronize()
        groups = {}
        for name, (vol, size) in vols.items():
            gmsh.model.mesh.setSize(gmsh.model.getBoundary([(3, vol)], recursive=True), size)
            for _, tag in gmsh.model.getBoundary([(3, vol)], oriented=False):
                x, y, z = occ.getCenterOfMass(2, tag)
                face = ("base" if z < 1e-9 else "top" if z > 4 * h - 1e-9 else
                        f"{name}_face" if abs(z - 2 * h) < 1e-9 else "x0" if x < 1e-9 else "y0" if y < 1e-9 else None)
                if face:
                    groups.setdefault(face, []).append(tag)
            gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [vol]), name)
        for name, tags in groups.items():
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.model.mesh.generate(3)
    tm = from_gmsh(gmsh.model if comm.rank == 0 else None, 3, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return tm


def run(h: float) -> dict:
    tm = slabs(h)
    sc = dc.Scene(large_rotations=False, linear_solver="direct")
    b = sc.add_solid(tm, material=dc.Elastic(E, NU), degree=1)
    sc.fix(b, "base", dofs=("uz",))
    sc.fix(b, "x0", dofs=("ux",))
    sc.fix(b, "y0", dofs=("uy",))
    sc.load(b, "top", traction=(0.0, 0.0, -P))
    pair = sc.contact((b, "upper_face"), (b, "lower_face"), law=dc.Penalty(), symmetric=True)
    for k in TIMERS:
        TIMERS[k] = 0.0
    COUNT["evaluate"] = 0
    comm.barrier()
    t = time.perf_counter()
    result = dc.solve(sc, dc.LoadControl(steps=1))
    wall = comm.allreduce(time.perf_counter() - t, op=MPI.MAX)
    n = COUNT["evaluate"] // len(pair)  # evaluations per pass
    per = {k: 1e3 * comm.allreduce(v, op=MPI.MAX) / n for k, v in TIMERS.items()}
    itfs = sc.interfaces
    row = {"h": h, "dofs": b.model.V.dofmap.index_map.size_global * 3,
           "slave_nodes": [len(i.area) for i in itfs], "master_faces": [len(i.faces) for i in itfs],
           "evaluations": n, "newton_iterations": int(result.history.rows[-1]["iterations"]),
           "wall_s": wall, **{f"{k}_ms": v for k, v in per.items()}}
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=float, nargs="+", default=[0.05, 0.025, 0.0125])
    args = parser.parse_args()
    run(0.1)  # compile and warm up
    rows = [run(h) for h in args.sizes]
    if comm.rank == 0:
        print(f"{comm.size} rank(s)")
        print(" h       dofs   slaves  faces  evals  wait ms  gather ms  search ms  pairs ms  evaluate ms  step s")
        for r in rows:
            print(f" {r['h']:<7g} {r['dofs']:<6d} {sum(r['slave_nodes']):<7d} {sum(r['master_faces']):<6d} "
                  f"{r['evaluations']:<6d} {r['wait_ms']:<8.2f} {r['gather_ms']:<10.2f} {r['search_ms']:<10.2f} "
                  f"{r['pairs_ms']:<9.2f} "
                  f"{r['evaluate_ms']:<12.2f} {r['wall_s']:.2f}")
    out = output_dir("contact_mpi_3d")
    if comm.rank == 0:
        with open(os.path.join(out, f"ranks{comm.size}.json"), "w") as f:
            json.dump({"ranks": comm.size, "rows": rows}, f, indent=2)
        plot(out)
        print(f"wrote {out}/ranks{comm.size}.json and {out}/contact_mpi_3d.png")


def plot(out: str) -> None:
    """Per-evaluation times against the master faces, for every ranks<N>.json written so far."""
    import glob

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for path in sorted(glob.glob(os.path.join(out, "ranks*.json"))):
        with open(path) as f:
            data = json.load(f)
        faces = [sum(r["master_faces"]) for r in data["rows"]]
        style = "-" if data["ranks"] == 1 else "--"
        for key, colour in (("evaluate_ms", "k"), ("pairs_ms", "C0"), ("search_ms", "C1"), ("gather_ms", "C2"),
                            ("wait_ms", "C3")):
            ax.loglog(faces, [r[key] for r in data["rows"]], style, color=colour, marker="o", ms=3,
                      label=f"{key[:-3]}, {data['ranks']} rank(s)")
    ax.set(xlabel="master faces (both passes)", ylabel="ms per contact evaluation (slowest rank)",
           title="3D contact across ranks")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "contact_mpi_3d.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()

"""Run under mpirun: arc-length on Lee's frame, interrupted with a checkpoint and restarted.

Prints the final load factor and state norm; the test compares them with an
uninterrupted run (and with the serial numbers)."""
import json
import sys

import numpy as np
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.gmsh_models import polyline

path = sys.argv[1]
tm = polyline([[0.0, 0.0], [0.0, 120.0], [24.0, 120.0], [120.0, 120.0]], [10, 2, 8], line_name="frame",
              point_names={0: "A", 2: "load", 3: "B"})


def scene():
    sc = dc.Scene()
    f = sc.add_beam(tm, "frame", section=dc.Section(A=6.0, I=2.0), material=dc.Elastic(720.0))
    sc.fix(f, "A", dofs=("ux", "uy"))
    sc.fix(f, "B", dofs=("ux", "uy"))
    sc.load(f, "load", force=(0.0, -0.1))
    sc.monitor("P", f, "load")
    return sc


def driver(n):
    return dc.ArcLength(initial_increment=0.5, desired_iterations=4, max_steps=n)


full_scene = scene()
full = dc.solve(full_scene, driver(30))
dc.solve(scene(), driver(15), checkpoint=path)
resumed_scene = scene()
resumed = dc.solve(resumed_scene, driver(30), restart=path)
a = full_scene.model.to_global(full_scene.model.state.x.array)
b = resumed_scene.model.to_global(resumed_scene.model.state.x.array)
if MPI.COMM_WORLD.rank == 0:
    print(json.dumps({"ranks": MPI.COMM_WORLD.size, "diff": float(np.abs(a - b).max()),
                      "load_factor": full.history.column("load_factor")[-1],
                      "tip": [full.history.column(c)[-1] for c in ("P_ux", "P_uy", "P_rz")]}))

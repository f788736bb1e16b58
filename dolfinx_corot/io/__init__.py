"""Input and output: gmsh meshes with named groups, history files, plots."""
from .fields import FieldWriter
from .mesh import GroupNotFoundError, TaggedMesh, from_arrays, from_gmsh

__all__ = ["FieldWriter", "GroupNotFoundError", "TaggedMesh", "from_arrays", "from_gmsh", "output_dir", "reference"]


def output_dir(name: str) -> str:
    """``output/<name>`` below the working directory (or below $DC_OUTPUT_DIR), created on rank 0."""
    import os

    from mpi4py import MPI

    root = os.environ.get("DC_OUTPUT_DIR", "output")
    path = os.path.join(root, name)
    if MPI.COMM_WORLD.rank == 0:
        os.makedirs(path, exist_ok=True)
    MPI.COMM_WORLD.barrier()
    return path


def reference(name: str) -> dict:
    """The reference solution ``<name>.json`` shipped in dolfinx_corot/reference (see its README)."""
    import json
    import os

    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "..", "reference", f"{name}.json")
    with open(path) as f:
        return json.load(f)


def write_rows(path: str, rows: list) -> None:
    """A CSV file of dict rows (the first row's keys as header); call on one rank."""
    import csv

    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

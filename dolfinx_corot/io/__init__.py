"""Input and output: gmsh meshes with named groups, history files, plots."""
from .mesh import GroupNotFoundError, TaggedMesh, from_gmsh

__all__ = ["GroupNotFoundError", "TaggedMesh", "from_gmsh"]

"""Small-strain element laws in the element frame (no knowledge of frames or DOLFINx).

Each module is imported where it is used (``from dolfinx_corot.elements import beam3d``): they
compile with numba, which a scene of continua alone does not load."""

__all__ = ["beam3d", "line2d", "shell_triangle"]

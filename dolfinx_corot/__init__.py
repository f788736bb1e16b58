"""dolfinx_corot: large-rotation structures and contact on DOLFINx."""
__version__ = "0.1.0"

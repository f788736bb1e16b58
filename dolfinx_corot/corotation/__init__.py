"""Co-rotational frames: rigid-body motion removed by a projector.

Each frame maps global nodal displacements/rotations ``d`` to deformations
``d̄`` in an element frame that rotates with the element, and back:
``δd̄ = P δd``, ``f = Pᵀ f̄``, ``K = Pᵀ K̄ P + ∂(Pᵀ)/∂d : f̄`` (Rankin &
Nour-Omid 1988, 1990; seed §2.1). The element law that produces ``f̄, K̄``
lives in :mod:`dolfinx_corot.elements` and never sees the frame.
:mod:`.transform` holds what the frames share (``f = Pᵀ f̄``, ``Pᵀ K̄ P``,
local coordinates); the rotation algebra is :mod:`dolfinx_corot.rotations`.
"""
from . import frame2d, frame3d, frame_quad, frame_triangle, transform

__all__ = ["frame2d", "frame3d", "frame_quad", "frame_triangle", "transform"]

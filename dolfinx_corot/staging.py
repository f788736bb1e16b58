r"""Staged construction: a scene run as a sequence of stages, each with the cells that exist in it.

A :class:`Stage` names the cell groups of solids that appear (``add``) in it, on top of those of
the stages before, and the driver that runs it (load control; its own steps). :func:`solve_stages`
runs the stages in turn on one configuration:

* **Existence.** A cell that does not exist contributes nothing — no stiffness, no weight — and the
  nodes that no existing cell touches are held where they are (they cost a Dirichlet row each).
  A solid without stages pays nothing: the factor and the shift below enter its forms only once
  it is staged.
* **Stage loads.** The external force of stage k, F_k (the weights and loads of what exists in
  it), is reached from that of the stage before: f_ext(λ) = F_{k−1} + λ (F_k − F_{k−1}), λ: 0 → 1.
  A new layer's weight is thus applied over its stage, while the weight already carried stays.
* **Strain-free activation.** A cell that appears takes the current displacement of its nodes
  as its activation shift s (per cell: a node shared with an existing cell keeps its
  displacement, the cells that meet there have shifts of their own). Approach I (seed §3.1.2,
  small construction deformations): strains of u − s on the mesh, the original mesh being the
  reference. Approach II (large construction deformations): the reference of the new cell is the
  deformed position X + s, F = (I + ∇u)(I + ∇s)⁻¹. At small strain the two coincide.
  The nodes that appear with a new cell are held at their positions until then; the seed's
  mapping of new continuum onto the deformed configuration (approach II: an auxiliary elastic
  problem with E = 1, ν = 0) is the next part of this module (issue 14).

Reference: Z_Soil "Large deformations" report, §3.1.2 (the two approaches).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from .assembly import make_system
from .result import Result
from .solvers import LoadControl, solve

APPROACHES = ("I", "II")


@dataclass
class Stage:
    """One construction stage: ``add`` = [(solid part, cell group), …] appearing in it, run by
    ``driver`` (its load factor λ goes 0 → 1 from the loads of the stage before to its own)."""

    name: str
    add: Sequence = field(default_factory=list)
    driver: LoadControl = field(default_factory=lambda: LoadControl(steps=1))


def solve_stages(scene, stages: Sequence[Stage], approach: str = "II", initial: Sequence = ()) -> list[Result]:
    """Run ``stages`` in turn on ``scene``; ``initial`` = [(solid part, cell group), …] exist from
    the start (the rest of each staged solid does not, until a stage adds it). Returns one
    :class:`Result` per stage."""
    if approach not in APPROACHES:
        raise ValueError(f"solve_stages: approach = {approach!r} is not one of {APPROACHES}")
    staged = {}
    for ref, group in list(initial) + [item for st in stages for item in st.add]:
        model = ref.model
        if id(model) not in staged:
            try:
                model.start_staging(approach)
            except NotImplementedError as err:  # parts that cannot be staged yet
                raise NotImplementedError(f"solve_stages: {ref.kind} '{ref.name}': {err}") from None
            staged[id(model)] = (model, np.zeros(len(model.cells_existing()), dtype=bool))
        model.tmesh.cells(group)  # fails early for a missing group
    for ref, group in initial:
        staged[id(ref.model)][1][ref.model.tmesh.cells(group)] = True
    for model, exists in staged.values():
        model.set_existing(exists)
    previous = None  # F_{k-1}, owned entries
    results = []
    for stage in stages:
        for ref, group in stage.add:
            staged[id(ref.model)][1][ref.model.tmesh.cells(group)] = True
        for model, exists in staged.values():
            model.set_existing(exists)
        system = make_system(scene.model, solver=scene.linear_solver, contributions=scene.contributions())
        try:
            previous = system.ramp_loads_from(previous)
            results.append(solve(scene, stage.driver, system=system))
        finally:
            system.destroy()
    return results

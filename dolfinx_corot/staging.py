r"""Staged construction: a scene run as a sequence of stages, each with the elements that exist in it.

A :class:`Stage` names the cell groups of solids and the groups of 2D beams and bars that appear
(``add``) or are excavated (``remove``) in it, on top of the stages before, and the driver that
runs it (its own steps). :func:`solve_stages` runs the stages in turn on one configuration:

* **Existence.** An element that does not exist contributes nothing — no stiffness, no weight —
  and the nodes that no existing element touches are held where they are (a Dirichlet row each).
  A part without stages pays nothing: existence enters its forms only once it is staged.
* **Stage loads.** Stage k starts where stage k − 1 ended and ramps to its own external force
  F_k (the weights and loads of what exists in it): f_ext(λ) = S_k + λ (F_k − S_k), λ: 0 → 1,
  S_k = F_{k−1} + f_int,k(u₀) − f_int,k−1(u₀) (the parts' internal force at the configuration
  u₀ that ended the last stage, with this stage's existence and the last one's). A new layer's
  weight is applied over its stage; an excavated block's forces on the ground are released over
  its stage (scaled from 1 to 0), not in one jump.
* **Geostatic stage** (``reset_displacements``): at its end the displacements are discarded and
  the strains kept (each existing cell's shift s becomes s − u).
* **Strain-free activation of continuum.** A cell that appears takes the current displacement of
  its nodes as its activation shift s. Approach I (seed §3.1.2, small construction
  deformations): strains of u − s on the mesh, the original mesh being the reference. Approach
  II (large construction deformations): the reference of the new cell is the deformed position
  X + s, F = (I + ∇u)(I + ∇s)⁻¹. At small strain the two coincide.
* **Structures** (2D beams and bars). Approach II: an element is added undeformed in the
  configuration of that moment — the state of its nodes then (U_os, with the angles) is
  memorized per element, its reference is X + U_os and its deformation U − U_os. Approach I:
  the mesh is its reference and U its deformation.

The seed's mapping of new continuum onto the deformed configuration (approach II: U_e memorized
after excavation, an auxiliary elastic problem with E = 1, ν = 0) and contact interfaces that
appear in a stage are the next parts of this module (issue 14).

Reference: Z_Soil "Large deformations" report, §3.1.2 (the two approaches).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from mpi4py import MPI

from .assembly import make_system
from .result import Result
from .solvers import ConvergenceError, LoadControl, solve

APPROACHES = ("I", "II")


@dataclass
class Stage:
    """One construction stage, run by ``driver`` (its load factor λ goes 0 → 1 from where the stage
    starts to its own loads).

    add: [(solid part, cell group), …] appearing in it (strain-free, by the approach of the run);
    remove: [(solid part, cell group), …] excavated in it — their forces on the remaining body are
    released over the stage (scaled from 1 to 0 with λ), not in one jump;
    reset_displacements: at its end the displacements are discarded and the strains (stresses)
    kept — a geostatic stage, after which displacements count from the initial state."""

    name: str
    add: Sequence = field(default_factory=list)
    remove: Sequence = field(default_factory=list)
    driver: LoadControl = field(default_factory=lambda: LoadControl(steps=1))
    reset_displacements: bool = False


def solve_stages(scene, stages: Sequence[Stage], approach: str = "II", initial: Sequence = ()) -> list[Result]:
    """Run ``stages`` in turn on ``scene``; ``initial`` = [(solid part, cell group), …] exist from
    the start (the rest of each staged solid does not, until a stage adds it). Returns one
    :class:`Result` per stage. A stage that fails raises :class:`ConvergenceError` whose
    ``results`` hold the stages before it and the converged steps of the failed one (its
    ``result``); the configuration is left at its last converged state.

    Stage start: f_ext(0) = F_{k−1} + f_int,k(u₀) − f_int,k−1(u₀), the loads that ended the stage
    before plus the change of the parts' internal force at the current configuration u₀ that
    the change of existence makes — the force of removed cells (released as λ → 1) and nothing
    for cells activated strain-free. The stage thus starts in equilibrium (to the tolerance the
    stage before ended with)."""
    if approach not in APPROACHES:
        raise ValueError(f"solve_stages: approach = {approach!r} is not one of {APPROACHES}")
    staged = {}
    listed = [(item, "initial") for item in initial]
    for st in stages:
        listed += [(item, st.name) for item in list(st.add) + list(st.remove)]
    for (ref, group), where in listed:
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
    loads = fint = None  # where the last stage ended: F_{k-1} and f_int,k-1(u₀) (owned entries)
    results = []
    for stage in stages:
        for ref, group in stage.add:
            staged[id(ref.model)][1][ref.model.tmesh.cells(group)] = True
        for ref, group in stage.remove:
            cells = ref.model.tmesh.cells(group)
            if ref.model.comm.allreduce(not staged[id(ref.model)][1][cells].all(), op=MPI.LOR):
                raise ValueError(f"solve_stages: stage '{stage.name}' removes '{group}' of {ref.kind} "
                                 f"'{ref.name}', which does not exist (entirely) at that stage")
            staged[id(ref.model)][1][cells] = False
        for model, exists in staged.values():
            model.set_existing(exists)
        system = make_system(scene.model, solver=scene.linear_solver, contributions=scene.contributions())
        try:
            start = system.parts_internal_force()
            if loads is not None:
                start += loads - fint
            loads = system.ramp_loads_from(start)
            if stage.reset_displacements:
                _check_resettable(system, staged, stage)
            try:
                result = solve(scene, stage.driver, system=system)
            except ConvergenceError as err:
                err.results = results + [err.result]
                raise
            results.append(result)
            fint = system.parts_internal_force()
            if stage.reset_displacements:
                for model, _ in staged.values():
                    model.reset_displacements()
        finally:
            system.destroy()
    return results


def _check_resettable(system, staged: dict, stage: Stage) -> None:
    """Only staged parts that keep their strains without their displacements (solids) can be reset."""
    for model in system.models:
        if id(model) not in staged or not model.keeps_strains_without_displacements:
            kinds = ", ".join(sorted({f"{p.kind} '{p.name}'" for p in model.parts}))
            why = "is not staged" if id(model) not in staged else "cannot keep its strains without its displacements"
            raise NotImplementedError(f"solve_stages: stage '{stage.name}' discards the displacements, but {kinds} "
                                      f"{why} (only staged solids can: put the structures in later stages)")

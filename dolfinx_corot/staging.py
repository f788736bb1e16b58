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

* **Mapping of new continuum** (approach II, seed §3.1.2). Before new cells appear, the shift w of
  their nodes solves linear elasticity with the seed's artificial constants E = 1, ν = 0 on the
  new cells alone, with imposed boundary shifts: nodes shared with existing continuum
  w = U − U_e (U_e memorized at the end of the last excavation stage: the deformation of the
  excavation is not part of the construction geometry); nodes shared with an existing structure
  w = U (structures here are added in their current configuration X + U_os and sit at X + U: the
  seed's U − U_os measured from their as-built geometry); slave nodes of a contact interface
  projected on their (existing, deformed) master at zero gap; supported dofs their value; free
  external boundary zero vertical shift. The nodes only new cells touch are moved to X + w, and
  the new cells take X + w as their stress-free reference (F = I at activation).
* **Contact in stages.** A slave exists when an existing facet of its surface touches it, a
  master segment when its element exists; pairs of non-existing ones are not searched. Approach
  I: a slave that meets a master for the first time takes its gap (open or overlapping) as zero
  (seed: the interface cancels the initial deformation of the bodies it joins).

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


def solve_stages(scene, stages: Sequence[Stage], approach: str = "II", initial: Sequence = (),
                 on_step=None) -> list[Result]:
    """Run ``stages`` in turn on ``scene``; ``initial`` = [(solid part, cell group), …] exist from
    the start (the rest of each staged solid does not, until a stage adds it). ``on_step(stage,
    row)`` is called after every converged step with the :class:`Stage` and the step's history
    row (e.g. to draw the configuration at the end of each stage). Returns one
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
    memorized = {}  # approach II: U_e of each staged solid after the last excavation stage
    loads = fint = None  # where the last stage ended: F_{k-1} and f_int,k-1(u₀) (owned entries)
    results = []
    for stage in stages:
        before = {key: exists.copy() for key, (_, exists) in staged.items()}
        for ref, group in stage.add:
            staged[id(ref.model)][1][ref.model.tmesh.cells(group)] = True
        for ref, group in stage.remove:
            cells = ref.model.tmesh.cells(group)
            if ref.model.comm.allreduce(not staged[id(ref.model)][1][cells].all(), op=MPI.LOR):
                raise ValueError(f"solve_stages: stage '{stage.name}' removes '{group}' of {ref.kind} "
                                 f"'{ref.name}', which does not exist (entirely) at that stage")
            staged[id(ref.model)][1][cells] = False
        # structures first (approach II: they memorize U_os), then the continua — in approach II
        # new continuum is mapped onto the deformed configuration before it appears
        mappings, held_slaves = [], []
        for model, exists in staged.values():
            if not model.continuum:
                model.set_existing(exists)
        for key, (model, exists) in staged.items():
            if model.continuum:
                new = exists & ~before[key]
                reference = None
                if approach == "II" and model.comm.allreduce(bool(new.any()), op=MPI.LOR):
                    reference, mapping, held = _map_new_continuum(scene, model, exists, new, memorized.get(key))
                    mappings.append(mapping)
                    held_slaves += held
                model.set_existing(exists, reference)
        system = make_system(scene.model, solver=scene.linear_solver, contributions=scene.contributions())
        try:
            system.start_stage(approach)
            for itf, slaves in held_slaves:  # slaves of new cells that cannot move onto their master
                itf.cancel_initial_gaps(slaves)
            start = system.evaluate_internal_force()
            if loads is not None:
                start += loads - fint
            loads = system.ramp_loads_from(start)
            if stage.reset_displacements:
                _check_resettable(system, staged, stage)
            try:
                step = None if on_step is None else (lambda row, stage=stage: on_step(stage, row))
                result = solve(scene, stage.driver, system=system, on_step=step)
            except ConvergenceError as err:
                err.result.mappings = mappings
                err.results = results + [err.result]
                raise
            result.mappings = mappings
            results.append(result)
            fint = system.evaluate_internal_force()
            # loads on constrained dofs act on nothing (a load on a node no element touches yet):
            # the next stage applies them over its steps, from zero
            start_row, stop_row = system.ownership_range()
            rows = system.constrained_global_dofs()
            loads[rows[(rows >= start_row) & (rows < stop_row)] - start_row] = 0.0
            if stage.reset_displacements:
                for model, _ in staged.values():
                    model.reset_displacements()
            if approach == "II" and stage.remove:
                for key, (model, _) in staged.items():
                    if model.continuum:
                        memorized[key] = model.state.x.array.reshape(-1, model.gdim).copy()
        finally:
            system.destroy()
    return results


@dataclass
class Mapping:
    """The mapping of one solid's new cells onto the deformed configuration (approach II), on every
    rank, node by node: X (n, gdim) mesh positions, shift (n, gdim) the nodes' mapped shift w, and
    the class of each node — "existing continuum" (shared with cells that exist: w = U − U_e),
    "structure" (shared with an existing structure: w = U), "slave" (projected on its master),
    "support" (some dof supported or prescribed), "free boundary" (zero vertical shift),
    "interior" (free). ``moved``: whether the node (new alone) was moved to X + w."""

    part: str
    X: np.ndarray
    shift: np.ndarray
    kind: np.ndarray
    moved: np.ndarray


def _map_new_continuum(scene, model, exists: np.ndarray, new: np.ndarray, memorized):
    """Seed §3.1.2 (approach II): the shift w of the nodes of ``model``'s new cells, from the
    E = 1, ν = 0 sub-problem on them with the seed's boundary shifts (in our frame every body sits
    at X + U; see :class:`Mapping` for the classes). The nodes that only new cells touch are moved
    to X + w; slaves of the new cells shared with existing elements cannot be, and take their
    initial gap as zero instead (once the stage's system is bound). Returns (w local blocks × gdim,
    :class:`Mapping`, [(interface, those slaves)])."""
    gdim = model.gdim
    u = model.state.x.array.reshape(-1, gdim)
    ue = np.zeros_like(u) if memorized is None else memorized
    continuum = model.touched_blocks(exists & ~new)
    structure = _touched_by_structures(scene, model)
    in_new = model.touched_blocks(new)
    new_only = in_new & ~continuum & ~structure
    outside = model.touched_blocks(~exists) | model.boundary_blocks()
    values = np.zeros_like(u)
    imposed = np.zeros(u.shape, dtype=bool)
    kind = np.full(len(u), "interior", dtype=object)
    # slaves of interfaces on this solid whose nodes only the new cells touch: onto their masters
    slave = np.zeros(len(u), dtype=bool)
    held = []
    for itf in scene.interfaces:
        if itf.slave_spec[0].model is not model:
            continue
        surf = itf.slave
        shared = (in_new & ~new_only)[surf.blocks]
        held.append((itf, np.concatenate(model.comm.allgather(surf.local[shared])).astype(np.int64)))
        mine = new_only[surf.blocks]
        wanted = np.concatenate(model.comm.allgather(surf.local[mine])).astype(np.int64)
        if not len(wanted):
            continue
        target = itf.project_slaves(wanted)
        lost = np.isnan(target[:, 0])
        if lost.any():
            raise ValueError(f"mapping of new continuum (approach II): {int(lost.sum())} slave node(s) of contact "
                             f"'{itf.name}' at {surf.X[wanted[lost]][:3].tolist()}… find no existing master "
                             "segment to be projected on")
        at = {int(k): i for i, k in enumerate(wanted)}
        for pos, block in zip(surf.local[mine], surf.blocks[mine]):
            values[block] = target[at[int(pos)]] - surf.X[pos]
            imposed[block] = True
            slave[block] = True
    free = new_only & outside & ~slave
    values[free, -1] = 0.0
    imposed[free, -1] = True
    values[continuum] = u[continuum] - ue[continuum]
    values[structure] = u[structure]
    imposed[continuum | structure] = True
    supported = np.zeros(u.size, dtype=bool)
    for dofs, _, _ in model.constraint_dofs():
        supported[dofs] = True
    values.ravel()[supported] = u.ravel()[supported]
    imposed.ravel()[supported] = True
    supported = supported.reshape(-1, gdim).any(axis=1)
    kind[free] = "free boundary"
    kind[slave] = "slave"
    kind[continuum] = "existing continuum"
    kind[structure] = "structure"
    kind[supported & in_new] = "support"
    w = model.map_new_cells(new, values, imposed)
    u[new_only] = w[new_only]
    # the record, node by node on every rank (owned nodes of the new cells)
    n_owned = model.V.dofmap.index_map.size_local
    rows = np.flatnonzero(in_new[:n_owned])
    X = model.V.tabulate_dof_coordinates()[rows, :gdim]
    gather = (lambda a: np.concatenate(model.comm.allgather(a)))
    record = Mapping(model.parts[0].name if model.parts else "solid", gather(X), gather(w[rows]),
                     gather(kind[rows]).astype(str), gather(new_only[rows]))
    return w, record, held


def _touched_by_structures(scene, model) -> np.ndarray:
    """(local blocks of the solid ``model``) whether an existing element of a structure sharing
    its nodes touches the node (structures' existence already set for the stage)."""
    keys = model.node_keys()
    out = np.zeros(len(keys), dtype=bool)
    whole = scene.model
    for other in (whole.models if whole.coupled else [whole]):
        if other.continuum or other.tmesh.node_source != model.tmesh.node_source:
            continue
        n_owned = other.V.dofmap.index_map.size_local
        held = np.zeros(n_owned + other.V.dofmap.index_map.num_ghosts, dtype=bool)
        held[other.held_blocks()] = True
        touched = other.node_keys()[:n_owned][~held[:n_owned]]
        out |= np.isin(keys, np.concatenate(model.comm.allgather(touched)))
    return out


def _check_resettable(system, staged: dict, stage: Stage) -> None:
    """Only staged parts that keep their strains without their displacements (solids), or none of
    whose elements exists yet, can be reset."""
    for model in system.models:
        if id(model) not in staged or not model.can_reset_displacements():
            kinds = ", ".join(sorted({f"{p.kind} '{p.name}'" for p in model.parts}))
            why = "is not staged" if id(model) not in staged else \
                "exists and cannot keep its strains without its displacements"
            raise NotImplementedError(f"solve_stages: stage '{stage.name}' discards the displacements, but {kinds} "
                                      f"{why} (only staged solids can: put the structures in later stages)")

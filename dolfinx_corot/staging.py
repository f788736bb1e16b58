r"""Staged construction: a scene run as a sequence of stages, each with the elements that exist in it.

A :class:`Stage` names the cell groups of solids and the groups of beams, bars, shells and membranes
that appear (``add``) or are excavated (``remove``) in it, on top of the stages before, the
supports, loads and contact interfaces it adds or removes, and the driver that runs it (its own
steps). :func:`solve_stages` runs the stages in turn on one configuration:

* **Existence.** An element that does not exist contributes nothing — no stiffness, no weight —
  and the nodes that no existing element touches are held where they are (a Dirichlet row each).
  A part without stages pays nothing: existence enters its forms only once it is staged.
* **Stage loads.** Stage k starts where stage k − 1 ended and ramps to its own external force
  F_k (the weights and loads of what exists in it): f_ext(λ) = S_k + λ (F_k − S_k), λ: 0 → 1,
  S_k = F_{k−1} + f_int,k(u₀) − f_int,k−1(u₀) (the parts' internal force at the configuration
  u₀ that ended the last stage, with this stage's existence and the last one's). A new layer's
  weight is applied over its stage; an excavated block's forces on the ground are released over
  its stage (scaled from 1 to 0), not in one jump. On rows constrained in stage k − 1 and free
  in stage k, S_k = f_int,k(u₀): a removed support's reaction is released over the stage.
* **Supports, loads and interfaces** (:mod:`dolfinx_corot.conditions`): the handles that
  ``Scene.fix``, ``prescribe``, ``load``, ``gravity`` and ``contact`` return are stage items. One
  that the first stage naming it adds does not exist before it; the others exist from the start.
  A support added holds its nodes where they are; a load added is applied over its stage, one
  removed taken off over its stage; an interface removed releases its forces over the stage.
* **Geostatic stage** (``reset_displacements``): at its end the displacements are discarded and
  the strains kept (each existing cell's shift s becomes s − u). Or K₀ initial stresses of level
  ground (``initial_stress=[K0(soil, k0, surface)]``): σ₀ carried at zero strain, in equilibrium
  with the ground's weight, so that the stage starts and ends at zero displacement.
* **Strain-free activation of continuum.** A cell that appears takes the current displacement of
  its nodes as its activation shift s. Approach I (seed §3.1.2, small construction
  deformations): strains of u − s on the mesh, the original mesh being the reference. Approach
  II (large construction deformations): the reference of the new cell is the deformed position
  X + s, F = (I + ∇u)(I + ∇s)⁻¹. At small strain the two coincide.
* **Structures** (beams and bars in 2D and 3D, shell triangles, quadrilateral membranes). Approach
  II: an element is added undeformed in the configuration of that moment — the state of its nodes
  then (U_os, with the rotations) is memorized per element, its reference is X + U_os and its
  deformation U − U_os (in 3D the rotations since then, R R_osᵀ; a shell's or membrane's frame and
  constants are those of X + U_os). Approach I: the mesh is its reference and U its deformation.

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
  master segment when its element exists; pairs of non-existing ones are not searched, nor those
  of an interface that does not exist. Approach I: a slave that meets a master for the first
  time takes its gap (open or overlapping) as zero (seed: the interface cancels the initial
  deformation of the bodies it joins). Approach II keeps the gaps: the forces of an overlap
  found by an interface that appears are in S_k and push the bodies apart over the stage.

Reference: Z_Soil "Large deformations" report, §3.1.2 (the two approaches).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from mpi4py import MPI

from .assembly import make_system
from .conditions import Condition
from .contact.pair import ContactPair
from .result import Result
from .solvers import CheckpointError, ConvergenceError, CriticalPoint, LoadControl, solve
from .solvers.run import read_checkpoint_on_all_ranks

APPROACHES = ("I", "II")


@dataclass
class Stage:
    """One construction stage, run by ``driver`` (its load factor λ goes 0 → 1 from where the stage
    starts to its own loads).

    add: what appears in it — (part, cell group) pairs of solids, beams, bars and shells (strain-free,
    by the approach of the run); supports, prescribed motions and loads (the
    :class:`~dolfinx_corot.conditions.Condition` that ``Scene.fix``, ``prescribe``, ``load`` and
    ``gravity`` return: a support added holds its nodes where they are, a load is applied over
    the stage); contact interfaces (the :class:`~dolfinx_corot.contact.ContactPair` of
    ``Scene.contact``: approach I takes the gaps it finds as zero);
    remove: what is excavated or taken away in it — cell groups, whose forces on the remaining body
    are released over the stage (scaled from 1 to 0 with λ), not in one jump; supports, whose
    reactions are released over the stage; loads and interfaces, whose forces are;
    reset_displacements: at its end the displacements are discarded and the strains (stresses)
    kept — a geostatic stage, after which displacements count from the initial state;
    initial_stress: [:class:`K0`, …] geostatic stresses of level ground given to solids at the
    start of the stage (the alternative to a gravity stage with ``reset_displacements``)."""

    name: str
    add: Sequence = field(default_factory=list)
    remove: Sequence = field(default_factory=list)
    driver: LoadControl = field(default_factory=lambda: LoadControl(steps=1))
    reset_displacements: bool = False
    initial_stress: Sequence = field(default_factory=list)


@dataclass(frozen=True)
class K0:
    """Initial stresses of level ground in the cells of a solid (the K₀ procedure): σ_v = −γ (surface
    − z) along the vertical (the last axis), σ_h = ``k0`` σ_v, no shear; γ = ``unit_weight``, or
    (None) ρ|g| of the solid's density and gravity. With the solid's gravity they are in
    equilibrium at zero displacement: the stage that sets them starts, and ends, there (for level
    ground; elsewhere the stage finds the equilibrium the ground's weight and σ₀ leave)."""

    part: object
    k0: float
    surface: float
    unit_weight: float | None = None

    def apply(self) -> None:
        model = self.part.model
        if not getattr(model, "continuum", False):
            raise ValueError(f"K0 initial stress on {self.part.kind} '{self.part.name}': only solids carry "
                             "initial stresses")
        model.set_k0_stress(self.k0, self.surface, self.unit_weight)


def solve_stages(scene, stages: Sequence[Stage], approach: str = "II", initial: Sequence = (),
                 on_step=None, checkpoint: str | None = None, restart: str | None = None, progress=None,
                 quiet: bool = False) -> list[Result]:
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
    stage before ended with).

    checkpoint: a file (``.npz``) rewritten after every converged step of every stage with what a
    restart needs besides the configuration: the stage reached, each element's activation state
    (s, m; U_os of the structures), U_e, the force the stage started from, the interfaces' initial
    gaps and the results of the stages before. restart: such a file; the run goes on in the stage
    and at the step it holds, with the same scene, approach and stages up to that one (later
    stages may differ; the stage reached may be given another driver of its kind, e.g. smaller
    steps after a failure, see the drivers' ``run``), and reproduces the uninterrupted run.
    progress, quiet: as for :func:`~dolfinx_corot.solve`, each stage named in its lines."""
    if approach not in APPROACHES:
        raise ValueError(f"solve_stages: approach = {approach!r} is not one of {APPROACHES}")
    models = scene.model.models if scene.model.coupled else [scene.model]
    if scene.follower_loads:
        raise NotImplementedError("solve_stages: follower loads (pressures, follower loads per length) cannot be "
                                  "staged yet (each stage ramps constant load vectors); give them as dead loads "
                                  "(follower=False) or solve without stages")
    if scene.model.amplitudes:
        raise ValueError("solve_stages: loads with an amplitude cannot be staged (each stage ramps its loads from "
                         "where it starts to its own); add or remove the loads in the stages instead")
    staged = {}
    initial, switched_on = _items(initial, "initial")
    plan = [(st, *_items(st.add, f"stage '{st.name}' add"), *_items(st.remove, f"stage '{st.name}' remove"))
            for st in stages]
    listed = [(item, "initial") for item in initial]
    for st, add, _, remove, _ in plan:
        listed += [(item, st.name) for item in add + remove]
    # a support, motion, load or interface exists from the start unless the first stage that names it
    # adds it (and ``initial`` does not list it)
    alive = {}
    for _, _, on, _, off in plan:
        for item in off + on:
            if id(item) not in alive:
                alive[id(item)] = any(item is other for other in switched_on) or not any(item is o for o in on)
                item.exists = alive[id(item)]
                if isinstance(item, Condition):
                    item.holds = False
    for stage, _, on, _, off in plan:  # each stage adds what does not exist and removes what does
        for item in on:
            if alive[id(item)]:
                raise ValueError(f"solve_stages: stage '{stage.name}' adds {item!r}, which exists already")
            alive[id(item)] = True
        for item in off:
            if not alive[id(item)]:
                raise ValueError(f"solve_stages: stage '{stage.name}' removes {item!r}, which does not exist at "
                                 "that stage")
            alive[id(item)] = False
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
    resume = None if restart is None else _StageFile.read(restart, scene.model.comm, approach, stages)
    memorized = {}  # approach II: U_e of each staged solid after the last excavation stage
    loads = fint = None  # where the last stage ended: F_{k-1} and f_int,k-1(u₀) (owned entries)
    results = []
    constrained = None  # the rows the last stage's system constrained (global, all ranks)
    for index, (stage, add, switch_on, remove, switch_off) in enumerate(plan):
        before = {key: exists.copy() for key, (_, exists) in staged.items()}
        _switch(switch_on, switch_off)
        for model in models:
            model.stage = stage.name
        for ref, group in add:
            staged[id(ref.model)][1][ref.model.tmesh.cells(group)] = True
        for ref, group in remove:
            cells = ref.model.tmesh.cells(group)
            if ref.model.comm.allreduce(not staged[id(ref.model)][1][cells].all(), op=MPI.LOR):
                raise ValueError(f"solve_stages: stage '{stage.name}' removes '{group}' of {ref.kind} "
                                 f"'{ref.name}', which does not exist (entirely) at that stage")
            staged[id(ref.model)][1][cells] = False
        for k0 in stage.initial_stress:
            k0.apply()
        resuming = resume is not None and index == resume.stage
        if resume is not None and index < resume.stage:  # done before the checkpoint
            for model, exists in staged.values():
                model.set_existing(exists)
            results.append(resume.results[index])
            continue
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
                if approach == "II" and not resuming and model.comm.allreduce(bool(new.any()), op=MPI.LOR):
                    reference, mapping, held = _map_new_continuum(scene, model, exists, new, memorized.get(key))
                    mappings.append(mapping)
                    held_slaves += held
                model.set_existing(exists, reference)
        if resuming:  # each element's activation state as the checkpoint holds it (before the weights)
            memorized, mappings = resume.enter([m for m, _ in staged.values()])
        system = make_system(scene.model, solver=scene.linear_solver, contributions=scene.contributions(),
                             tangent=scene.tangent)
        try:
            if resuming:  # the stage's start as the checkpoint holds it (the configuration: solve's restart)
                start = resume.start(system)
                loads = system.ramp_loads_from(start)
            else:
                system.start_stage(approach)
                for itf, slaves in held_slaves:  # slaves of new cells that cannot move onto their master
                    itf.cancel_initial_gaps(slaves)
                force = system.evaluate_internal_force()
                start = force.copy()
                if loads is not None:
                    start += loads - fint
                    # rows constrained before and free now (a support removed, nodes that a new
                    # element touches) start loaded by the parts' force there: a removed support's
                    # reaction, released over the stage
                    start_row, stop_row = system.ownership_range()
                    freed = np.setdiff1d(constrained, system.constrained_global_dofs())
                    freed = freed[(freed >= start_row) & (freed < stop_row)] - start_row
                    start[freed] = force[freed]
                loads = system.ramp_loads_from(start)
            if stage.reset_displacements:
                _check_resettable(system, staged, stage)
            attach = ({}, None) if checkpoint is None else \
                _StageFile.attach(system, [m for m, _ in staged.values()], approach, stages, index, results,
                                  mappings, start, memorized)
            try:
                step = None if on_step is None else (lambda row, stage=stage: on_step(stage, row))
                result = solve(scene, stage.driver, system=system, on_step=step, checkpoint=checkpoint,
                               restart=restart if resuming else None, attach=attach, progress=progress,
                               quiet=quiet, label=f"stage {index + 1}/{len(stages)} '{stage.name}'")
            except ConvergenceError as err:
                err.result.mappings = mappings
                err.results = results + [err.result]
                raise
            result.mappings = mappings
            results.append(result)
            fint = system.evaluate_internal_force()
            # loads on constrained dofs act on nothing (a load on a node no element touches yet, or
            # on a support): a stage that frees them starts from the parts' force there
            start_row, stop_row = system.ownership_range()
            constrained = system.constrained_global_dofs()
            loads[constrained[(constrained >= start_row) & (constrained < stop_row)] - start_row] = 0.0
            if stage.reset_displacements:
                for model, _ in staged.values():
                    model.reset_displacements()
            if approach == "II" and remove:
                for key, (model, _) in staged.items():
                    if model.continuum:
                        memorized[key] = model.state.x.array.reshape(-1, model.gdim).copy()
        finally:
            system.destroy()
    for model in models:
        model.stage = None
    return results


def _items(items: Sequence, where: str) -> tuple[list, list]:
    """The (part, cell group) pairs of a stage's list, and its supports, motions, loads and contact
    interfaces."""
    cells, switches = [], []
    for item in items:
        if isinstance(item, (Condition, ContactPair)):
            switches.append(item)
        elif isinstance(item, tuple) and len(item) == 2 and isinstance(item[1], str) and hasattr(item[0], "model"):
            cells.append(item)
        else:
            raise TypeError(f"solve_stages: {where}: {item!r} is none of a (part, cell group) pair, a support, "
                            "motion or load (what Scene.fix, prescribe, load and gravity return) or a contact "
                            "interface (what Scene.contact returns)")
    return cells, switches


def _switch(on: list, off: list) -> None:
    """The supports, motions, loads and interfaces that a stage adds (``on``) exist from now on — a
    support added holds its nodes where they are — and those it removes (``off``) do not."""
    for item in on:
        item.exists = True
        if isinstance(item, Condition) and item.kind == "support":
            item.holds = True
    for item in off:
        item.exists = False


class _StageFile:
    """What a staged run writes into its checkpoints besides the configuration (``staging`` in the
    file's meta, arrays ``staging_*``), and reads back at a restart."""

    def __init__(self, stage: int, results: list, meta: dict, arrays: dict, path: str):
        self.stage, self.results, self.meta, self.arrays, self.path = stage, results, meta, arrays, path

    @staticmethod
    def _mapping_arrays(prefix: str, mappings: list) -> dict:
        out = {}
        for q, mp in enumerate(mappings):
            out.update({f"{prefix}mapping{q}_X": mp.X, f"{prefix}mapping{q}_shift": mp.shift,
                        f"{prefix}mapping{q}_kind": np.asarray(mp.kind, dtype=str),
                        f"{prefix}mapping{q}_moved": np.asarray(mp.moved, dtype=bool)})
        return out

    @staticmethod
    def _mappings(arrays: dict, prefix: str, parts: list) -> list:
        return [Mapping(part, arrays[f"{prefix}mapping{q}_X"], arrays[f"{prefix}mapping{q}_shift"],
                        arrays[f"{prefix}mapping{q}_kind"].astype(str), arrays[f"{prefix}mapping{q}_moved"])
                for q, part in enumerate(parts)]

    @classmethod
    def attach(cls, system, models: list, approach: str, stages, index: int, results: list, mappings: list,
               start: np.ndarray, memorized: dict) -> tuple[dict, dict | None]:
        """(meta, arrays on rank 0) of stage ``index`` (collective): they do not change within it."""
        arrays = {}
        vec = system.new_vector()
        vec.array[:] = start
        for key, value in system.global_arrays({"staging_start": vec}).items():
            if key.startswith("staging_start"):
                arrays[key] = value
        vec.destroy()
        for j, model in enumerate(models):
            for key, value in model.staging_arrays().items():
                arrays[f"staging_part{j}_{key}"] = value
            if id(model) in memorized:
                arrays[f"staging_part{j}_Ue"] = model.to_global(memorized[id(model)])
        finished = []
        for k, res in enumerate(results):
            finished.append({"history": res.history.rows, "completed": res.completed, "message": res.message,
                             "totals": res.totals, "profiles": list(res.profiles),
                             "critical_points": [c.as_dict() for c in res.critical_points],
                             "mappings": [mp.part for mp in getattr(res, "mappings", [])]})
            for p, profile in enumerate(res.profiles.values()):
                arrays.update(profile.arrays(f"staging_result{k}_profile{p}_"))
            arrays.update(cls._mapping_arrays(f"staging_result{k}_", getattr(res, "mappings", [])))
        arrays.update(cls._mapping_arrays("staging_current_", mappings))
        meta = {"approach": approach, "stages": [st.name for st in stages], "stage": index, "finished": finished,
                "mappings": [mp.part for mp in mappings]}
        return meta, (arrays if system.comm.rank == 0 else None)

    @classmethod
    def read(cls, path: str, comm, approach: str, stages) -> "_StageFile":
        """The staged part of a checkpoint, checked against this run's approach and stages."""
        meta, arrays = read_checkpoint_on_all_ranks(path, comm)
        st = meta.get("staging")
        if st is None:
            raise CheckpointError(f"the checkpoint {path} was written by a run without stages: restart it with solve")
        if st["approach"] != approach:
            raise CheckpointError(f"the checkpoint {path} was computed with approach {st['approach']}, this run asks "
                                  f"for approach {approach}: a restart goes on with the same approach")
        k = int(st["stage"])
        names = [s.name for s in stages]
        if len(names) <= k or names[: k + 1] != st["stages"][: k + 1]:
            first = next((i for i in range(k + 1) if i >= len(names) or names[i] != st["stages"][i]), k)
            now = repr(names[first]) if first < len(names) else "no stage"
            raise CheckpointError(f"the checkpoint {path} is in stage {k + 1} '{st['stages'][k]}' of a run whose "
                                  f"stage {first + 1} is '{st['stages'][first]}', this run has {now} there: a "
                                  "restart goes on with the same stages up to the one it stopped in")
        from .result import History, Profile
        results = []
        for j, done in enumerate(st["finished"]):
            history = History()
            for row in done["history"]:
                history.append(row)
            profiles = {name: Profile.from_arrays(arrays, f"staging_result{j}_profile{p}_")
                        for p, name in enumerate(done["profiles"])}
            points = [CriticalPoint(**{**c, "bracket": tuple(c["bracket"])}) for c in done["critical_points"]]
            res = Result(history, done["completed"], done["message"], done["totals"], profiles, points)
            res.mappings = cls._mappings(arrays, f"staging_result{j}_", done["mappings"])
            results.append(res)
        return cls(k, results, st, arrays, path)

    def enter(self, models: list) -> tuple[dict, list]:
        """Restore the staged parts' element state; returns (U_e per staged solid, the stage's
        mappings)."""
        memorized = {}
        for j, model in enumerate(models):
            prefix = f"staging_part{j}_"
            mine = {k[len(prefix):]: v for k, v in self.arrays.items() if k.startswith(prefix)}
            try:
                model.set_staging_arrays(mine)
                if "Ue" in mine:
                    memorized[id(model)] = model.from_global(mine["Ue"]).reshape(-1, model.gdim)
            except ValueError as err:
                raise CheckpointError(f"the checkpoint {self.path} was written for another scene: {err}") from None
        return memorized, self._mappings(self.arrays, "staging_current_", self.meta["mappings"])

    def start(self, system) -> np.ndarray:
        """The force the stage started from (owned entries of ``system``)."""
        vec = system.new_vector()
        try:
            system.global_to_vector(self.arrays, "staging_start", vec)
        except (KeyError, ValueError) as err:
            raise CheckpointError(f"the checkpoint {self.path} was written for another scene: {err}") from None
        start = vec.array.copy()
        vec.destroy()
        return start


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
        if itf.slave_spec[0].model is not model or not itf.exists:
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
    # seed §3.1.2: the mapping puts new nodes along an interface onto their master, so they must be
    # slaves; a new face that is only a master has nothing to tell where it lies
    for itf in scene.interfaces:
        if itf.master_spec[0].model is not model or not itf.exists:
            continue
        surf = itf.master
        masters = surf.blocks[new_only[surf.blocks] & ~slave[surf.blocks]]
        count = model.comm.allreduce(len(masters), op=MPI.SUM)
        if count:
            where = np.concatenate(model.comm.allgather(surf.X[surf.local[np.isin(surf.blocks, masters)]]))
            raise ValueError(
                f"mapping of new continuum (approach II): {count} node(s) of the new cells along contact "
                f"'{itf.name}' (the first at {where[0].tolist()}) are masters there and slaves of no interface. "
                "Approach II maps new continuum onto the deformed configuration by projecting its nodes along "
                "a contact interface on their master, so they must be slave nodes (seed §3.1.2): put the slaves "
                f"on '{itf.master_spec[1]}' and the masters on '{itf.slave_spec[1]}', or use approach I")
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

"""Supports, prescribed motions and loads as handles that construction stages add or remove.

``Scene.fix``, ``prescribe``, ``load`` and ``gravity`` return a :class:`Condition`, as
``Scene.contact`` returns a :class:`~dolfinx_corot.contact.ContactPair`. Outside staged runs a
condition always exists. In a staged run (:mod:`dolfinx_corot.staging`) a condition that a stage
adds exists from that stage on, and one that a stage removes exists no more; the others exist
from the start. A stage starts in equilibrium and ramps to its own loads (λ: 0 → 1), so

* a support added by a stage holds its nodes where they are when it appears (not at zero);
* a support removed by a stage releases its reaction over the stage: the released nodes start
  loaded by the force the support exerted, which goes to zero with λ;
* a load or a weight added by a stage is applied over the stage and stays; one removed is taken
  off over the stage;
* a prescribed motion gives absolute values ū(λ) (or ū(λ, stage), a function of the stage's
  name): one added by a stage should start where its nodes are.
"""
from __future__ import annotations

KINDS = ("support", "motion", "load", "gravity")


class Condition:
    """One support, prescribed motion or load of a scene (``kind`` one of :data:`KINDS`) on group
    ``where`` of a part; ``exists`` (staged runs: whether it exists in the current stage) and
    ``holds`` (a support added by a stage: it holds its nodes where they are)."""

    def __init__(self, kind: str, label: str):
        if kind not in KINDS:
            raise ValueError(f"condition kind {kind!r} is not one of {KINDS}")
        self.kind = kind
        self.label = label
        self.exists = True
        self.holds = False

    def __repr__(self) -> str:
        return f"Condition({self.kind} {self.label})"

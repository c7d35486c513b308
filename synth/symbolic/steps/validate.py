"""``validate --engine symbolic`` with the steps in the BDD: the report without the per-situation loop.

:class:`~synth.symbolic.steps.sync.StepSync` explores SYNC over (steps, plant state) level
by level; :class:`~synth.symbolic.steps.reach.StepReach` gives it the interface the
report reads (:mod:`synth.symbolic.verdicts`), the findings' first nodes and traces
batched (:class:`~synth.symbolic.steps.batch.Batched`), so the report is the explicit
engine's, byte for byte.

:func:`validate_steps` runs on the models :func:`synth.symbolic.validate.choose_path`
sends here, and answers None when the exploration meets what the step encoding does not
cover (:class:`~synth.symbolic.steps.encoding.Unsupported`: an OR-divergence conflict, a
long search for stability, region moves reading other elements' orders, an initial
region that never settles); the caller then runs the per-situation engine.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> rs, p, g = load_model(_plants("../tests/data/home/no_restart.g7"), _plants("../tests/data/home/cylinder.rules"))
>>> from synth.symbolic.steps.encoding import anchors
>>> m = GrafcetMachine(g)
>>> sup = SymbolicSupervisor(p, rs.constraints, anchored=anchors(m, p))
>>> v = validate_steps(rs, p, g, sup, m, CompiledConstraints(p, rs.constraints))
>>> v is not None and (v.passed, v.stats["aggregated_states"])
(False, 7)
"""

from __future__ import annotations

from typing import Callable, Sequence

from synth.grafcet.language import Grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.plant.composition import Plant
from synth.plant.rules import RuleSet
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.steps.batch import Batched
from synth.symbolic.steps.encoding import Unsupported
from synth.symbolic.steps.reach import StepReach
from synth.symbolic.steps.sync import StepSync
from synth.symbolic.supervisor import SymbolicSupervisor
from synth.symbolic.ties import Settled
from synth.symbolic.verdicts import Model, empty_validation, engine_stats, validation_of
from synth.validation.result import Validation

__all__ = ["validate_steps", "explore_steps"]


def explore_steps(sup: SymbolicSupervisor, machine: GrafcetMachine,
                  progress: Callable[[str], None] | None = None) -> StepSync:
    """SYNC over (steps, plant state) explored; raises :class:`Unsupported` when the
    exploration meets what the step encoding does not cover, or the initial region never
    settles (the per-situation engine's report says so)."""
    s = StepSync(sup, machine, progress).explore()
    if s.initial == s.false:
        raise Unsupported("the initial region never settles")
    return s


def validate_steps(
    rs: RuleSet,
    p: Plant,
    g: Grafcet,
    sup: SymbolicSupervisor,
    machine: GrafcetMachine,
    oracle: CompiledConstraints,
    *,
    expert: bool = False,
    homes: Sequence[str] = (),
    progress: Callable[[str], None] | None = None,
) -> Validation | None:
    """The validation from :class:`StepSync` (``sup`` built with the step variables
    anchored: :func:`~synth.symbolic.steps.encoding.anchors`); None when the exploration
    gives up (see module docstring)."""
    model = Model(rs, p, g, machine, oracle)
    if not oracle.kept(p.initial):  # SUP is empty: nothing to explore
        counts = {"plant_states": p.size, "sync_states": 0, "aggregated_states": 0, "aggregated_transitions": 0}
        return empty_validation(model, expert=expert, homes=homes, sup_empty=True, counts=counts,
                                stats=engine_stats(sup.enc, 0))
    try:
        s = explore_steps(sup, machine, progress)
    except Unsupported:
        return None
    r = StepReach(s)
    r.settled = Settled(s.helper, oracle)  # first nodes as the explicit engine numbers them, ties included
    return validation_of(r, Batched(r), model, expert=expert, homes=homes,
                         engine_stats=lambda: engine_stats(sup.enc, s.situations))

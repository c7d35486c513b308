"""``synth validate --engine symbolic``: the symbolic SYNC, then the explicit diagnosis.

The symbolic engine decides everything that needs the whole SYNC (counts, coreachability,
blocking components, held states, prohibited orders, never-starts); the states a report
shows (those along each trace, the blocking components, the initial states) are then
made explicit :class:`~synth.validation.sync.Node` objects in a small
:class:`~synth.validation.sync.Sync`, and the existing diagnosis and output run on it
unchanged, so the texts and the JSON are those of the explicit engine
(:mod:`synth.symbolic.verdicts`, for both representations).

Which representation explores SYNC is :func:`choose_path`'s decision: the steps in the
BDD (:mod:`synth.symbolic.steps`) when the step encoding carries the Grafcet, else one
BDD per stable situation (:mod:`synth.symbolic.situations`). The step exploration may
still give up on what it meets while exploring (an OR-divergence conflict, a long search
for stability, an initial region that never settles: :func:`~synth.symbolic.steps.validate.validate_steps`
answers None), and the per-situation path runs.

Example
-------
>>> from synth.plant.composition import _plants
>>> v = validate_symbolic(_plants("../grafcets/tri_missing_order.g7"), _plants("tri.rules"))
>>> v.passed, v.stats["aggregated_states"]
(False, 30)
>>> from synth.validation.result import load_model
>>> _, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> choose_path(GrafcetMachine(g), p)
PathChoice(path=<SymbolicPath.SITUATIONS: 'situations'>, reason='timers')
"""

from __future__ import annotations

import gc
from contextlib import contextmanager
from dataclasses import dataclass
from enum import Enum
from pathlib import Path
from typing import Callable, Iterator, Sequence

from synth.errors import SynthError
from synth.grafcet.language import Grafcet, Semantics
from synth.grafcet.machine import GrafcetMachine
from synth.plant.composition import Plant
from synth.plant.rules import RuleSet
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.encoding import NodeBudget
from synth.symbolic.searches import OneByOne
from synth.symbolic.situations.reach import SituationReach
from synth.symbolic.situations.sync import SymbolicSync
from synth.symbolic.steps.encoding import anchors, unsupported
from synth.symbolic.steps.validate import validate_steps
from synth.symbolic.supervisor import SymbolicSupervisor
from synth.symbolic.ties import Settled
from synth.symbolic.verdicts import Model, empty_validation, engine_stats, validation_of
from synth.validation.result import Validation, home_conditions, load_model

__all__ = ["validate_symbolic", "validate_loaded", "choose_path", "SymbolicPath", "PathChoice"]


class SymbolicPath(Enum):
    """How the symbolic engine represents SYNC."""

    STEPS = "steps"  # the Grafcet's steps as BDD variables: one BDD per set of nodes
    SITUATIONS = "situations"  # the stable situations explicit: one BDD of plant states per situation


@dataclass(frozen=True)
class PathChoice:
    """The representation chosen for a model, and why."""

    path: SymbolicPath
    reason: str


def choose_path(machine: GrafcetMachine, p: Plant) -> PathChoice:
    """The step path when the step encoding carries the Grafcet
    (:func:`~synth.symbolic.steps.encoding.unsupported`), else the per-situation path."""
    why = unsupported(machine, p)
    if why is None:
        return PathChoice(SymbolicPath.STEPS, "the step encoding carries the Grafcet")
    return PathChoice(SymbolicPath.SITUATIONS, why)


def validate_symbolic(
    grafcet_path: str | Path,
    rules_path: str | Path,
    *,
    expert: bool = False,
    homes: Sequence[str] = (),
    max_nodes: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> Validation:
    """Run the whole method with the symbolic engine (see module docstring)."""
    rs, p, g = load_model(grafcet_path, rules_path)
    return validate_loaded(rs, p, g, expert=expert, homes=homes, max_nodes=max_nodes, progress=progress)


def validate_loaded(
    rs: RuleSet,
    p: Plant,
    g: Grafcet,
    *,
    expert: bool = False,
    homes: Sequence[str] = (),
    max_nodes: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> Validation:
    """:func:`validate_symbolic` on a rule set, its plant and a Grafcet already loaded."""
    if g.semantics is not Semantics.GRAFCET:
        raise SynthError(f"--semantics {g.semantics} runs on the explicit engine: use --engine explicit (or auto)")
    with _cyclic_gc_paused():
        return _validate_loaded(rs, p, g, expert=expert, homes=homes, max_nodes=max_nodes, progress=progress)


@contextmanager
def _cyclic_gc_paused() -> Iterator[None]:
    """Python's cyclic collector off for the run: the exploration keeps millions of
    long-lived objects (BDD handles, bundles) and makes no reference cycles, so each
    full collection would walk them all for nothing (5 % of ``par_12``)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def _validate_loaded(
    rs: RuleSet,
    p: Plant,
    g: Grafcet,
    *,
    expert: bool,
    homes: Sequence[str],
    max_nodes: int | None,
    progress: Callable[[str], None] | None,
) -> Validation:
    home_conditions(homes, p, g)  # input errors first, as the explicit engine reports them
    machine = GrafcetMachine(g)
    oracle = CompiledConstraints(p, rs.constraints)
    stepwise = choose_path(machine, p).path is SymbolicPath.STEPS  # the steps in the BDD: no loop over situations
    sup = SymbolicSupervisor(p, rs.constraints, NodeBudget(max_nodes), anchors(machine, p) if stepwise else None)
    if stepwise:
        passed = validate_steps(rs, p, g, sup, machine, oracle, expert=expert, homes=homes, progress=progress)
        if passed is not None:
            return passed
    ssync = SymbolicSync(sup, machine, progress=progress).explore()
    r = SituationReach(ssync)
    model = Model(rs, p, g, machine, oracle)

    def stats() -> dict[str, int | list[str]]:
        return engine_stats(ssync.enc, len(ssync.situations))

    if not ssync.situations or r.is_empty(ssync.initial):
        return empty_validation(model, expert=expert, homes=homes, sup_empty=not oracle.kept(p.initial),
                                counts={"plant_states": p.size, **r.stats()}, stats=stats())
    settled = Settled(ssync, oracle)  # first nodes as the explicit engine numbers them, ties included
    return validation_of(r, OneByOne(r, settled), model, expert=expert, homes=homes, engine_stats=stats)

"""The explicit validation engine: plant + constraints + Grafcet → SYNC explored state by
state, its analysis and diagnoses, as a :class:`~synth.validation.result.Validation`.

Which engine runs (``--engine``) is decided above both, in :mod:`synth.engines`.

Example
-------
>>> from synth.plant.composition import _plants
>>> v = validate(_plants("../grafcets/tri_missing_order.g7"), _plants("tri.rules"))
>>> v.passed, len(v.analysis.blocking), len(v.analysis.prohibited)
(False, 1, 0)
"""

from __future__ import annotations

import gc
from pathlib import Path
from typing import Callable, Sequence

from synth.grafcet.language import Grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.logic.expr import Expr, evaluate
from synth.plant.composition import Plant
from synth.plant.rules import Constraint, RuleSet
from synth.validation.analysis import analyse
from synth.validation.result import Validation, home_conditions, load_model
from synth.validation.sync import WATCHED_WIDE, WIDE, Exploration, Sync, Wide, synchronous_product

__all__ = ["validate", "validate_loaded", "home_states", "explore"]


def home_states(sync: Sync, conditions: Sequence[Expr]) -> frozenset[int]:
    """The home states: the initial aggregated states, the states that differ from one only
    by elapsed timers (the initial situation after waiting: docs/method.md, "Home states"),
    and every state where one of ``conditions`` holds (read on its active steps and its
    plant values)."""
    homes = set(sync.initial)
    start = {(n.situation.steps, n.situation.stored, n.plant) for n in (sync.nodes[i] for i in sync.initial)}
    plants = {q for _, _, q in start}  # read first: most nodes are elsewhere
    homes.update(i for i, n in enumerate(sync.nodes)
                 if n.plant in plants and (n.situation.steps, n.situation.stored, n.plant) in start)
    for i, n in enumerate(sync.nodes if conditions else ()):
        val = sync.plant.valuation(n.plant)
        steps = set(n.situation.step_variables)

        def value(name: str) -> bool:
            return name in steps if name not in val else val[name]

        if any(evaluate(c, value) for c in conditions):
            homes.add(i)
    return frozenset(homes)


def explore(p: Plant, constraints: Sequence[Constraint], machine: GrafcetMachine, how: Exploration = Exploration()) -> Sync:
    """SYNC: state by state while at most :data:`~synth.validation.sync.WIDE` states wait
    (a narrow SYNC, a sequence, a small station), then a frontier at a time
    (:func:`synth.validation.frontier.explore_wide`, imported only then); ``how.watch(met,
    waiting)``: the aggregated states met and those waiting, after each state or frontier
    expanded (it may raise to stop the run: ``validate --engine auto``; the frontier then
    takes over past :data:`~synth.validation.sync.WATCHED_WIDE`)."""
    try:
        return synchronous_product(p, constraints, machine, how, wide=WIDE if how.watch is None else WATCHED_WIDE)
    except Wide as wide:
        from synth.validation.frontier import explore_wide

        return explore_wide(p, constraints, machine, how, partial=wide.partial)


def validate(
    grafcet_path: str | Path,
    rules_path: str | Path,
    *,
    expert: bool = False,
    homes: Sequence[str] = (),
    max_states: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Validation:
    """Run the whole method on a Grafcet and a plant; ``homes`` are ``--home`` conditions."""
    rs, p, g = load_model(grafcet_path, rules_path)
    return validate_loaded(rs, p, g, expert=expert, homes=homes, how=Exploration(max_states, progress))


def validate_loaded(
    rs: RuleSet,
    p: Plant,
    g: Grafcet,
    *,
    expert: bool = False,
    homes: Sequence[str] = (),
    how: Exploration = Exploration(),
) -> Validation:
    """:func:`validate` on a rule set, its plant and a Grafcet already loaded, SYNC explored
    as ``how`` says (its limit, progress and watch: :func:`explore`)."""
    conditions = home_conditions(homes, p, g)
    machine = GrafcetMachine(g)
    # the run's objects (nodes, edges, situations, their indexes) make no reference cycles:
    # the collector's passes over them free nothing (4-7 % of a run of 10^4 SYNC states)
    collecting = gc.isenabled()
    gc.disable()
    try:
        sync = explore(p, rs.constraints, machine, how)
        sup_empty = not sync.oracle.kept(p.initial)  # the constraints compiled once
        analysis = analyse(sync, home_states(sync, conditions))
        if not (analysis.blocking or analysis.never_starts or analysis.prohibited):  # a passing run imports no diagnosis
            return Validation(rs, p, g, sync, analysis, {}, expert, sup_empty, tuple(homes), None)
        from synth.validation.diagnosis import diagnose_all

        diagnoses, never, prohibitions = diagnose_all(sync, analysis, expert=expert)
        return Validation(rs, p, g, sync, analysis, diagnoses, expert, sup_empty, tuple(homes), never, prohibitions)
    finally:
        if collecting:
            gc.enable()

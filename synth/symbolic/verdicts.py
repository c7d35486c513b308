"""The recipe "explored symbolic SYNC → :class:`~synth.validation.result.Validation`", once
for both representations (:class:`~synth.symbolic.interface.SymbolicGraph`).

On the BDDs: the homes (initial nodes, the initial situation once its timers elapsed,
``--home`` conditions), coreachability, the stuck nodes and their terminal components,
held nodes with a prohibited order (once per set of active steps), the prohibited orders
and the OR-divergence conflicts; each finding's first node and trace (a
:class:`~synth.symbolic.interface.Finder`: one target at a time, or batched). Then the
nodes a report shows are made explicit (:class:`~synth.symbolic.explicit.ExplicitNodes`,
in the order the explicit engine's report lists them) and handed to the explicit
diagnosis (:func:`~synth.validation.diagnosis.diagnose_all`) unchanged, so the texts and
the JSON are the explicit engine's.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.symbolic.validate import validate_symbolic
>>> v = validate_symbolic(_plants("../tests/data/home/no_restart.g7"), _plants("../tests/data/home/cylinder.rules"))
>>> v.passed, len(v.analysis.blocking), v.stats["aggregated_states"]  # the step path, through validation_of
(False, 1, 7)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

from synth.grafcet.language import Grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.plant.composition import Plant
from synth.plant.rules import RuleSet
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.encoding import PlantEncoding, live_nodes
from synth.symbolic.explicit import ExplicitNodes
from synth.symbolic.interface import Finder, Key, M, PathKey, S, Steps, SymbolicGraph
from synth.symbolic.searches import MAX_LISTED, terminal_components
from synth.validation.analysis import Analysis
from synth.validation.conflicts import Conflict
from synth.validation.diagnosis import diagnose_all
from synth.validation.result import Validation, home_conditions
from synth.validation.sync import Sync

__all__ = ["Model", "validation_of", "empty_validation", "home_nodes", "engine_stats", "MAX_HELD_ASKED"]

MAX_HELD_ASKED = 1000
"""Above this many listed nodes the held set is computed at once (else node by node)."""

EngineStats = dict[str, int | list[str]]


@dataclass(frozen=True)
class Model:
    """What a validation reads: the rules, their plant, the Grafcet, its machine, SUP's oracle."""

    rs: RuleSet
    p: Plant
    g: Grafcet
    machine: GrafcetMachine
    oracle: CompiledConstraints


def engine_stats(enc: PlantEncoding, situations: int) -> EngineStats:
    """The engine's statistics: live BDD nodes, stable situations, and the elements in the
    BDD variable order (:func:`~synth.symbolic.encoding.element_order`)."""
    elements = enc.plant.elements
    return {"bdd_nodes": live_nodes(enc.engine, exact=True), "situations": situations,
            "variable_order": [elements[a].name for a in enc.order]}


def empty_validation(model: Model, *, expert: bool, homes: Sequence[str], sup_empty: bool, counts: dict[str, int],
                     stats: EngineStats) -> Validation:
    """The validation of a SYNC without a node (SUP empty, or the initial region never settles)."""
    sync = Sync(model.p, model.oracle, model.machine)
    analysis = Analysis((), {}, {}, frozenset(), (), {})
    return Validation(model.rs, model.p, model.g, sync, analysis, {}, expert, sup_empty, tuple(homes), None,
                      counts=counts, reached_steps=frozenset(), engine_stats=stats)


def home_nodes(g: SymbolicGraph[S, M], texts: Sequence[str], model: Model) -> S:
    """The home nodes: the initial ones (and the initial situation once its timers
    elapsed), and those where a ``--home`` condition holds."""
    return g.join([g.waited(), *(g.where(c) for c in home_conditions(texts, model.p, model.g))])


def validation_of(g: SymbolicGraph[S, M], finder: Finder[S], model: Model, *, expert: bool, homes: Sequence[str],
                  engine_stats: Callable[[], EngineStats]) -> Validation:
    """The validation of the explored SYNC ``g`` (see the module docstring); ``finder``
    answers the first nodes and traces, ``engine_stats`` is read last (live BDD nodes)."""
    ex = ExplicitNodes(g.numbering, model.oracle)
    counts = {"plant_states": model.p.size, **g.stats()}
    initial = tuple(ex.node(k) for k in g.listed(g.initial, MAX_LISTED))
    home = home_nodes(g, homes, model)
    back = g.backward(home)
    stuck = g.minus(g.reached, back)
    proh_sets = g.prohibited()
    held: S | None = g.held() if proh_sets else None  # else only the listed nodes are asked

    # blocking: held with a prohibited order, once per set of active steps; terminal components
    by_steps: dict[Steps, S] = {}
    for (steps, _), u in proh_sets.items():
        assert held is not None
        v = g.meet(u, held)
        if not g.is_empty(v):
            by_steps[steps] = g.union(by_steps.get(steps, g.empty), v)
    comps = [c for c in terminal_components(g, stuck) if not g.only_steps(c, by_steps)]
    blocking_sets = list(by_steps.values()) + comps
    conflicts = g.conflicts()
    firsts_of = finder.firsts(blocking_sets + list(proh_sets.values()) + [sources for sources, _, _, _ in conflicts])
    found: list[tuple[int, PathKey, Key, list[Key]]] = [
        (depth, path, key, g.listed(u, MAX_LISTED)) for u, (key, depth, path) in zip(blocking_sets, firsts_of)]
    firsts: dict[Key, tuple[int, PathKey]] = {}
    for key, depth, path in firsts_of[len(blocking_sets):len(blocking_sets) + len(proh_sets)]:
        firsts[key] = (depth, path)
    conflict_keys = [key for key, _, _ in firsts_of[len(blocking_sets) + len(proh_sets):]]
    wanted = list(dict.fromkeys([key for _, _, key, _ in found] + list(firsts) + conflict_keys))
    paths = dict(zip(wanted, finder.traces(wanted)))

    blocking, components, traces, no_return = ex.blocking(found, lambda key: ex.trace_of(paths[key]),
                                                          lambda key: g.contains(back, key))
    ordered = sorted(firsts, key=lambda k: firsts[k])  # prohibited orders: the first node meeting each
    prohibited = [ex.node(k) for k in ordered]
    for i, k in zip(prohibited, ordered):
        traces.setdefault(i, ex.trace_of(paths[k]))
    found_conflicts: list[Conflict] = []
    for key, (_, event, step, names) in zip(conflict_keys, conflicts):
        i = ex.node(key)
        traces.setdefault(i, ex.trace_of(paths[key]))
        found_conflicts.append(Conflict(i, event, step, names))
    never = g.never_leaves()
    if never:  # the explicit diagnosis reads the situation of every node: one node per situation
        for key in g.one_per_situation():
            ex.node(key)
    sync = Sync(model.p, model.oracle, model.machine, tuple(ex.nodes), tuple(ex.edges), initial,
                tuple(found_conflicts), counts["sync_states"])
    keys = {v: k for k, v in ex.index.items()}
    listed = [keys[i] for i in range(len(ex.nodes))]
    if held is None and len(listed) > MAX_HELD_ASKED:
        held = g.held()
    analysis = Analysis(
        tuple(blocking), traces, no_return,
        frozenset(i for i, k in enumerate(listed) if g.contains(back, k)),
        tuple(prohibited), components,
        frozenset(i for i, k in enumerate(listed) if g.contains(home, k)),
        frozenset(i for i, k in enumerate(listed) if (g.contains(held, k) if held is not None else g.is_held(k))),
        never,
    )
    diagnoses, never_d, prohibitions = diagnose_all(sync, analysis, expert=expert)
    return Validation(model.rs, model.p, model.g, sync, analysis, diagnoses, expert, not model.oracle.kept(model.p.initial),
                      tuple(homes), never_d, prohibitions, counts=counts, reached_steps=g.reached_steps(),
                      engine_stats=engine_stats())

"""``synth validate --engine symbolic``: the symbolic SYNC, then the explicit diagnosis.

The symbolic engine decides everything that needs the whole SYNC (counts, coreachability,
blocking components, held states, prohibited orders, never-starts); the states a report
shows (those along each trace, the blocking components, the initial states) are then
made explicit :class:`~synth.validation.sync.Node` objects in a small
:class:`~synth.validation.sync.Sync`, and the existing diagnosis and output run on it
unchanged, so the texts and the JSON are those of the explicit engine.

Example
-------
>>> from synth.plant.composition import _plants
>>> v = validate_symbolic(_plants("../grafcets/tri_missing_order.g7"), _plants("tri.rules"))
>>> v.passed, v.stats["aggregated_states"]
(False, 30)
"""

from __future__ import annotations

import gc
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator, Sequence

from synth.errors import SynthError
from synth.grafcet.language import Grafcet, Semantics
from synth.grafcet.machine import GrafcetMachine
from synth.logic.bdd import Function
from synth.logic.expr import evaluate
from synth.plant.composition import Plant
from synth.plant.rules import RuleSet
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.encoding import NodeBudget, live_nodes
from synth.symbolic.situations.reach import (
    MAX_LISTED,
    coreachable,
    first_node,
    held_nodes,
    node_held,
    listed,
    prohibited_nodes,
    stuck_nodes,
    terminal_components,
)
from synth.symbolic.explicit import ExplicitNodes, Key, PathKey
from synth.symbolic.ties import Settled
from synth.symbolic.steps.encoding import anchors, unsupported
from synth.symbolic.steps.validate import validate_steps
from synth.symbolic.supervisor import SymbolicSupervisor
from synth.symbolic.situations.graph import NodeSet
from synth.symbolic.situations.sync import SymbolicSync
from synth.validation.analysis import Analysis
from synth.validation.diagnosis import diagnose_all
from synth.validation.conflicts import Conflict
from synth.validation.sync import Sync
from synth.validation.result import Validation, home_conditions, load_model

__all__ = ["validate_symbolic", "validate_loaded"]



def _homes(ssync: SymbolicSync, texts: Sequence[str], p: Plant, g: Grafcet) -> NodeSet:
    homes: NodeSet = dict(ssync.initial)
    engine = ssync.engine
    for s0, u in ssync.initial.items():  # the initial situation after waiting: its timers elapsed
        key = (ssync.situations[s0].steps, ssync.situations[s0].stored)
        for s, r in enumerate(ssync.regions):
            if s != s0 and (ssync.situations[s].steps, ssync.situations[s].stored) == key:
                hit = u & r.nodes
                if hit != engine.false:
                    homes[s] = homes.get(s, engine.false) | hit
    conditions = home_conditions(texts, p, g)
    if not conditions:
        return homes
    for s, r in enumerate(ssync.regions):
        steps = set(ssync.situations[s].step_variables)

        def value(name: str, steps: set[str] = steps) -> Function:
            return engine.var(name) if name in p.owner else (engine.true if name in steps else engine.false)

        hit = engine.false
        for c in conditions:
            v = evaluate(c, value)  # a condition folding to a constant (`1`, `X0 & 0`) is a bool
            hit |= (engine.true if v else engine.false) if isinstance(v, bool) else v
        hit &= r.nodes
        if hit != engine.false:
            homes[s] = homes.get(s, engine.false) | hit
    return homes


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
    sup_empty = not oracle.kept(p.initial)
    stepwise = unsupported(machine, p) is None  # the steps in the BDD: no loop over situations
    sup = SymbolicSupervisor(p, rs.constraints, NodeBudget(max_nodes), anchors(machine, p) if stepwise else None)
    if stepwise:
        passed = validate_steps(rs, p, g, sup, machine, oracle, expert=expert, homes=homes, progress=progress)
        if passed is not None:
            return passed
    ssync = SymbolicSync(sup, machine, progress=progress).explore()
    ex = ExplicitNodes(ssync, oracle)
    false = ssync.false
    stats = {
        "plant_states": p.size,
        "sync_states": ssync.sync_states,
        "aggregated_states": ssync.aggregated_states,
        "aggregated_transitions": ssync.aggregated_transitions,
    }
    if not ssync.situations or all(u == false for u in ssync.initial.values()):
        sync = Sync(p, oracle, machine)
        analysis = Analysis((), {}, {}, frozenset(), (), {})
        return Validation(rs, p, g, sync, analysis, {}, expert, sup_empty, tuple(homes), None,
                          counts=stats, reached_steps=frozenset(), engine_stats=_stats(ssync))
    initial_keys = listed(ssync, ssync.initial)
    initial = tuple(ex.node(k) for k in initial_keys)
    settled = Settled(ssync, oracle)  # first nodes as the explicit engine numbers them, ties included
    home = _homes(ssync, homes, p, g)
    back = coreachable(ssync, home)
    stuck = stuck_nodes(ssync, back)
    proh_sets = prohibited_nodes(ssync)
    held: NodeSet | None = held_nodes(ssync) if proh_sets else None  # else only the listed nodes are asked

    # blocking: held with a prohibited order, once per set of steps; terminal components
    found: list[tuple[int, PathKey, Key, list[Key]]] = []
    by_steps: dict[tuple[str, ...], NodeSet] = {}
    for (steps, _), u in proh_sets.items():
        for s, v in u.items():
            assert held is not None
            v &= held.get(s, false)
            if v != false:
                d = by_steps.setdefault(steps, {})
                d[s] = d.get(s, false) | v
    for steps, u in by_steps.items():
        s, local, depth, path = first_node(ssync, u, settled)
        found.append((depth, path, (s, local), listed(ssync, u, MAX_LISTED)))
    for comp in terminal_components(ssync, stuck):
        if all(ssync.situations[s].steps in by_steps for s in comp):
            continue
        s, local, depth, path = first_node(ssync, comp, settled)
        found.append((depth, path, (s, local), listed(ssync, comp, MAX_LISTED)))
    blocking, components, traces, no_return = ex.blocking(found, ex.trace, lambda key: _is_in(ssync, back, key))
    # prohibited orders: the first node meeting each (steps, event)
    firsts: dict[Key, tuple[int, PathKey]] = {}
    for u in proh_sets.values():
        s, local, depth, path = first_node(ssync, u, settled)
        firsts[(s, local)] = (depth, path)
    prohibited = [ex.node(k) for k in sorted(firsts, key=lambda k: firsts[k])]
    for i in prohibited:
        keys = {v: k for k, v in ex.index.items()}
        traces.setdefault(i, ex.trace(keys[i]))
    conflicts: list[Conflict] = []
    for s, sources, event, step, names in ssync.conflicts:
        cs, local, _, _ = first_node(ssync, {s: sources}, settled)
        i = ex.node((cs, local))
        traces.setdefault(i, ex.trace((cs, local)))
        conflicts.append(Conflict(i, event, step, names))
    first_steps = ssync.situations[initial_keys[0][0]].steps
    never = all(sit.steps == first_steps for sit in ssync.situations)
    if never:  # the explicit diagnosis reads the situation of every node: one node per situation
        _one_per_situation(ssync, ex)
    sync = Sync(p, oracle, machine, tuple(ex.nodes), tuple(ex.edges), initial, tuple(conflicts), stats["sync_states"])
    keys = {v: k for k, v in ex.index.items()}
    analysis = Analysis(
        tuple(blocking), traces, no_return,
        frozenset(i for i in range(len(ex.nodes)) if _is_in(ssync, back, keys[i])),
        tuple(prohibited), components,
        frozenset(i for i in range(len(ex.nodes)) if _is_in(ssync, home, keys[i])),
        _held_listed(ssync, held, ex, keys),
        never,
    )
    diagnoses, never_d, prohibitions = diagnose_all(sync, analysis, expert=expert)
    reached = frozenset(st for sit in ssync.situations for st in sit.steps)
    return Validation(rs, p, g, sync, analysis, diagnoses, expert, sup_empty, tuple(homes), never_d, prohibitions,
                      counts=stats, reached_steps=reached, engine_stats=_stats(ssync))


def _held_listed(ssync: SymbolicSync, held: NodeSet | None, ex: ExplicitNodes, keys: dict[int, Key]) -> frozenset[int]:
    """The listed nodes that are held: read from ``held`` when it was computed (a
    prohibited order made it necessary) or when many nodes are listed, else asked node by
    node (a forward search that stops at the first change of active steps)."""
    if held is None and len(ex.nodes) > _HELD_ONE_BY_ONE:
        held = held_nodes(ssync)
    if held is not None:
        return frozenset(i for i in range(len(ex.nodes)) if _is_in(ssync, held, keys[i]))
    return frozenset(i for i in range(len(ex.nodes)) if node_held(ssync, *keys[i]))


_HELD_ONE_BY_ONE = 1000


def _is_in(ssync: SymbolicSync, u: NodeSet, key: Key) -> bool:
    s, local = key
    return s in u and (u[s] & ssync.enc.state(local)) != ssync.false


def _one_per_situation(ssync: SymbolicSync, ex: ExplicitNodes) -> None:
    for s, r in enumerate(ssync.regions):
        if r.nodes != ssync.false:
            ex.node((s, ssync.enc.one(r.nodes)))


def _stats(ssync: SymbolicSync) -> dict[str, int | list[str]]:
    """The engine's statistics: live BDD nodes, stable situations, and the elements in
    the BDD variable order (:func:`~synth.symbolic.encoding.element_order`)."""
    elements = ssync.plant.elements
    return {"bdd_nodes": live_nodes(ssync.enc.engine), "situations": len(ssync.situations),
            "variable_order": [elements[a].name for a in ssync.enc.order]}

"""``validate --engine symbolic`` with the steps in the BDD: the report without the per-situation loop.

:class:`~synth.symbolic.steps.sync.StepSync` explores SYNC over (steps, plant state) level
by level; :class:`~synth.symbolic.steps.reach.StepReach` finds what the report shows:
coreachability from the homes, stuck nodes and their terminal components, held nodes,
prohibited orders, each finding's first node (distance, then the explicit exploration's
order) and its shortest trace. Those nodes are made explicit by
:class:`~synth.symbolic.explicit.ExplicitNodes` and handed to the existing diagnosis and
output, in the order :mod:`synth.symbolic.validate` asks for them, so the report is the
explicit engine's, byte for byte.

:func:`validate_steps` answers None when the model is outside the step encoding
(:func:`~synth.symbolic.steps.encoding.unsupported`, or :class:`~synth.symbolic.steps.encoding.Unsupported`
met while exploring: an OR-divergence conflict, a long search for stability, region moves
reading other elements' orders, an empty SUP); the caller then runs the per-situation
engine.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine, Situation
>>> from synth.sup.constraints import CompiledConstraints
>>> from synth.symbolic.steps.encoding import anchors
>>> from synth.symbolic.supervisor import SymbolicSupervisor
>>> rs, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> m = GrafcetMachine(g)
>>> sup = SymbolicSupervisor(p, rs.constraints, anchored=anchors(m, p))
>>> validate_steps(rs, p, g, sup, m, CompiledConstraints(p, rs.constraints)) is None  # timers: per situation
True
"""

from __future__ import annotations

from typing import Callable, Sequence

from synth.grafcet.language import Grafcet, step_variable
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.logic.bdd import Function
from synth.logic.expr import evaluate
from synth.plant.composition import Plant
from synth.plant.rules import RuleSet
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.encoding import live_nodes
from synth.symbolic.explicit import ExplicitNodes, Key, PathKey
from synth.symbolic.ties import Settled
from synth.symbolic.steps.batch import Findings
from synth.symbolic.steps.reach import StepReach
from synth.symbolic.steps.sync import StepSync
from synth.symbolic.steps.encoding import Unsupported, unsupported
from synth.symbolic.supervisor import SymbolicSupervisor
from synth.validation.analysis import Analysis, Trace
from synth.validation.diagnosis import diagnose_all
from synth.validation.result import Validation, home_conditions
from synth.validation.sync import Sync

__all__ = ["validate_steps", "MAX_HELD_ASKED"]

MAX_HELD_ASKED = 1000
"""Above this many listed nodes the held set is computed at once (else node by node)."""


def _homes(s: StepSync, texts: Sequence[str], p: Plant, g: Grafcet) -> Function:
    """The initial nodes, and the nodes where a ``--home`` condition holds (a step variable
    is the step's BDD variable; no timers here, so no elapsed initial situation)."""
    engine = s.engine
    variables = {step_variable(st): st for st in s.steps.steps}

    def value(name: str) -> Function:
        if name in p.owner:
            return engine.var(name)
        return s.steps.var(variables[name]) if name in variables else engine.false

    hit = engine.false
    for c in home_conditions(texts, p, g):
        v = evaluate(c, value)  # a condition folding to a constant (`1`, `X0 & 0`) is a bool
        hit |= (engine.true if v else engine.false) if isinstance(v, bool) else v
    return s.initial | (hit & s.nodes)


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
    """The validation of a passing model from :class:`StepSync` (``sup`` built with the
    step variables anchored: :func:`~synth.symbolic.steps.encoding.anchors`); None when the
    per-situation engine must run (see module docstring)."""
    if unsupported(machine, p) is not None:
        return None
    if not oracle.kept(p.initial):  # SUP is empty: nothing to explore
        sync = Sync(p, oracle, machine)
        stats = {"plant_states": p.size, "sync_states": 0, "aggregated_states": 0, "aggregated_transitions": 0}
        return Validation(rs, p, g, sync, Analysis((), {}, {}, frozenset(), (), {}), {}, expert, True, tuple(homes), None,
                          counts=stats, reached_steps=frozenset(), engine_stats=_engine_stats(sup, 0))
    try:
        s = StepSync(sup, machine, progress).explore()
    except Unsupported:
        return None
    if s.initial == s.false:  # the initial region never settles: the per-situation engine's report
        return None
    false = s.false
    r = StepReach(s)
    r.settled = Settled(s.helper, oracle)  # first nodes as the explicit engine numbers them, ties included
    ex = ExplicitNodes(s.helper, oracle)
    initial_keys = r.listed(s.initial)
    initial = tuple(ex.node(k) for k in initial_keys)
    home = _homes(s, homes, p, g)
    back = s.backward(home)
    stuck = s.nodes & ~back
    proh_sets = r.prohibited()
    held = r.held() if proh_sets else None

    by_steps: dict[tuple[str, ...], Function] = {}
    for (steps, _), u in proh_sets.items():
        assert held is not None
        v = u & held
        if v != false:
            by_steps[steps] = by_steps.get(steps, false) | v
    covered = s.steps.engine.disjunction(s.steps.cube(Situation(steps)) for steps in by_steps)
    comps = [c for c in r.terminal_components(stuck)
             if (r.steps_of(c) & ~covered) != false]  # else every situation of it has a prohibited order
    blocking_sets = list(by_steps.values()) + comps
    # every finding's first node, then every trace, in one pass each (steps.batch)
    search = Findings(r, blocking_sets + list(proh_sets.values()))
    firsts_of = search.firsts
    found: list[tuple[int, PathKey, Key, list[Key]]] = [
        (depth, path, key, r.listed(u)) for u, (key, depth, path) in zip(blocking_sets, firsts_of)]
    firsts: dict[Key, tuple[int, PathKey]] = {}
    for key, depth, path in firsts_of[len(blocking_sets):]:
        firsts[key] = (depth, path)
    wanted = list(dict.fromkeys([key for _, _, key, _ in found] + list(firsts)))
    paths = dict(zip(wanted, search.traces(wanted)))
    blocking, components, traces, no_return = ex.blocking(found, lambda key: ex.trace_of(paths[key]),
                                                          lambda key: (r.cube(key) & back) != false)
    ordered = sorted(firsts, key=lambda k: firsts[k])
    prohibited = [ex.node(k) for k in ordered]
    for i, k in zip(prohibited, ordered):
        traces.setdefault(i, ex.trace_of(paths[k]))
    assert s.initial_situation is not None
    never = (r.steps_of(s.nodes) & ~s.steps.cube(s.initial_situation)) == false  # situations are active steps here
    if never:  # the explicit diagnosis reads the situation of every node: one node per situation
        for sit in r.situations_of(s.nodes):
            ex.node((s.helper.situation(sit), s.enc.one(r.within(s.nodes, sit))))
    stats = {
        "plant_states": p.size,
        "sync_states": s.sync_states,
        "aggregated_states": s.aggregated_states,
        "aggregated_transitions": s.edge_count,
    }
    sync = Sync(p, oracle, machine, tuple(ex.nodes), tuple(ex.edges), initial, (), stats["sync_states"])
    keys = _keys(ex)
    cubes = [r.cube(keys[i]) for i in range(len(ex.nodes))]
    if held is None and len(cubes) > MAX_HELD_ASKED:
        held = r.held()
    analysis = Analysis(
        tuple(blocking), traces, no_return,
        frozenset(i for i, u in enumerate(cubes) if (u & back) != false),
        tuple(prohibited), components,
        frozenset(i for i, u in enumerate(cubes) if (u & home) != false),
        frozenset(i for i, u in enumerate(cubes) if ((u & held) != false if held is not None else s.held(u))),
        never,
    )
    diagnoses, never_d, prohibitions = diagnose_all(sync, analysis, expert=expert)
    return Validation(rs, p, g, sync, analysis, diagnoses, expert, False, tuple(homes), never_d, prohibitions,
                      counts=stats, reached_steps=s.reached_steps(), engine_stats=_engine_stats(sup, s.situations))


def _engine_stats(sup: SymbolicSupervisor, situations: int) -> dict[str, int | list[str]]:
    """As :func:`synth.symbolic.validate._stats`: live BDD nodes, stable situations, element order."""
    elements = sup.plant.elements
    return {"bdd_nodes": live_nodes(sup.enc.engine), "situations": situations,
            "variable_order": [elements[a].name for a in sup.enc.order]}


def _keys(ex: ExplicitNodes) -> dict[int, Key]:
    return {v: k for k, v in ex.index.items()}


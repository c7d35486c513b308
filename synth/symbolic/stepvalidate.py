"""``validate --engine symbolic`` with the steps in the BDD: the verdict without the per-situation loop.

:class:`~synth.symbolic.stepsync.StepSync` explores SYNC over (steps, plant state) level
by level; this module decides from it what the report needs when the model passes:
the counts, the coreachability of every node (a backward fixpoint from the homes), the
absence of prohibited orders, and the few explicit nodes a passing report shows (the
initial nodes), built by :class:`~synth.symbolic.explicit.ExplicitNodes` and handed to
the existing diagnosis and output, as :mod:`synth.symbolic.validate` does.

A report that shows more — a blocking component, a prohibited order, a Grafcet that
never leaves its initial steps, more than :data:`MAX_HELD_ASKED` initial nodes — needs
the traces, the onion rings and the tie-breaking by exploration order of the
per-situation engine: :func:`validate_steps` then answers None and the caller runs that
engine (so does a model :mod:`synth.symbolic.steps` does not cover). Reports are
therefore those of the explicit engine, byte for byte, on either path.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> from synth.sup.constraints import CompiledConstraints
>>> from synth.symbolic.steps import anchors
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
from synth.grafcet.machine import GrafcetMachine
from synth.logic.bdd import Function
from synth.logic.expr import evaluate
from synth.plant.composition import Plant
from synth.plant.rules import RuleSet
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.encoding import Copy, live_nodes
from synth.symbolic.explicit import ExplicitNodes
from synth.symbolic.reachability import MAX_LISTED
from synth.symbolic.stepsync import StepSync
from synth.symbolic.steps import Unsupported, unsupported
from synth.symbolic.supervisor import SymbolicSupervisor
from synth.validation.analysis import Analysis
from synth.validation.diagnosis import diagnose_all
from synth.validation.result import Validation, home_conditions
from synth.validation.sync import Sync

__all__ = ["validate_steps", "MAX_HELD_ASKED"]

MAX_HELD_ASKED = 1000
"""Above this many listed nodes the per-situation engine computes the held set at once."""


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
        hit |= evaluate(c, value)
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
    step variables anchored: :func:`~synth.symbolic.steps.anchors`); None when the
    per-situation engine must run (see module docstring)."""
    if unsupported(machine, p) is not None:
        return None
    try:
        s = StepSync(sup, machine, progress).explore()
    except Unsupported:
        return None
    false = s.false
    home = _homes(s, homes, p, g)
    back = s.backward(home)
    if (s.nodes & ~back) != false or (s.nodes & s.refused) != false:
        return None  # blocking or prohibited orders: traces and components per situation
    assert s.initial_situation is not None
    first = s.steps.cube(s.initial_situation)
    if (s.enc.exists(s.nodes, Copy.CURRENT) & ~first) == false:
        return None  # never leaves its initial steps: one node per situation is shown
    initial_states = list(s.enc.states(s.steps.exists(s.initial, Copy.CURRENT), MAX_LISTED))
    if len(initial_states) > MAX_HELD_ASKED:
        return None
    s.helper.situation(s.initial_situation)  # situation 0 of the explicit nodes
    ex = ExplicitNodes(s.helper, oracle)
    initial = tuple(ex.node((0, local)) for local in initial_states)
    cubes = [first & s.enc.state(local) for local in initial_states]
    stats = {
        "plant_states": p.size,
        "sync_states": s.sync_states,
        "aggregated_states": s.aggregated_states,
        "aggregated_transitions": s.edge_count,
    }
    sync = Sync(p, oracle, machine, tuple(ex.nodes), (), initial, (), stats["sync_states"])
    analysis = Analysis(
        (), {}, {},
        frozenset(i for i, u in enumerate(cubes) if (u & back) != false),
        (), {},
        frozenset(i for i, u in enumerate(cubes) if (u & home) != false),
        frozenset(i for i, u in enumerate(cubes) if s.held(u)),
        False,
    )
    diagnoses, never_d, prohibitions = diagnose_all(sync, analysis, expert=expert)
    elements = p.elements
    engine_stats: dict[str, int | list[str]] = {
        "bdd_nodes": live_nodes(s.engine), "situations": s.situations,
        "variable_order": [elements[a].name for a in s.enc.order]}
    return Validation(rs, p, g, sync, analysis, diagnoses, expert, not oracle.kept(p.initial), tuple(homes), never_d,
                      prohibitions, counts=stats, reached_steps=s.reached_steps(), engine_stats=engine_stats)


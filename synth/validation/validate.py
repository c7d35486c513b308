"""``synth validate``: plant + constraints + Grafcet → verdict, problems, traces, diagnoses.

The result is a frozen :class:`Validation`; its JSON and text are in
:mod:`synth.output.result`, the HTML report in :mod:`synth.output.html`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Sequence

from synth.validation.analysis import Analysis, analyse
from synth.plant.composition import Plant, plant
from synth.errors import InputError, close_names
from synth.logic.expr import Edge as ExprEdge, Expr, evaluate, names
from synth.syntax import parse_expression
from synth.grafcet.language import Grafcet
from synth.grafcet.language_check import load_grafcet
from synth.plant.rules import RuleSet
from synth.plant.rules_check import load_rules
from synth.grafcet.machine import GrafcetMachine
from synth.sup.constraints import CompiledConstraints
from synth.validation.sync import Edge, Sync, synchronous_product

if TYPE_CHECKING:  # pragma: no cover - imported by validate() when there is something to diagnose
    from synth.validation.diagnosis import Diagnosis

__all__ = ["Validation", "ReducedController", "validate", "home_conditions", "home_states", "reduced_controller"]


@dataclass(frozen=True)
class Validation:
    """One whole run of ``synth validate``: its inputs, SYNC, the analysis and the diagnoses."""

    rules: RuleSet
    plant: Plant
    grafcet: Grafcet
    sync: Sync
    analysis: Analysis
    diagnoses: dict[int, Diagnosis]
    expert: bool
    sup_empty: bool
    homes: tuple[str, ...] = ()  # the --home conditions, as written
    never_starts: Diagnosis | None = None
    # set by the symbolic engine, whose ``sync`` holds only the nodes a report shows:
    counts: dict[str, int] | None = None  # the stats, counted on the whole SYNC
    reached_steps: frozenset[str] | None = None  # steps active in some reachable situation
    engine_stats: dict[str, int] | None = None  # BDD nodes, situations

    @property
    def unreached_steps(self) -> list[str]:
        """Steps active in no stable situation SYNC reaches: dead code under this plant."""
        active = self.reached_steps
        if active is None:
            active = frozenset(st for n in self.sync.nodes for st in n.situation.steps)
        return [s.variable for s in self.grafcet.steps if s.name not in active]

    @property
    def stats(self) -> dict[str, int]:
        if self.counts is not None:
            return dict(self.counts)
        return {
            "plant_states": self.plant.size,
            "sync_states": self.sync.sync_states,
            "aggregated_states": len(self.sync.nodes),
            "aggregated_transitions": len(self.sync.edges),
        }

    @property
    def passed(self) -> bool:
        return (not self.sup_empty and not self.analysis.blocking and not self.analysis.prohibited
                and self.never_starts is None)

def home_conditions(texts: Sequence[str], p: Plant, g: Grafcet) -> tuple[Expr, ...]:
    """``--home`` conditions read and checked: names are step variables or plant
    variables (E and Z), no edges; errors are located in the option text."""
    known = [s.variable for s in g.steps] + list(p.inputs) + list(p.outputs)
    out = []
    for text in texts:
        e = parse_expression(text, "--home")
        for n in names(e):
            if isinstance(n, ExprEdge):
                raise InputError(f"an edge is not a state: {n.text()}", n.loc,
                                 notes=("a home state is a condition on levels, e.g. --home \"X1 & v10\"",))
            if n.name not in known:
                raise InputError(f"unknown name '{n.name}' in --home", n.loc, suggestions=close_names(n.name, known),
                                 notes=("a home condition reads step variables (X1) and plant variables (E, Z)",))
        out.append(e)
    return tuple(out)


def home_states(sync: Sync, conditions: Sequence[Expr]) -> frozenset[int]:
    """The home states: the initial aggregated states, and every state where one of
    ``conditions`` holds (read on its active steps and its plant values)."""
    homes = set(sync.initial)
    for i, n in enumerate(sync.nodes if conditions else ()):
        val = sync.plant.valuation(n.plant)
        steps = set(n.situation.step_variables)

        def value(name: str) -> bool:
            return name in steps if name not in val else val[name]

        if any(evaluate(c, value) for c in conditions):
            homes.add(i)
    return frozenset(homes)


def validate(
    grafcet_path: str | Path,
    rules_path: str | Path,
    *,
    expert: bool = False,
    homes: Sequence[str] = (),
    max_states: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    engine: str = "explicit",
    max_nodes: int | None = None,
    symbolic_progress: Callable[[str], None] | None = None,
) -> Validation:
    """Run the whole method on a Grafcet and a plant; ``homes`` are ``--home`` conditions.

    ``engine``: ``explicit``, ``symbolic`` (:mod:`synth.symbolic`, ``max_nodes`` its BDD
    node budget) or ``auto`` (by estimated size, :mod:`synth.symbolic.engine`)."""
    rs = load_rules(rules_path)
    p = plant(rs)
    g = load_grafcet(grafcet_path, inputs=p.inputs, outputs=p.outputs)
    if engine != "explicit":
        from synth.symbolic.engine import EngineChoice, choose

        if choose(engine, p.size * max(1, len(g.steps))) == EngineChoice.SYMBOLIC:
            from synth.symbolic.validate import validate_loaded

            return validate_loaded(rs, p, g, expert=expert, homes=homes, max_nodes=max_nodes, progress=symbolic_progress)
    conditions = home_conditions(homes, p, g)
    machine = GrafcetMachine(g)
    sup_empty = not CompiledConstraints(p, rs.constraints).kept(p.initial)
    sync = synchronous_product(p, rs.constraints, machine, max_states=max_states, progress=progress)
    analysis = analyse(sync, home_states(sync, conditions))
    diagnoses: dict[int, Diagnosis] = {}
    never = None
    if analysis.blocking or analysis.never_starts:  # a passing run never imports the diagnosis
        from synth.validation.diagnosis import diagnose, diagnose_never_starts

        diagnoses = {b: diagnose(sync, b, expert=expert, component=analysis.components[b]) for b in analysis.blocking}
        never = diagnose_never_starts(sync, expert=expert) if analysis.never_starts else None
    return Validation(rs, p, g, sync, analysis, diagnoses, expert, sup_empty, tuple(homes), never)


@dataclass(frozen=True)
class ReducedController:
    """COR (docs/method.md): the aggregated automaton without the states from which the
    initial situation cannot be reached again, nor the transitions into them.
    ``states`` are aggregated-state indices, in order."""

    states: tuple[int, ...]
    edges: tuple[Edge, ...]
    initial: tuple[int, ...]
    removed: int


def reduced_controller(v: Validation) -> ReducedController:
    """The :class:`ReducedController` of a validation."""
    keep = tuple(sorted(v.analysis.coreachable))
    kept = set(keep)
    edges = tuple(e for e in v.sync.edges if e.source in kept and e.target in kept)
    return ReducedController(keep, edges, tuple(i for i in v.sync.initial if i in kept), len(v.sync.nodes) - len(keep))

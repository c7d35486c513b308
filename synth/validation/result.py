"""What both validation engines produce and share: the :class:`Validation` result, the
reduced controller (COR) and the ``--home`` conditions.

The explicit engine (:mod:`synth.validation.validate`) and the symbolic one
(:mod:`synth.symbolic.validate`) both build a :class:`Validation`; its JSON and text
are in :mod:`synth.output.result`, the HTML report in :mod:`synth.output.html`.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.validate import validate
>>> v = validate(_plants("../grafcets/tri_missing_order.g7"), _plants("tri.rules"))
>>> v.passed, len(reduced_controller(v).states) <= v.stats["aggregated_states"]
(False, True)
"""

from __future__ import annotations

from dataclasses import field
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

from synth.errors import InputError, close_names
from synth.frozen import frozen
from synth.grafcet.language import Grafcet
from synth.logic.expr import Edge as ExprEdge, Expr, names
from synth.plant.composition import Plant, plant
from synth.plant.rules import RuleSet
from synth.syntax import parse_expression
from synth.validation.analysis import Analysis
from synth.validation.sync import Edge, Sync

if TYPE_CHECKING:  # pragma: no cover - imported by the engines when there is something to diagnose
    from synth.grafcet.language import Semantics
    from synth.validation.diagnosis import Diagnosis

__all__ = ["Validation", "ReducedController", "reduced_controller", "home_conditions", "load_model"]


@frozen
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
    # prohibited node -> the diagnosis of each order change refused there (``sync.nodes[i].proh``, in order)
    prohibitions: dict[int, tuple[str, ...]] = field(default_factory=dict)
    # set by the symbolic engine, whose ``sync`` holds only the nodes a report shows:
    counts: dict[str, int] | None = None  # the stats, counted on the whole SYNC
    reached_steps: frozenset[str] | None = None  # steps active in some reachable situation
    engine_stats: dict[str, int | list[str]] | None = None  # BDD nodes, situations, variable order

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


@frozen
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


def load_model(grafcet_path: str | Path, rules_path: str | Path,
               semantics: "Semantics | str" = "grafcet") -> tuple[RuleSet, Plant, Grafcet]:
    """What both engines validate: the rules, their plant, and the Grafcet checked against
    the plant's inputs and outputs (the rules first: the Grafcet's names are checked by them),
    read with ``semantics`` (``grafcet`` or ``sfc``)."""
    from synth.grafcet.language_check import load_grafcet
    from synth.plant.rules_check import load_rules

    rs = load_rules(rules_path)
    p = plant(rs)
    return rs, p, load_grafcet(grafcet_path, inputs=p.inputs, outputs=p.outputs, semantics=semantics)

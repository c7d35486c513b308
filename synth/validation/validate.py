"""``synth validate``: plant + constraints + Grafcet → verdict, problems, traces, diagnoses.

The result is a frozen :class:`Validation`; its JSON and text are in
:mod:`synth.output.result`, the HTML report in :mod:`synth.output.html`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from synth.validation.analysis import Analysis, analyse
from synth.plant.composition import Plant, plant
from synth.validation.diagnosis import Diagnosis, diagnose
from synth.grafcet.language import Grafcet, load_grafcet
from synth.plant.rules import RuleSet, load_rules
from synth.grafcet.machine import GrafcetMachine
from synth.sup.constraints import CompiledConstraints
from synth.validation.sync import Edge, Sync, synchronous_product

__all__ = ["Validation", "ReducedController", "validate", "reduced_controller"]


@dataclass(frozen=True)
class Validation:
    rules: RuleSet
    plant: Plant
    grafcet: Grafcet
    sync: Sync
    analysis: Analysis
    diagnoses: dict[int, Diagnosis]
    expert: bool
    sup_empty: bool

    @property
    def unreached_steps(self) -> list[str]:
        """Steps active in no stable situation SYNC reaches: dead code under this plant."""
        active = {st for n in self.sync.nodes for st in n.situation.steps}
        return [s.variable for s in self.grafcet.steps if s.name not in active]

    @property
    def stats(self) -> dict[str, int]:
        return {
            "plant_states": self.plant.size,
            "sync_states": self.sync.sync_states,
            "aggregated_states": len(self.sync.nodes),
            "aggregated_transitions": len(self.sync.edges),
        }

    @property
    def passed(self) -> bool:
        return not self.sup_empty and not self.analysis.blocking and not self.analysis.prohibited

def validate(
    grafcet_path: str | Path,
    rules_path: str | Path,
    *,
    expert: bool = False,
    max_states: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Validation:
    """Run the whole method on a Grafcet and a plant."""
    rs = load_rules(rules_path)
    p = plant(rs)
    g = load_grafcet(grafcet_path, inputs=p.inputs, outputs=p.outputs)
    machine = GrafcetMachine(g)
    sup_empty = not CompiledConstraints(p, rs.constraints).kept(p.initial)
    sync = synchronous_product(p, rs.constraints, machine, max_states=max_states, progress=progress)
    analysis = analyse(sync)
    diagnoses = {b: diagnose(sync, b, expert=expert, component=analysis.components[b]) for b in analysis.blocking}
    return Validation(rs, p, g, sync, analysis, diagnoses, expert, sup_empty)


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

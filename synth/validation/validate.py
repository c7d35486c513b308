"""``synth validate``: plant + constraints + Grafcet → verdict, problems, traces, diagnoses.

The result is plain data (:meth:`Validation.as_json`, schema in ``docs/validate-json.md``)
and terminal text; the HTML report is written by :mod:`synth.output.html`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from synth.validation.analysis import Analysis, analyse
from synth.plant.composition import Plant, plant
from synth.validation.diagnosis import Diagnosis, diagnose, diagnose_prohibition
from synth.grafcet.language import Grafcet, load_grafcet
from synth.plant.rules import RuleSet, load_rules
from synth.grafcet.machine import GrafcetMachine
from synth.sup.constraints import CompiledConstraints
from synth.validation.sync import Node, Sync, synchronous_product

__all__ = ["Validation", "validate", "reduced_controller"]


@dataclass
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
        return [f"X{s.name}" for s in self.grafcet.steps if s.name not in active]

    @property
    def passed(self) -> bool:
        return not self.sup_empty and not self.analysis.blocking and not self.analysis.prohibited

    # ------------------------------------------------------------------ data
    def state_data(self, i: int) -> dict[str, Any]:
        n: Node = self.sync.nodes[i]
        val = self.plant.valuation(n.plant)
        return {
            "situation": [f"X{s}" for s in n.situation.steps],
            "stored": list(n.situation.stored),
            "elapsed": list(n.situation.elapsed),
            "E": {v: int(val[v]) for v in self.plant.inputs},
            "Z": {v: int(val[v]) for v in self.plant.outputs},
            "ord": list(n.ord),
            "proh": [{"order": p.order, "event": p.event, "constraints": list(p.constraints)} for p in n.proh],
        }

    @property
    def stats(self) -> dict[str, int]:
        return {
            "plant_states": self.plant.size,
            "sync_states": self.sync.sync_states,
            "aggregated_states": len(self.sync.nodes),
            "aggregated_transitions": len(self.sync.edges),
        }

    def prohibited_data(self, i: int) -> list[dict[str, Any]]:
        """One entry per order change SUP refuses in aggregated state ``i``."""
        out = []
        for pr in self.sync.nodes[i].proh:
            d = self.state_data(i)
            d.update(
                {
                    "order": pr.order,
                    "event": pr.event,
                    "constraints": list(pr.constraints),
                    "trace": list(self.analysis.traces[i].events),
                    "diagnosis": diagnose_prohibition(self.sync, i, pr),
                }
            )
            out.append(d)
        return out

    def as_json(self) -> dict[str, Any]:
        a = self.analysis
        blocking = []
        for b in a.blocking:
            tr = a.traces[b]
            nr = a.no_return[b]
            d = self.state_data(b)
            d["trace"] = list(tr.events)
            d["trace_states"] = [self.state_data(i) for i in tr.nodes]
            d["no_return"] = {
                "situation": [f"X{s}" for s in self.sync.nodes[nr].situation.steps],
                "after": list(tr.events[: tr.nodes.index(nr)]),
            }
            d["component_size"] = len(a.components[b])
            d["diagnosis"] = self.diagnoses[b].as_dict()
            blocking.append(d)
        prohibited = [d for i in a.prohibited for d in self.prohibited_data(i)]
        return {
            "verdict": "pass" if self.passed else "fail",
            "mode": "expert" if self.expert else "designer",
            "grafcet": self.grafcet.path,
            "plant": self.rules.path,
            "sup_empty": self.sup_empty,
            "stats": self.stats,
            "constraints": {c.id: c.label for c in self.rules.constraints},
            "blocking": blocking,
            "prohibited": prohibited,
            "unreached_steps": self.unreached_steps,
            "conflicts": [
                {
                    "step": f"X{c.step}",
                    "transitions": list(c.transitions),
                    "event": c.event,
                    "situation": [f"X{s}" for s in self.sync.nodes[c.node].situation.steps],
                    "trace": list(self.analysis.traces[c.node].events) + [c.event],
                }
                for c in self.sync.conflicts
            ],
        }

    # ------------------------------------------------------------------ text
    def text(self) -> str:
        a = self.analysis
        st = self.stats
        head = "PASS" if self.passed else "FAIL"
        lines = [
            f"{head}: {len(a.blocking)} blocking situation(s), {len(a.prohibited)} situation(s) with prohibited orders"
            f"  [{'expert' if self.expert else 'designer'} mode; SYNC {st['sync_states']} states, "
            f"aggregated {st['aggregated_states']} states / {st['aggregated_transitions']} transitions]"
        ]
        if self.sup_empty:
            lines.append("SUP is empty: the initial plant state is illegal, defended or weakly defended")
        for c in self.sync.conflicts:
            lines.append(
                f"warning: transitions {', '.join(c.transitions)} leaving step {c.step} fired together on {c.event} "
                f"in {self.sync.nodes[c.node].situation.text()}: every branch of the divergence became active "
                "(make their receptivities exclusive if they are meant as alternatives)"
            )
        if self.unreached_steps and not self.sup_empty:
            lines.append(
                f"note: {len(self.unreached_steps)} step(s) never active in any reachable stable situation: "
                + ", ".join(self.unreached_steps)
            )
        for k, b in enumerate(a.blocking, 1):
            lines += [""] + self._problem_lines(f"Blocking {k}", b)
            tr = a.traces[b]
            nr = a.no_return[b]
            if nr != b:
                after = tr.events[: tr.nodes.index(nr)]
                lines.append(
                    f"  no return since {self.sync.nodes[nr].situation.text()} (after {' '.join(after) or 'the start'}):"
                    " from there the initial situation can no longer be reached"
                )
            d = self.diagnoses[b]
            lines.append(f"  diagnosis [{d.verdict}]: {d.summary}")
            lines += [f"    {x}" for x in d.details]
        for k, i in enumerate(a.prohibited, 1):
            lines += [""] + self._problem_lines(f"Prohibited {k}", i)
            for pr in self.sync.nodes[i].proh:
                lines.append(f"  diagnosis: {diagnose_prohibition(self.sync, i, pr)}")
        return "\n".join(lines)

    def _problem_lines(self, title: str, i: int) -> list[str]:
        d = self.state_data(i)
        n = self.sync.nodes[i]
        true_e = [k for k, v in d["E"].items() if v] or ["-"]
        true_z = [k for k, v in d["Z"].items() if v] or ["-"]
        proh = ", ".join(f"{p['order']} ({', '.join(p['constraints'])})" for p in d["proh"]) or "-"
        return [
            f"{title}: situation {n.situation.text()}",
            f"  E: {' '.join(true_e)}",
            f"  Z: {' '.join(true_z)}",
            f"  ORD: {', '.join(d['ord']) or '-'}   PROH: {proh}",
            f"  trace: {' '.join(self.analysis.traces[i].events) or '(initial state)'}",
        ]


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


def reduced_controller(v: Validation) -> dict[str, Any]:
    """COR (METHOD.md §8): the aggregated automaton without the states from which the
    initial situation cannot be reached again, nor the transitions into them."""
    keep = sorted(v.analysis.coreachable)
    number = {i: k for k, i in enumerate(keep)}
    states = []
    for i in keep:
        d = v.state_data(i)
        n = v.sync.nodes[i]
        states.append({"id": number[i], "situation": d["situation"], "E": d["E"], "Z": d["Z"], "orders": sorted(n.emitted)})
    transitions = [
        {"source": number[e.source], "event": e.event, "target": number[e.target]}
        for e in v.sync.edges
        if e.source in number and e.target in number
    ]
    transitions.sort(key=lambda t: (t["source"], t["event"], t["target"]))
    removed = len(v.sync.nodes) - len(keep)
    return {"states": states, "transitions": transitions, "initial": sorted(number[i] for i in v.sync.initial if i in number), "removed_states": removed}

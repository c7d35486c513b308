"""The result of ``synth validate`` as data and as terminal text: the JSON of
``docs/validate-json.md`` (schema ``synth/output/schemas/validate.json``), the text
report, and the reduced controller (COR) as JSON and DOT.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from synth.grafcet.language import step_variable
from synth.output.dot import dot_graph

if TYPE_CHECKING:  # pragma: no cover
    from synth.validation.result import ReducedController, Validation

__all__ = ["state_json", "state_names", "prohibited_json", "validation_json", "validation_text", "cor_json", "cor_dot"]


def _steps(steps: tuple[str, ...]) -> list[str]:
    return [step_variable(s) for s in steps]


def state_json(v: Validation, i: int) -> dict[str, Any]:
    """Aggregated state ``i``: situation, stored outputs, elapsed timers, E, Z, ORD, PROH."""
    n = v.sync.nodes[i]
    val = v.plant.valuation(n.plant)
    return {
        "situation": _steps(n.situation.steps),
        "stored": list(n.situation.stored),
        "elapsed": list(n.situation.elapsed),
        "E": {x: int(val[x]) for x in v.plant.inputs},
        "Z": {x: int(val[x]) for x in v.plant.outputs},
        "ord": list(n.ord),
        "proh": [{"order": p.order, "event": p.event, "constraints": list(p.constraints)} for p in n.proh],
    }


def state_names(state: dict[str, Any]) -> tuple[list[str], list[str], str]:
    """What a reader sees of a :func:`state_json` state: the true inputs, the true
    outputs (by name) and the PROH text (``AVANCER1 (C2_1, C2_6)``, empty for none)."""
    true_e = [k for k, x in state["E"].items() if x]
    true_z = [k for k, x in state["Z"].items() if x]
    proh = ", ".join(f"{p['order']} ({', '.join(p['constraints'])})" for p in state["proh"])
    return true_e, true_z, proh


def prohibited_json(v: Validation, i: int) -> list[dict[str, Any]]:
    """One entry per order change SUP refuses in aggregated state ``i``."""
    out = []
    for pr, diagnosis in zip(v.sync.nodes[i].proh, v.prohibitions[i]):
        d = state_json(v, i)
        d.update(
            {
                "order": pr.order,
                "event": pr.event,
                "constraints": list(pr.constraints),
                "trace": list(v.analysis.traces[i].events),
                "diagnosis": diagnosis,
            }
        )
        out.append(d)
    return out


def validation_json(v: Validation) -> dict[str, Any]:
    """The whole result (``synth validate --json``)."""
    a = v.analysis
    blocking = []
    for b in a.blocking:
        tr = a.traces[b]
        nr = a.no_return[b]
        d = state_json(v, b)
        d["trace"] = list(tr.events)
        d["trace_states"] = [state_json(v, i) for i in tr.nodes]
        d["no_return"] = {
            "situation": _steps(v.sync.nodes[nr].situation.steps),
            "after": list(tr.events[: tr.nodes.index(nr)]),
        }
        d["component_size"] = len(a.components[b])
        d["diagnosis"] = v.diagnoses[b].as_dict()
        blocking.append(d)
    prohibited = [d for i in a.prohibited for d in prohibited_json(v, i)]
    semantics = {"semantics": str(v.grafcet.semantics)} if v.grafcet.semantics == "sfc" else {}
    return {
        "verdict": "pass" if v.passed else "fail",
        "mode": "expert" if v.expert else "designer",
        **semantics,
        "grafcet": v.grafcet.path,
        "plant": v.rules.path,
        "sup_empty": v.sup_empty,
        "homes": list(v.homes),
        "never_starts": v.never_starts.as_dict() if v.never_starts is not None else None,
        "stats": v.stats,
        "constraints": {c.id: c.label for c in v.rules.constraints},
        "blocking": blocking,
        "prohibited": prohibited,
        "unreached_steps": v.unreached_steps,
        "conflicts": [
            {
                "step": step_variable(c.step),
                "transitions": list(c.transitions),
                "event": c.event,
                "situation": _steps(v.sync.nodes[c.node].situation.steps),
                "trace": list(a.traces[c.node].events) + [c.event],
            }
            for c in v.sync.conflicts
        ],
    }


def validation_text(v: Validation) -> str:
    """The terminal report: verdict line, warnings, then each problem with its trace and diagnosis."""
    a = v.analysis
    st = v.stats
    head = "PASS" if v.passed else "FAIL"
    lines = [
        f"{head}: {len(a.blocking)} blocking situation(s), {len(a.prohibited)} situation(s) with prohibited orders"
        f"  [{'expert' if v.expert else 'designer'} mode; "
        + ("IEC 61131-3 SFC semantics; " if v.grafcet.semantics == "sfc" else "")
        + f"SYNC {st['sync_states']} states, "
        f"aggregated {st['aggregated_states']} states / {st['aggregated_transitions']} transitions]"
    ]
    if v.sup_empty:
        lines.append("SUP is empty: the initial plant state is illegal, defended or weakly defended")
    if v.never_starts is not None:
        d = v.never_starts
        lines.append(f"never starts [{d.cause}]: {d.summary}")
        lines += [f"    {x}" for x in d.details]
    if v.homes:
        lines.append(f"home states: the initial state and where {' or '.join(v.homes)} holds")
    for c in v.sync.conflicts:
        lines.append(
            f"warning: transitions {', '.join(c.transitions)} leaving step {c.step} fired together on {c.event} "
            f"in {v.sync.nodes[c.node].situation.text()}: every branch of the divergence became active "
            "(make their receptivities exclusive if they are meant as alternatives)"
        )
    if v.unreached_steps and not v.sup_empty:
        lines.append(
            f"note: {len(v.unreached_steps)} step(s) never active in any reachable stable situation: "
            + ", ".join(v.unreached_steps)
        )
    for k, b in enumerate(a.blocking, 1):
        lines += [""] + _problem_lines(v, f"Blocking {k}", b)
        tr = a.traces[b]
        nr = a.no_return[b]
        if nr != b:
            after = tr.events[: tr.nodes.index(nr)]
            lines.append(
                f"  no return since {v.sync.nodes[nr].situation.text()} (after {' '.join(after) or 'the start'}):"
                + (" from there no home state can be reached" if v.homes
                   else " from there the initial situation can no longer be reached")
            )
        d = v.diagnoses[b]
        lines.append(f"  diagnosis [{d.verdict}]: {d.summary}")
        lines += [f"    {x}" for x in d.details]
    for k, i in enumerate(a.prohibited, 1):
        lines += [""] + _problem_lines(v, f"Prohibited {k}", i)
        lines += [f"  diagnosis: {d}" for d in v.prohibitions[i]]
    return "\n".join(lines)


def _problem_lines(v: Validation, title: str, i: int) -> list[str]:
    d = state_json(v, i)
    n = v.sync.nodes[i]
    true_e, true_z, proh = state_names(d)
    return [
        f"{title}: situation {n.situation.text()}",
        f"  E: {' '.join(true_e) or '-'}",
        f"  Z: {' '.join(true_z) or '-'}",
        f"  ORD: {', '.join(d['ord']) or '-'}   PROH: {proh or '-'}",
        f"  trace: {' '.join(v.analysis.traces[i].events) or '(initial state)'}",
    ]


def cor_json(v: Validation, cor: ReducedController) -> dict[str, Any]:
    """The reduced controller as JSON (``synth validate --cor FILE``)."""
    number = {i: k for k, i in enumerate(cor.states)}
    states = []
    for i in cor.states:
        d = state_json(v, i)
        states.append({"id": number[i], "situation": d["situation"], "E": d["E"], "Z": d["Z"],
                       "orders": sorted(v.sync.nodes[i].emitted)})
    transitions = [{"source": number[e.source], "event": e.event, "target": number[e.target]} for e in cor.edges]
    transitions.sort(key=lambda t: (t["source"], t["event"], t["target"]))
    return {"states": states, "transitions": transitions, "initial": sorted(number[i] for i in cor.initial),
            "removed_states": cor.removed}


def cor_dot(cor: dict[str, Any]) -> str:
    """DOT text of :func:`cor_json`'s data: one box per state (situation, orders)."""
    nodes = [(str(s["id"]), "{" + ", ".join(s["situation"]) + "}\n" + ", ".join(s["orders"]), {"shape": "box"})
             for s in cor["states"]]
    plain: dict[str, str] = {}
    edges = [(str(t["source"]), str(t["target"]), str(t["event"]), plain) for t in cor["transitions"]]
    return dot_graph("COR", nodes, edges)

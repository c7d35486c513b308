"""JSON-ready summaries and terminal texts of the plant, its elements, SUP and the ASS.

Pure functions: data in, dicts or text out; the ``cli`` prints them, the JSON Schemas
in ``synth/output/schemas/`` describe them (the tests validate every ``--json`` output).

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> from synth.grafcet.machine import GrafcetMachine
>>> from synth.grafcet.ass import stable_situation_automaton
>>> g = parse_grafcet("grafcet G { initial step 0 step 1: A transition 0 -> 1 when ↑a transition 1 -> 0 when !a }")
>>> print(ass_text(stable_situation_automaton(GrafcetMachine(g))), end="")
ASS: 2 stable situations, 2 transitions
inputs explored: a
<BLANKLINE>
S0  {X0}  (initial)
    orders: -
    ↑a -> S1
<BLANKLINE>
S1  {X1}
    orders: A
    ↓a -> S0
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping, Sequence

from synth.output.dot import orders_text

if TYPE_CHECKING:  # pragma: no cover
    from pathlib import Path

    from synth.engines import SupRun
    from synth.grafcet.ass import ASS

    from synth.grafcet.simulation import SimulationStep
    from synth.plant.library import LibraryModel
    from synth.plant.composition import Plant
    from synth.plant.element import ElementAutomaton
    from synth.plant.rules import RuleSet
    from synth.sup.supervisor import Supervisor
    from synth.symbolic.supervisor import SymbolicSupervisor

__all__ = [
    "element_summary",
    "element_text",
    "plant_summary",
    "plant_text",
    "sup_summary",
    "sup_text",
    "sup_run_summary",
    "sup_run_text",
    "ass_json",
    "ass_text",
    "run_text",
    "library_json",
    "library_text",
    "json_text",
    "print_json",
]


def element_summary(a: "ElementAutomaton", detail: bool = False) -> dict[str, Any]:
    """An element automaton's sizes; with ``detail``, its states and transitions too."""
    d: dict[str, Any] = {
        "name": a.name,
        "model": a.spec.model,
        "variables": list(a.variables),
        "states": a.size,
        "transitions": a.count(),
        "controllable": a.count(True),
        "uncontrollable": a.count(False),
    }
    if detail:
        d["initial"] = a.state_label(a.initial)
        d["state_list"] = [a.state_label(k) for k in range(a.size)]
        d["transition_list"] = [
            {
                "source": a.state_label(int(a.src[t])),
                "event": a.event(t),
                "target": a.state_label(int(a.dst[t])),
                "controllable": bool(a.controllable[t]),
            }
            for t in range(a.src.size)
        ]
    return d


def element_text(data: Mapping[str, Any]) -> str:
    """The terminal listing of :func:`element_summary` (``detail=True``)."""
    lines = [
        f"element {data['name']}: {data['states']} states, {data['transitions']} transitions "
        f"({data['controllable']} controllable, {data['uncontrollable']} uncontrollable)",
        f"initial state: {data['initial']}",
    ]
    for tr in data["transition_list"]:
        kind = "c" if tr["controllable"] else "u"
        lines.append(f"  {tr['source']:<28} --{tr['event']}--> {tr['target']}  [{kind}]")
    return "\n".join(lines) + "\n"


def _sizes(p: "Plant") -> dict[str, int]:
    return {
        "states": p.state_count,  # the grid's size unless elements read each other
        "transitions": p.count_transitions(),
        "controllable": p.count_transitions(True),
        "uncontrollable": p.count_transitions(False),
    }


def plant_summary(p: "Plant", path: str) -> dict[str, Any]:
    """The plant: its vectors E and Z, initial state, elements and sizes."""
    e0, z0 = p.vectors(p.initial)
    return {
        "file": path,
        "inputs": list(p.inputs),
        "outputs": list(p.outputs),
        "initial": {"state": p.label(p.initial), "E": e0, "Z": z0},
        "elements": [element_summary(a) for a in p.elements],
        **_sizes(p),
    }


def plant_text(data: Mapping[str, Any]) -> str:
    """The terminal listing of :func:`plant_summary`."""
    lines = [
        f"plant {data['file']}: {data['states']} states, {data['transitions']} transitions "
        f"({data['controllable']} controllable, {data['uncontrollable']} uncontrollable)",
        f"E = {{{', '.join(data['inputs'])}}}",
        f"Z = {{{', '.join(data['outputs'])}}}",
        f"initial: E0={data['initial']['E']} Z0={data['initial']['Z']}",
    ]
    for el in data["elements"]:
        model = f" ({el['model']})" if el["model"] else ""
        lines.append(f"  {el['name']:<10}{model:<18} {el['states']:>4} states {el['controllable']:>4} c {el['uncontrollable']:>4} u")
    return "\n".join(lines) + "\n"


def sup_summary(rs: "RuleSet", sup: "Supervisor | SymbolicSupervisor", path: str) -> dict[str, Any]:
    """SUP's sizes, what it removed and why, and the constraints it enforces."""
    return {
        "file": path,
        "plant": _sizes(sup.plant),
        **sup.summary(),
        "forbidden_by_constraint": sup.forbidden_counts(),
        "constraints": [{"id": c.id, "label": c.label, "expr": c.text()} for c in rs.constraints],
        "empty": sup.empty,
    }


def sup_run_summary(run: "SupRun") -> dict[str, Any]:
    """The JSON of ``synth sup`` (the key ``symbolic`` when the symbolic engine ran)."""
    data = sup_summary(run.rules, run.sup, run.path)
    if run.bdd_nodes is not None:
        data["symbolic"] = {"bdd_nodes": run.bdd_nodes}
    return data


def sup_run_text(run: "SupRun") -> str:
    """The terminal listing of :func:`sup_run_summary`, with why SUP is empty when it is."""
    labels = run.labels
    return sup_text(sup_run_summary(run), labels, run.why().text(labels) if run.sup.empty else "")


def sup_text(data: Mapping[str, Any], labels: Mapping[str, str], empty_why: str = "") -> str:
    """The terminal listing of :func:`sup_summary`; ``empty_why`` explains an empty SUP."""
    pl = data["plant"]
    lines = [f"plant {data['file']}: {pl['states']} states, {pl['transitions']} transitions"]
    if data["empty"]:
        lines.append("SUP is empty: the initial state itself is illegal, defended or weakly defended")
        lines.append(empty_why)
    lines.append(f"SUP: {data['states']} states, {data['transitions']} transitions "
                 f"({data['controllable']} controllable, {data['uncontrollable']} uncontrollable)")
    lines.append(f"removed: {data['illegal']} illegal, {data['defended']} defended, "
                 f"{data['weakly_defended']} weakly defended, {data['unreachable_removed']} unreachable")
    lines.append(f"forbidden controllable transitions: {data['forbidden_transitions']}")
    for cid, n in data["forbidden_by_constraint"].items():
        lines.append(f"  {cid:<8} {n:>8}  {labels.get(cid, '')}")
    return "\n".join(lines) + "\n"


def ass_text(ass: "ASS", title: str = "") -> str:
    """The ASS as a readable listing."""
    lines = []
    kind = "situations after a PLC scan (--semantics sfc)" if ass.per_scan else "stable situations"
    head = f"ASS{' of ' + title if title else ''}: {len(ass.states)} {kind}, {len(ass.transitions)} transitions"
    lines.append(head)
    lines.append("inputs explored: " + (", ".join(ass.inputs) if ass.inputs else "none"))
    if any(s.conditional for s in ass.states):
        lines.append("(an order marked ? is emitted only under some input values: conditional action)")
    for s in ass.states:
        mark = "  (initial)" if s.id == ass.initial else ""
        lines.append("")
        lines.append(f"S{s.id}  {s.situation.text()}{mark}")
        lines.append(f"    orders: {orders_text(s.orders, s.conditional)}")
        for t in ass.successors(s.id):
            cond = "" if t.condition == "any" else f"  [{t.condition}]"
            lines.append(f"    {t.event}{cond} -> S{t.target}")
    return "\n".join(lines) + "\n"


def ass_json(ass: "ASS") -> dict[str, Any]:
    """The ASS as JSON-ready data."""
    return {
        "initial": ass.initial,
        "inputs": list(ass.inputs),
        "states": [
            {
                "id": s.id,
                "situation": list(s.situation.steps),
                "stored": list(s.situation.stored),
                "elapsed": list(s.situation.elapsed),
                "orders": list(s.orders),
                "conditional_orders": list(s.conditional),
            }
            for s in ass.states
        ],
        "transitions": [
            {"source": t.source, "event": t.event, "condition": t.condition, "target": t.target}
            for t in ass.transitions
        ],
    }


def run_text(rows: "Sequence[SimulationStep]") -> str:
    """``synth run``'s table: number, event, stable situation, orders, transitions fired."""
    cells = [(r.event, r.situation.text(), orders_text(r.orders), "; ".join(", ".join(f) for f in r.fired)) for r in rows]
    w_event = max(len(c[0]) for c in cells)
    w_sit = max(len(c[1]) for c in cells)
    out = []
    for i, (ev, sit, orders, fired) in enumerate(cells):
        line = f"{i:<3}{ev:<{w_event}}  {sit:<{w_sit}}  orders: {orders}"
        if fired:
            line += f"   fired: {fired}"
        out.append(line.rstrip() + "\n")
    return "".join(out)


def library_json(models: "Sequence[LibraryModel]") -> list[dict[str, Any]]:
    """``synth lib --json``: one object per model."""
    return [
        {"model": m.name, "use": m.use, "orders": list(m.orders), "sensors": list(m.sensors),
         "initial": {n: int(v) for n, v in m.initial}, "summary": m.summary}
        for m in models
    ]


def library_text(models: "Sequence[LibraryModel]", where: "Path") -> str:
    """``synth lib``: each model with its orders, sensors (initial values) and use line."""
    lines = [f"element library: {where}"]
    for m in models:
        init = dict(m.initial)
        lines += [
            "",
            f"{m.name}  ({m.use})" + (f"  {m.summary}" if m.summary else ""),
            "  orders:  " + (", ".join(f"{o} = {int(init[o])}" for o in m.orders) or "-"),
            "  sensors: " + (", ".join(f"{x} = {int(init[x])}" for x in m.sensors) or "-"),
            f'  use "{m.use}"   element NAME = {m.name}('
            + ", ".join(f"{v}={v}1" for v in m.orders + m.sensors) + ")",
        ]
    return "\n".join(lines) + "\n"


def json_text(data: Any) -> str:
    """``data`` as synth writes JSON: indented by 2, UTF-8 kept, a final newline."""
    import json

    return json.dumps(data, indent=2, ensure_ascii=False) + "\n"


def print_json(data: Any) -> None:
    """Print ``data`` on stdout as :func:`json_text` (every ``--json`` output)."""
    import sys

    sys.stdout.write(json_text(data))

"""CLI commands ``synth plant`` and ``synth sup``."""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

from synth.plant.composition import Plant, plant
from synth.errors import LimitExceeded, SynthError, close_names
from synth.output.faudes import element_generator, plant_generator, supervisor_generator
from synth.output.files import write_atomic
from synth.plant.element import ElementAutomaton
from synth.output.dot import element_dot
from synth.output.html import write_svg
from synth.plant.rules import RuleSet, load_rules
from synth.sup.explain import explain
from synth.sup.supervisor import supremal_controllable

__all__ = ["register", "plant_summary", "element_summary", "print_warnings"]

MAX_DRAWN_STATES = 400
DEFAULT_MAX_STATES = 2**36


def register(sub: "argparse._SubParsersAction") -> None:
    p = sub.add_parser("plant", help="build the plant automaton from a .rules file")
    p.add_argument("rules", metavar="RULES", help="the .rules file")
    p.add_argument("--element", metavar="NAME", help="only this element's automaton")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--dot", metavar="FILE", help="write the automaton as Graphviz DOT")
    g.add_argument("--svg", metavar="FILE", help="draw the automaton as SVG (needs Graphviz's dot)")
    p.add_argument("--export", metavar="FILE.gen", help="write a libFAUDES System (.gen)")
    p.set_defaults(handler=cmd_plant)

    s = sub.add_parser("sup", help="synthesise SUP, the maximal admissible plant behaviour")
    s.add_argument("rules", metavar="RULES", help="the .rules file (elements and constraints)")
    s.add_argument("--json", action="store_true", help="print JSON instead of text")
    s.add_argument("--export", metavar="FILE.gen", help="write SUP as a libFAUDES System (.gen)")
    s.add_argument("--why", metavar="STATE", help="explain one state, written as its true variables, e.g. 'TAPIS,v10,v20,v30,v40'")
    s.add_argument("--max-states", metavar="N", type=int, default=DEFAULT_MAX_STATES,
                   help=f"refuse plants larger than N states (default {DEFAULT_MAX_STATES}); synth validate needs no such limit")
    s.add_argument("--quiet", action="store_true", help="no progress on stderr")
    s.set_defaults(handler=cmd_sup)


def element_summary(a: ElementAutomaton, detail: bool = False) -> dict[str, Any]:
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


def plant_summary(p: Plant, path: str) -> dict[str, Any]:
    e0, z0 = p.vectors(p.initial)
    return {
        "file": path,
        "inputs": list(p.inputs),
        "outputs": list(p.outputs),
        "initial": {"state": p.label(p.initial), "E": e0, "Z": z0},
        "elements": [element_summary(a) for a in p.elements],
        "states": p.size,
        "transitions": p.count_transitions(),
        "controllable": p.count_transitions(True),
        "uncontrollable": p.count_transitions(False),
    }


def _find_element(p: Plant, rs: RuleSet, name: str) -> ElementAutomaton:
    for a in p.elements:
        if a.name == name:
            return a
    names = [a.name for a in p.elements]
    hint = close_names(name, names)
    raise SynthError(
        f"no element '{name}' in {rs.path}"
        + (f" (did you mean {' or '.join(hint)}?)" if hint else "")
        + f"; elements: {', '.join(names)}"
    )


def print_warnings(p: Plant) -> None:
    """Warnings about the plant model (rules that never apply), on stderr."""
    for w in p.warnings:
        print(w.render(), file=sys.stderr)


def _print_json(data: Any) -> None:
    json.dump(data, sys.stdout, indent=2, ensure_ascii=False)
    sys.stdout.write("\n")


def cmd_plant(args: argparse.Namespace) -> int:
    rs = load_rules(args.rules)
    p = plant(rs)
    print_warnings(p)
    if args.element:
        a = _find_element(p, rs, args.element)
        data = element_summary(a, detail=True)
        dot = element_dot(a) if (args.dot or args.svg) else None
        gen = element_generator(a) if args.export else None
    else:
        data = plant_summary(p, args.rules)
        if (args.dot or args.svg) and p.size > MAX_DRAWN_STATES:
            raise SynthError(
                f"the plant has {p.size} states, too many to draw (limit {MAX_DRAWN_STATES}); draw one element with --element NAME"
            )
        dot = _plant_dot(p) if (args.dot or args.svg) else None
        gen = plant_generator(p, "plant") if args.export else None
    if args.dot:
        write_atomic(args.dot, dot or "")
    if args.svg:
        write_svg(args.svg, dot or "")
    if args.export:
        write_atomic(args.export, gen or "")
    if args.json:
        _print_json(data)
        return 0
    if args.element:
        print(f"element {data['name']}: {data['states']} states, {data['transitions']} transitions "
              f"({data['controllable']} controllable, {data['uncontrollable']} uncontrollable)")
        print(f"initial state: {data['initial']}")
        for tr in data["transition_list"]:
            kind = "c" if tr["controllable"] else "u"
            print(f"  {tr['source']:<28} --{tr['event']}--> {tr['target']}  [{kind}]")
    else:
        print(f"plant {args.rules}: {data['states']} states, {data['transitions']} transitions "
              f"({data['controllable']} controllable, {data['uncontrollable']} uncontrollable)")
        print(f"E = {{{', '.join(p.inputs)}}}")
        print(f"Z = {{{', '.join(p.outputs)}}}")
        print(f"initial: E0={data['initial']['E']} Z0={data['initial']['Z']}")
        for el in data["elements"]:
            model = f" ({el['model']})" if el["model"] else ""
            print(f"  {el['name']:<10}{model:<18} {el['states']:>4} states {el['controllable']:>4} c {el['uncontrollable']:>4} u")
    for what, path in (("DOT", args.dot), ("SVG", args.svg), ("libFAUDES", args.export)):
        if path:
            print(f"{what} written to {path}", file=sys.stderr)
    return 0


def _plant_dot(p: Plant) -> str:
    from synth.output.dot import CONTROLLABLE_STYLE, UNCONTROLLABLE_STYLE, dot_graph

    nodes = []
    for code in range(p.size):
        local = p.local(code)
        nodes.append((str(code), p.label(local), {"peripheries": "2"} if local == p.initial else {}))
    edges = []
    for t, src, dst in p.transition_arrays():
        style = CONTROLLABLE_STYLE if t.controllable else UNCONTROLLABLE_STYLE
        for s, d in zip(src.tolist(), dst.tolist()):
            edges.append((str(s), str(d), t.event, style))
    edges.sort(key=lambda e: (int(e[0]), e[2]))
    return dot_graph("plant", nodes, edges)


def _progress(enabled: bool):
    if not enabled:
        return None
    start = time.monotonic()

    def show(text: str) -> None:
        sys.stderr.write(f"\r\033[K[{time.monotonic() - start:6.1f}s] {text}")
        sys.stderr.flush()

    return show


def cmd_sup(args: argparse.Namespace) -> int:
    rs = load_rules(args.rules)
    p = plant(rs)
    print_warnings(p)
    if p.size > args.max_states:
        raise LimitExceeded(
            f"the plant of {args.rules} has {p.size} states, more than --max-states {args.max_states}; "
            f"exploring SUP keeps a bitmap of visited states ({p.size / 8 / 2**30:.1f} GiB here). "
            "Raise --max-states, or validate a Grafcet with "
            "`synth validate`, which decides SUP membership on the fly"
        )
    show = _progress(not args.quiet and sys.stderr.isatty())
    sup = supremal_controllable(p, rs.constraints, progress=show)
    if show is not None:
        sys.stderr.write("\r\033[K")
    labels = {c.id: c.label for c in rs.constraints}
    if args.why:
        local = p.parse_state(args.why)
        ex = explain(sup, local)
        if args.json:
            _print_json(ex.as_dict())
        else:
            print(ex.text(labels))
        return 0
    summary = sup.summary()
    data: dict[str, Any] = {
        "file": args.rules,
        "plant": {
            "states": p.size,
            "transitions": p.count_transitions(),
            "controllable": p.count_transitions(True),
            "uncontrollable": p.count_transitions(False),
        },
        **summary,
        "forbidden_by_constraint": sup.forbidden_counts(),
        "constraints": [{"id": c.id, "label": c.label, "expr": c.text()} for c in rs.constraints],
        "empty": sup.empty,
    }
    if args.export:
        write_atomic(args.export, supervisor_generator(sup, "sup"))
    if args.json:
        _print_json(data)
    else:
        pl = data["plant"]
        print(f"plant {args.rules}: {pl['states']} states, {pl['transitions']} transitions")
        if sup.empty:
            print("SUP is empty: the initial state itself is illegal, defended or weakly defended")
            print(explain(sup, p.initial).text(labels))
        print(f"SUP: {summary['states']} states, {summary['transitions']} transitions "
              f"({summary['controllable']} controllable, {summary['uncontrollable']} uncontrollable)")
        print(f"removed: {summary['illegal']} illegal, {summary['defended']} defended, "
              f"{summary['weakly_defended']} weakly defended, {summary['unreachable_removed']} unreachable")
        print(f"forbidden controllable transitions: {summary['forbidden_transitions']}")
        for cid, n in data["forbidden_by_constraint"].items():
            print(f"  {cid:<8} {n:>8}  {labels.get(cid, '')}")
    if args.export:
        print(f"libFAUDES written to {args.export}", file=sys.stderr)
    return 0

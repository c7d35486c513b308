"""CLI commands of the Grafcet stage: ``synth ass`` and ``synth run``.

``synth ass FILE.g7 [--plant RULES] [--json] [--dot FILE] [--svg FILE]`` prints the
automaton of the stable situations; ``synth run FILE.g7 [--plant RULES] --events
"↑dcy,↑cp12,2s/X101,↓v10"`` simulates the Grafcet event by event and prints each
stable situation with its orders (the initial one first).

Example (text output of ``synth run``)::

    0  initial   {X0, X100, X200, X300}   orders: -
    1  ↑dcy      {X1, X100, X200, X300}   orders: TAPIS   fired: 0->1
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING, Callable, Iterator, Mapping, Sequence

from synth.errors import InputError, Location, close_names

if TYPE_CHECKING:  # pragma: no cover - the library is imported by the commands only (fast --help)
    from synth.grafcet.language import Grafcet

__all__ = ["register", "parse_events", "cmd_ass", "cmd_run"]


# --------------------------------------------------------------------------- loading


def _load(args: argparse.Namespace) -> tuple[Grafcet, dict[str, bool], Callable[[Mapping[str, bool]], bool] | None]:
    """The Grafcet (checked against the plant if given), the initial input values, and
    the plant's test of admissible input vectors (None without a plant)."""
    from synth.grafcet.language import load_grafcet

    initial: dict[str, bool] = {}
    admissible = None
    if args.plant:
        from synth.plant.composition import plant
        from synth.plant.rules import load_rules

        rs = load_rules(args.plant)
        grafcet = load_grafcet(args.file, inputs=rs.inputs, outputs=rs.outputs)
        initial = {v.name: v.initial for v in rs.variables if v.is_input}
        admissible = plant(rs).admissible_inputs()
    else:
        grafcet = load_grafcet(args.file)
    initial = {n: initial.get(n, False) for n in grafcet.inputs}
    if args.initial:
        initial.update(_parse_initial(args.initial, grafcet.inputs))
    return grafcet, initial, admissible


def _comma_items(text: str) -> Iterator[tuple[str, int]]:
    """The non-empty comma-separated items of an option's text, with their 1-based columns.

    >>> list(_comma_items("a, b,,c"))
    [('a', 1), ('b', 4), ('c', 7)]
    """
    col = 1
    for part in text.split(","):
        item = part.strip()
        start = col + (len(part) - len(part.lstrip()))
        col += len(part) + 1
        if item:
            yield item, start


def _parse_initial(text: str, inputs: Sequence[str]) -> dict[str, bool]:
    """``"v10=1, v20=1"`` (or ``"v10, v20"``) → values; errors point into the option text."""
    out: dict[str, bool] = {}
    for item, start in _comma_items(text):
        name, _, value = item.partition("=")
        name = name.strip()
        loc = Location("--initial", 1, start, text, max(1, len(name)))
        if name not in inputs:
            raise InputError(f"unknown input '{name}'", loc, suggestions=close_names(name, inputs))
        if value.strip() not in ("", "0", "1"):
            raise InputError(f"the value of {name} must be 0 or 1", loc)
        out[name] = value.strip() != "0"
    return out


def parse_events(text: str, grafcet: Grafcet) -> list[tuple[str, tuple[str, bool] | str, Location]]:
    """``"↑dcy, ^cp12, 2s/X101, _v10"`` → ``[(text, event, location), ...]``.

    An input event is ``(name, rising)``; a timer event is its id. Unknown names are
    :class:`InputError` located in the option text, with suggestions.
    """
    out: list[tuple[str, tuple[str, bool] | str, Location]] = []
    timers = [t.id for t in grafcet.timers]
    for item, start in _comma_items(text):
        loc = Location("--events", 1, start, text, len(item))
        if item[0] in "↑^↓_":
            rising = item[0] in "↑^"
            name = item[1:].strip()
            if name not in grafcet.inputs:
                raise InputError(
                    f"unknown input '{name}' in event {item}",
                    Location("--events", 1, start + 1, text, max(1, len(name))),
                    suggestions=tuple(item[0] + c for c in close_names(name, grafcet.inputs)),
                    notes=("inputs: " + ", ".join(grafcet.inputs),) if grafcet.inputs else (),
                )
            out.append((("↑" if rising else "↓") + name, (name, rising), loc))
        elif item in timers:
            out.append((item, item, loc))
        else:
            hint = close_names(item, timers + ["↑" + i for i in grafcet.inputs] + ["↓" + i for i in grafcet.inputs])
            raise InputError(
                f"unknown event '{item}'",
                loc,
                suggestions=hint,
                notes=("an event is ↑x / ^x (rising), ↓x / _x (falling) of an input, or a timer of the Grafcet"
                       + (": " + ", ".join(timers) if timers else ""),),
            )
    return out


# --------------------------------------------------------------------------- commands


def cmd_ass(args: argparse.Namespace) -> int:
    from synth.grafcet.ass import stable_situation_automaton
    from synth.grafcet.machine import GrafcetMachine
    from synth.output.dot import ass_dot
    from synth.output.files import write_atomic
    from synth.output.html import write_svg
    from synth.output.summary import ass_json, ass_text

    grafcet, initial, admissible = _load(args)
    machine = GrafcetMachine(grafcet)
    ass = stable_situation_automaton(machine, initial_inputs=initial, admissible=admissible)
    dot = ass_dot(ass, grafcet.path)
    if args.dot:
        write_atomic(args.dot, dot)
    if args.svg:
        write_svg(args.svg, dot)
    if args.json:
        sys.stdout.write(json.dumps(ass_json(ass), indent=2, ensure_ascii=False) + "\n")
    else:
        sys.stdout.write(ass_text(ass, grafcet.path))
    return 0


def _inputs_text(values: Mapping[str, bool], names: Sequence[str]) -> str:
    ones = [n for n in names if values[n]]
    return ", ".join(ones) if ones else "-"


def cmd_run(args: argparse.Namespace) -> int:
    from synth.grafcet.machine import GrafcetMachine
    from synth.output.dot import orders_text as _orders_text

    grafcet, inputs, _ = _load(args)
    machine = GrafcetMachine(grafcet)
    events = parse_events(args.events or "", grafcet)
    sit = machine.initial(inputs)
    rows: list[tuple[str, str, str, str]] = [("initial", sit.text(), _orders_text(sorted(machine.orders(sit, inputs), key=grafcet.outputs.index)), "")]
    for text, event, loc in events:
        if isinstance(event, str):
            if event not in machine.timers(sit):
                step = next(t.step for t in grafcet.timers if t.id == event)
                if event in sit.elapsed:
                    why = "it has already elapsed"
                elif step not in sit.steps:
                    why = f"step {step} is not active"
                else:
                    why = f"a shorter timer of step {step} must elapse first ({', '.join(machine.timers(sit))})"
                raise InputError(f"timer {event} cannot elapse now: {why}", loc, notes=(f"situation: {sit.text()}",))
            sit, rounds = machine.fire_timer_with_trace(sit, event, inputs)
        else:
            name, rising = event
            if inputs[name] == rising:
                raise InputError(
                    f"{text} cannot happen: {name} is already {int(rising)}", loc,
                    notes=("inputs at 1 now: " + _inputs_text(inputs, grafcet.inputs),),
                )
            after = dict(inputs)
            after[name] = rising
            sit, rounds = machine.react_with_trace(sit, inputs, after)
            inputs = after
        fired = "; ".join(", ".join(t.name for t in r) for r in rounds)
        orders = sorted(machine.orders(sit, inputs), key=grafcet.outputs.index)
        rows.append((text, sit.text(), _orders_text(orders), fired))
    w_event = max(len(r[0]) for r in rows)
    w_sit = max(len(r[1]) for r in rows)
    out = sys.stdout
    for i, (ev, s, orders, fired) in enumerate(rows):
        line = f"{i:<3}{ev:<{w_event}}  {s:<{w_sit}}  orders: {orders}"
        if fired:
            line += f"   fired: {fired}"
        out.write(line.rstrip() + "\n")
    return 0


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", metavar="FILE.g7", help="the Grafcet")
    p.add_argument("--plant", metavar="RULES", help="plant .rules file: its inputs/outputs and initial input values")
    p.add_argument("--initial", metavar="X=1,...", help="initial input values (default: the plant's, else all 0)")


def register(sub: "argparse._SubParsersAction") -> None:
    """Add this stage's sub-commands to the ``synth`` parser."""
    p = sub.add_parser("ass", help="automaton of the stable situations of a Grafcet",
                       description="Build the automaton of the stable situations (ASS) of a Grafcet.")
    _common(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.add_argument("--dot", metavar="FILE", help="write the Graphviz DOT text")
    p.add_argument("--svg", metavar="FILE", help="write an SVG drawing (Graphviz)")
    p.set_defaults(handler=cmd_ass)
    p = sub.add_parser("run", help="simulate a Grafcet event by event",
                       description="Simulate a Grafcet: print each stable situation and its orders.")
    _common(p)
    p.add_argument("--events", metavar="EVENTS", default="",
                   help='comma-separated events: "↑dcy,^cp12,2s/X101,↓v10,_v11"')
    p.set_defaults(handler=cmd_run)

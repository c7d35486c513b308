"""Simulating a Grafcet event by event, as ``synth run`` does: options read with located
errors, the IEC 60848 machine stepped, one row per stable situation.

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet("grafcet G { initial step 0 step 1: A transition 0 -> 1 when ↑a "
...                   "transition 1 -> 0 when !a }", "g.g7")
>>> rows = simulate(g, {"a": False}, parse_events("^a, _a", g))
>>> [(r.event, r.situation.text(), r.orders, r.fired) for r in rows]
[('initial', '{X0}', (), ()), ('↑a', '{X1}', ('A',), (('0->1',),)), ('↓a', '{X0}', (), (('1->0',),))]
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterator, Mapping, Sequence

from synth.errors import InputError, Location, close_names
from synth.grafcet.language import Grafcet, Transition
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.grafcet.situation import OutOfRange, with_trace
from synth.logic.events import FALL_MARKS, RISE_MARKS, Event, EventKind

__all__ = ["SimulationStep", "comma_items", "parse_initial", "parse_events", "simulate", "inputs_text"]


@dataclass(frozen=True)
class SimulationStep:
    """One row of a simulation: the event (``initial`` first), the stable situation it
    led to, the orders emitted there (in output order), the transitions fired per round."""

    event: str
    situation: Situation
    orders: tuple[str, ...]
    fired: tuple[tuple[str, ...], ...]


def comma_items(text: str) -> Iterator[tuple[str, int]]:
    """The non-empty comma-separated items of an option's text, with their 1-based columns.

    >>> list(comma_items("a, b,,c"))
    [('a', 1), ('b', 4), ('c', 7)]
    """
    col = 1
    for part in text.split(","):
        item = part.strip()
        start = col + (len(part) - len(part.lstrip()))
        col += len(part) + 1
        if item:
            yield item, start


def parse_initial(text: str, inputs: Sequence[str]) -> dict[str, bool]:
    """``"v10=1, v20=1"`` (or ``"v10, v20"``) → values; errors point into the option text."""
    out: dict[str, bool] = {}
    for item, start in comma_items(text):
        name, _, value = item.partition("=")
        name = name.strip()
        loc = Location("--initial", 1, start, text, max(1, len(name)))
        if name not in inputs:
            raise InputError(f"unknown input '{name}'", loc, suggestions=close_names(name, inputs))
        if value.strip() not in ("", "0", "1"):
            raise InputError(f"the value of {name} must be 0 or 1", loc)
        out[name] = value.strip() != "0"
    return out





def parse_events(text: str, grafcet: Grafcet) -> list[tuple[Event, Location]]:
    """``"↑dcy, ^cp12, 2s/X101, _v10"`` → ``[(event, location), ...]``; unknown names are
    :class:`InputError` located in the option text, with suggestions."""
    out: list[tuple[Event, Location]] = []
    timers = [t.id for t in grafcet.timers]
    for item, start in comma_items(text):
        loc = Location("--events", 1, start, text, len(item))
        if item[0] in RISE_MARKS + FALL_MARKS:
            rising = item[0] in RISE_MARKS
            name = item[1:].strip()
            if name not in grafcet.inputs:
                raise InputError(
                    f"unknown input '{name}' in event {item}",
                    Location("--events", 1, start + 1, text, max(1, len(name))),
                    suggestions=tuple(item[0] + c for c in close_names(name, grafcet.inputs)),
                    notes=("inputs: " + ", ".join(grafcet.inputs),) if grafcet.inputs else (),
                )
            out.append((Event.edge(name, rising), loc))
        elif item in timers:
            out.append((Event.timer(item), loc))
        else:
            edges = [Event.edge(i, r) for r in (True, False) for i in grafcet.inputs]
            hint = close_names(item, [*timers, *edges])
            raise InputError(
                f"unknown event '{item}'",
                loc,
                suggestions=hint,
                notes=("an event is ↑x / ^x (rising), ↓x / _x (falling) of an input, or a timer of the Grafcet"
                       + (": " + ", ".join(timers) if timers else ""),),
            )
    return out


def inputs_text(values: Mapping[str, bool], names: Sequence[str]) -> str:
    ones = [n for n in names if values[n]]
    return ", ".join(ones) if ones else "-"


MAX_SCANS = 100
"""``--semantics sfc``: at most this many scans without input change are shown after an event."""


def simulate(grafcet: Grafcet, inputs: Mapping[str, bool], events: Sequence[tuple[Event, Location]]) -> list[SimulationStep]:
    """Run ``events`` from the initial situation; an event that cannot happen now (an
    input already at that level, a timer not running) is an :class:`InputError` at its
    place in the option text."""
    machine = GrafcetMachine(grafcet)

    def ordered(sit: Situation) -> tuple[str, ...]:
        return tuple(sorted(machine.orders(sit, inputs), key=grafcet.outputs.index))

    try:
        sit = machine.initial(inputs)
    except OutOfRange as err:
        raise with_trace(err, ()) from None
    rows = [SimulationStep("initial", sit, ordered(sit), ())]

    def scans() -> None:
        """``--semantics sfc``: the PLC scans until no transition is fireable (or the
        situation repeats, as a level self-loop jump does every scan)."""
        nonlocal sit
        seen = {sit}
        while machine.scans(sit, inputs) and len(seen) <= MAX_SCANS:
            sit, rounds = machine.scan(sit, inputs)
            rows.append(SimulationStep(str(Event.scan()), sit, ordered(sit), tuple(tuple(t.name for t in r) for r in rounds)))
            if sit in seen:
                return
            seen.add(sit)

    for event, loc in events:
        scans()
        try:
            sit, rounds, inputs = _one_event(machine, grafcet, sit, inputs, event, loc)
        except OutOfRange as err:
            raise with_trace(err, [r.event for r in rows[1:]] + [str(event)]) from None
        rows.append(SimulationStep(str(event), sit, ordered(sit), tuple(tuple(t.name for t in r) for r in rounds)))
    scans()
    return rows


def _one_event(machine: GrafcetMachine, grafcet: Grafcet, sit: Situation, inputs: Mapping[str, bool],
               event: Event, loc: Location) -> tuple[Situation, tuple[tuple[Transition, ...], ...], Mapping[str, bool]]:
    """The situation after ``event``, the rounds fired, the inputs after it."""
    if event.kind is EventKind.TIMER:
        if machine.timer_event(event) not in machine.timers(sit):
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
        if inputs[event.name] == event.rising:
            raise InputError(
                f"{event} cannot happen: {event.name} is already {int(event.rising)}", loc,
                notes=("inputs at 1 now: " + inputs_text(inputs, grafcet.inputs),),
            )
        after = dict(inputs)
        after[event.name] = event.rising
        sit, rounds = machine.react_with_trace(sit, inputs, after)
        inputs = after
    return sit, rounds, inputs

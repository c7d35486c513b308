"""Diagnosis: the analysis the thesis leaves to a human (docs/method.md, diagnosis).

For a blocking state: which receptivities are awaited; which sensor events would make
each one true; which orders cause those events, through which rules of which element;
whether the situation emits those orders and whether SUP authorises them there, and if
not which constraints forbid them. From that a verdict in plain words:

- ``never_starts``: the Grafcet never leaves its initial steps (with the verdict on
  the initial situation as its ``cause``);
- ``missing_order``: an order that would cause the awaited event is not emitted;
- ``prohibited_order``: it is emitted but SUP forbids it (wrong control, or over-strict
  constraint; in expert mode the Grafcet is trusted, so the constraint is blamed);
- ``element_model`` (expert mode): the orders are emitted and authorised, yet the
  element's rules never produce the awaited event from its current state;
- ``unproducible_event``: no rule of any element produces the awaited event;
- ``livelock``: the awaited event comes with the orders as they are: the Grafcet keeps
  running in a loop of situations that never meets a home state (``--home``);
- ``trap``: the Grafcet still moves on operator inputs, in a closed loop of situations;
- ``dead_end``: no transition leaves the active steps;
- ``waiting``: the situation only waits on other steps (see the other grafcets' verdicts).
"""

from __future__ import annotations

from dataclasses import field
from enum import StrEnum
from itertools import combinations
from typing import Any, Iterable, Sequence

from synth.frozen import frozen
from synth.grafcet.language import step_variable
from synth.logic.events import Event
from synth.plant.composition import Plant
from synth.plant.element import ElementAutomaton
from synth.plant.rules import VarKind
from synth.validation.analysis import Analysis
from synth.validation.sync import Node, Prohibition, Sync

__all__ = ["Verdict", "Cause", "Awaited", "Diagnosis", "diagnose", "diagnose_never_starts", "diagnose_prohibition",
           "diagnose_all"]


class Verdict(StrEnum):
    """The verdict on a blocking state, most specific first (the cascade's order)."""

    NEVER_STARTS = "never_starts"
    DEAD_END = "dead_end"
    PROHIBITED_ORDER = "prohibited_order"
    LIVELOCK = "livelock"
    ELEMENT_MODEL = "element_model"
    MISSING_ORDER = "missing_order"
    TRAP = "trap"
    UNPRODUCIBLE_EVENT = "unproducible_event"
    WAITING = "waiting"
    UNKNOWN = "unknown"


@frozen
class Cause:
    """How an awaited sensor event could happen, seen from its element."""

    event: Event
    element: str | None
    changes: tuple[Event, ...] = ()  # order changes needed (↑AVANCER2)
    rules: tuple[str, ...] = ()  # rules producing the event
    emitted: bool = False  # the situation asks for those changes
    authorised: bool = True  # SUP allows them here
    constraints: tuple[str, ...] = ()  # constraints forbidding them
    producible_now: bool = False  # under the current orders the element can produce it
    free: bool = False  # an operator input: it may change at any time

    def as_dict(self) -> dict[str, Any]:
        return {
            "event": self.event,
            "element": self.element,
            "orders": list(self.changes),
            "rules": list(self.rules),
            "emitted": self.emitted,
            "authorised": self.authorised,
            "constraints": list(self.constraints),
            "producible_now": self.producible_now,
            "free": self.free,
        }


@frozen
class Awaited:
    """A transition a blocked Grafcet waits on, and why it cannot fire."""

    transition: str
    grafcet: str
    receptivity: str
    events: tuple[Event, ...]  # input events that would make it true (one event each)
    steps: tuple[str, ...] = ()  # step variables it waits on, not active
    causes: tuple[Cause, ...] = ()
    sources: tuple[str, ...] = ()  # the transition's source steps
    first: tuple[Event, ...] = ()  # no single event suffices: the changes needed first (causes are theirs)
    last: Event | None = None  # ... and the change that then makes it true

    def as_dict(self) -> dict[str, Any]:
        return {
            "transition": self.transition,
            "grafcet": self.grafcet,
            "steps": list(self.sources),
            "receptivity": self.receptivity,
            "events": list(self.events),
            "waits_on_steps": list(self.steps),
            "causes": [c.as_dict() for c in self.causes],
            **({"first": list(self.first), "then": self.last} if self.first else {}),
        }


@frozen
class Diagnosis:
    """The verdict on a blocking situation (or a Grafcet that never starts), its summary and its causes."""

    verdict: Verdict
    summary: str
    awaited: tuple[Awaited, ...] = ()
    details: tuple[str, ...] = field(default=())
    cause: Verdict | None = None  # for never_starts: the verdict on the initial situation

    def as_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "verdict": self.verdict,
            "summary": self.summary,
            "awaited": [a.as_dict() for a in self.awaited],
            "details": list(self.details),
        }
        if self.cause is not None:
            d["cause"] = self.cause
        return d


def _element_cause(sync: Sync, node: Node, event: Event) -> Cause:
    """How ``event`` (an edge of a plant variable) could happen from ``node``: the fewest
    order changes after which its element produces it on its own, and whether the
    situation asks for them and SUP allows them here."""
    p: Plant = sync.plant
    if event.name not in p.owner:
        return Cause(event, None)
    axis = p.owner[event.name]
    a = p.elements[axis]
    spec = a.spec
    decl = spec.variable(event.name)
    if decl is not None and decl.kind == VarKind.FREE:
        return Cause(event, a.name, producible_now=True, free=True)
    rules = tuple(r.text() for r in spec.rules if r.consequence.event == event)
    k = node.plant[axis]
    # no order change needed: it happens with the orders as they are (in the plant, if a reads)
    if a.produces(k, event) and (a.guards is None or p.drifts_to(node.plant, event)):
        return Cause(event, a.name, (), rules, emitted=True, authorised=True, producible_now=True)
    best = _fewest_changes(a, k, event, [v.name for v in spec.orders if not v.held])
    if best is None:
        return Cause(event, a.name, (), rules)
    emitted = all(ch.rising == (ch.name in node.emitted) for ch in best)
    constraints: list[str] = []
    authorised = True
    proh = {pr.event: pr for pr in node.proh}
    for ch in best:
        if ch in proh:
            authorised = False
            constraints += [c for c in proh[ch].constraints if c not in constraints]
            continue
        for t in p.transitions:
            if t.controllable and t.event == ch and t.src == node.plant[t.axis]:
                ok, why = sync.oracle.move(t, node.plant)
                if not ok:
                    authorised = False
                    constraints += [c for c in why if c not in constraints]
    return Cause(event, a.name, best, rules, emitted, authorised, tuple(constraints))


def _fewest_changes(a: ElementAutomaton, k: int, event: Event, orders: Sequence[str]) -> tuple[Event, ...] | None:
    """The smallest set of order changes (first in ``orders`` order) after which element
    ``a``, in local state ``k``, produces ``event`` by itself; None if none does."""
    for n_changes in range(1, len(orders) + 1):
        for subset in combinations(orders, n_changes):
            j = a.flipped(k, subset)
            if j is not None and a.produces(j, event):
                return tuple(Event.edge(o, a.is_true(j, o)) for o in subset)
    return None


def _emitting_steps(sync: Sync, node: Node, order: str) -> tuple[str, ...]:
    """The active steps of ``node`` with an action on ``order``."""
    emitting = {s.name for s in sync.machine.grafcet.steps if any(act.order == order for act in s.actions)}
    return tuple(s for s in node.situation.steps if s in emitting)


def _labels(sync: Sync) -> dict[str, str]:
    return {c.id: c.label for c in sync.oracle.constraints}


def _named(sync: Sync, ids: Iterable[str]) -> str:
    labels = _labels(sync)
    return ", ".join(f'{i} "{labels[i]}"' if labels.get(i) else i for i in ids)


def diagnose(sync: Sync, node_index: int, *, expert: bool = False, component: Sequence[int] = ()) -> Diagnosis:
    """The diagnosis of a blocking node (see module docstring); ``component`` is the
    terminal component it belongs to (the states it can still move between)."""
    node = sync.nodes[node_index]
    awaited: list[Awaited] = []
    machine = sync.machine
    inputs = sync.inputs(node.plant)
    for t in machine.awaited(node.situation):
        events = machine.enabling_events(node.situation, t, inputs)
        if not events:  # an input together with a timer of an active step: once time has passed
            events = machine.enabling_events(node.situation, t, inputs, after_time=True)
        steps = machine.waiting_steps(node.situation, t)
        first, last = ((), None) if events else machine.first_events(node.situation, t, inputs, after_time=True)
        causes = tuple(_element_cause(sync, node, e) for e in events or first)
        awaited.append(Awaited(t.name, t.grafcet, t.receptivity.text(), events, steps, causes, tuple(t.sources),
                               first, last))
    details = []
    waiting = []
    stuck = []
    for a in awaited:
        if a.first:
            details.append(f"transition {a.transition} of {a.grafcet} awaits {a.receptivity}: no single input change "
                           f"makes it true; it needs {', '.join(a.first)} first, then {a.last}")
        elif not a.events:
            if a.steps:
                waiting.append(f"{a.grafcet} {a.transition} ({', '.join(a.steps)})")
            else:
                stuck.append(f"{a.grafcet} {a.transition} ({a.receptivity})")
            continue
        else:
            details.append(f"transition {a.transition} of {a.grafcet} awaits {a.receptivity}: "
                           f"it becomes true with {' or '.join(a.events)}")
        for c in a.causes:
            if c.element is None:
                details.append(f"  {c.event}: no plant element drives {c.event.name}")
                continue
            if c.free:
                details.append(f"  {c.event}: an operator input, it may change at any time")
                continue
            rules = "; ".join(c.rules) if c.rules else "no rule"
            if c.producible_now:
                details.append(f"  {c.event} (element {c.element}) occurs with the orders as they are; rules: {rules}")
            elif c.changes:
                state = "emitted" if c.emitted else "not emitted"
                sup = "authorised by SUP" if c.authorised else f"prohibited by {_named(sync, c.constraints)}"
                details.append(f"  {c.event} (element {c.element}) needs {', '.join(c.changes)}: {state}, {sup}; rules: {rules}")
            else:
                details.append(f"  {c.event} (element {c.element}) cannot be produced from its current state; rules: {rules}")
    if waiting:
        details.append("waiting on steps: " + "; ".join(waiting))
    if stuck:
        details.append("no input change can make true: " + "; ".join(stuck))
    verdict, summary = _verdict(sync, node, awaited, expert, component)
    return Diagnosis(verdict, summary, tuple(awaited), tuple(details))


def _verdict(
    sync: Sync, node: Node, awaited: list[Awaited], expert: bool, component: Sequence[int]
) -> tuple[Verdict, str]:
    p = sync.plant
    if not awaited:
        active = ", ".join(node.situation.step_variables)
        return (
            Verdict.DEAD_END,
            f"no transition leaves the active steps {{{active}}}: the Grafcet stops here and never returns "
            "to its initial situation",
        )
    free = [(a, c) for a in awaited for c in a.causes if c.free]
    items = [(a, c) for a in awaited for c in a.causes if not c.free]

    def context(a: Awaited) -> str:
        return f"transition {a.transition} of {a.grafcet} awaits {a.receptivity}"

    def by_rule(c: Cause) -> str:
        """The element, and its first rule producing the event whose cause is a needed change."""
        spec = p.elements[p.owner[c.event.name]].spec
        causing = [r.text() for r in spec.rules if r.cause.text() in c.changes and r.consequence.text() == c.event]
        rules = causing or list(c.rules)
        return f"element {c.element}" + (f", rule {rules[0]}" if rules else "")

    # 1. an order the awaited event needs is emitted but prohibited by SUP
    for a, c in items:
        if c.changes and c.emitted and not c.authorised:
            order = c.changes[0].name
            steps = _emitting_steps(sync, node, order)
            where = f" in step {', '.join(steps)}" if steps else ""
            who = (
                "the Grafcet is trusted, so the constraint is over-strict"
                if expert
                else "wrong control or over-strict constraint"
            )
            return (
                Verdict.PROHIBITED_ORDER,
                f"order {order}{where} prohibited by {_named(sync, c.constraints)}: {context(a)}, "
                f"which needs {c.event}, caused by {order} ({by_rule(c)}); SUP forbids {c.changes[0]} here: {who}",
            )
    # the awaited event comes by itself: the Grafcet moves on, in a loop that never meets a home
    for a, c in items:
        if c.producible_now:
            step_sets = sorted({sync.nodes[i].situation.steps for i in component} or {node.situation.steps})
            loop = " → ".join("{" + ", ".join(step_variable(x) for x in st) + "}" for st in step_sets)
            home = " & ".join(step_variable(x) for x in node.situation.steps)
            return (
                Verdict.LIVELOCK,
                f"the Grafcet keeps running through {loop} and never returns to a home state: {context(a)}, "
                f"and {c.event} occurs with the orders as they are (element {c.element}); if this loop is the "
                f'intended cycle, declare its home with --home "{home}"',
            )
    # prohibited orders of the situation that nothing above explained
    if node.proh and expert:
        pr = node.proh[0]
        return (
            Verdict.PROHIBITED_ORDER,
            f"order {pr.order} prohibited by {_named(sync, pr.constraints)}: the trusted Grafcet emits it "
            f"and SUP forbids {pr.event} here, so the constraint is over-strict",
        )
    # 2. expert: orders emitted and authorised, the element cannot produce the event
    if expert:
        for a, c in items:
            if c.element is None or c.producible_now:
                continue
            axis = p.owner[c.event.name]
            el = p.elements[axis]
            own_orders = [o for o in el.variables if o in el.orders]
            emitted_here = [o for o in own_orders if o in node.emitted]
            if emitted_here and not any(pr.order in own_orders for pr in node.proh):
                state = el.state_label(node.plant[axis])
                moves = el.drift(node.plant[axis])
                drift = f"; under these orders it only does {', '.join(moves)}" if moves else "; under these orders it does not move"
                return (
                    Verdict.ELEMENT_MODEL,
                    f"element {c.element} cannot produce the awaited {c.event}: {', '.join(emitted_here)} "
                    f"{'is' if len(emitted_here) == 1 else 'are'} emitted and authorised, {c.element} is in {state}, "
                    f"and no rule of {c.element} produces {c.event} there: an occurrence rule is missing or its guard "
                    f"is wrong ({context(a)}){drift}",
                )
    # 3. designer: an order the awaited event needs is not emitted
    for a, c in items:
        if c.changes and not c.emitted:
            ch = c.changes[0]
            order = ch.name
            steps = a.sources
            step_text = f" in step {', '.join(steps)}" if steps else ""
            sup = "SUP authorises it here" if c.authorised else f"SUP forbids it here ({_named(sync, c.constraints)})"
            if ch.rising:
                return (
                    Verdict.MISSING_ORDER,
                    f"missing order {order}{step_text}: {context(a)}, which needs {c.event}; "
                    f"only {order} causes {c.event} ({by_rule(c)}) and {sup}",
                )
            return (
                Verdict.MISSING_ORDER,
                f"order {order} must be released{step_text}: {context(a)}, which needs {c.event}; "
                f"{c.event} only follows {ch} ({by_rule(c)}) and {sup}",
            )
    # 4. the Grafcet still moves, on operator inputs, but in a closed set of situations
    if free:
        sits = sorted({sync.nodes[i].situation for i in component} or {node.situation})
        events = sorted({c.event for _, c in free})
        return (
            Verdict.TRAP,
            f"the Grafcet keeps evolving on operator inputs ({', '.join(events)}) between "
            f"{', '.join(s.text() for s in sits)} but can never return to its initial situation: "
            f"a loop with no way out ({context(free[0][0])})",
        )
    # 5. events nobody produces
    for a, c in items:
        if not c.changes and not c.rules:
            owner = f"element {c.element}" if c.element else "no element"
            return (
                Verdict.UNPRODUCIBLE_EVENT,
                f"awaited event {c.event} can never occur: {context(a)} and {owner} has no rule producing {c.event}",
            )
    for a, c in items:
        if not c.changes:
            return (
                Verdict.UNPRODUCIBLE_EVENT,
                f"awaited event {c.event} cannot occur from the current state of element {c.element}: {context(a)}",
            )
    if node.proh:
        pr = node.proh[0]
        return (
            Verdict.PROHIBITED_ORDER,
            f"order {pr.order} prohibited by {_named(sync, pr.constraints)}: the situation emits it and SUP forbids {pr.event}",
        )
    waits = sorted({s for a in awaited for s in a.steps})
    if waits:
        return (Verdict.WAITING, f"the situation only waits on steps {', '.join(waits)}, which can no longer become active")
    return (Verdict.UNKNOWN, "no awaited receptivity can become true and no order change is prohibited")


def diagnose_never_starts(sync: Sync, *, expert: bool = False) -> Diagnosis:
    """The diagnosis of a Grafcet that never leaves its initial steps: what the first
    initial aggregated state awaits, and why it does not come (timers of the initial
    steps play no part: the state diagnosed is the one before any elapses)."""
    first = sync.initial[0]
    d = diagnose(sync, first, expert=expert, component=range(len(sync.nodes)))
    steps = ", ".join(sync.nodes[first].situation.step_variables)
    return Diagnosis(
        Verdict.NEVER_STARTS,
        f"the Grafcet never leaves its initial steps {{{steps}}}: {d.summary}",
        d.awaited,
        d.details,
        cause=d.verdict,
    )


def diagnose_prohibition(sync: Sync, node_index: int, pr: Prohibition) -> str:
    """Plain words for a prohibited order met on the way."""
    node = sync.nodes[node_index]
    order = pr.order
    steps = _emitting_steps(sync, node, order)
    where = f" by step {', '.join(steps)}" if steps else ""
    verb = "emitted" if pr.event.rising else "released"
    return (
        f"order {order} {verb}{where} in situation {node.situation.text()} is prohibited by "
        f"{_named(sync, pr.constraints)}: SUP forbids {pr.event} there"
    )



def diagnose_all(sync: Sync, analysis: Analysis, *, expert: bool = False
                 ) -> tuple[dict[int, Diagnosis], Diagnosis | None, dict[int, tuple[str, ...]]]:
    """Every diagnosis a validation shows, computed once: each blocking state's, the
    never-starts one (None when the Grafcet starts), and for each prohibited node the
    words for each order change refused there (in the order of ``proh``)."""
    blocking = {b: diagnose(sync, b, expert=expert, component=analysis.components[b]) for b in analysis.blocking}
    never = diagnose_never_starts(sync, expert=expert) if analysis.never_starts else None
    prohibitions = {i: tuple(diagnose_prohibition(sync, i, pr) for pr in sync.nodes[i].proh) for i in analysis.prohibited}
    return blocking, never, prohibitions

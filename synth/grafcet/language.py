"""The Grafcet language (``.g7``) as plain frozen data: partial grafcets, steps with their
actions, transitions with their receptivities, gathered in a :class:`Grafcet`.

:mod:`synth.grafcet.language_reader` turns the text into items;
:mod:`synth.grafcet.language_check` checks them (``load_grafcet`` / ``parse_grafcet``).
The syntax is described in ``docs/grafcet.md``.

Receptivities and action conditions are :mod:`synth.logic.expr` expressions in which

* a plant input is ``Var("dcy")``, its edges ``Edge(True, "dcy")`` (``↑dcy``);
* a step variable is ``Var("X12")`` (true while step ``12`` is active);
* a timer is ``Var("2s/X101")`` (true once step ``101`` has been active for 2 s).

Example
-------
>>> from synth.logic.expr import Edge
>>> t = Transition("t1", ("0",), ("1",), Edge(True, "dcy"), "G1")
>>> steps = (Step("0", "G1", initial=True), Step("1", "G1", actions=(Action(CONTINUOUS, "TAPIS"),)))
>>> g = Grafcet((PartialGrafcet("G1", steps, (t,)),), inputs=("dcy",), outputs=("TAPIS",))
>>> g.initial_steps, t.text(), g.step("1").actions[0].text()
(('0',), 't1: 0 -> 1 when ↑dcy', 'TAPIS')
"""

from __future__ import annotations

import re
from fractions import Fraction
from dataclasses import field
from enum import StrEnum
from typing import Collection, Iterator, Mapping, Sequence

from synth.errors import Location
from synth.frozen import frozen
from synth.logic.expr import Expr, Var, evaluate, names

__all__ = [
    "STEP_PREFIX",
    "TIMER_RE",
    "duration_seconds",
    "DURATION_RE",
    "step_variable",
    "step_of",
    "ActionKind",
    "StoredWhen",
    "Semantics",
    "CONTINUOUS",
    "CONDITIONAL",
    "STORED",
    "ON_ACTIVATION",
    "ON_DEACTIVATION",
    "ON_EVENT",
    "Action",
    "ASSIGN",
    "Internal",
    "Sum",
    "Step",
    "Timer",
    "Transition",
    "PartialGrafcet",
    "Grafcet",
    "receptivity_inputs",
    "expr_inputs",
    "step_key",
    "timer_id",
]

class ActionKind(StrEnum):
    """How an action emits its order (IEC 60848)."""

    CONTINUOUS = "continuous"
    CONDITIONAL = "conditional"
    STORED = "stored"
    ASSIGN = "assign"


class StoredWhen(StrEnum):
    """When a stored action runs."""

    ACTIVATION = "activation"
    DEACTIVATION = "deactivation"
    EVENT = "event"


class Semantics(StrEnum):
    """How the Grafcet evolves (docs/grafcet.md, "Semantics"): IEC 60848 with search for
    stability (``grafcet``, the default), or IEC 61131-3 SFC, one evolution per PLC scan (``sfc``)."""

    GRAFCET = "grafcet"
    SFC = "sfc"


CONTINUOUS, CONDITIONAL, STORED = ActionKind.CONTINUOUS, ActionKind.CONDITIONAL, ActionKind.STORED
ASSIGN = ActionKind.ASSIGN
ON_ACTIVATION, ON_DEACTIVATION, ON_EVENT = StoredWhen.ACTIVATION, StoredWhen.DEACTIVATION, StoredWhen.EVENT

# a timer atom: duration, unit and step, e.g. ``2s/X101``
DURATION = r"([0-9]+(?:\.[0-9]+)?)(ms|s|min|h)"
"""A duration as ``.g7`` writes it (``2s``, ``700ms``, ``1.5min``): its number and its unit."""
DURATION_RE = re.compile(DURATION)
TIMER_RE = re.compile(rf"^{DURATION}/X([A-Za-z0-9_]+)$")
_SECONDS = {"ms": Fraction(1, 1000), "s": Fraction(1), "min": Fraction(60), "h": Fraction(3600)}


def duration_seconds(number: str, unit: str) -> Fraction:
    """A duration as an exact number of seconds, so that equal durations compare equal.

    >>> duration_seconds("700", "ms") == duration_seconds("0.7", "s"), duration_seconds("2", "min")
    (True, Fraction(120, 1))
    """
    return Fraction(number) * _SECONDS[unit]


STEP_PREFIX = "X"  # the step variable of step 12 is X12 (IEC 60848)


def step_variable(step: str) -> str:
    """The name of ``step``'s step variable: ``step_variable("12") == "X12"``."""
    return STEP_PREFIX + step


def step_of(name: str, steps: Collection[str]) -> str | None:
    """The step whose variable ``name`` is, if it is one of ``steps``.

    >>> step_of("X12", {"12", "3"}), step_of("Xa", {"12"})
    ('12', None)
    """
    if name.startswith(STEP_PREFIX) and name[len(STEP_PREFIX):] in steps:
        return name[len(STEP_PREFIX):]
    return None


def step_key(name: str) -> tuple[int, int, str]:
    """Sort key of step names: numbers numerically first, then identifiers.

    >>> sorted(["10", "2", "a", "X"], key=step_key)
    ['2', '10', 'X', 'a']
    """
    return (0, int(name), name) if name.isdigit() else (1, 0, name)


def timer_id(duration: str, step: str) -> str:
    """The canonical text of a timer atom, e.g. ``timer_id("2s", "101") == "2s/X101"``."""
    return f"{duration}/X{step}"


@frozen
class Internal:
    """An internal variable: ``internal cnt : 0..3 = 0`` (bounded integer) or
    ``internal busy : bool`` (Boolean, held as 0/1). Only assignments change it.

    >>> Internal("cnt", 0, 3, 0).text(), Internal("busy", 0, 1, 0, boolean=True).text()
    ('internal cnt : 0..3 = 0', 'internal busy : bool = 0')
    """

    name: str
    low: int
    high: int
    initial: int
    boolean: bool = False
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        kind = "bool" if self.boolean else f"{self.low}..{self.high}"
        return f"internal {self.name} : {kind} = {self.initial}"


@frozen
class Sum:
    """The right side of an assignment: signed terms, each a constant or an internal variable.

    >>> e = Sum(((1, "cnt"), (1, 1)))
    >>> e.text(), e.value({"cnt": 2}), Sum(((1, "cnt"), (-1, 1))).text(), Sum(((-1, 2),)).text()
    ('cnt + 1', 3, 'cnt - 1', '-2')
    """

    terms: tuple[tuple[int, int | str], ...]
    loc: Location | None = field(default=None, compare=False)
    expr: Expr | None = None  # a Boolean's right side written as an expression: ``(a & !b)``

    def text(self) -> str:
        if self.expr is not None:
            return f"({self.expr.text()})"
        out = ""
        for i, (sign, x) in enumerate(self.terms):
            if i:
                out += " + " if sign > 0 else " - "
            elif sign < 0:
                out += "-"
            out += str(x)
        return out

    def names(self) -> tuple[str, ...]:
        if self.expr is not None:
            return tuple(dict.fromkeys(n.name for n in names(self.expr)))
        return tuple(x for _, x in self.terms if isinstance(x, str))

    def value(self, values: Mapping[str, int]) -> int:
        if self.expr is not None:
            return int(bool(evaluate(self.expr, lambda n: values[n] != 0)))
        return sum(sign * (values[x] if isinstance(x, str) else x) for sign, x in self.terms)


@frozen
class Action:
    """An action attached to a step.

    * continuous: ``TAPIS`` (emitted while the step is active in a stable situation);
    * conditional: ``AVANCER1 if v10`` (the same, when ``condition`` holds);
    * stored: ``set M on activation`` / ``reset M on deactivation`` / ``set M on ↑cp12``
      (``value`` is True for set; ``when`` is activation, deactivation or event;
      ``condition`` is the event expression for ``on <event>``);
    * assignment: ``cnt := cnt + 1 on activation`` (``order`` is the internal variable,
      ``assign`` the value, ``when``/``condition`` as for stored actions).
    """

    kind: ActionKind
    order: str
    condition: Expr | None = None
    value: bool = True
    when: StoredWhen | None = None
    loc: Location | None = field(default=None, compare=False)
    assign: Sum | None = None

    def text(self) -> str:
        if self.kind == ASSIGN:
            assert self.assign is not None
            moment = self.condition.text() if self.when == ON_EVENT and self.condition is not None else self.when
            return f"{self.order} := {self.assign.text()} on {moment}"
        if self.kind == CONTINUOUS:
            return self.order
        if self.kind == CONDITIONAL:
            assert self.condition is not None
            return f"{self.order} if {self.condition.text()}"
        verb = "set" if self.value else "reset"
        if self.when == ON_EVENT:
            assert self.condition is not None
            return f"{verb} {self.order} on {self.condition.text()}"
        return f"{verb} {self.order} on {self.when}"


@frozen
class Step:
    """A step: its name (``12`` or ``wait``), partial grafcet, initial flag and actions."""

    name: str
    grafcet: str
    initial: bool = False
    actions: tuple[Action, ...] = ()
    loc: Location | None = field(default=None, compare=False)

    @property
    def variable(self) -> str:
        """The step variable's name, ``X12``."""
        return step_variable(self.name)


@frozen
class Timer:
    """A timer atom ``2s/X101``: true once step ``101`` has been active for ``seconds``."""

    id: str
    step: str
    seconds: Fraction  # exact: 700ms and 0.7s are the same duration
    loc: Location | None = field(default=None, compare=False)


@frozen
class Transition:
    """A transition: source steps, target steps, receptivity, partial grafcet.

    An AND divergence has several targets, an AND convergence several sources; a source
    transition has no source step and a sink transition no target step.
    """

    label: str | None
    sources: tuple[str, ...]
    targets: tuple[str, ...]
    receptivity: Expr
    grafcet: str
    loc: Location | None = field(default=None, compare=False)

    @property
    def name(self) -> str:
        """Display name: ``t1``, ``(4)`` for a numbered transition, else ``101->102``."""
        if self.label is not None:
            return f"({self.label})" if self.label.isdigit() else self.label
        return ",".join(self.sources) + "->" + ",".join(self.targets)

    def text(self) -> str:
        return f"{self.name}: {', '.join(self.sources)} -> {', '.join(self.targets)} when {self.receptivity.text()}"


@frozen
class PartialGrafcet:
    """One partial grafcet (``grafcet G1 { ... }``): its steps and transitions."""

    name: str
    steps: tuple[Step, ...]
    transitions: tuple[Transition, ...]
    loc: Location | None = field(default=None, compare=False)


@frozen
class Grafcet:
    """A checked Grafcet program.

    ``inputs`` are the controller inputs (the plant's when one was given, else the
    declared or inferred ones); ``outputs`` likewise. ``steps``/``transitions`` list every
    partial grafcet's, in file order.
    """

    grafcets: tuple[PartialGrafcet, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    timers: tuple[Timer, ...] = ()
    path: str = "<grafcet>"
    internals: tuple[Internal, ...] = ()
    semantics: Semantics = Semantics.GRAFCET

    @property
    def steps(self) -> tuple[Step, ...]:
        return tuple(s for g in self.grafcets for s in g.steps)

    @property
    def transitions(self) -> tuple[Transition, ...]:
        return tuple(t for g in self.grafcets for t in g.transitions)

    def step(self, name: str) -> Step:
        for s in self.steps:
            if s.name == name:
                return s
        raise KeyError(name)

    @property
    def initial_steps(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.steps if s.initial)

    def expressions(self) -> Iterator[Expr]:
        """Every Boolean expression of the Grafcet: receptivities, then action conditions."""
        for t in self.transitions:
            yield t.receptivity
        for s in self.steps:
            for a in s.actions:
                if a.condition is not None:
                    yield a.condition

    @property
    def read_inputs(self) -> tuple[str, ...]:
        """Inputs the Grafcet actually reads (receptivities, conditions, events), in ``inputs`` order."""
        used: set[str] = set()
        for x in self.expressions():
            used.update(expr_inputs(x, self.inputs))
        return tuple(i for i in self.inputs if i in used)


def expr_inputs(e: Expr, inputs: Sequence[str]) -> tuple[str, ...]:
    """The input names ``e`` reads (levels and edges), unique, in text order."""
    known = set(inputs)
    out: list[str] = []
    for n in names(e):
        if n.name in known and n.name not in out:
            out.append(n.name)
    return tuple(out)


def receptivity_inputs(t: Transition, inputs: Sequence[str] | None = None) -> tuple[str, ...]:
    """Plant input names the receptivity of ``t`` uses (not step variables, not timers).

    Without ``inputs``, every name that is not ``X<step>``-like or a timer is taken.
    """
    if inputs is not None:
        return expr_inputs(t.receptivity, inputs)
    out: list[str] = []
    for n in names(t.receptivity):
        if TIMER_RE.match(n.name) or (isinstance(n, Var) and n.name.startswith("X") and n.name[1:].isdigit()):
            continue
        if n.name not in out:
            out.append(n.name)
    return tuple(out)

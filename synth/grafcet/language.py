"""The Grafcet language (``.g7``): parsing and checking into a frozen model.

``load_grafcet(path)`` reads a ``.g7`` file and returns an immutable
:class:`Grafcet` (partial grafcets, steps with their actions, transitions with
their receptivities). Every mistake is an :class:`~synth.errors.InputError`
pointing at the offending token. The syntax is described in ``docs/grafcet.md``.

Receptivities and action conditions are :mod:`synth.logic.expr` expressions in which

* a plant input is ``Var("dcy")``, its edges ``Edge(True, "dcy")`` (``↑dcy``);
* a step variable is ``Var("X12")`` (true while step ``12`` is active);
* a timer is ``Var("2s/X101")`` (true once step ``101`` has been active for 2 s).

Example
-------
>>> g = parse_grafcet('''
... grafcet G1 {
...   initial step 0
...   step 1: TAPIS
...   transition t1: 0 -> 1 when ↑dcy
...   transition 1 -> 0 when /dcy . X1
... }
... ''', "demo.g7")
>>> g.inputs, g.outputs
(('dcy',), ('TAPIS',))
>>> [(t.name, t.sources, t.targets, t.receptivity.text()) for t in g.transitions]
[('t1', ('0',), ('1',), '↑dcy'), ('1->0', ('1',), ('0',), '!dcy & X1')]
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator, Sequence

from lark import Token, UnexpectedInput

from synth.errors import InputError, InputErrors, Location, close_names, location_in
from synth.logic.expr import Const, Edge, Expr, Var, names
from synth.syntax import ExprTransformer, parser, read_source, syntax_error

__all__ = [
    "CONTINUOUS",
    "CONDITIONAL",
    "STORED",
    "ON_ACTIVATION",
    "ON_DEACTIVATION",
    "ON_EVENT",
    "Action",
    "Step",
    "Timer",
    "Transition",
    "PartialGrafcet",
    "Grafcet",
    "parse_grafcet",
    "load_grafcet",
    "receptivity_inputs",
    "expr_inputs",
    "step_key",
    "timer_id",
]

CONTINUOUS, CONDITIONAL, STORED = "continuous", "conditional", "stored"
ON_ACTIVATION, ON_DEACTIVATION, ON_EVENT = "activation", "deactivation", "event"

_TIMER_RE = re.compile(r"^([0-9]+(?:\.[0-9]+)?)(ms|s|min|h)/X([A-Za-z0-9_]+)$")
_SECONDS = {"ms": 0.001, "s": 1.0, "min": 60.0, "h": 3600.0}


def step_key(name: str) -> tuple[int, int, str]:
    """Sort key of step names: numbers numerically first, then identifiers.

    >>> sorted(["10", "2", "a", "X"], key=step_key)
    ['2', '10', 'X', 'a']
    """
    return (0, int(name), name) if name.isdigit() else (1, 0, name)


def timer_id(duration: str, step: str) -> str:
    """The canonical text of a timer atom, e.g. ``timer_id("2s", "101") == "2s/X101"``."""
    return f"{duration}/X{step}"


@dataclass(frozen=True)
class Action:
    """An action attached to a step.

    * continuous: ``TAPIS`` (emitted while the step is active in a stable situation);
    * conditional: ``AVANCER1 if v10`` (the same, when ``condition`` holds);
    * stored: ``set M on activation`` / ``reset M on deactivation`` / ``set M on ↑cp12``
      (``value`` is True for set; ``when`` is activation, deactivation or event;
      ``condition`` is the event expression for ``on <event>``).
    """

    kind: str
    order: str
    condition: Expr | None = None
    value: bool = True
    when: str = ""
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
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


@dataclass(frozen=True)
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
        return "X" + self.name


@dataclass(frozen=True)
class Timer:
    """A timer atom ``2s/X101``: true once step ``101`` has been active for ``seconds``."""

    id: str
    step: str
    seconds: float
    loc: Location | None = field(default=None, compare=False)


@dataclass(frozen=True)
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


@dataclass(frozen=True)
class PartialGrafcet:
    """One partial grafcet (``grafcet G1 { ... }``): its steps and transitions."""

    name: str
    steps: tuple[Step, ...]
    transitions: tuple[Transition, ...]
    loc: Location | None = field(default=None, compare=False)


@dataclass(frozen=True)
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

    @property
    def read_inputs(self) -> tuple[str, ...]:
        """Inputs the Grafcet actually reads (receptivities, conditions, events), in ``inputs`` order."""
        used: set[str] = set()
        for x in _all_exprs(self):
            used.update(expr_inputs(x, self.inputs))
        return tuple(i for i in self.inputs if i in used)


def _all_exprs(g: Grafcet) -> Iterator[Expr]:
    for t in g.transitions:
        yield t.receptivity
    for s in g.steps:
        for a in s.actions:
            if a.condition is not None:
                yield a.condition


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
        if _TIMER_RE.match(n.name) or (isinstance(n, Var) and n.name.startswith("X") and n.name[1:].isdigit()):
            continue
        if n.name not in out:
            out.append(n.name)
    return tuple(out)


# --------------------------------------------------------------------------- parsing


@dataclass(frozen=True)
class _Decl:
    kind: str  # "inputs" | "outputs"
    names: tuple[tuple[str, Location], ...]


@dataclass(frozen=True)
class _StepRef:
    name: str
    loc: Location


@dataclass(frozen=True)
class _Step:
    name: str
    initial: bool
    actions: tuple[Action, ...]
    loc: Location


@dataclass(frozen=True)
class _Trans:
    label: str | None
    label_loc: Location | None
    sources: tuple[_StepRef, ...]
    targets: tuple[_StepRef, ...]
    receptivity: Expr
    loc: Location


@dataclass(frozen=True)
class _Graf:
    name: str
    steps: tuple[_Step, ...]
    transitions: tuple[_Trans, ...]
    loc: Location


class _ToModel(ExprTransformer):
    """Parse tree → plain frozen objects that keep their locations."""

    def __init__(self, file: str, source: str) -> None:
        super().__init__(file, source)
        self.errors: list[InputError] = []

    def const(self, items: list) -> Const:
        (tok,) = items
        if str(tok) not in ("0", "1"):
            self.errors.append(
                InputError(f"a constant must be 0 or 1, not {tok}", self._loc(tok), notes=("timers are written 2s/X12",))
            )
        return Const(str(tok) != "0", self._loc(tok))

    def timer(self, items: list) -> Var:
        (tok,) = items
        m = _TIMER_RE.match(str(tok))
        assert m is not None
        number, unit, step = m.groups()
        if "." in number:
            number = number.rstrip("0").rstrip(".")
        return Var(timer_id(number + unit, step), self._loc(tok))

    # declarations
    def inputs_decl(self, items: list) -> _Decl:
        return _Decl("inputs", tuple((str(t), self._loc(t)) for t in items))

    def outputs_decl(self, items: list) -> _Decl:
        return _Decl("outputs", tuple((str(t), self._loc(t)) for t in items))

    # steps and actions
    def step_id(self, items: list) -> _StepRef:
        (tok,) = items
        return _StepRef(str(tok), self._loc(tok))

    def continuous(self, items: list) -> Action:
        (tok,) = items
        return Action(CONTINUOUS, str(tok), loc=self._loc(tok))

    def conditional(self, items: list) -> Action:
        tok, cond = items
        return Action(CONDITIONAL, str(tok), cond, loc=self._loc(tok))

    def on_activation(self, items: list) -> tuple[str, Expr | None]:
        return (ON_ACTIVATION, None)

    def on_deactivation(self, items: list) -> tuple[str, Expr | None]:
        return (ON_DEACTIVATION, None)

    def on_event(self, items: list) -> tuple[str, Expr | None]:
        return (ON_EVENT, items[0])

    def _stored(self, items: list, value: bool) -> Action:
        tok, when = items
        kind, cond = when if when is not None else (ON_ACTIVATION, None)
        return Action(STORED, str(tok), cond, value, kind, self._loc(tok))

    def set_action(self, items: list) -> Action:
        return self._stored(items, True)

    def reset_action(self, items: list) -> Action:
        return self._stored(items, False)

    def step(self, items: list) -> _Step:
        initial, ref, *actions = items
        return _Step(ref.name, initial is not None, tuple(a for a in actions if a is not None), ref.loc)

    # transitions
    def tlabel(self, items: list) -> Token:
        return items[0]

    def step_list(self, items: list) -> tuple[_StepRef, ...]:
        return tuple(items)

    def transition(self, items: list) -> _Trans:
        label, sources, arrow, targets, receptivity = items
        loc = self._loc(label) if label is not None else None
        where = loc or (sources[0].loc if sources else self._loc(arrow))
        return _Trans(
            str(label) if label is not None else None,
            loc,
            sources or (),
            targets or (),
            receptivity,
            where,
        )

    def grafcet(self, items: list) -> _Graf:
        name, *body = items
        steps = tuple(b for b in body if isinstance(b, _Step))
        trans = tuple(b for b in body if isinstance(b, _Trans))
        return _Graf(str(name), steps, trans, self._loc(name))

    def start(self, items: list) -> list:
        return items


def _raise(errors: Sequence[InputError]) -> None:
    if len(errors) == 1:
        raise errors[0]
    if errors:
        raise InputErrors(errors)


def _parse(source: str, file: str) -> list:
    p = parser("grafcet")
    try:
        tree = p.parse(source)
    except UnexpectedInput as err:
        raise syntax_error(err, file, source, p) from None
    tm = _ToModel(file, source)
    items = tm.transform(tree)
    _raise(tm.errors)
    return items


# --------------------------------------------------------------------------- checking


class _Checker:
    """Names, steps, variables and orders; collects every error of the file."""

    def __init__(self, file: str, source: str, plant_inputs: Sequence[str] | None, plant_outputs: Sequence[str] | None) -> None:
        self.file = file
        self.source = source
        self.plant_inputs = tuple(plant_inputs) if plant_inputs is not None else None
        self.plant_outputs = tuple(plant_outputs) if plant_outputs is not None else None
        self.errors: list[InputError] = []
        self.steps: dict[str, tuple[_Step, str]] = {}
        self.timers: dict[str, Timer] = {}

    def fail(self, *args, **kwargs) -> None:
        self.errors.append(InputError(*args, **kwargs))

    # ---- declarations
    def declared(self, decls: list[_Decl], kind: str, plant: tuple[str, ...] | None) -> tuple[str, ...] | None:
        names_: list[str] = []
        for d in decls:
            if d.kind != kind:
                continue
            for n, loc in d.names:
                if n in names_:
                    self.fail(f"{kind[:-1]} '{n}' is declared twice", loc)
                    continue
                if plant is not None and n not in plant:
                    self.fail(
                        f"'{n}' is declared as an {kind[:-1]} but the plant has no such {kind[:-1]}",
                        loc,
                        suggestions=close_names(n, plant),
                    )
                names_.append(n)
        if plant is not None:
            return plant
        return tuple(names_) if any(d.kind == kind for d in decls) else None

    # ---- the whole file
    def check(self, items: list) -> Grafcet:
        decls = [i for i in items if isinstance(i, _Decl)]
        grafs = [i for i in items if isinstance(i, _Graf)]
        inputs = self.declared(decls, "inputs", self.plant_inputs)
        outputs = self.declared(decls, "outputs", self.plant_outputs)
        if inputs is not None and outputs is not None:
            for d in decls:
                if d.kind == "inputs":
                    for n, loc in d.names:
                        if n in outputs:
                            self.fail(f"'{n}' is declared both as an input and as an output", loc)
        if not grafs:
            self.fail(
                "no grafcet in this file",
                location_in(self.file, self.source, 1, 1),
                notes=("write at least one partial grafcet: grafcet G1 { initial step 0 ... }",),
            )
            _raise(self.errors)
        # steps (unique across the whole file)
        gnames: dict[str, _Graf] = {}
        for g in grafs:
            if g.name in gnames:
                self.fail(f"partial grafcet '{g.name}' is defined twice", g.loc, notes=(f"first defined at {gnames[g.name].loc}",))
            gnames.setdefault(g.name, g)
            for s in g.steps:
                if s.name in self.steps:
                    first, where = self.steps[s.name]
                    self.fail(
                        f"step {s.name} is declared twice",
                        s.loc,
                        notes=(f"first declared at {first.loc} (grafcet {where}); step names are unique in the file",),
                    )
                else:
                    self.steps[s.name] = (s, g.name)
        step_vars = {"X" + n for n in self.steps}
        if inputs is not None:
            for n in inputs:
                if n in step_vars:
                    step = self.steps[n[1:]][0]
                    self.fail(
                        f"input '{n}' has the name of the step variable of step {n[1:]}; rename the input or the step",
                        step.loc,
                    )
        # infer inputs/outputs when neither the file nor the caller gave them
        if inputs is None:
            inputs = self.infer_inputs(grafs, step_vars)
        if outputs is None:
            outputs = tuple(dict.fromkeys(a.order for g in grafs for s in g.steps for a in s.actions))
        # transitions and expressions
        built: list[PartialGrafcet] = []
        for g in grafs:
            labels: dict[str, _Trans] = {}
            transitions: list[Transition] = []
            for t in g.transitions:
                if t.label is not None:
                    if t.label in labels:
                        self.fail(f"transition {t.label} is defined twice in grafcet {g.name}", t.label_loc, notes=(f"first defined at {labels[t.label].loc}",))
                    labels.setdefault(t.label, t)
                if not t.sources and not t.targets:
                    self.fail("a transition needs at least one source or target step", t.loc)
                for role, refs in (("source", t.sources), ("target", t.targets)):
                    seen: set[str] = set()
                    for r in refs:
                        if r.name in seen:
                            self.fail(f"step {r.name} is listed twice as a {role} of this transition", r.loc)
                        seen.add(r.name)
                        self.check_step_ref(r, g.name)
                self.check_expr(t.receptivity, inputs, "receptivity", allow_edges=True)
                transitions.append(
                    Transition(t.label, tuple(r.name for r in t.sources), tuple(r.name for r in t.targets), t.receptivity, g.name, t.loc)
                )
            steps: list[Step] = []
            for s in g.steps:
                for a in s.actions:
                    self.check_action(a, outputs, inputs)
                steps.append(Step(s.name, g.name, s.initial, s.actions, s.loc))
            if not any(s.initial for s in g.steps) and not any(not t.sources for t in g.transitions):
                self.fail(
                    f"partial grafcet {g.name} has no initial step",
                    g.loc,
                    notes=("mark one with `initial step N`, or give it a source transition (`transition -> N when ↑x`); "
                           "otherwise its steps can never become active",),
                )
            built.append(PartialGrafcet(g.name, tuple(steps), tuple(transitions), g.loc))
        self.check_stored_outputs(grafs)
        _raise(self.errors)
        timers = tuple(sorted(self.timers.values(), key=lambda x: (step_key(x.step), x.seconds, x.id)))
        return Grafcet(tuple(built), tuple(inputs), tuple(outputs), timers, self.file)

    def infer_inputs(self, grafs: list[_Graf], step_vars: set[str]) -> tuple[str, ...]:
        found: list[str] = []
        exprs: list[Expr] = []
        for g in grafs:
            exprs.extend(t.receptivity for t in g.transitions)
            exprs.extend(a.condition for s in g.steps for a in s.actions if a.condition is not None)
        for e in exprs:
            for n in names(e):
                if n.name in step_vars or _TIMER_RE.match(n.name):
                    continue
                if isinstance(n, Var) and re.fullmatch(r"X[0-9]+", n.name):
                    continue  # X of a missing step: reported by check_expr
                if n.name not in found:
                    found.append(n.name)
        return tuple(found)

    def check_step_ref(self, r: _StepRef, grafcet: str) -> None:
        if r.name not in self.steps:
            self.fail(
                f"unknown step {r.name}",
                r.loc,
                suggestions=close_names(r.name, self.steps),
                notes=("declare it with `step " + r.name + "` in grafcet " + grafcet,),
            )
            return
        owner = self.steps[r.name][1]
        if owner != grafcet:
            self.fail(
                f"step {r.name} belongs to grafcet {owner}; a transition links steps of its own grafcet",
                r.loc,
                notes=(f"to synchronise with {owner}, read its step variable X{r.name} in a receptivity",),
            )

    def check_expr(self, e: Expr, inputs: Sequence[str], role: str, allow_edges: bool) -> None:
        known = set(inputs)
        for n in names(e):
            m = _TIMER_RE.match(n.name)
            if m is not None:
                step = m.group(3)
                if isinstance(n, Edge):
                    self.fail(f"an edge of a timer is not allowed; write the timer {n.name}", n.loc)
                elif step not in self.steps:
                    self.fail(
                        f"timer {n.name} refers to step {step}, which does not exist",
                        n.loc,
                        suggestions=tuple(f"X{c}" for c in close_names(step, self.steps)),
                    )
                else:
                    seconds = float(m.group(1)) * _SECONDS[m.group(2)]
                    self.timers.setdefault(n.name, Timer(n.name, step, seconds, n.loc))
                continue
            if n.name.startswith("X") and n.name[1:] in self.steps and n.name not in known:
                if isinstance(n, Edge):
                    self.fail(
                        f"edges of step variables are not supported: {n.text()}",
                        n.loc,
                        notes=("edges are input events; read the level X" + n.name[1:] + " instead",),
                    )
                continue
            if n.name in known:
                if isinstance(n, Edge) and not allow_edges:
                    self.fail(
                        f"an edge is not allowed in a {role}; write a level",
                        n.loc,
                        notes=("to act on an event, use a stored action: set ORDER on ↑x",),
                    )
                continue
            step_vars = sorted("X" + s for s in self.steps)
            if re.fullmatch(r"X[0-9]+", n.name):
                self.fail(
                    f"{n.name} refers to step {n.name[1:]}, which does not exist",
                    n.loc,
                    suggestions=close_names(n.name, step_vars),
                    notes=("X<step> is the variable of a step: true while the step is active",),
                )
                continue
            self.fail(
                f"unknown variable '{n.name}'" + (" (not an input of the plant)" if self.plant_inputs is not None else ""),
                n.loc,
                suggestions=close_names(n.name, sorted(known) + step_vars),
                notes=(("known inputs: " + ", ".join(inputs)) if inputs else "no input is declared",),
            )

    def check_action(self, a: Action, outputs: Sequence[str], inputs: Sequence[str]) -> None:
        if a.order not in outputs:
            source = "of the plant" if self.plant_outputs is not None else "declared"
            self.fail(
                f"'{a.order}' is not an output ({source})",
                a.loc,
                suggestions=close_names(a.order, outputs),
                notes=("outputs: " + ", ".join(outputs),) if outputs else (),
            )
        if a.kind == CONDITIONAL and a.condition is not None:
            self.check_expr(a.condition, inputs, "condition of an action", allow_edges=False)
        if a.kind == STORED and a.when == ON_EVENT and a.condition is not None:
            self.check_expr(a.condition, inputs, "event of a stored action", allow_edges=True)
            if not any(isinstance(n, Edge) for n in names(a.condition)):
                self.fail(
                    f"the event of '{a.text()}' has no edge: it would never occur",
                    a.condition.loc or next((n.loc for n in names(a.condition)), a.loc),
                    notes=("write an input event such as ↑cp12 (possibly with a condition: ↑cp12 . v10)",),
                )

    def check_stored_outputs(self, grafs: list[_Graf]) -> None:
        stored = {a.order for g in grafs for s in g.steps for a in s.actions if a.kind == STORED}
        for g in grafs:
            for s in g.steps:
                for a in s.actions:
                    if a.kind != STORED and a.order in stored:
                        self.fail(
                            f"output {a.order} is set/reset by stored actions and also assigned here",
                            a.loc,
                            notes=("an output is either assigned (continuous/conditional actions) or stored (set/reset), not both",),
                        )


def parse_grafcet(
    source: str,
    file: str = "<grafcet>",
    *,
    inputs: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
) -> Grafcet:
    """Parse and check ``.g7`` text; ``inputs``/``outputs`` are the plant's, if known."""
    items = _parse(source, file)
    return _Checker(file, source, inputs, outputs).check(items)


def load_grafcet(
    path: str | Path,
    *,
    inputs: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
) -> Grafcet:
    """Read, parse and check a ``.g7`` file (see :func:`parse_grafcet`)."""
    return parse_grafcet(read_source(path), str(path), inputs=inputs, outputs=outputs)

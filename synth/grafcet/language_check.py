"""Checking the ``.g7`` language: names, steps, variables and orders, every error of a
file collected and reported together; ``load_grafcet`` / ``parse_grafcet``.

``load_grafcet(path)`` reads a ``.g7`` file and returns an immutable
:class:`~synth.grafcet.language.Grafcet`. Every mistake is an
:class:`~synth.errors.InputError` pointing at the offending token.

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
>>> items = grafcet_items("grafcet G { initial step 0 transition 0 -> 9 when 1 }", "g.g7")
>>> try:
...     GrafcetChecker("g.g7", "", None, None).check(items)
... except Exception as err:
...     print(err.message)
unknown step 9
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path
from typing import Sequence

from synth.errors import close_names, location_in
from synth.grafcet.language import (
    TIMER_RE,
    ASSIGN,
    CONDITIONAL,
    ON_EVENT,
    STORED,
    Action,
    Grafcet,
    Internal,
    Sum,
    PartialGrafcet,
    Semantics,
    Step,
    Timer,
    Transition,
    duration_seconds,
    step_key,
    step_of,
    step_variable,
)
from synth.logic.expr import Compare, Edge, Expr, Var, names
from synth.grafcet.language_reader import (
    GrafcetDecl, InternalDecl, StepDecl, StepRef, TransitionDecl, VectorDecl, grafcet_items,
)
from synth.syntax import Checker, VectorKind, read_source

__all__ = ["GrafcetChecker", "parse_grafcet", "load_grafcet"]


class GrafcetChecker(Checker):
    """Names, steps, variables and orders; collects every error of the file."""

    def __init__(self, file: str, source: str, plant_inputs: Sequence[str] | None, plant_outputs: Sequence[str] | None) -> None:
        super().__init__()
        self.file = file
        self.source = source
        self.plant_inputs = tuple(plant_inputs) if plant_inputs is not None else None
        self.plant_outputs = tuple(plant_outputs) if plant_outputs is not None else None
        self.steps: dict[str, tuple[StepDecl, str]] = {}
        self.timers: dict[str, Timer] = {}
        self.internals: dict[str, Internal] = {}

    # ---- declarations
    def declared(self, decls: list[VectorDecl], kind: VectorKind, plant: tuple[str, ...] | None) -> tuple[str, ...] | None:
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
    def declare_internals(self, decls: list[InternalDecl], taken: dict[str, str]) -> None:
        """``internal`` declarations: unique names, not an input, output or step variable,
        a non-empty range holding the initial value."""
        for d in decls:
            if d.name in self.internals:
                self.fail(f"internal variable '{d.name}' is declared twice", d.loc,
                          notes=(f"first declared at {self.internals[d.name].loc}",))
                continue
            if d.name in taken:
                self.fail(f"internal variable '{d.name}' has the name of {taken[d.name]}", d.loc,
                          notes=("internal variables, inputs, outputs and step variables have distinct names",))
                continue
            low, high = d.low, d.high
            if low > high:
                self.fail(f"the range {low}..{high} of '{d.name}' is empty", d.range_loc,
                          notes=("write LOW..HIGH with LOW <= HIGH, e.g. 0..3",))
                high = low  # still declared: its uses are checked
            initial = low if d.initial is None else d.initial
            if not low <= initial <= high:
                self.fail(f"the initial value {initial} of '{d.name}' is outside "
                          + ("0..1 (a Boolean)" if d.boolean else f"its range {low}..{high}"),
                          d.initial_loc or d.loc)
                initial = low
            self.internals[d.name] = Internal(d.name, low, high, initial, d.boolean, d.loc)

    def check(self, items: list[VectorDecl | InternalDecl | GrafcetDecl]) -> Grafcet:
        decls = [i for i in items if isinstance(i, VectorDecl)]
        grafs = [i for i in items if isinstance(i, GrafcetDecl)]
        inputs = self.declared(decls, VectorKind.INPUTS, self.plant_inputs)
        outputs = self.declared(decls, VectorKind.OUTPUTS, self.plant_outputs)
        taken = {n: "an input" for n in inputs or ()} | {n: "an output" for n in outputs or ()}
        taken |= {step_variable(s.name): f"the variable of step {s.name}" for g in grafs for s in g.steps}
        self.declare_internals([i for i in items if isinstance(i, InternalDecl)], taken)
        if inputs is not None and outputs is not None:
            for d in decls:
                if d.kind is VectorKind.INPUTS:
                    for n, loc in d.names:
                        if n in outputs:
                            self.fail(f"'{n}' is declared both as an input and as an output", loc)
        if not grafs:
            self.fail(
                "no grafcet in this file",
                location_in(self.file, self.source, 1, 1),
                notes=("write at least one partial grafcet: grafcet G1 { initial step 0 ... }",),
            )
            self.raise_errors()
        # steps (unique across the whole file)
        gnames: dict[str, GrafcetDecl] = {}
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
        step_vars = {step_variable(n) for n in self.steps}
        if inputs is not None:
            for n in inputs:
                clash = step_of(n, self.steps)
                if clash is not None:
                    self.fail(
                        f"input '{n}' has the name of the step variable of step {clash}; rename the input or the step",
                        self.steps[clash][0].loc,
                    )
        # infer inputs/outputs when neither the file nor the caller gave them
        if inputs is None:
            inputs = self.infer_inputs(grafs, step_vars)
        if outputs is None:
            outputs = tuple(dict.fromkeys(a.order for g in grafs for s in g.steps for a in s.actions
                                          if a.order not in self.internals))
        # transitions and expressions
        built: list[PartialGrafcet] = []
        for g in grafs:
            labels: dict[str, TransitionDecl] = {}
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
                actions = tuple(self.check_action(a, outputs, inputs) for a in s.actions)
                steps.append(Step(s.name, g.name, s.initial, actions, s.loc))
            if not any(s.initial for s in g.steps) and not any(not t.sources for t in g.transitions):
                self.fail(
                    f"partial grafcet {g.name} has no initial step",
                    g.loc,
                    notes=("mark one with `initial step N`, or give it a source transition (`transition -> N when ↑x`); "
                           "otherwise its steps can never become active",),
                )
            built.append(PartialGrafcet(g.name, tuple(steps), tuple(transitions), g.loc))
        self.check_stored_outputs(grafs)
        self.raise_errors()
        timers = tuple(sorted(self.timers.values(), key=lambda x: (step_key(x.step), x.seconds, x.id)))
        return Grafcet(tuple(built), tuple(inputs), tuple(outputs), timers, self.file, tuple(self.internals.values()))

    def infer_inputs(self, grafs: list[GrafcetDecl], step_vars: set[str]) -> tuple[str, ...]:
        found: list[str] = []
        exprs: list[Expr] = []
        for g in grafs:
            exprs.extend(t.receptivity for t in g.transitions)
            exprs.extend(a.condition for s in g.steps for a in s.actions if a.condition is not None)
        for e in exprs:
            for n in names(e):
                if n.name in step_vars or TIMER_RE.match(n.name) or isinstance(n, Compare) or n.name in self.internals:
                    continue
                if isinstance(n, Var) and re.fullmatch(r"X[0-9]+", n.name):
                    continue  # X of a missing step: reported by check_expr
                if n.name not in found:
                    found.append(n.name)
        return tuple(found)

    def check_step_ref(self, r: StepRef, grafcet: str) -> None:
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
            if isinstance(n, Compare) or n.name in self.internals:
                self.check_internal_read(n)
                continue
            m = TIMER_RE.match(n.name)
            if m is not None:
                step = m.group(3)
                if isinstance(n, Edge):
                    self.fail(f"an edge of a timer is not allowed; write the timer {n.name}", n.loc)
                elif step not in self.steps:
                    self.fail(
                        f"timer {n.name} refers to step {step}, which does not exist",
                        n.loc,
                        suggestions=tuple(step_variable(c) for c in close_names(step, self.steps)),
                    )
                else:
                    seconds = duration_seconds(m.group(1), m.group(2))
                    self.timers.setdefault(n.name, Timer(n.name, step, seconds, n.loc))
                continue
            step_var_of = step_of(n.name, self.steps)
            if step_var_of is not None and n.name not in known:
                if isinstance(n, Edge):
                    self.fail(
                        f"edges of step variables are not supported: {n.text()}",
                        n.loc,
                        notes=(f"edges are input events; read the level {n.name} instead",),
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
            step_vars = sorted(step_variable(s) for s in self.steps)
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

    def check_internal_read(self, n: Var | Edge) -> None:
        """A comparison of integer internal variables, or a Boolean internal variable's level."""
        if isinstance(n, Compare):
            for x in n.operands():
                v = self.internals.get(x)
                if v is None:
                    self.fail(f"unknown internal variable '{x}' in the comparison {n.text()}", n.loc,
                              suggestions=close_names(x, self.internals),
                              notes=("declare it: internal " + x + " : 0..3",))
                elif v.boolean:
                    self.fail(f"'{x}' is a Boolean: read it as a level ({x} or !{x}), not in a comparison", n.loc)
        elif isinstance(n, Edge):
            self.fail(f"edges of internal variables are not supported: {n.text()}", n.loc,
                      notes=("edges are input events; read the level instead",))
        elif not self.internals[n.name].boolean:
            v = self.internals[n.name]
            self.fail(f"'{n.name}' is an integer ({v.low}..{v.high}): compare it, e.g. {n.name} >= {min(v.high, v.low + 1)}",
                      n.loc)

    def check_assignment(self, a: Action) -> Action:
        """``x := …``: ``x`` internal; an integer takes a sum of integer internals and constants,
        a Boolean 0, 1 or another Boolean internal; ``set``/``reset`` of a Boolean internal is
        ``x := 1``/``x := 0``."""
        v = self.internals[a.order]
        if a.kind == STORED:
            return Action(ASSIGN, a.order, a.condition, True, a.when, a.loc, Sum(((1, 1 if a.value else 0),), a.loc))
        if a.kind != ASSIGN:
            self.fail(f"internal variable '{a.order}' is changed by assignments only",
                      a.loc, notes=(f"write {a.order} := … on activation (or on deactivation, on ↑x)",))
            return a
        assert a.assign is not None
        if a.assign.expr is not None and not v.boolean:
            self.fail(f"'{a.order}' is an integer: assign a sum such as {a.order} + 1, not a Boolean expression",
                      a.assign.loc)
            return a
        for x in a.assign.names():
            w = self.internals.get(x)
            if w is None:
                self.fail(f"unknown internal variable '{x}' in the assignment to {a.order}", a.assign.loc,
                          suggestions=close_names(x, self.internals),
                          notes=("an assignment reads internal variables and integer constants",))
            elif w.boolean != v.boolean:
                self.fail(f"'{x}' is {'a Boolean' if w.boolean else 'an integer'} and '{a.order}' "
                          f"{'a Boolean' if v.boolean else 'an integer'}", a.assign.loc)
        if a.assign.expr is not None:
            for n in names(a.assign.expr):
                if isinstance(n, Edge):
                    self.fail(f"an edge in the assignment to {a.order}: {n.text()}", n.loc,
                              notes=("an assignment reads levels; put the event after on: ... on ↑x",))
            return a
        terms = a.assign.terms
        if v.boolean and not (len(terms) == 1 and terms[0][0] > 0 and terms[0][1] in (0, 1) or isinstance(terms[0][1], str)):
            self.fail(f"'{a.order}' is a Boolean: assign 0, 1 or another Boolean internal variable", a.assign.loc)
        return a

    def check_action(self, a: Action, outputs: Sequence[str], inputs: Sequence[str]) -> Action:
        if a.kind in (STORED, ASSIGN) and a.when == ON_EVENT:
            self.check_event(a, inputs)
        if a.order in self.internals:
            return self.check_assignment(a)
        if a.kind == ASSIGN:
            self.fail(f"unknown internal variable '{a.order}'", a.loc, suggestions=close_names(a.order, self.internals),
                      notes=(f"declare it before the grafcets: internal {a.order} : 0..3 = 0",))
            return a
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
        return a

    def check_event(self, a: Action, inputs: Sequence[str]) -> None:
        if a.condition is not None:
            self.check_expr(a.condition, inputs, "event of a stored action", allow_edges=True)
            if not any(isinstance(n, Edge) for n in names(a.condition)):
                self.fail(
                    f"the event of '{a.text()}' has no edge: it would never occur",
                    a.condition.loc or next((n.loc for n in names(a.condition)), a.loc),
                    notes=("write an input event such as ↑cp12 (possibly with a condition: ↑cp12 . v10)",),
                )

    def check_stored_outputs(self, grafs: list[GrafcetDecl]) -> None:
        stored = {a.order for g in grafs for s in g.steps for a in s.actions
                  if a.kind == STORED and a.order not in self.internals}
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
    semantics: Semantics | str = Semantics.GRAFCET,
) -> Grafcet:
    """Parse and check ``.g7`` text; ``inputs``/``outputs`` are the plant's, if known;
    ``semantics``: how it evolves (IEC 60848, or IEC 61131-3 SFC)."""
    g = GrafcetChecker(file, source, inputs, outputs).check(grafcet_items(source, file))
    return g if Semantics(semantics) is Semantics.GRAFCET else replace(g, semantics=Semantics(semantics))


def load_grafcet(
    path: str | Path,
    *,
    inputs: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
    semantics: Semantics | str = Semantics.GRAFCET,
) -> Grafcet:
    """Read, parse and check a ``.g7`` file (see :func:`parse_grafcet`)."""
    return parse_grafcet(read_source(path), str(path), inputs=inputs, outputs=outputs, semantics=semantics)

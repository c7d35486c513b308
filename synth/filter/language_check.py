"""Checking a filter file: names resolved, constraints classified (CSs / CSc), reliefs
turned into forced values, every mistake located; ``load_filter`` / ``parse_filter``.

Example
-------
>>> f = parse_filter('outputs O1, O2\\ninputs i1\\nsafety K1: O1 & O2 keep O1\\nsafety S1: i1 & O1', "x.filter")
>>> [(s.id, s.kind.value, [(c.output, c.value) for c in s.forced]) for s in f.safeties]
[('K1', 'combined', [('O2', False)]), ('S1', 'simple', [])]
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from synth.errors import InputError, Location, Severity, close_names, location_in
from synth.filter.language import (
    MAX_BITS,
    Assumption,
    Comparison,
    ConstraintKind,
    Criterion,
    Declared,
    Equation,
    Filter,
    Forcing,
    IntegerObserver,
    Safety,
    SimCriterion,
    VarKind,
    request_name,
)
from synth.filter.language_reader import IntegerDecl, Use, Vector, filter_items
from synth.logic.past import base_name, is_pre
from synth.logic.expr import And, Compare, Edge, Expr, Not, Or, Var, names
from synth.syntax import Checker, read_source

if TYPE_CHECKING:
    from synth.plant.rules import RuleSet
    from synth.logic.bdd import Engine

__all__ = ["parse_filter", "load_filter", "output_polarities"]


def output_polarities(e: Expr, outputs: set[str] | frozenset[str]) -> dict[str, set[bool]]:
    """For each output at t in ``e`` (text order), the polarities it occurs with
    (``True``: the expression grows with the output; ``↑o`` counts as ``o``, ``↓o`` as ``!o``).

    >>> output_polarities(Not(And((Var("a"), Edge(False, "b")))), {"a", "b"})
    {'a': {False}, 'b': {True}}
    """
    found: dict[str, set[bool]] = {}

    def walk(x: Expr, positive: bool) -> None:
        if isinstance(x, Var) and x.name in outputs:
            found.setdefault(x.name, set()).add(positive)
        elif isinstance(x, Edge) and x.name in outputs:
            found.setdefault(x.name, set()).add(x.rising == positive)
        elif isinstance(x, Not):
            walk(x.arg, not positive)
        elif isinstance(x, (And, Or)):
            for a in x.args:
                walk(a, positive)

    walk(e, True)
    return found


class _FilterChecker(Checker):
    def __init__(self, file: str, source: str, base: Path | None) -> None:
        super().__init__()
        self.file, self.source, self.base = file, source, base
        self.declared: dict[str, Declared] = {}
        self.warnings: list[InputError] = []
        self.plant: str | None = None
        self.rules: RuleSet | None = None  # the plant's rule set, read once: verify builds its plant from it
        self.engine: "Engine | None" = None
        self.integers: dict[str, IntegerObserver] = {}

    # ---- declarations
    def declare(self, name: str, kind: VarKind, loc: Location | None, grafcet: str | None = None,
                definition: Expr | None = None) -> None:
        if name in self.declared:
            first = self.declared[name]
            if first.kind is kind and loc is None:  # a plant's vector repeated in the filter
                return
            where = f" at {first.loc}" if first.loc else " by the plant"
            self.fail(f"'{name}' is declared twice", loc, notes=(f"first declared as {first.kind.value}{where}",))
            return
        self.declared[name] = Declared(name, kind, loc, grafcet, definition)

    def use(self, u: Use) -> None:
        from synth.plant.rules_check import parse_rules

        if self.plant is not None:
            self.fail("a filter uses at most one plant", u.loc)
            return
        target = (self.base / u.path) if self.base is not None else Path(u.path)
        try:  # a missing file, a folder, a named pipe, a name too long: located at the `use`
            source = read_source(target, u.loc)
        except InputError as err:
            self.errors.append(err)
            return
        rs = parse_rules(source, str(target), target.parent)
        self.plant, self.rules = str(target), rs
        for kind, vector in ((VarKind.INPUT, rs.inputs), (VarKind.OUTPUT, rs.outputs)):
            for n in vector:
                if n not in self.declared:
                    self.declared[n] = Declared(n, kind, None)

    def of_kind(self, kind: VarKind) -> tuple[str, ...]:
        return tuple(n for n, d in self.declared.items() if d.kind is kind)

    # ---- expressions
    def known(self, e: Expr, what: str) -> bool:
        ok = True
        for v in names(e):
            if isinstance(v, Compare):
                ok = self.comparison(v, what) and ok
                continue
            base = base_name(v.name) if isinstance(v, Var) else v.name
            if base not in self.declared:
                self.fail(
                    f"unknown variable '{base}' in {what}",
                    v.loc,
                    suggestions=close_names(base, self.levels()),
                )
                ok = False
            elif base in self.integers:
                i = self.integers[base]
                level = f"the edge {v.text()} is" if isinstance(v, Edge) else f"'{v.name}' is"
                self.fail(f"{level} not a Boolean level: '{base}' is an integer observer ({i.low}..{i.high})", v.loc,
                          notes=(f"compare it, e.g. {base} >= {min(i.high, i.low + 1)}"
                                 + (f" or {base}^-1 < {base}" if isinstance(v, Edge) else ""),))
                ok = False
        return ok

    def levels(self) -> list[str]:
        """The declared names but the integer observers' bits (the names to suggest)."""
        bits = {b for i in self.integers.values() for b in i.bits}
        return [n for n in self.declared if n not in bits]

    def comparison(self, c: Compare, what: str) -> bool:
        """``cpt >= 2``: integer observers (or their past values) compared with a constant
        in their range or with each other."""
        for x in c.operands():
            base = base_name(x)
            d = self.declared.get(base)
            if d is None:
                self.fail(f"unknown variable '{base}' in the comparison {c.text()} in {what}", c.loc,
                          suggestions=close_names(base, self.integers) or close_names(base, self.levels()),
                          notes=(f"declare it: observer {base} : 0..3",))
                return False
            if base not in self.integers:
                self.fail(f"'{base}' is a Boolean {d.kind.value}: read it as a level ({base} or !{base}), "
                          f"not in the comparison {c.text()}", c.loc)
                return False
        i = self.integers[base_name(c.left)]
        if isinstance(c.right, int) and not i.low <= c.right <= i.high:
            self.fail(f"the constant {c.right} in {c.text()} is outside the range {i.low}..{i.high} of '{i.name}'",
                      c.loc)
            return False
        return True

    def outputs_at_t(self, e: Expr) -> tuple[str, ...]:
        outs = self.of_kind(VarKind.OUTPUT)
        seen: list[str] = []
        for v in names(e):
            if v.name in outs and v.name not in seen:
                seen.append(v.name)
        return tuple(seen)

    # ---- statements
    def safety(self, s: Safety, ids: dict[str, Safety]) -> Safety | None:
        if s.id in ids:
            self.fail(f"constraint '{s.id}' is declared twice", s.loc, notes=(f"first declared at {ids[s.id].loc}",))
            return None
        ids[s.id] = s
        if not self.known(s.expr, f"constraint {s.id}"):
            return None
        outs = self.outputs_at_t(s.expr)
        if not outs:
            self.fail(
                f"constraint {s.id} does not involve an output at t",
                s.loc,
                notes=("a safety constraint names an output or its edge; past values x^-1 are read-only",),
            )
            return None
        s = Safety(s.id, s.label, s.expr, s.loc, s.keep, s.force, outs)
        if s.kind is ConstraintKind.SIMPLE:
            if s.has_priority:
                self.warnings.append(InputError(
                    f"{s.id} is a simple constraint (output {outs[0]}): its relief is implied, keep/force is ignored",
                    s.loc, severity=Severity.WARNING))
            return s
        forced = self.forced(s)
        if forced is None:
            return None
        return Safety(s.id, s.label, s.expr, s.loc, s.keep, s.force, outs, forced)

    def forced(self, s: Safety) -> tuple[Forcing, ...] | None:
        if s.force:
            seen: set[str] = set()
            for f in s.force:
                if f.output not in s.outputs:
                    self.fail(f"force: '{f.output}' is not an output of {s.id}", f.loc, expected=s.outputs,
                              suggestions=close_names(f.output, s.outputs))
                    return None
                if f.output in seen:
                    self.fail(f"'{f.output}' is forced twice in {s.id}", f.loc)
                    return None
                seen.add(f.output)
            return self.relieving(s, s.force)
        if s.keep is None:
            return ()
        kept: list[str] = []
        for v in names(s.keep):
            if v.name not in s.outputs:
                self.fail(f"keep: '{v.name}' is not an output of {s.id} at t", v.loc, expected=s.outputs,
                          suggestions=close_names(v.name, s.outputs))
                return None
            kept.append(v.name)
        polarity = output_polarities(s.expr, set(s.outputs))
        forced: list[Forcing] = []
        for o in s.outputs:
            if o in kept:
                continue
            if len(polarity[o]) > 1:
                self.fail(f"keep: cannot tell the value to force on '{o}' in {s.id}, it occurs both negated and not",
                          s.loc, notes=(f"write the relief as `force {o}=0` or `force {o}=1`",))
                return None
            forced.append(Forcing(o, not next(iter(polarity[o])), s.keep.loc if hasattr(s.keep, "loc") else None))
        if not forced:
            self.fail(f"keep: {s.id} keeps every output, nothing is left to force", s.loc)
            return None
        return self.relieving(s, tuple(forced))

    def relieving(self, s: Safety, forced: tuple[Forcing, ...]) -> tuple[Forcing, ...] | None:
        from synth.filter.model import filter_engine

        if self.engine is None:  # one manager for the file: creating one costs ~10 ms
            self.engine = filter_engine(self.partial())
        engine = self.engine
        u = engine.expr(s.expr)
        if engine.let({f.output: f.value for f in forced}, u) != engine.false:
            values = ", ".join(f"{f.output}={int(f.value)}" for f in forced)
            self.fail(f"the relief of {s.id} does not make it false: {values} leaves it satisfiable", s.loc)
            return None
        return forced

    def observer_definition(self, d: Declared) -> None:
        """``observer P := EXPR``: inputs and requests at t, anything at t-1 (no output or
        observer at t: the observer is computed before the outputs, from the cycle's reads)."""
        if d.definition is None or not self.known(d.definition, f"the definition of observer {d.name}"):
            return
        observers = self.of_kind(VarKind.OBSERVER)
        for v in names(d.definition):
            now = [x for x in v.operands() if not is_pre(x)] if isinstance(v, Compare) else []
            if now:
                self.fail(f"observer {d.name} cannot read the integer observer '{now[0]}' at t", v.loc,
                          notes=(f"an observer is computed from the inputs, the requests and past values: "
                                 f"compare {now[0]}^-1",))
                return
            if v.name in self.of_kind(VarKind.OUTPUT) or v.name in observers:
                what = "output" if v.name not in observers else "observer"
                self.fail(f"observer {d.name} cannot read the {what} '{v.name}' at t", v.loc,
                          notes=(f"an observer is computed from the inputs, the requests and past values: "
                                 f"write {v.name}^-1",))
                return

    def assumption(self, a: Assumption) -> Assumption | None:
        if not self.known(a.expr, "an assumption"):
            return None
        for o in self.outputs_at_t(a.expr):
            loc = next(v.loc for v in names(a.expr) if v.name == o)
            self.fail(f"an assumption cannot use the output '{o}' at t", loc,
                      notes=("assumptions describe the read-only variables; a condition on outputs is a `safety`",))
            return None
        return a

    def sim(self, c: SimCriterion, simmed: set[str]) -> SimCriterion | None:
        outs = self.of_kind(VarKind.OUTPUT)
        for o, loc in zip(c.outputs, c.locs or (c.loc,) * len(c.outputs)):
            if o not in outs:
                self.fail(f"maximize sim: '{o}' is not an output", loc, suggestions=close_names(o, outs))
                return None
            if o in simmed:
                self.fail(f"output '{o}' has two sim criteria", loc)
                return None
            simmed.add(o)
        return c

    def equation(self, q: Equation, done: dict[str, Equation]) -> Equation | None:
        outs = self.of_kind(VarKind.OUTPUT)
        if q.output not in outs:
            self.fail(f"equation: '{q.output}' is not an output", q.loc, suggestions=close_names(q.output, outs))
            return None
        if q.output in done:
            self.fail(f"output '{q.output}' has two equations", q.loc, notes=(f"first at {done[q.output].loc}",))
            return None
        done[q.output] = q
        return q if self.known(q.expr, f"the equation of {q.output}") else None

    def integer(self, d: IntegerDecl) -> None:
        """``observer cpt : LOW..HIGH``: a non-empty range of at most 2^MAX_BITS values."""
        if d.low > d.high:
            self.fail(f"the range {d.low}..{d.high} of '{d.name}' is empty", d.range_loc,
                      notes=("write LOW..HIGH with LOW <= HIGH, e.g. 0..3",))
            return
        if (d.high - d.low).bit_length() > MAX_BITS:
            self.fail(f"the range {d.low}..{d.high} of '{d.name}' has more than {1 << MAX_BITS} values",
                      d.range_loc, notes=(f"an integer observer is encoded in at most {MAX_BITS} bits",))
            return
        self.declare(d.name, VarKind.INTEGER, d.loc)
        if self.declared[d.name].kind is VarKind.INTEGER and d.name not in self.integers:
            self.integers[d.name] = IntegerObserver(d.name, d.low, d.high, d.loc)

    def partial(self) -> Filter:
        """What the checks need of the filter being checked: its integer observers."""
        return Filter(self.file, (), (), integers=tuple(self.integers.values()))

    def resolved(self, f: Filter) -> Filter:
        """The comparisons of every expression resolved (:class:`Comparison`)."""
        if not self.integers:
            return f
        from dataclasses import replace

        r = self.integers
        return replace(
            f,
            observers=tuple(replace(d, definition=_resolved(d.definition, r)) if d.definition is not None else d
                            for d in f.observers),
            assumptions=tuple(replace(a, expr=_resolved(a.expr, r)) for a in f.assumptions),
            safeties=tuple(replace(s, expr=_resolved(s.expr, r)) for s in f.safeties),
            criteria=tuple(replace(c, expr=_resolved(c.expr, r)) if isinstance(c, Criterion) else c
                           for c in f.criteria),
            equations=tuple(replace(q, expr=_resolved(q.expr, r)) for q in f.equations),
        )

    def check(self, items: list) -> Filter:
        for it in items:
            if isinstance(it, Use):
                self.use(it)
        for it in items:
            if isinstance(it, Vector):
                for n, loc in it.names:
                    self.declare(n, it.kind, loc)
            elif isinstance(it, Declared):
                self.declare(it.name, it.kind, it.loc, it.grafcet, it.definition)
            elif isinstance(it, IntegerDecl):
                self.integer(it)
        outputs = self.of_kind(VarKind.OUTPUT)
        for o in outputs:
            r = request_name(o)
            if r in self.declared:
                self.fail(f"'{r}' is the implicit request of output {o}; it cannot be declared", self.declared[r].loc)
            else:
                self.declared[r] = Declared(r, VarKind.REQUEST, None)
        for i in self.integers.values():
            for k, b in enumerate(i.bits):
                if b in self.declared:
                    self.fail(f"'{b}' is bit {k} of the integer observer {i.name}; it cannot be declared",
                              self.declared[b].loc or i.loc)
                else:
                    self.declared[b] = Declared(b, VarKind.OBSERVER, i.loc)
        if not outputs:
            self.fail("no outputs declared", location_in(self.file, self.source, 1, 1),
                      notes=("declare them with `outputs A0, A1, ...` or `use` a plant",))
        for d in self.of_kind(VarKind.OBSERVER):
            self.observer_definition(self.declared[d])
        ids: dict[str, Safety] = {}
        simmed: set[str] = set()
        eqs: dict[str, Equation] = {}
        safeties: list[Safety | None] = []
        assumptions: list[Assumption | None] = []
        criteria: list[Criterion | SimCriterion | None] = []
        equations: list[Equation | None] = []
        for it in items:
            if isinstance(it, Safety):
                safeties.append(self.safety(it, ids))
            elif isinstance(it, Assumption):
                assumptions.append(self.assumption(it))
            elif isinstance(it, Criterion):
                criteria.append(it if self.known(it.expr, "a criterion") else None)
            elif isinstance(it, SimCriterion):
                criteria.append(self.sim(it, simmed))
            elif isinstance(it, Equation):
                equations.append(self.equation(it, eqs))
        self.raise_errors()  # every None above came with an error
        return self.resolved(Filter(
            self.file,
            self.of_kind(VarKind.INPUT),
            outputs,
            tuple(d for d in self.declared.values() if d.kind is VarKind.OBSERVER),
            tuple(a for a in assumptions if a is not None),
            tuple(s for s in safeties if s is not None),
            tuple(c for c in criteria if c is not None),
            tuple(q for q in equations if q is not None),
            self.plant,
            tuple(self.warnings),
            tuple(d for d in self.declared.values() if d.kind is not VarKind.REQUEST),
            tuple(self.integers.values()),
            self.rules,
        ))


def _resolved(e: Expr, integers: dict[str, IntegerObserver]) -> Expr:
    """``e`` with each comparison a :class:`Comparison` that knows the bits it reads."""
    if isinstance(e, Compare):
        return Comparison.resolved(e, integers)
    if isinstance(e, Not):
        return Not(_resolved(e.arg, integers), e.loc)
    if isinstance(e, (And, Or)):
        return type(e)(tuple(_resolved(a, integers) for a in e.args), e.loc)
    return e


def parse_filter(source: str, file: str = "<filter>", base: Path | None = None) -> Filter:
    """Parse and check filter text; ``base`` is the folder ``use`` paths are relative to."""
    items = filter_items(source, file)
    return _FilterChecker(file, source, base).check(items)


def load_filter(path: str | Path) -> Filter:
    """Read, parse and check a ``.filter`` file."""
    return parse_filter(read_source(path), str(path), Path(path).parent)

"""The rules language: plant elements, occurrence rules, precedences and constraints.

``load_rules(path)`` reads a ``.rules`` file (and the files it ``use``-s), checks it
and returns an immutable :class:`RuleSet`. Every mistake is an
:class:`~synth.errors.InputError` pointing at the offending token.

Example
-------
>>> text = '''
... element V3 {
...   order AVANCER3 = 0
...   sensor v30 = 1, v31 = 0
...   incoherent v30 & v31
...   ↑AVANCER3 [v30] -> ↓v30
...   ↑AVANCER3 [!v30 & !v31] -> ↑v31
...   ↓AVANCER3 [v31] -> ↓v31
...   ↓AVANCER3 [!v30 & !v31] -> ↑v30
... }
... constraint C1 "never out": v31 = 0
... '''
>>> rs = parse_rules(text, "v3.rules")
>>> [e.name for e in rs.elements], [c.id for c in rs.constraints]
(['V3'], ['C1'])
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Iterable, Mapping

from lark import Token, UnexpectedInput

from synth.errors import InputError, InputErrors, Location, close_names, location_in
from synth.logic.expr import Const, Edge, Expr, Not, Var, disjunctive_normal_form, evaluate, names
from synth.syntax import ExprTransformer, parser, read_source, syntax_error

__all__ = [
    "VarDecl",
    "Rule",
    "Precedence",
    "ElementSpec",
    "Constraint",
    "RuleSet",
    "parse_rules",
    "load_rules",
]

ORDER, SENSOR, FREE = "order", "sensor", "free"


@dataclass(frozen=True)
class VarDecl:
    """A variable of an element: an order (output Z), a sensor or a free input (input E)."""

    name: str
    kind: str
    initial: bool
    loc: Location | None = field(default=None, compare=False)
    held: bool = False

    @property
    def is_input(self) -> bool:
        return self.kind != ORDER


@dataclass(frozen=True)
class Rule:
    """Occurrence rule ``cause [guard] -> consequence``."""

    cause: Edge
    guard: Expr | None
    consequence: Edge
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        g = f" [{self.guard.text()}]" if self.guard is not None else ""
        return f"{self.cause.text()}{g} -> {self.consequence.text()}"


@dataclass(frozen=True)
class Precedence:
    """``cause: first < then``: after ``cause``, ``then`` can only follow ``first``."""

    cause: Edge
    first: Edge
    then: Edge
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        return f"{self.cause.text()}: {self.first.text()} < {self.then.text()}"


@dataclass(frozen=True)
class ElementSpec:
    """One plant element as written (after instantiation of a model)."""

    name: str
    variables: tuple[VarDecl, ...]
    incoherences: tuple[Expr, ...] = ()
    rules: tuple[Rule, ...] = ()
    precedences: tuple[Precedence, ...] = ()
    loc: Location | None = field(default=None, compare=False)
    model: str | None = None

    @property
    def orders(self) -> tuple[VarDecl, ...]:
        return tuple(v for v in self.variables if v.kind == ORDER)

    @property
    def inputs(self) -> tuple[VarDecl, ...]:
        return tuple(v for v in self.variables if v.kind != ORDER)

    def variable(self, name: str) -> VarDecl | None:
        return next((v for v in self.variables if v.name == name), None)


@dataclass(frozen=True)
class Constraint:
    """``id "label": expr = 0`` (or ``= 1``: the expression must always hold)."""

    id: str
    label: str
    expr: Expr
    equals: bool = False
    loc: Location | None = field(default=None, compare=False)

    @property
    def forbidden(self) -> Expr:
        """The expression that must never be true."""
        return Not(self.expr) if self.equals else self.expr

    def text(self) -> str:
        return f"{self.expr.text()} = {int(self.equals)}"


@dataclass(frozen=True)
class RuleSet:
    """A checked plant description: elements, constraints, and the file they came from."""

    elements: tuple[ElementSpec, ...]
    constraints: tuple[Constraint, ...]
    path: str = "<rules>"
    order: tuple[str, ...] = ()  # names listed by `inputs` / `outputs`, first in the vectors

    @property
    def variables(self) -> tuple[VarDecl, ...]:
        return tuple(v for e in self.elements for v in e.variables)

    def _vector(self, inputs: bool) -> tuple[str, ...]:
        names = [v.name for v in self.variables if v.is_input == inputs]
        listed = [n for n in self.order if n in names]
        return tuple(listed + [n for n in names if n not in listed])

    @property
    def inputs(self) -> tuple[str, ...]:
        """The vector E: listed inputs first (``inputs ...``), then the others as declared."""
        return self._vector(True)

    @property
    def outputs(self) -> tuple[str, ...]:
        """The vector Z: listed orders first (``outputs ...``), then the others as declared."""
        return self._vector(False)

    def owner(self, name: str) -> ElementSpec | None:
        return next((e for e in self.elements if e.variable(name) is not None), None)

    def element(self, name: str) -> ElementSpec | None:
        return next((e for e in self.elements if e.name == name), None)


# --------------------------------------------------------------------------- parsing


@dataclass(frozen=True)
class _Body:
    decls: tuple[VarDecl, ...]
    incoherences: tuple[Expr, ...]
    rules: tuple[Rule, ...]
    precedences: tuple[Precedence, ...]


@dataclass(frozen=True)
class _Model:
    name: str
    body: _Body
    loc: Location


@dataclass(frozen=True)
class _Instance:
    name: str
    model: str
    renaming: tuple[tuple[str, str, Location, Location], ...]
    loc: Location
    model_loc: Location


@dataclass(frozen=True)
class _Inline:
    name: str
    body: _Body
    loc: Location


@dataclass(frozen=True)
class _Use:
    path: str
    loc: Location


@dataclass(frozen=True)
class _Hold:
    decls: tuple[VarDecl, ...]


@dataclass(frozen=True)
class _Vector:
    kind: str  # "inputs" | "outputs"
    names: tuple[tuple[str, Location], ...]


class _ToModel(ExprTransformer):
    """Parse tree → plain frozen objects that keep their locations."""

    # declarations
    def decl(self, items: list) -> tuple[Token, Token]:
        return (items[0], items[1])

    def _decls(self, items: list, kind: str, held: bool = False) -> tuple[VarDecl, ...]:
        return tuple(VarDecl(str(n), kind, str(b) == "1", self._loc(n), held) for n, b in items)

    def orders(self, items: list) -> tuple[VarDecl, ...]:
        return self._decls(items, ORDER)

    def sensors(self, items: list) -> tuple[VarDecl, ...]:
        return self._decls(items, SENSOR)

    def free(self, items: list) -> tuple[VarDecl, ...]:
        return self._decls(items, FREE)

    def hold(self, items: list) -> _Hold:
        return _Hold(self._decls(items, ORDER, held=True))

    def incoherent(self, items: list) -> Expr:
        return items[0]

    def guard(self, items: list) -> Expr:
        return items[0]

    def rule(self, items: list) -> Rule:
        cause, guard, arrow, consequence = items
        return Rule(cause, guard, consequence, cause.loc)

    def precedence(self, items: list) -> Precedence:
        cause, first, then = items
        return Precedence(cause, first, then, cause.loc)

    def _body(self, items: Iterable) -> _Body:
        decls: list[VarDecl] = []
        inc: list[Expr] = []
        rules: list[Rule] = []
        precs: list[Precedence] = []
        for it in items:
            if isinstance(it, tuple):
                decls.extend(it)
            elif isinstance(it, Rule):
                rules.append(it)
            elif isinstance(it, Precedence):
                precs.append(it)
            else:
                inc.append(it)
        return _Body(tuple(decls), tuple(inc), tuple(rules), tuple(precs))

    def model(self, items: list) -> _Model:
        name, *rest = items
        return _Model(str(name), self._body(rest), self._loc(name))

    def element_inline(self, items: list) -> _Inline:
        name, *rest = items
        return _Inline(str(name), self._body(rest), self._loc(name))

    def renaming(self, items: list) -> tuple[str, str, Location, Location]:
        a, b = items
        return (str(a), str(b), self._loc(a), self._loc(b))

    def element_instance(self, items: list) -> _Instance:
        name, model, *ren = items
        ren = tuple(r for r in ren if r is not None)
        return _Instance(str(name), str(model), ren, self._loc(name), self._loc(model))

    def vector(self, items: list) -> _Vector:
        kind, *names = items
        return _Vector(str(kind), tuple((str(n), self._loc(n)) for n in names))

    def use(self, items: list) -> _Use:
        (tok,) = items
        return _Use(str(tok)[1:-1], self._loc(tok))

    def constraint(self, items: list) -> Constraint:
        ident, label, expr, bit = items
        text = str(label)[1:-1] if label is not None else ""
        return Constraint(str(ident), text, expr, str(bit) == "1", self._loc(ident))

    def start(self, items: list) -> list:
        return items


def _parse(source: str, file: str) -> list:
    p = parser("rules")
    try:
        tree = p.parse(source)
    except UnexpectedInput as err:
        raise syntax_error(err, file, source, p) from None
    return _ToModel(file, source).transform(tree)


# --------------------------------------------------------------------------- checking


class _Checker:
    """Resolves ``use``, models and instances, then checks names and ownership."""

    def __init__(self) -> None:
        self.models: dict[str, _Model] = {}
        self.elements: list[ElementSpec] = []
        self.constraints: list[Constraint] = []
        self.holds: list[VarDecl] = []
        self.top_free: list[VarDecl] = []
        self.vectors: list[_Vector] = []
        self.order: tuple[str, ...] = ()
        self.errors: list[InputError] = []
        self.loaded: set[Path] = set()

    def fail(self, *args, **kwargs) -> None:
        self.errors.append(InputError(*args, **kwargs))

    # ---- collection
    def collect(self, items: list, base: Path | None) -> None:
        for it in items:
            if isinstance(it, _Use):
                self.use(it, base)
            elif isinstance(it, _Model):
                if it.name in self.models:
                    self.fail(
                        f"model '{it.name}' is defined twice",
                        it.loc,
                        notes=(f"first defined at {self.models[it.name].loc}",),
                    )
                else:
                    self.models[it.name] = it
            elif isinstance(it, _Inline):
                self.add_element(ElementSpec(it.name, it.body.decls, it.body.incoherences, it.body.rules, it.body.precedences, it.loc))
            elif isinstance(it, _Instance):
                self.instantiate(it)
            elif isinstance(it, _Hold):
                self.holds.extend(it.decls)
            elif isinstance(it, tuple):  # top-level free inputs
                self.top_free.extend(it)
            elif isinstance(it, Constraint):
                self.constraints.append(it)
            elif isinstance(it, _Vector):
                self.vectors.append(it)

    def use(self, u: _Use, base: Path | None) -> None:
        target = (base / u.path) if base is not None else Path(u.path)
        try:
            resolved = target.resolve()
            if resolved in self.loaded:
                return
            source = target.read_text(encoding="utf-8-sig")
        except OSError as exc:
            self.fail(f"cannot read '{u.path}': {exc.strerror or exc}", u.loc)
            return
        except UnicodeDecodeError:
            self.fail(f"'{u.path}' is not UTF-8 text", u.loc)
            return
        self.loaded.add(resolved)
        try:
            items = _parse(source, str(target))
        except InputError as err:
            self.errors.append(err)
            return
        self.collect(items, target.parent)

    def instantiate(self, inst: _Instance) -> None:
        model = self.models.get(inst.model)
        if model is None:
            self.fail(
                f"unknown model '{inst.model}' for element {inst.name}",
                inst.model_loc,
                suggestions=close_names(inst.model, self.models),
                notes=("models are defined with `model NAME { ... }`, here or in a file named by `use`",),
            )
            return
        declared = {d.name for d in model.body.decls}
        mapping: dict[str, str] = {}
        for old, new, old_loc, _ in inst.renaming:
            if old not in declared:
                self.fail(
                    f"model '{model.name}' has no variable '{old}'",
                    old_loc,
                    suggestions=close_names(old, declared),
                    expected=(", ".join(sorted(declared)),),
                )
                continue
            if old in mapping:
                self.fail(f"'{old}' is renamed twice in element {inst.name}", old_loc)
                continue
            mapping[old] = new
        self.add_element(_rename(inst.name, model, mapping, inst.loc))

    def add_element(self, e: ElementSpec) -> None:
        for other in self.elements:
            if other.name == e.name:
                self.fail(f"element '{e.name}' is declared twice", e.loc, notes=(f"first declared at {other.loc}",))
                return
        self.elements.append(e)

    # ---- checks
    def check(self) -> None:
        owner: dict[str, tuple[ElementSpec, VarDecl]] = {}
        elements: list[ElementSpec] = []
        for v in self.top_free:
            elements.append(ElementSpec(v.name, (v,), loc=v.loc))
        elements.extend(self.elements)
        named: dict[str, ElementSpec] = {}
        for e in elements:
            if e.name in named and e.loc is not None:
                self.fail(
                    f"element '{e.name}' is declared twice",
                    e.loc,
                    notes=(f"first declared at {named[e.name].loc} (a top-level free input is an element of its own)",),
                )
            named.setdefault(e.name, e)
        for e in elements:
            for v in e.variables:
                if v.name in owner:
                    first_el, first = owner[v.name]
                    where = "again" if first_el.name == e.name else f"by element {e.name}"
                    self.fail(
                        f"variable '{v.name}' is declared {where} but already belongs to element {first_el.name}",
                        v.loc,
                        notes=(f"{first_el.name} declares it at {first.loc}", "each variable belongs to exactly one element"),
                    )
                else:
                    owner[v.name] = (e, v)
        # outputs held constant
        held: dict[str, VarDecl] = {}
        for h in self.holds:
            if h.name not in owner:
                self.fail(f"hold: unknown order '{h.name}'", h.loc, suggestions=close_names(h.name, [n for n, (_, d) in owner.items() if d.kind == ORDER]))
            elif owner[h.name][1].kind != ORDER:
                self.fail(f"hold: '{h.name}' is an input of element {owner[h.name][0].name}; only orders can be held", h.loc)
            else:
                held[h.name] = h
        final: list[ElementSpec] = []
        for e in elements:
            if any(v.name in held for v in e.variables):
                e = replace(
                    e,
                    variables=tuple(
                        replace(v, initial=held[v.name].initial, held=True) if v.name in held else v for v in e.variables
                    ),
                )
            self.check_element(e, owner)
            final.append(e)
        self.elements = final
        listed: dict[str, Location] = {}
        for vec in self.vectors:
            want_input = vec.kind == "inputs"
            pool = [n for n, (_, d) in owner.items() if d.is_input == want_input]
            for n, loc in vec.names:
                if n in listed:
                    self.fail(f"'{n}' is listed twice in the vectors", loc, notes=(f"first listed at {listed[n]}",))
                elif n not in owner:
                    self.fail(f"{vec.kind}: unknown variable '{n}'", loc, suggestions=close_names(n, pool))
                elif owner[n][1].is_input != want_input:
                    what = "an input" if owner[n][1].is_input else "an order"
                    self.fail(f"{vec.kind}: '{n}' is {what} of element {owner[n][0].name}", loc)
                else:
                    listed[n] = loc
        self.order = tuple(listed)
        all_names = set(owner)
        ids: dict[str, Constraint] = {}
        for c in self.constraints:
            if c.id in ids:
                self.fail(f"constraint id '{c.id}' is used twice", c.loc, notes=(f"first used at {ids[c.id].loc}",))
            ids[c.id] = c
            try:
                disjunctive_normal_form(c.forbidden)
            except ValueError as exc:
                if "negated" in str(exc):
                    self.fail(
                        f"constraint {c.id}: an edge cannot be negated (or the constraint written = 1 around an edge)",
                        c.loc,
                        notes=("write the forbidden case as a conjunction, e.g. `↓AVANCER1 & !v11 = 0`",),
                    )
                else:
                    self.fail(
                        f"constraint {c.id} is too large once expanded into monomials (more than 4096)",
                        c.loc,
                        notes=("split it into several constraints",),
                    )
            for n in names(c.expr):
                if n.name not in all_names:
                    what = "edge of an undeclared variable" if isinstance(n, Edge) else "undeclared variable"
                    self.fail(f"constraint {c.id} uses {what} '{n.name}'", n.loc, suggestions=close_names(n.name, all_names))
                elif isinstance(n, Edge) and owner[n.name][1].kind != ORDER:
                    self.fail(
                        f"constraint {c.id}: edges in constraints must be edges of orders; '{n.name}' is an input of element {owner[n.name][0].name}",
                        n.loc,
                        notes=("an edge restricts the matching controllable event; inputs are written as levels",),
                    )

    def check_element(self, e: ElementSpec, owner: Mapping[str, tuple[ElementSpec, VarDecl]]) -> None:
        own = {v.name: v for v in e.variables}

        def unknown(n: Var | Edge, role: str) -> None:
            if n.name in owner and owner[n.name][0].name != e.name:
                other = owner[n.name][0].name
                self.fail(
                    f"{role} of element {e.name} uses '{n.name}', which belongs to element {other}",
                    n.loc,
                    suggestions=close_names(n.name, own),
                    notes=(f"an element's {role}s may only use its own variables: {', '.join(sorted(own))}",),
                )
            else:
                self.fail(f"unknown variable '{n.name}' in element {e.name}", n.loc, suggestions=close_names(n.name, own))

        def levels_only(x: Expr, role: str) -> None:
            for n in names(x):
                if isinstance(n, Edge):
                    self.fail(f"an edge is not allowed in a {role}; write a level", n.loc)
                elif n.name not in own:
                    unknown(n, role)

        for inc in e.incoherences:
            levels_only(inc, "incoherence")
        for r in e.rules:
            c, q = r.cause, r.consequence
            if c.name not in own:
                unknown(c, "rule")
            elif own[c.name].kind != ORDER:
                self.fail(
                    f"the cause of a rule must be an edge of one of {e.name}'s orders; '{c.name}' is an input",
                    c.loc,
                    suggestions=close_names(c.name, [v.name for v in e.orders]),
                )
            if q.name not in own:
                if q.name in owner:
                    other = owner[q.name][0].name
                    self.fail(
                        f"rule of element {e.name} produces {q.text()}, but {q.name} is a sensor of element {other}",
                        q.loc,
                        suggestions=close_names(q.name, [v.name for v in e.inputs]),
                        notes=(f"a rule may only produce edges of its own element's sensors: {', '.join(v.name for v in e.inputs)}",),
                    )
                else:
                    unknown(q, "rule")
            elif own[q.name].kind == ORDER:
                self.fail(
                    f"the consequence of a rule must be an edge of a sensor of {e.name}; '{q.name}' is an order",
                    q.loc,
                    suggestions=close_names(q.name, [v.name for v in e.inputs]),
                )
            if r.guard is not None:
                levels_only(r.guard, "guard")
        for p in e.precedences:
            for role, x in (("cause", p.cause), ("first", p.first), ("then", p.then)):
                if x.name not in own:
                    unknown(x, "precedence")
                elif (own[x.name].kind == ORDER) != (role == "cause"):
                    want = "an edge of one of its orders" if role == "cause" else "an edge of one of its sensors"
                    self.fail(f"in a precedence of {e.name}, the {role} must be {want}; '{x.name}' is not", x.loc)
        # the initial state must be coherent
        init = {v.name: v.initial for v in e.variables}
        for inc in e.incoherences:
            if all(n.name in init for n in names(inc)) and evaluate(inc, init.__getitem__):
                where = inc.loc or next((n.loc for n in names(inc)), e.loc)
                self.fail(
                    f"the initial state of element {e.name} is incoherent: {inc.text()} holds initially",
                    where,
                    notes=("initial values: " + ", ".join(f"{k}={int(v)}" for k, v in init.items()),),
                )
        if not e.variables:
            self.fail(f"element {e.name} declares no variable", e.loc)


def _rename(name: str, model: _Model, mapping: Mapping[str, str], loc: Location) -> ElementSpec:
    def r(n: str) -> str:
        return mapping.get(n, n)

    def rx(x: Expr) -> Expr:
        if isinstance(x, Var):
            return Var(r(x.name), x.loc)
        if isinstance(x, Edge):
            return Edge(x.rising, r(x.name), x.loc)
        if isinstance(x, Const):
            return x
        if isinstance(x, Not):
            return Not(rx(x.arg), x.loc)
        return type(x)(tuple(rx(a) for a in x.args), x.loc)

    b = model.body
    return ElementSpec(
        name,
        tuple(replace(d, name=r(d.name)) for d in b.decls),
        tuple(rx(i) for i in b.incoherences),
        tuple(Rule(rx(x.cause), rx(x.guard) if x.guard is not None else None, rx(x.consequence), x.loc) for x in b.rules),
        tuple(Precedence(rx(p.cause), rx(p.first), rx(p.then), p.loc) for p in b.precedences),
        loc,
        model.name,
    )


def parse_rules(source: str, file: str = "<rules>", base: Path | None = None) -> RuleSet:
    """Parse and check rules text; ``base`` is the folder ``use`` paths are relative to."""
    items = _parse(source, file)
    checker = _Checker()
    if base is not None:
        checker.loaded.add((base / Path(file).name).resolve())  # a file that uses itself back
    checker.collect(items, base)
    if not checker.errors:
        checker.check()
    if not checker.elements and not checker.top_free and not checker.errors:
        checker.fail(
            "the plant is empty: no element is declared",
            location_in(file, source, 1, 1),
            notes=("declare elements with `element NAME { ... }` or `element NAME = MODEL(...)`",),
        )
    if len(checker.errors) == 1:
        raise checker.errors[0]
    if checker.errors:
        raise InputErrors(checker.errors)
    return RuleSet(tuple(checker.elements), tuple(checker.constraints), file, checker.order)


def load_rules(path: str | Path) -> RuleSet:
    """Read, parse and check a ``.rules`` file."""
    return parse_rules(read_source(path), str(path), Path(path).parent)

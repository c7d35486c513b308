r"""Reading the rules language: lark parse tree → plain frozen objects with locations.

What :mod:`synth.plant.rules_check` resolves (``use``, models, instances) and checks.

Example
-------
>>> [type(i).__name__ for i in rules_items('use "lib/a.rules"\nfree dcy = 0', "x.rules")]
['_Use', 'tuple']
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

from synth.errors import Location
from synth.logic.expr import Expr
from synth.plant.rules import FREE, ORDER, SENSOR, Constraint, Precedence, Rule, VarDecl
from synth.syntax import ExprTransformer, Token, parse_tree

__all__ = ["rules_items"]


@dataclass(frozen=True)
class _Body:
    """The items of a ``model`` or ``element`` body."""

    decls: tuple[VarDecl, ...]
    incoherences: tuple[Expr, ...]
    rules: tuple[Rule, ...]
    precedences: tuple[Precedence, ...]


@dataclass(frozen=True)
class _Model:
    """``model NAME { … }``."""

    name: str
    body: _Body
    loc: Location


@dataclass(frozen=True)
class _Instance:
    """``element NAME = MODEL(a = b, …)``."""

    name: str
    model: str
    renaming: tuple[tuple[str, str, Location, Location], ...]
    loc: Location
    model_loc: Location


@dataclass(frozen=True)
class _Inline:
    """``element NAME { … }``."""

    name: str
    body: _Body
    loc: Location


@dataclass(frozen=True)
class _Use:
    """``use "FILE"``."""

    path: str
    loc: Location


@dataclass(frozen=True)
class _Hold:
    """``hold NAME = BIT, …``."""

    decls: tuple[VarDecl, ...]


@dataclass(frozen=True)
class _Vector:
    """``inputs …`` or ``outputs …``."""

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


def rules_items(source: str, file: str) -> list:
    """The top-level items of a rules text, in file order."""
    return parse_tree("rules", source, file, _ToModel(file, source))

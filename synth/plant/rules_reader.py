r"""Reading the rules language: lark parse tree → plain frozen objects with locations.

What :mod:`synth.plant.rules_check` resolves (``use``, models, instances) and checks.

Example
-------
>>> [type(i).__name__ for i in rules_items('use "lib/a.rules"\nfree dcy = 0', "x.rules")]
['Use', 'tuple']
"""

from __future__ import annotations

from typing import Iterable

from synth.errors import Location
from synth.frozen import frozen
from synth.logic.expr import Expr
from synth.plant.rules import Constraint, Precedence, Read, Rule, VarDecl, VarKind
from synth.syntax import ExprTransformer, Token, VectorKind, parse_tree

__all__ = ["Body", "Model", "Instance", "Inline", "Use", "Hold", "Vector", "Item", "rules_items"]


@frozen
class Body:
    """The items of a ``model`` or ``element`` body."""

    decls: tuple[VarDecl, ...]
    incoherences: tuple[Expr, ...]
    rules: tuple[Rule, ...]
    precedences: tuple[Precedence, ...]
    reads: tuple[Read, ...] = ()


@frozen
class Model:
    """``model NAME { … }``."""

    name: str
    body: Body
    loc: Location


@frozen
class Instance:
    """``element NAME = MODEL(a = b, …)``."""

    name: str
    model: str
    renaming: tuple[tuple[str, str, Location, Location], ...]
    loc: Location
    model_loc: Location


@frozen
class Inline:
    """``element NAME { … }``."""

    name: str
    body: Body
    loc: Location


@frozen
class Use:
    """``use "FILE"``."""

    path: str
    loc: Location


@frozen
class Hold:
    """``hold NAME = BIT, …``."""

    decls: tuple[VarDecl, ...]


@frozen
class Vector:
    """``inputs …`` or ``outputs …``."""

    kind: VectorKind
    names: tuple[tuple[str, Location], ...]


# a top-level item; a bare tuple is a line of top-level free inputs
Item = Use | Model | Inline | Instance | Hold | Vector | Constraint | tuple[VarDecl, ...]


class _ToModel(ExprTransformer):
    """Parse tree → plain frozen objects that keep their locations."""

    # declarations
    def decl(self, items: list) -> tuple[Token, Token]:
        return (items[0], items[1])

    def _decls(self, items: list, kind: VarKind, held: bool = False) -> tuple[VarDecl, ...]:
        return tuple(VarDecl(str(n), kind, str(b) == "1", self._loc(n), held) for n, b in items)

    def orders(self, items: list) -> tuple[VarDecl, ...]:
        return self._decls(items, VarKind.ORDER)

    def sensors(self, items: list) -> tuple[VarDecl, ...]:
        return self._decls(items, VarKind.SENSOR)

    def free(self, items: list) -> tuple[VarDecl, ...]:
        return self._decls(items, VarKind.FREE)

    def hold(self, items: list) -> Hold:
        return Hold(self._decls(items, VarKind.ORDER, held=True))

    def reads(self, items: list) -> list[Read]:
        return [Read(str(n), self._loc(n)) for n in items]

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

    def _body(self, items: Iterable) -> Body:
        decls: list[VarDecl] = []
        inc: list[Expr] = []
        rules: list[Rule] = []
        precs: list[Precedence] = []
        reads: list[Read] = []
        for it in items:
            if isinstance(it, list):
                reads.extend(it)
            elif isinstance(it, tuple):
                decls.extend(it)
            elif isinstance(it, Rule):
                rules.append(it)
            elif isinstance(it, Precedence):
                precs.append(it)
            else:
                inc.append(it)
        return Body(tuple(decls), tuple(inc), tuple(rules), tuple(precs), tuple(reads))

    def model(self, items: list) -> Model:
        name, *rest = items
        return Model(str(name), self._body(rest), self._loc(name))

    def element_inline(self, items: list) -> Inline:
        name, *rest = items
        return Inline(str(name), self._body(rest), self._loc(name))

    def renaming(self, items: list) -> tuple[str, str, Location, Location]:
        a, b = items
        return (str(a), str(b), self._loc(a), self._loc(b))

    def element_instance(self, items: list) -> Instance:
        name, model, *ren = items
        renaming = tuple(r for r in ren if r is not None)
        return Instance(str(name), str(model), renaming, self._loc(name), self._loc(model))

    def vector(self, items: list) -> Vector:
        kind, *names = items
        return Vector(VectorKind(str(kind)), tuple((str(n), self._loc(n)) for n in names))

    def use(self, items: list) -> Use:
        (tok,) = items
        return Use(str(tok)[1:-1], self._loc(tok))

    def constraint(self, items: list) -> Constraint:
        ident, label, expr, bit = items
        text = str(label)[1:-1] if label is not None else ""
        return Constraint(str(ident), text, expr, str(bit) == "1", self._loc(ident))

    def start(self, items: list) -> list:
        return items


def rules_items(source: str, file: str) -> list[Item]:
    """The top-level items of a rules text, in file order."""
    return parse_tree("rules", source, file, _ToModel(file, source))

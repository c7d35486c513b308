r"""Reading the filter language: lark parse tree → the frozen objects of
:mod:`synth.filter.language`, with locations; :mod:`synth.filter.language_check`
resolves names and classifies the constraints.

Example
-------
>>> items = filter_items('outputs O1, O2\nsafety K1: O1 & O2^-1 keep O1', "x.filter")
>>> [type(i).__name__ for i in items]
['Vector', 'Safety']
>>> items[1].expr.text()
'O1 & O2^-1'
"""

from __future__ import annotations

from dataclasses import dataclass

from synth.errors import Location
from synth.filter.language import (
    Assumption,
    Criterion,
    Declared,
    Equation,
    Forcing,
    Safety,
    Sense,
    SimCriterion,
    VarKind,
)
from synth.logic.past import pre_name
from synth.logic.expr import Expr, Var
from synth.syntax import ExprTransformer, Token, parse_tree

__all__ = ["filter_items", "filter_expression", "Use", "Vector"]


@dataclass(frozen=True)
class Use:
    """``use "plant.rules"``."""

    path: str
    loc: Location


@dataclass(frozen=True)
class Vector:
    """``inputs ...`` or ``outputs ...``."""

    kind: VarKind
    names: tuple[tuple[str, Location], ...]


class _ToFilter(ExprTransformer):
    """Parse tree → plain frozen objects that keep their locations."""

    def pre(self, items: list) -> Var:
        tok = items[0]
        return Var(pre_name(str(tok)), self._loc(tok))

    def use(self, items: list) -> Use:
        (tok,) = items
        return Use(str(tok)[1:-1], self._loc(tok))

    def vector(self, items: list) -> Vector:
        kind, *names = items
        which = VarKind.INPUT if str(kind) == "inputs" else VarKind.OUTPUT
        return Vector(which, tuple((str(n), self._loc(n)) for n in names))

    def observed(self, items: list) -> Declared:
        name, grafcet = items
        return Declared(str(name), VarKind.OBSERVER, self._loc(name), str(grafcet)[1:-1] if grafcet else None)

    def observer(self, items: list) -> tuple[Declared, ...]:
        return tuple(items)

    def defined(self, items: list) -> Declared:
        name, e = items
        return Declared(str(name), VarKind.OBSERVER, self._loc(name), None, e)

    def assume(self, items: list) -> Assumption:
        (e,) = items
        return Assumption(e, _first_loc(e))

    def forcing(self, items: list) -> Forcing:
        name, bit = items
        return Forcing(str(name), str(bit) == "1", self._loc(name))

    def keep(self, items: list) -> Expr:
        return items[0]

    def force(self, items: list) -> tuple[Forcing, ...]:
        return tuple(items)

    def safety(self, items: list) -> Safety:
        ident, label, expr, relief = items
        text = str(label)[1:-1] if label is not None else ""
        keep = relief if relief is not None and not isinstance(relief, tuple) else None
        force = relief if isinstance(relief, tuple) else ()
        return Safety(str(ident), text, expr, self._loc(ident), keep=keep, force=force)

    def minimize(self, items: list) -> Criterion:
        (e,) = items
        return Criterion(Sense.MIN, e, _first_loc(e))

    def maximize(self, items: list) -> Criterion:
        (e,) = items
        return Criterion(Sense.MAX, e, _first_loc(e))

    def maximize_sim(self, items: list) -> SimCriterion:
        return SimCriterion(tuple(str(n) for n in items), self._loc(items[0]), tuple(self._loc(n) for n in items))

    def equation(self, items: list) -> Equation:
        name, e = items
        return Equation(str(name), e, self._loc(name))

    def start(self, items: list) -> list:
        out: list = []
        for it in items:
            out.extend(it if isinstance(it, tuple) and not isinstance(it, Token) else (it,))
        return out


def _first_loc(e: Expr) -> Location | None:
    """The location of the first name of ``e`` (constants have theirs too)."""
    if getattr(e, "loc", None) is not None:
        return e.loc
    for a in getattr(e, "args", ()) or ((e.arg,) if hasattr(e, "arg") else ()):
        loc = _first_loc(a)
        if loc is not None:
            return loc
    return None


def filter_items(source: str, file: str) -> list:
    """The top-level items of a filter text, in file order (observer lists flattened)."""
    return parse_tree("filter", source, file, _ToFilter(file, source))


def filter_expression(source: str, file: str) -> Expr:
    """One expression in filter syntax (``x^-1``, edges of any variable), e.g. an equation
    ``synth filter solve`` printed.

    >>> filter_expression("R_A0 & !A1^-1 | ↑C6", "eq").text()
    'R_A0 & !A1^-1 | ↑C6'
    """
    from synth.syntax import parse_expression

    return parse_expression(source, file, "filter", _ToFilter(file, source))

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
>>> decl, assumption = filter_items("observer cpt : 0..3\nassume cpt^-1 <= cpt", "x.filter")
>>> decl.text(), assumption.expr.text(), assumption.expr.loc.column, assumption.expr.loc.width
('observer cpt : 0..3', 'cpt^-1 <= cpt', 8, 13)
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
from synth.logic.expr import CMP_SPELLINGS, Compare, Expr, Var
from synth.syntax import ExprTransformer, Token, parse_tree

__all__ = ["filter_items", "filter_expression", "Use", "Vector", "IntegerDecl"]


@dataclass(frozen=True)
class Use:
    """``use "plant.rules"``."""

    path: str
    loc: Location


@dataclass(frozen=True)
class IntegerDecl:
    """``observer cpt : LOW..HIGH`` as written (checked later)."""

    name: str
    low: int
    high: int
    loc: Location
    range_loc: Location

    def text(self) -> str:
        return f"observer {self.name} : {self.low}..{self.high}"


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

    def integer(self, items: list) -> IntegerDecl:
        name, low, high = items
        width = high.end_pos - low.start_pos if high.end_pos is not None and low.start_pos is not None else None
        return IntegerDecl(str(name), int(low), int(high), self._loc(name), self._loc(low, width=width))

    def cmp_right(self, items: list) -> tuple[str | int, Token]:
        tok, pre = items[0], items[1] if len(items) > 1 else None
        if tok.type == "SIGNED":
            return int(tok), tok
        return (pre_name(str(tok)), pre) if pre is not None else (str(tok), tok)

    def compare(self, items: list) -> Compare:
        """``cpt >= 2``, ``cpt^-1 < cpt``: located on the whole comparison."""
        left, pre, op, (right, last) = items
        name = pre_name(str(left)) if pre is not None else str(left)
        width = last.end_pos - left.start_pos if last.end_pos is not None and left.start_pos is not None else None
        return Compare.of(name, CMP_SPELLINGS.get(str(op), str(op)), right, self._loc(left, width=width))

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

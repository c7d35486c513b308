"""Boolean expressions over plant variables and their edges.

Shared by the rules language (guards, incoherences, constraints) and the Grafcet
language (receptivities, action conditions). Expressions are immutable and keep
the :class:`~synth.errors.Location` of each name so that later checks can point
at the offending token.

Evaluation is generic: ``value(name)`` may return Python booleans or numpy
boolean arrays (then the result is an array, broadcast as numpy does).

Example
-------
>>> e = And((Var("a"), Not(Var("b"))))
>>> evaluate(e, lambda n: {"a": True, "b": False}[n])
True
>>> e.text()
'a & !b'
"""

from __future__ import annotations

import operator
from dataclasses import field
from functools import reduce
from itertools import product
from typing import Any, Callable, Iterator, Mapping, Union


from synth.errors import Location
from synth.frozen import frozen
from synth.logic.events import Event

__all__ = [
    "Expr",
    "Var",
    "Const",
    "Compare",
    "CMP_OPS",
    "CMP_SPELLINGS",
    "Not",
    "And",
    "Or",
    "Edge",
    "Literal",
    "Monomial",
    "disjunctive_normal_form",
    "edge_text",
    "evaluate",
    "names",
    "renamed",
    "NegatedEdge",
    "NormalFormTooLarge",
]


class NegatedEdge(ValueError):
    """An edge under a negation: events are not levels, ``!↑x`` has no normal form."""


class NormalFormTooLarge(ValueError):
    """The disjunctive normal form would have more monomials than the limit."""


def edge_text(rising: bool, name: str) -> Event:
    """The event ``↑name`` or ``↓name``."""
    return Event.edge(name, rising)


@frozen
class Var:
    """A variable (a plant input or output, a step variable ``X12``): true or false."""

    name: str
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        return self.name


CMP_OPS: dict[str, Callable[[int, int], bool]] = {
    ">=": operator.ge, "<=": operator.le, "<>": operator.ne, "=": operator.eq, "<": operator.lt, ">": operator.gt,
}
"""The comparison operators of :class:`Compare`, by canonical spelling (IEC 61131-3's)."""

CMP_SPELLINGS = {"!=": "<>", "≠": "<>", "≥": ">=", "≤": "<="}
"""Other spellings of the comparison operators, and the canonical one each stands for."""


@frozen
class Compare(Var):
    """``cnt >= 3``: a comparison of an integer variable with a constant or another one.

    To every walker that does not know comparisons it is an atomic proposition named by its
    text (``name``), like a step variable: a Boolean function of the state that holds it.

    >>> c = Compare.of("cnt", ">=", 3)
    >>> c.name, c.text(), c.holds({"cnt": 3}), c.holds({"cnt": 2})
    ('cnt>=3', 'cnt >= 3', True, False)
    """

    left: str = ""
    op: str = "="
    right: int | str = 0

    @staticmethod
    def of(left: str, op: str, right: int | str, loc: Location | None = None) -> "Compare":
        return Compare(f"{left}{op}{right}", loc, left, op, right)

    def text(self) -> str:
        return f"{self.left} {self.op} {self.right}"

    def operands(self) -> tuple[str, ...]:
        """The variable names compared (one or two)."""
        return (self.left,) + ((self.right,) if isinstance(self.right, str) else ())

    def holds(self, values: "Mapping[str, int]") -> bool:
        right = values[self.right] if isinstance(self.right, str) else self.right
        return CMP_OPS[self.op](values[self.left], right)


@frozen
class Const:
    """The constant ``1`` (True) or ``0`` (False)."""

    value: bool
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        return "1" if self.value else "0"


@frozen
class Edge:
    """A rising (``↑x``) or falling (``↓x``) edge of a variable: an event, not a level."""

    rising: bool
    name: str
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        return edge_text(self.rising, self.name)

    @property
    def event(self) -> Event:
        return Event.edge(self.name, self.rising)


@frozen
class Not:
    """``!arg``."""

    arg: "Expr"
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        inner = self.arg.text()
        atomic = isinstance(self.arg, (Var, Const, Edge, Not)) and not isinstance(self.arg, Compare)
        return "!" + (inner if atomic else f"({inner})")


@frozen
class And:
    """``a & b & …``: true when every argument is."""

    args: tuple["Expr", ...]
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        return " & ".join(a.text() if not isinstance(a, Or) else f"({a.text()})" for a in self.args)


@frozen
class Or:
    """``a | b | …``: true when some argument is."""

    args: tuple["Expr", ...]
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        return " | ".join(a.text() for a in self.args)


Expr = Union[Var, Const, Edge, Not, And, Or]


def _not(r: Any) -> Any:
    if isinstance(r, bool):
        return not r
    if type(r).__module__ == "numpy":  # arrays of values: numpy is loaded already
        import numpy as np

        return np.logical_not(r)
    return ~r  # a BDD (or any value with Boolean operators)


def _combine(a: Any, b: Any, absorbing: bool, ufunc: str, op: Callable[[Any, Any], Any]) -> Any:
    """``a & b`` (``absorbing`` False) or ``a | b`` (True) for booleans, numpy arrays and BDDs:
    a Python boolean next to another value is absorbing or neutral."""
    if isinstance(a, bool):
        return absorbing if a == absorbing else b
    if isinstance(b, bool):
        return absorbing if b == absorbing else a
    if type(a).__module__ == "numpy" or type(b).__module__ == "numpy":
        import numpy as np

        return getattr(np, ufunc)(a, b)
    return op(a, b)


def _and(a: Any, b: Any) -> Any:
    return _combine(a, b, False, "logical_and", operator.and_)


def _or(a: Any, b: Any) -> Any:
    return _combine(a, b, True, "logical_or", operator.or_)


def _evaluate(e: Expr, value: Callable[[str], Any], edge: Callable[[Edge], Any]) -> Any:
    if isinstance(e, Var):
        return value(e.name)
    if isinstance(e, Const):
        return e.value
    if isinstance(e, Edge):
        return edge(e)
    if isinstance(e, Not):
        return _not(_evaluate(e.arg, value, edge))
    parts = [_evaluate(a, value, edge) for a in e.args]
    if all(isinstance(p, bool) for p in parts):
        return all(parts) if isinstance(e, And) else any(parts)
    if isinstance(e, And):
        return reduce(_and, parts, True)
    return reduce(_or, parts, False)


def _no_edge(e: Edge) -> bool:
    return False


def evaluate(e: Expr, value: Callable[[str], Any], edge: Callable[[Edge], Any] = _no_edge) -> Any:
    """Value of ``e``; names through ``value``, edges through ``edge`` (false by default).

    One walker for every kind of value: Python booleans, numpy arrays of them (element by
    element), and BDDs or anything else with the Boolean operators ``~ & |`` (the symbolic
    engine's ``--home``); a Python boolean next to such a value is absorbed or neutral.

    >>> e = And((Var("a"), Not(Var("b"))))
    >>> evaluate(e, {"a": True, "b": False}.__getitem__)
    True
    >>> class Bits(int):  # values with Boolean operators, as BDDs have
    ...     def __invert__(self): return Bits(~int(self) & 0b1111)
    ...     def __and__(self, o): return Bits(int(self) & int(o))
    ...     def __or__(self, o): return Bits(int(self) | int(o))
    >>> bin(evaluate(Or((e, Const(False))), {"a": Bits(0b1100), "b": Bits(0b1010)}.__getitem__))
    '0b100'
    """
    return _evaluate(e, value, edge)


def names(e: Expr) -> Iterator[Var | Edge]:
    """Every variable and edge occurrence of ``e``, in text order."""
    if isinstance(e, (Var, Edge)):
        yield e
    elif isinstance(e, Not):
        yield from names(e.arg)
    elif isinstance(e, (And, Or)):
        for a in e.args:
            yield from names(a)


def renamed(e: Expr, rename: Callable[[str], str]) -> Expr:
    """``e`` with every variable and edge name passed through ``rename`` (locations kept).

    >>> renamed(And((Var("A"), Edge(True, "b"))), str.upper).text()
    'A & ↑B'
    """
    if isinstance(e, Compare):
        right = rename(e.right) if isinstance(e.right, str) else e.right
        return Compare.of(rename(e.left), e.op, right, e.loc)
    if isinstance(e, Var):
        return Var(rename(e.name), e.loc)
    if isinstance(e, Edge):
        return Edge(e.rising, rename(e.name), e.loc)
    if isinstance(e, Const):
        return e
    if isinstance(e, Not):
        return Not(renamed(e.arg, rename), e.loc)
    return type(e)(tuple(renamed(a, rename) for a in e.args), e.loc)


@frozen(order=True)
class Literal:
    """``name`` (positive) or ``!name``; ``edge`` is set for ``↑name`` / ``↓name``."""

    name: str
    positive: bool = True
    edge: bool = False


Monomial = frozenset[Literal]


def disjunctive_normal_form(e: Expr, limit: int = 4096) -> list[Monomial]:
    """The expression as a list of satisfiable monomials (conjunctions of literals).

    Edges appear as literals with ``edge=True`` (``positive`` tells rising or falling).

    >>> sorted(sorted(str(l.name) + str(l.positive) for l in m)
    ...        for m in disjunctive_normal_form(And((Var("a"), Or((Var("b"), Not(Var("c"))))))))
    [['aTrue', 'bTrue'], ['aTrue', 'cFalse']]
    """

    def dnf(x: Expr, positive: bool) -> list[frozenset[Literal]]:
        if isinstance(x, Var):
            return [frozenset({Literal(x.name, positive)})]
        if isinstance(x, Edge):
            if not positive:
                raise NegatedEdge(x.text())
            return [frozenset({Literal(x.name, x.rising, edge=True)})]
        if isinstance(x, Const):
            return [frozenset()] if x.value == positive else []
        if isinstance(x, Not):
            return dnf(x.arg, not positive)
        conj = isinstance(x, And) == positive
        parts = [dnf(a, positive) for a in x.args]
        if not conj:
            return [m for p in parts for m in p]
        out: list[frozenset[Literal]] = []
        for combo in product(*parts):
            m = frozenset().union(*combo)
            out.append(m)
            if len(out) > limit:
                raise NormalFormTooLarge(f"more than {limit} monomials")
        return out

    result: list[Monomial] = []
    for m in dnf(e, True):
        levels = {(l.name, l.positive) for l in m if not l.edge}
        if any((n, not p) in levels for n, p in levels):
            continue  # x & !x
        edges = [l for l in m if l.edge]
        if len({(l.name, l.positive) for l in edges}) > 1:
            continue  # two different events never happen at once
        if m not in result:
            result.append(m)
    return result

"""The ``.filter`` language as plain frozen data: declarations, safety constraints with
their relief, assumptions, criteria and (optional) equations to check.

Expressions are the shared :mod:`synth.logic.expr` AST. The previous cycle's value of
``x`` (written ``x^-1`` or ``pre(x)``) is the variable named ``x^-1``; the request of an
output ``o`` is the variable ``R_o``. An edge ``↑x`` stands for ``!x^-1 & x``.

Example
-------
>>> request_name("A2")
'R_A2'
>>> cpt = IntegerObserver("cpt", 0, 4)
>>> cpt.bits, cpt.values(3)
(('cpt_b0', 'cpt_b1', 'cpt_b2'), (True, True, False))
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from synth.errors import InputError, Location
from synth.logic.expr import Compare, Expr
from synth.logic.past import base_name, is_pre, pre_name

TYPE_CHECKING = False  # typing.TYPE_CHECKING
if TYPE_CHECKING:
    from synth.plant.rules import RuleSet

__all__ = [
    "REQUEST_PREFIX",
    "request_name",
    "BIT_INFIX",
    "MAX_BITS",
    "bit_name",
    "IntegerObserver",
    "Comparison",
    "VarKind",
    "ConstraintKind",
    "Sense",
    "Declared",
    "Forcing",
    "Safety",
    "Assumption",
    "Criterion",
    "SimCriterion",
    "Equation",
    "Filter",
]

REQUEST_PREFIX = "R_"


def request_name(output: str) -> str:
    """The request ``R_o`` of output ``o`` (the program's order, 000's g1)."""
    return REQUEST_PREFIX + output


BIT_INFIX = "_b"
MAX_BITS = 10
"""An integer observer has at most ``2**MAX_BITS`` values (a located error past it)."""


def bit_name(integer: str, k: int) -> str:
    """The Boolean observer holding bit ``k`` (0: the least significant) of the code
    ``value - low`` of an integer observer: ``cpt_b0``."""
    return f"{integer}{BIT_INFIX}{k}"


@dataclass(frozen=True)
class IntegerObserver:
    """``observer cpt : 0..3``: a read-only integer the program supplies every cycle,
    encoded as the Boolean observers :attr:`bits` (the binary code of ``value - low``)."""

    name: str
    low: int
    high: int
    loc: Location | None = field(default=None, compare=False)

    @property
    def width(self) -> int:
        """ceil(log2(high - low + 1)) bits, at least one."""
        return max(1, (self.high - self.low).bit_length())

    @property
    def bits(self) -> tuple[str, ...]:
        return tuple(bit_name(self.name, k) for k in range(self.width))

    def values(self, value: int) -> tuple[bool, ...]:
        """The bits of ``value`` (in ``low..high``), least significant first."""
        code = value - self.low
        return tuple(bool((code >> k) & 1) for k in range(self.width))


@dataclass(frozen=True)
class Comparison(Compare):
    """A checked comparison of integer observers: ``reads`` are the Boolean variables it is
    a function of (the bits of its operands, ``cpt_b0^-1`` for ``cpt^-1``)."""

    reads: tuple[str, ...] = field(default=(), compare=False)

    @staticmethod
    def resolved(c: Compare, integers: "dict[str, IntegerObserver]") -> "Comparison":
        reads: list[str] = []
        for x in c.operands():
            obs = integers[base_name(x)]
            reads += [pre_name(b) if is_pre(x) else b for b in obs.bits]
        return Comparison(c.name, c.loc, c.left, c.op, c.right, tuple(reads))


class VarKind(StrEnum):
    """What a declared name is. Only outputs at t are controllable; the rest is Y."""

    INPUT = "input"
    OUTPUT = "output"
    OBSERVER = "observer"
    REQUEST = "request"
    INTEGER = "integer observer"


class ConstraintKind(StrEnum):
    """CSs (one output at t) or CSc (two or more), after 000 eqs. (1)-(2)."""

    SIMPLE = "simple"
    COMBINED = "combined"


class Sense(StrEnum):
    """The direction of an optimisation criterion (004 §2.2)."""

    MIN = "minimize"
    MAX = "maximize"


@dataclass(frozen=True)
class Declared:
    """A declared name; ``grafcet`` is the file of an observer computed from a Grafcet;
    ``definition`` the expression of an observer declared ``observer P := EXPR`` (over
    inputs, requests and past values, evaluated at the start of every cycle)."""

    name: str
    kind: VarKind
    loc: Location | None = field(default=None, compare=False)
    grafcet: str | None = None
    definition: Expr | None = None


@dataclass(frozen=True)
class Forcing:
    """``o=v`` in a ``force`` list: relieving the constraint sets output ``o`` to ``v``."""

    output: str
    value: bool
    loc: Location | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Safety:
    """``safety ID "label": EXPR [keep L | force o=v, ...]``: EXPR must be 0 after every cycle.

    ``outputs`` are the outputs at t the expression mentions (edges of an output count),
    in text order; ``forced`` is the relief as a column of 000's MC0/MC1 (empty when the
    constraint gives none, or is simple)."""

    id: str
    label: str
    expr: Expr
    loc: Location | None = field(default=None, compare=False)
    keep: Expr | None = None
    force: tuple[Forcing, ...] = ()
    outputs: tuple[str, ...] = ()
    forced: tuple[Forcing, ...] = ()

    @property
    def kind(self) -> ConstraintKind:
        return ConstraintKind.SIMPLE if len(self.outputs) == 1 else ConstraintKind.COMBINED

    @property
    def has_priority(self) -> bool:
        return self.keep is not None or bool(self.force)


@dataclass(frozen=True)
class Assumption:
    """``assume EXPR``: EXPR is true on every reachable valuation of Y."""

    expr: Expr
    loc: Location | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Criterion:
    """``minimize EXPR`` / ``maximize EXPR``; ``origin`` says where it comes from (for reports)."""

    sense: Sense
    expr: Expr
    loc: Location | None = field(default=None, compare=False)
    origin: str = ""


@dataclass(frozen=True)
class SimCriterion:
    """``maximize sim o1, o2, ...``: one ``Max(R_o·o + !R_o·!o)`` per output, in this order."""

    outputs: tuple[str, ...]
    loc: Location | None = field(default=None, compare=False)
    locs: tuple[Location, ...] = field(default=(), compare=False)  # one per output


@dataclass(frozen=True)
class Equation:
    """``equation o = EXPR``: a proposed implementation of output ``o`` that ``check`` verifies."""

    output: str
    expr: Expr
    loc: Location | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Filter:
    """A checked ``.filter`` file. ``criteria`` keeps the file's order, sims included."""

    file: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    observers: tuple[Declared, ...] = ()
    assumptions: tuple[Assumption, ...] = ()
    safeties: tuple[Safety, ...] = ()
    criteria: tuple[Criterion | SimCriterion, ...] = ()
    equations: tuple[Equation, ...] = ()
    plant: str | None = None
    warnings: tuple[InputError, ...] = ()
    declarations: tuple[Declared, ...] = field(default=(), compare=False)  # inputs, outputs, observers, with locations
    integers: tuple[IntegerObserver, ...] = ()  # their bits are among the observers
    rules: RuleSet | None = field(default=None, compare=False, repr=False)  # the rule set ``plant``, read once

    @property
    def integer_observers(self) -> tuple[IntegerObserver, ...]:
        """The integer observers whose bits this filter reads (all of a file's; those a
        cluster of outputs uses, in a cluster's filter)."""
        mine = set(self.observer_names)
        return tuple(i for i in self.integers if any(b in mine for b in i.bits))

    @property
    def requests(self) -> tuple[str, ...]:
        return tuple(request_name(o) for o in self.outputs)

    @property
    def observer_names(self) -> tuple[str, ...]:
        return tuple(d.name for d in self.observers)

    @property
    def simple(self) -> tuple[Safety, ...]:
        return tuple(s for s in self.safeties if s.kind is ConstraintKind.SIMPLE)

    @property
    def combined(self) -> tuple[Safety, ...]:
        return tuple(s for s in self.safeties if s.kind is ConstraintKind.COMBINED)

    def safety(self, ident: str) -> Safety:
        return next(s for s in self.safeties if s.id == ident)

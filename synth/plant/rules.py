"""The rules language as plain frozen data: plant elements, occurrence rules, precedences
and constraints, gathered in a :class:`RuleSet`.

:mod:`synth.plant.rules_reader` turns the text into items; :mod:`synth.plant.rules_check`
resolves and checks them (``load_rules`` / ``parse_rules``).

Example
-------
>>> from synth.logic.expr import Var
>>> v3 = ElementSpec("V3", (VarDecl("AVANCER3", VarKind.ORDER, False), VarDecl("v30", VarKind.SENSOR, True)))
>>> rs = RuleSet((v3,), (Constraint("C1", "never out", Var("v30")),))
>>> rs.inputs, rs.outputs, rs.constraints[0].text()
(('v30',), ('AVANCER3',), 'v30 = 0')
"""


from __future__ import annotations

from dataclasses import field
from enum import StrEnum

from synth.errors import Location
from synth.frozen import frozen
from synth.logic.expr import Edge, Expr, Not

__all__ = [
    "VarKind",
    "VarDecl",
    "Read",
    "Rule",
    "Precedence",
    "ElementSpec",
    "Constraint",
    "RuleSet",
]


class VarKind(StrEnum):
    """What a plant variable is: an order (output Z), a sensor or a free input (both in E)."""

    ORDER = "order"
    SENSOR = "sensor"
    FREE = "free"



@frozen
class VarDecl:
    """A variable of an element: an order (output Z), a sensor or a free input (input E)."""

    name: str
    kind: VarKind
    initial: bool
    loc: Location | None = field(default=None, compare=False)
    held: bool = False

    @property
    def is_input(self) -> bool:
        return self.kind != VarKind.ORDER


@frozen
class Read:
    """``reads NAME``: a variable of another element that this element's rules may read
    (in guards, and as the cause of a rule); it keeps its one owner."""

    name: str
    loc: Location | None = field(default=None, compare=False)


@frozen
class Rule:
    """Occurrence rule ``cause [guard] -> consequence``."""

    cause: Edge
    guard: Expr | None
    consequence: Edge
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        g = f" [{self.guard.text()}]" if self.guard is not None else ""
        return f"{self.cause.text()}{g} -> {self.consequence.text()}"


@frozen
class Precedence:
    """``cause: first < then``: after ``cause``, ``then`` can only follow ``first``."""

    cause: Edge
    first: Edge
    then: Edge
    loc: Location | None = field(default=None, compare=False)

    def text(self) -> str:
        return f"{self.cause.text()}: {self.first.text()} < {self.then.text()}"


@frozen
class ElementSpec:
    """One plant element as written (after instantiation of a model)."""

    name: str
    variables: tuple[VarDecl, ...]
    incoherences: tuple[Expr, ...] = ()
    rules: tuple[Rule, ...] = ()
    precedences: tuple[Precedence, ...] = ()
    loc: Location | None = field(default=None, compare=False)
    model: str | None = None
    reads: tuple[Read, ...] = ()

    @property
    def orders(self) -> tuple[VarDecl, ...]:
        return tuple(v for v in self.variables if v.kind == VarKind.ORDER)

    @property
    def inputs(self) -> tuple[VarDecl, ...]:
        return tuple(v for v in self.variables if v.kind != VarKind.ORDER)

    def variable(self, name: str) -> VarDecl | None:
        return next((v for v in self.variables if v.name == name), None)

    @property
    def read_names(self) -> tuple[str, ...]:
        """The other elements' variables it reads, as declared."""
        return tuple(r.name for r in self.reads)


@frozen
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


@frozen
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

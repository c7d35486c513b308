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

from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

from synth.errors import Location, location_in
from synth.logic.expr import Edge, Expr, Not
from synth.syntax import read_source

__all__ = [
    "VarKind",
    "VarDecl",
    "Rule",
    "Precedence",
    "ElementSpec",
    "Constraint",
    "RuleSet",
    "parse_rules",
    "load_rules",
]


class VarKind(StrEnum):
    """What a plant variable is: an order (output Z), a sensor or a free input (both in E)."""

    ORDER = "order"
    SENSOR = "sensor"
    FREE = "free"


ORDER, SENSOR, FREE = VarKind.ORDER, VarKind.SENSOR, VarKind.FREE



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


def parse_rules(source: str, file: str = "<rules>", base: Path | None = None) -> RuleSet:
    """Parse and check rules text; ``base`` is the folder ``use`` paths are relative to."""
    from synth.plant.rules_check import RulesChecker
    from synth.plant.rules_reader import rules_items

    items = rules_items(source, file)
    checker = RulesChecker()
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
    checker.raise_errors()
    return RuleSet(tuple(checker.elements), tuple(checker.constraints), file, checker.order)


def load_rules(path: str | Path) -> RuleSet:
    """Read, parse and check a ``.rules`` file."""
    return parse_rules(read_source(path), str(path), Path(path).parent)

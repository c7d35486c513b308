"""Reading the ``.g7`` language: lark parse tree → plain frozen objects with locations,
checked by :mod:`synth.grafcet.language_check`.

Example
-------
>>> [type(i).__name__ for i in grafcet_items("grafcet G { initial step 0 }", "g.g7")]
['GrafcetDecl']
"""

from __future__ import annotations

from synth.errors import InputError, Location
from synth.frozen import frozen
from synth.grafcet.language import (
    TIMER_RE,
    CONDITIONAL,
    CONTINUOUS,
    ON_ACTIVATION,
    ON_DEACTIVATION,
    ON_EVENT,
    STORED,
    ASSIGN,
    Action,
    StoredWhen,
    Sum,
    timer_id,
)
from synth.logic.expr import CMP_SPELLINGS, Compare, Const, Expr, Var
from synth.syntax import ExprTransformer, Token, VectorKind, parse_tree

__all__ = ["parse_receptivity", "VectorDecl", "InternalDecl", "StepRef", "StepDecl", "TransitionDecl", "GrafcetDecl", "grafcet_items"]


@frozen
class VectorDecl:
    """``inputs …`` or ``outputs …``."""

    kind: VectorKind
    names: tuple[tuple[str, Location], ...]


@frozen
class InternalDecl:
    """``internal NAME [: bool | : LOW..HIGH] [= INITIAL]`` as written (checked later)."""

    name: str
    boolean: bool
    low: int
    high: int
    initial: int | None
    loc: Location
    range_loc: Location
    initial_loc: Location | None


@frozen
class StepRef:
    """A step named as a transition's source or target."""

    name: str
    loc: Location


@frozen
class StepDecl:
    """A step declaration with its actions."""

    name: str
    initial: bool
    actions: tuple[Action, ...]
    loc: Location


@frozen
class TransitionDecl:
    """A transition: its sources, targets and receptivity."""

    label: str | None
    label_loc: Location | None
    sources: tuple[StepRef, ...]
    targets: tuple[StepRef, ...]
    receptivity: Expr
    loc: Location


@frozen
class GrafcetDecl:
    """``grafcet NAME { … }``."""

    name: str
    steps: tuple[StepDecl, ...]
    transitions: tuple[TransitionDecl, ...]
    loc: Location


class _ToModel(ExprTransformer):
    """Parse tree → plain frozen objects that keep their locations."""

    def __init__(self, file: str, source: str) -> None:
        super().__init__(file, source)
        self.errors: list[InputError] = []

    def const(self, items: list) -> Const:
        (tok,) = items
        if str(tok) not in ("0", "1"):
            self.errors.append(
                InputError(f"a constant must be 0 or 1, not {tok}", self._loc(tok), notes=("timers are written 2s/X12",))
            )
        return Const(str(tok) != "0", self._loc(tok))

    def timer(self, items: list) -> Var:
        (tok,) = items
        m = TIMER_RE.match(str(tok))
        assert m is not None
        number, unit, step = m.groups()
        if "." in number:
            number = number.rstrip("0").rstrip(".")
        return Var(timer_id(number + unit, step), self._loc(tok))

    # declarations
    def inputs_decl(self, items: list) -> VectorDecl:
        return VectorDecl(VectorKind.INPUTS, tuple((str(t), self._loc(t)) for t in items))

    def outputs_decl(self, items: list) -> VectorDecl:
        return VectorDecl(VectorKind.OUTPUTS, tuple((str(t), self._loc(t)) for t in items))

    def bool_type(self, items: list) -> tuple[bool, int, int, Location]:
        return (True, 0, 1, self._loc(items[0]))

    def range_type(self, items: list) -> tuple[bool, int, int, Location]:
        low, high = items
        loc = self._loc(low, width=high.end_pos - low.start_pos if high.end_pos is not None and low.start_pos is not None else None)
        return (False, int(low), int(high), loc)

    def internal_decl(self, items: list) -> InternalDecl:
        name, vtype, initial = items
        boolean, low, high, rloc = vtype if vtype is not None else (True, 0, 1, self._loc(name))
        return InternalDecl(str(name), boolean, low, high, int(initial) if initial is not None else None,
                            self._loc(name), rloc, self._loc(initial) if initial is not None else None)

    def compare(self, items: list) -> Compare:
        left, op, right = items
        value: int | str = str(right) if right.type == "NAME" else int(right)
        return Compare.of(str(left), CMP_SPELLINGS.get(str(op), str(op)), value, self._loc(left))

    def operand(self, items: list) -> tuple[int | str, Location]:
        (tok,) = items
        return (str(tok) if tok.type == "NAME" else int(tok), self._loc(tok))

    def sum(self, items: list) -> Sum:
        first, *rest = items
        terms: list[tuple[int, int | str]] = [(1, first[0])]
        for sign, (x, _) in zip(rest[::2], rest[1::2]):
            terms.append((1 if str(sign) == "+" else -1, x))
        if isinstance(terms[0][1], int) and terms[0][1] < 0:
            terms[0] = (-1, -terms[0][1])
        return Sum(tuple(terms), first[1])

    def assign_bool_action(self, items: list) -> Action:
        tok, expr, when = items
        moment, cond = when if when is not None else (ON_ACTIVATION, None)
        return Action(ASSIGN, str(tok), cond, True, moment, self._loc(tok), Sum((), self._loc(tok), expr))

    def assign_action(self, items: list) -> Action:
        tok, value, when = items
        moment, cond = when if when is not None else (ON_ACTIVATION, None)
        return Action(ASSIGN, str(tok), cond, True, moment, self._loc(tok), value)

    # steps and actions
    def step_id(self, items: list) -> StepRef:
        (tok,) = items
        return StepRef(str(tok), self._loc(tok))

    def continuous(self, items: list) -> Action:
        (tok,) = items
        return Action(CONTINUOUS, str(tok), loc=self._loc(tok))

    def conditional(self, items: list) -> Action:
        tok, cond = items
        return Action(CONDITIONAL, str(tok), cond, loc=self._loc(tok))

    def on_activation(self, items: list) -> tuple[StoredWhen, Expr | None]:
        return (ON_ACTIVATION, None)

    def on_deactivation(self, items: list) -> tuple[StoredWhen, Expr | None]:
        return (ON_DEACTIVATION, None)

    def on_event(self, items: list) -> tuple[StoredWhen, Expr | None]:
        return (ON_EVENT, items[0])

    def _stored(self, items: list, value: bool) -> Action:
        tok, when = items
        moment, cond = when if when is not None else (ON_ACTIVATION, None)
        return Action(STORED, str(tok), cond, value, moment, self._loc(tok))

    def set_action(self, items: list) -> Action:
        return self._stored(items, True)

    def reset_action(self, items: list) -> Action:
        return self._stored(items, False)

    def step(self, items: list) -> StepDecl:
        initial, ref, *actions = items
        return StepDecl(ref.name, initial is not None, tuple(a for a in actions if a is not None), ref.loc)

    # transitions
    def tlabel(self, items: list) -> Token:
        return items[0]

    def step_list(self, items: list) -> tuple[StepRef, ...]:
        return tuple(items)

    def transition(self, items: list) -> TransitionDecl:
        label, sources, arrow, targets, receptivity = items
        loc = self._loc(label) if label is not None else None
        where = loc or (sources[0].loc if sources else self._loc(arrow))
        return TransitionDecl(
            str(label) if label is not None else None,
            loc,
            sources or (),
            targets or (),
            receptivity,
            where,
        )

    def grafcet(self, items: list) -> GrafcetDecl:
        name, *body = items
        steps = tuple(b for b in body if isinstance(b, StepDecl))
        trans = tuple(b for b in body if isinstance(b, TransitionDecl))
        return GrafcetDecl(str(name), steps, trans, self._loc(name))

    def start(self, items: list) -> list:
        return items


def grafcet_items(source: str, file: str) -> list[VectorDecl | InternalDecl | GrafcetDecl]:
    """The top-level items of a ``.g7`` text, in file order."""
    return parse_tree("grafcet", source, file, _ToModel(file, source))


def parse_receptivity(source: str, file: str) -> Expr:
    """One receptivity in ``.g7`` syntax (comparisons included), its names located in ``file``.

    >>> parse_receptivity("cnt < 4 | X2", "r").text()
    'cnt < 4 | X2'
    """
    from synth.syntax import parse_expression

    return parse_expression(source, file, "grafcet", _ToModel(file, source))

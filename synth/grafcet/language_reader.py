"""Reading the ``.g7`` language: lark parse tree → plain frozen objects with locations,
checked by :mod:`synth.grafcet.language_check`.

Example
-------
>>> [type(i).__name__ for i in grafcet_items("grafcet G { initial step 0 }", "g.g7")]
['_Graf']
"""

from __future__ import annotations

from dataclasses import dataclass

from synth.errors import InputError, Location
from synth.grafcet.language import (
    _TIMER_RE,
    CONDITIONAL,
    CONTINUOUS,
    ON_ACTIVATION,
    ON_DEACTIVATION,
    ON_EVENT,
    STORED,
    Action,
    timer_id,
)
from synth.logic.expr import Const, Expr, Var
from synth.syntax import ExprTransformer, Token, parse_tree

__all__ = ["grafcet_items"]




@dataclass(frozen=True)
class _Decl:
    """``inputs …`` or ``outputs …``."""

    kind: str  # "inputs" | "outputs"
    names: tuple[tuple[str, Location], ...]


@dataclass(frozen=True)
class _StepRef:
    """A step named as a transition's source or target."""

    name: str
    loc: Location


@dataclass(frozen=True)
class _Step:
    """A step declaration with its actions."""

    name: str
    initial: bool
    actions: tuple[Action, ...]
    loc: Location


@dataclass(frozen=True)
class _Trans:
    """A transition: its sources, targets and receptivity."""

    label: str | None
    label_loc: Location | None
    sources: tuple[_StepRef, ...]
    targets: tuple[_StepRef, ...]
    receptivity: Expr
    loc: Location


@dataclass(frozen=True)
class _Graf:
    """``grafcet NAME { … }``."""

    name: str
    steps: tuple[_Step, ...]
    transitions: tuple[_Trans, ...]
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
        m = _TIMER_RE.match(str(tok))
        assert m is not None
        number, unit, step = m.groups()
        if "." in number:
            number = number.rstrip("0").rstrip(".")
        return Var(timer_id(number + unit, step), self._loc(tok))

    # declarations
    def inputs_decl(self, items: list) -> _Decl:
        return _Decl("inputs", tuple((str(t), self._loc(t)) for t in items))

    def outputs_decl(self, items: list) -> _Decl:
        return _Decl("outputs", tuple((str(t), self._loc(t)) for t in items))

    # steps and actions
    def step_id(self, items: list) -> _StepRef:
        (tok,) = items
        return _StepRef(str(tok), self._loc(tok))

    def continuous(self, items: list) -> Action:
        (tok,) = items
        return Action(CONTINUOUS, str(tok), loc=self._loc(tok))

    def conditional(self, items: list) -> Action:
        tok, cond = items
        return Action(CONDITIONAL, str(tok), cond, loc=self._loc(tok))

    def on_activation(self, items: list) -> tuple[str, Expr | None]:
        return (ON_ACTIVATION, None)

    def on_deactivation(self, items: list) -> tuple[str, Expr | None]:
        return (ON_DEACTIVATION, None)

    def on_event(self, items: list) -> tuple[str, Expr | None]:
        return (ON_EVENT, items[0])

    def _stored(self, items: list, value: bool) -> Action:
        tok, when = items
        kind, cond = when if when is not None else (ON_ACTIVATION, None)
        return Action(STORED, str(tok), cond, value, kind, self._loc(tok))

    def set_action(self, items: list) -> Action:
        return self._stored(items, True)

    def reset_action(self, items: list) -> Action:
        return self._stored(items, False)

    def step(self, items: list) -> _Step:
        initial, ref, *actions = items
        return _Step(ref.name, initial is not None, tuple(a for a in actions if a is not None), ref.loc)

    # transitions
    def tlabel(self, items: list) -> Token:
        return items[0]

    def step_list(self, items: list) -> tuple[_StepRef, ...]:
        return tuple(items)

    def transition(self, items: list) -> _Trans:
        label, sources, arrow, targets, receptivity = items
        loc = self._loc(label) if label is not None else None
        where = loc or (sources[0].loc if sources else self._loc(arrow))
        return _Trans(
            str(label) if label is not None else None,
            loc,
            sources or (),
            targets or (),
            receptivity,
            where,
        )

    def grafcet(self, items: list) -> _Graf:
        name, *body = items
        steps = tuple(b for b in body if isinstance(b, _Step))
        trans = tuple(b for b in body if isinstance(b, _Trans))
        return _Graf(str(name), steps, trans, self._loc(name))

    def start(self, items: list) -> list:
        return items


def grafcet_items(source: str, file: str) -> list:
    """The top-level items of a ``.g7`` text, in file order."""
    return parse_tree("grafcet", source, file, _ToModel(file, source))

"""A Grafcet's situation, and its expressions compiled to fast functions of it.

A :class:`Situation` is what :class:`~synth.grafcet.machine.GrafcetMachine` moves between:
the active steps, the outputs set by stored actions, the elapsed timers, and the values
of the internal variables (``internal cnt : 0..3``).

Example
-------
>>> Situation(("1",), data=(("cnt", 2),)).text()
'{X1} cnt=2'
>>> from synth.logic.expr import And, Compare, Var
>>> f = compile_expr(And((Var("X1"), Compare.of("cnt", ">=", 2))), {"1"}, set(), set())
>>> f({}, frozenset({"1"}), frozenset(), None, {"cnt": 2}), f({}, frozenset({"1"}), frozenset(), None, {"cnt": 1})
(True, False)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

from synth.errors import ModelFailure
from synth.frozen import frozen
from synth.grafcet.language import Action, Internal, step_key, step_of, step_variable
from synth.logic.events import Event
from synth.logic.expr import And, Compare, Const, Edge, Expr, Not, Var

__all__ = ["Situation", "State", "CompiledFn", "compile_expr", "sorted_steps", "OutOfRange", "assign"]

_PY_OPS = {">=": ">=", "<=": "<=", "<>": "!=", "=": "==", "<": "<", ">": ">"}


def sorted_steps(steps: Sequence[str] | set[str] | frozenset[str]) -> tuple[str, ...]:
    return tuple(sorted(steps, key=step_key))


@frozen(order=True)
class Situation:
    """A situation of the Grafcet: active steps, stored outputs set, elapsed timers, and
    the values of its internal variables (declaration order; Booleans as 0/1).

    >>> Situation(("1", "101"), ("M",), ("2s/X101",)).text()
    '{X1, X101} stored{M} elapsed{2s/X101}'
    """

    steps: tuple[str, ...]
    stored: tuple[str, ...] = ()
    elapsed: tuple[str, ...] = ()
    data: tuple[tuple[str, int], ...] = ()

    def text(self) -> str:
        out = "{" + ", ".join(self.step_variables) + "}"
        if self.stored:
            out += " stored{" + ", ".join(self.stored) + "}"
        if self.elapsed:
            out += " elapsed{" + ", ".join(self.elapsed) + "}"
        for name, value in self.data:
            out += f" {name}={value}"
        return out

    @property
    def step_variables(self) -> tuple[str, ...]:
        return tuple(step_variable(s) for s in self.steps)

    @property
    def values(self) -> dict[str, int]:
        """The internal variables' values by name."""
        return dict(self.data)


@dataclass
class State:
    """The machine's mutable state during one evolution."""

    active: set[str]
    stored: set[str]
    elapsed: set[str]
    data: dict[str, int]

    def key(self) -> tuple[frozenset[str], frozenset[str], frozenset[str], tuple[tuple[str, int], ...]]:
        return (frozenset(self.active), frozenset(self.stored), frozenset(self.elapsed), tuple(self.data.items()))


CompiledFn = Callable[[Mapping[str, bool], frozenset[str], frozenset[str], "Event | None", Mapping[str, int]], bool]
"""An expression as a function of (inputs I, active steps A, elapsed timers T, event E, internal values D)."""


def _code(e: Expr, steps: set[str], timers: set[str], internals: set[str]) -> str:
    if isinstance(e, Compare):
        right = f"D[{e.right!r}]" if isinstance(e.right, str) else str(e.right)
        return f"(D[{e.left!r}] {_PY_OPS[e.op]} {right})"
    if isinstance(e, Var):
        if e.name in timers:
            return f"({e.name!r} in T)"
        if e.name in internals:
            return f"(D[{e.name!r}] != 0)"
        step = step_of(e.name, steps)
        if step is not None:
            return f"({step!r} in A)"
        return f"I[{e.name!r}]"
    if isinstance(e, Const):
        return "True" if e.value else "False"
    if isinstance(e, Edge):
        return f"(E == {str(e.event)!r})"
    if isinstance(e, Not):
        return f"(not {_code(e.arg, steps, timers, internals)})"
    op = " and " if isinstance(e, And) else " or "
    return "(" + op.join(_code(a, steps, timers, internals) for a in e.args) + ")"


def compile_expr(e: Expr, steps: set[str], timers: set[str], internals: set[str]) -> CompiledFn:
    """``e`` as a fast :data:`CompiledFn`."""
    fn: CompiledFn = eval(  # noqa: S307 - names are repr-quoted
        f"lambda I, A, T, E, D: {_code(e, steps, timers, internals)}", {"__builtins__": {}})
    return fn


class OutOfRange(ModelFailure):
    """An assignment gives an internal variable a value outside its declared range (exit 1)."""


def assign(data: dict[str, int], actions: Sequence[Action], internals: Mapping[str, Internal], where: str) -> None:
    """Run ``actions`` (assignments) simultaneously, in place: every right side is read on
    the values before any of them; for one variable, the last in file order wins. A value
    outside the variable's range is an :class:`OutOfRange` at the assignment.

    >>> from synth.grafcet.language import ASSIGN, Sum
    >>> d = {"a": 1, "b": 2}
    >>> assign(d, [Action(ASSIGN, "a", assign=Sum(((1, "b"),))), Action(ASSIGN, "b", assign=Sum(((1, "a"),)))],
    ...        {"a": Internal("a", 0, 3, 0), "b": Internal("b", 0, 3, 0)}, "{X0}")
    >>> d
    {'a': 2, 'b': 1}
    """
    new: dict[str, tuple[int, Action]] = {}
    for a in actions:
        assert a.assign is not None
        new[a.order] = (a.assign.value(data), a)
    for name, (value, a) in new.items():
        v = internals[name]
        if not v.low <= value <= v.high:
            raise OutOfRange(
                f"{a.order} := {a.assign.text() if a.assign else ''} gives {value}, outside the range "
                f"{v.low}..{v.high} of '{name}'",
                a.loc,
                notes=(f"in situation {where}",),
            )
        data[name] = value


def with_trace(err: OutOfRange, events: Sequence[str]) -> OutOfRange:
    """``err`` with the events that lead to it from the initial situation, as a note.

    >>> e = with_trace(OutOfRange("cnt := cnt + 1 gives 2", None), ["↑a", "↓a", "↑a"])
    >>> e.notes
    ('trace: ↑a ↓a ↑a',)
    """
    trace = " ".join(events) if events else "(the initial situation)"
    return OutOfRange(err.message, err.location, notes=err.notes + (f"trace: {trace}",))

"""The Grafcet's internal variables in Structured Text: their declarations, comparisons,
and the assignments of one phase (on activation, on deactivation, on an event).

An assignment phase is simultaneous, as :func:`synth.grafcet.situation.assign` runs it:
every right side reads the values before the phase, and for one variable the last
assignment in the machine's order (steps by name, then actions in file order) wins. In ST,
each variable assigned in the phase gets its next value in ``_Next_<v>``, copied back once
every right side has been read.

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet("internal cnt : 0..3 grafcet G { initial step 0 step 1: cnt := cnt + 1 "
...                   "transition 0 -> 1 when ↑a transition 1 -> 0 when cnt >= 3 }")
>>> [d.text() for d in declarations(g, str)]
['cnt : INT := 0; (* internal 0..3 *)', '_Next_cnt : INT; (* the next value of cnt in an assignment phase *)']
>>> for line in assignment_phase(g, lambda a, s: f"_Enter[{s}]" if a.when == "activation" else None, str):
...     print(line)
_Next_cnt := cnt;
IF _Enter[1] THEN _Next_cnt := cnt + 1; END_IF;
cnt := _Next_cnt;
"""

from __future__ import annotations

from typing import Callable

from synth.codegen.st import Declaration, st_expr
from synth.grafcet.language import ASSIGN, Action, Grafcet, Internal, Sum, step_key
from synth.logic.expr import Compare, Var

__all__ = ["declarations", "compare_text", "assignment_phase", "assigned", "sum_text"]


def _type(v: Internal) -> str:
    return "BOOL" if v.boolean else "INT"


def _literal(v: Internal, value: int) -> str:
    return ("TRUE" if value else "FALSE") if v.boolean else str(value)


def assigned(g: Grafcet) -> list[Internal]:
    """The internal variables some action assigns, in declaration order."""
    names = {a.order for s in g.steps for a in s.actions if a.kind == ASSIGN}
    return [v for v in g.internals if v.name in names]


def declarations(g: Grafcet, st: Callable[[str], str]) -> list[Declaration]:
    """One local variable per internal variable (its initial value) and per assigned one its ``_Next_``."""
    out = [Declaration(st(v.name), _type(v), _literal(v, v.initial),
                       "internal Boolean" if v.boolean else f"internal {v.low}..{v.high}") for v in g.internals]
    out += [Declaration(f"_Next_{st(v.name)}", _type(v), comment=f"the next value of {st(v.name)} in an assignment phase")
            for v in assigned(g)]
    return out


def compare_text(c: Compare, st: Callable[[str], str]) -> str:
    """``cnt >= 3`` in ST (IEC 61131-3 spells the operators as synth does)."""
    right = st(c.right) if isinstance(c.right, str) else str(c.right)
    return f"{st(c.left)} {c.op} {right}"


def sum_text(v: Internal, e: Sum, st: Callable[[str], str]) -> str:
    """The right side of an assignment to ``v`` in ST."""
    if e.expr is not None:
        return st_expr(e.expr, lambda x: st(x.name) if isinstance(x, Var) else x.text())
    if v.boolean and len(e.terms) == 1 and isinstance(e.terms[0][1], int):
        return _literal(v, e.terms[0][1])
    return Sum(tuple((sign, st(x) if isinstance(x, str) else x) for sign, x in e.terms)).text()


def assignment_phase(g: Grafcet, condition: Callable[[Action, str], str | None], st: Callable[[str], str]) -> list[str]:
    """The statements of one assignment phase: ``condition(action, step)`` is the ST condition
    under which the assignment runs in this phase, or None when it does not belong to it."""
    internals = {v.name: v for v in g.internals}
    chosen: dict[str, list[tuple[str, Action]]] = {}
    for s in sorted(g.steps, key=lambda s: step_key(s.name)):
        for a in s.actions:
            if a.kind == ASSIGN:
                cond = condition(a, s.name)
                if cond is not None:
                    chosen.setdefault(a.order, []).append((cond, a))
    lines: list[str] = []
    order = [v.name for v in g.internals if v.name in chosen]
    for name in order:
        lines.append(f"_Next_{st(name)} := {st(name)};")
        for cond, a in chosen[name]:
            assert a.assign is not None
            value = sum_text(internals[name], a.assign, st)
            then = f"_Next_{st(name)} := {value};"
            lines.append(then if cond == "TRUE" else f"IF {cond} THEN {then} END_IF;")
    lines += [f"{st(name)} := _Next_{st(name)};" for name in order]
    return lines

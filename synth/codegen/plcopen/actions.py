"""The ST body of a POU action referenced from an SFC step (``synth import``): its Boolean
assignments as ``.g7`` stored actions.

A PLC runs the body while the action is active and never undoes what it assigned, so
``X := TRUE;`` is ``set X`` and ``X := FALSE;`` is ``reset X`` (on activation; on
deactivation for ``P0``). ``IF c THEN X := TRUE; END_IF`` in a body that runs while the step
is active (qualifier ``N``) stores X the first time ``c`` holds: ``set X on`` the rising edge
of ``c`` (for ``c`` a conjunction of inputs, ``↑(a & !b)`` is ``↑a & !b | a & ↓b``), with a
located warning for the one case the two differ (``c`` already true when the step becomes
active). Anything else (data, block calls, ELSE) is an :class:`~synth.errors.InputError` at
its statement.

Example
-------
>>> rising("a & !b")
'↑a & !b | a & ↓b'
"""

from __future__ import annotations

import contextvars
import re
from typing import Any, Callable

from synth.codegen.plcopen.assign import sum_text
from synth.codegen.plcopen.data import DATA
from synth.codegen.plcopen.vendor import IecQualifier
from synth.codegen.plcopen.st_condition import ExprReader
from synth.errors import InputError, Location, Severity

__all__ = ["ACTION_WARNINGS", "action_body", "rising"]

ACTION_WARNINGS: contextvars.ContextVar[list[InputError] | None] = contextvars.ContextVar(
    "ACTION_WARNINGS", default=None)
"""While a chart is read: the warnings of its action bodies (a level ``IF`` read as an edge)."""

_ASSIGN = re.compile(r"([\w.]+)\s*:=\s*(TRUE|FALSE)\s*;", re.I)
_DATA = re.compile(r"(\w+)\s*:=\s*([^;]*?)\s*;", re.I)
_IF = re.compile(r"IF\b(?P<cond>.*?)\bTHEN\b(?P<body>.*?)\bEND_IF\b\s*;?", re.I | re.S)


def rising(expr: str) -> str:
    """The rising edge of a conjunction of inputs and negated inputs (``.g7`` text), or ``""``
    when ``expr`` is not one."""
    literals = expr.split(" & ")
    if not all(re.fullmatch(r"!?[A-Za-z]\w*", lit) for lit in literals):
        return ""
    terms = []
    for i, lit in enumerate(literals):
        edge = "↓" + lit[1:] if lit.startswith("!") else "↑" + lit
        terms.append(" & ".join(edge if j == i else other for j, other in enumerate(literals)))
    return " | ".join(terms)


def _order(name: str, where: Location) -> str:
    """The ``.g7`` name of an assigned variable: its declared spelling (ST ignores case), a
    dotted global flattened (``GVL.X``: ``GVL_X``, with a warning)."""
    scope = DATA.get()
    if scope is None:
        return name
    if "." in name:
        if name.split(".")[0].upper() not in scope.global_lists:
            raise InputError(f"{name} is a member of the block instance {name.rsplit('.', 1)[0]}: .g7 holds this "
                             "chart's variables, not another block's", where)
        return scope.global_name(name, True, where)
    v = scope.find(name)
    if v is None and name.upper() in scope.inputs:
        return scope.input_written(name, where)
    return v.name if v is not None else scope.spelling.get(name.upper(), name)


def _data(m: re.Match[str], base: int, where: Callable[[int, int], Location]) -> tuple[str, bool] | None:
    """``V := sum;`` (``m``, in a text at ``base``) with ``V`` an internal variable: ``V := sum`` and
    whether the sum reads a variable; None when ``V`` is not one."""
    scope = DATA.get()
    v = scope.find(m[1]) if scope is not None else None
    if scope is None or v is None:
        return None
    value = sum_text(scope, v, m[2], lambda o, w: where(base + m.start(2) + o, w))
    return f"{v.name} := {value}", bool(re.search(r"[A-Za-z]", value))


def _timer_statement(statement: str, pos: int, where: Callable[[int, int], Location]) -> bool:
    """A call of a TON made a step timer, or an assignment of its alias: nothing in ``.g7``."""
    scope = DATA.get()
    if scope is None:
        return False
    call = re.fullmatch(r"(\w+)\s*\(.*\)", statement, re.S)
    if call and call[1].upper() in scope.timer_blocks:
        return True
    alias = re.fullmatch(r"(\w+)\s*:=\s*(.*)", statement, re.S)
    if alias and (alias[1].upper() in scope.timers or alias[1].upper() in scope.step_timers):
        if not re.fullmatch(r"\w+\.Q", alias[2].strip(), re.I):
            timer = scope.timers.get(alias[1].upper()) or ", ".join(scope.step_timers[alias[1].upper()].values())
            scope.warnings.append(InputError(
                f"{statement} is left out: {alias[1]} stands for the step timer {timer}",
                where(pos, len(alias[1])), severity=Severity.WARNING))
        return True
    return False


def action_body(name: str, text: str, qualifier: IecQualifier, where: Callable[[int, int], Location],
                steps: dict[str, str]) -> list[str]:
    """The ``.g7`` stored actions of the ST ``text`` of POU action ``name`` run with
    ``qualifier``; ``where(offset, width)`` locates a character of ``text``."""
    if qualifier == IecQualifier.R:
        raise InputError(f"qualifier R on action {name}: a reset action has no body to run in .g7", where(0, 1))
    when = " on deactivation" if qualifier == IecQualifier.P0 else ""
    clean = re.sub(r"\(\*.*?\*\)|//[^\n]*", lambda c: re.sub(r"[^\n]", " ", c[0]), text, flags=re.S)
    out: list[str] = []
    pos = len(clean) - len(clean.lstrip())
    while pos < len(clean):
        end = clean.find(";", pos)
        statement = " ".join(clean[pos:end if end >= 0 else len(clean)].split())
        m = _ASSIGN.match(clean, pos) or re.compile(r";").match(clean, pos)  # ';' alone: an empty statement
        if m and m[0] == ";":
            pass
        elif _timer_statement(statement, pos, where):
            m = re.compile(r"[^;]*;?").match(clean, pos)
        elif m:
            out.append(f"{'set' if m[2].upper() == 'TRUE' else 'reset'} {_order(m[1], where(pos, len(m[1])))}{when}")
        elif (m := _DATA.match(clean, pos)) and (found := _data(m, 0, where)) is not None:
            if found[1] and qualifier == IecQualifier.N and (scope := DATA.get()) is not None:
                scope.every_scan(statement, f"action {name}", where(pos, len(m[1])))
            _in_sequence(found[0], [o.split(" := ")[0] for o in out if " := " in o], name, where(pos, len(m[1])))
            out.append(found[0] + when)
        elif (m := _IF.match(clean, pos)) and qualifier == IecQualifier.N:
            out += _level_if(name, m, where, steps)
        else:
            call = re.fullmatch(r"([\w.]+)\s*\(.*\)", statement, re.S)
            if call:
                raise InputError(f"a call of the block instance {call[1]} in action {name} ({statement}): .g7 runs no "
                                 "function blocks (its timers time a step's activity: 2s/X1)", where(pos, len(call[1])))
            data = re.fullmatch(r"([\w.]+)\s*:=\s*(.*)", statement, re.S)
            if data and not re.fullmatch(r"TRUE|FALSE", data[2], re.I) and \
                    re.search(r"^[-+]?\d|[+\-*/]|\bMOD\b", data[2], re.I):
                raise InputError(f"an assignment of data in action {name} ({statement}): {data[1]} is not a local "
                                 "variable of an integer type (.g7 internal variables are the chart's own)",
                                 where(pos, len(data[1])))
            raise InputError(f"a statement of action {name} that .g7 cannot hold ({statement}): a PLC keeps what an "
                             "action body assigns after its step is left, so only X := TRUE; and X := FALSE; (and, "
                             "in an N action, IF condition THEN X := TRUE; END_IF) are read", where(pos, 1))
        assert m is not None
        pos = m.end()
        pos += len(clean[pos:]) - len(clean[pos:].lstrip())
    return out


def _level_if(name: str, m: re.Match[str], where: Callable[[int, int], Location],
              steps: dict[str, str]) -> list[str]:
    """``IF c THEN X := TRUE; END_IF`` run while the step is active: ``set X on ↑c`` (an
    assignment of an internal variable likewise: ``V := V + 1 on ↑c``)."""
    start = m.start("cond")
    body_at = m.start("body")
    actions: list[str] = []
    pos = 0
    body = m["body"]
    while body[pos:].strip():
        pos += len(body[pos:]) - len(body[pos:].lstrip())
        end = body.find(";", pos)
        if _timer_statement(" ".join(body[pos:end if end >= 0 else len(body)].split()), body_at + pos, where):
            pos = end + 1 if end >= 0 else len(body)
            continue
        a = _ASSIGN.match(body, pos)
        d = None if a else _DATA.match(body, pos)
        found = _data(d, body_at, where) if d else None
        if a:
            actions.append(f"{'set' if a[2].upper() == 'TRUE' else 'reset'} "
                           f"{_order(a[1], where(body_at + pos, len(a[1])))}")
        elif found is not None:
            actions.append(found[0])
        else:
            end = body.find(";", pos)
            statement = " ".join(body[pos:end if end >= 0 else len(body)].split())
            raise InputError(f"a statement of action {name} that .g7 cannot hold in IF ... THEN ({statement}): only "
                             "X := TRUE;, X := FALSE; and assignments of internal variables are read",
                             where(body_at + pos, 1))
        pos = (a or d).end()  # type: ignore[union-attr]
    if not actions:  # only a TON made a step timer
        return []
    cond = ExprReader(m["cond"], lambda o, w: where(start + o, w), steps, "an action's IF").whole()
    edge = rising(cond[1:-1] if cond.startswith("(") and cond.endswith(")") else cond)
    if not edge or any(f"X{s}" in re.findall(r"\w+", edge) for s in steps.values()):
        raise InputError(f"IF {' '.join(m['cond'].split())} in action {name}: only a condition that is a "
                         "conjunction of inputs (a AND NOT b) has a rising edge .g7 can write", where(start, 1))
    warnings = ACTION_WARNINGS.get()
    if warnings is not None:
        warnings.append(InputError(
            f"IF {' '.join(m['cond'].split())} in action {name} (run while its step is active) is read as the stored "
            f"action on the rising edge {edge}: if the condition already holds when the step becomes active, the PLC "
            "assigns at once and .g7 waits for the edge", where(m.start(), 2), severity=Severity.WARNING))
    return [f"{a} on {edge}" for a in actions]


def _in_sequence(assignment: str, before: list[str], name: str, at: Location) -> None:
    """A PLC runs a body's statements in sequence, ``.g7`` the assignments of one phase at once:
    they differ when a right side reads a variable an earlier statement of the body assigned."""
    target, value = assignment.split(" := ", 1)
    read = [b for b in before if re.search(rf"\b{re.escape(b)}\b", value)]
    if read:
        raise InputError(f"{assignment.split(' := ')[0]} := … in action {name} reads {', '.join(read)}, assigned before "
                         "it in the same body: the PLC runs the statements in sequence, .g7 the assignments of a phase "
                         "at once (each reads the values before the phase)", at,
                         notes=(f"write the assignment to {target} first, or use the value it computes",))

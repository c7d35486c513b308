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

from synth.codegen.plcopen_vendor import IecQualifier
from synth.codegen.st_condition import ExprReader
from synth.errors import InputError, Location, Severity

__all__ = ["ACTION_WARNINGS", "action_body", "rising"]

ACTION_WARNINGS: contextvars.ContextVar[list[InputError] | None] = contextvars.ContextVar(
    "ACTION_WARNINGS", default=None)
"""While a chart is read: the warnings of its action bodies (a level ``IF`` read as an edge)."""

_ASSIGN = re.compile(r"(\w+)\s*:=\s*(TRUE|FALSE)\s*;", re.I)
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
        m = _ASSIGN.match(clean, pos) or re.compile(r";").match(clean, pos)  # ';' alone: an empty statement
        if m and m[0] == ";":
            pass
        elif m:
            out.append(f"{'set' if m[2].upper() == 'TRUE' else 'reset'} {m[1]}{when}")
        elif (m := _IF.match(clean, pos)) and qualifier == IecQualifier.N and \
                re.fullmatch(r"(\s*\w+\s*:=\s*(TRUE|FALSE)\s*;)+\s*", m["body"], re.I):
            out += _level_if(name, m, where, steps)
        else:
            end = clean.find(";", pos)
            statement = " ".join(clean[pos:end if end >= 0 else len(clean)].split())
            call = re.fullmatch(r"([\w.]+)\s*\(.*\)", statement, re.S)
            if call:
                raise InputError(f"a call of the block instance {call[1]} in action {name} ({statement}): .g7 runs no "
                                 "function blocks (its timers time a step's activity: 2s/X1)", where(pos, len(call[1])))
            data = re.fullmatch(r"([\w.]+)\s*:=\s*(.*)", statement, re.S)
            if data and not re.fullmatch(r"TRUE|FALSE", data[2], re.I) and \
                    re.search(r"^[-+]?\d|[+\-*/]|\bMOD\b", data[2], re.I):
                raise InputError(f"an assignment of data in action {name} ({statement}): .g7 actions set Boolean "
                                 "outputs; internal integer variables are not read yet", where(pos, len(data[1])))
            raise InputError(f"a statement of action {name} that .g7 cannot hold ({statement}): a PLC keeps what an "
                             "action body assigns after its step is left, so only X := TRUE; and X := FALSE; (and, "
                             "in an N action, IF condition THEN X := TRUE; END_IF) are read", where(pos, 1))
        pos = m.end()
        pos += len(clean[pos:]) - len(clean[pos:].lstrip())
    return out


def _level_if(name: str, m: re.Match[str], where: Callable[[int, int], Location],
              steps: dict[str, str]) -> list[str]:
    """``IF c THEN X := TRUE; END_IF`` run while the step is active: ``set X on ↑c``."""
    start = m.start("cond")
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
    return [f"{'set' if a[2].upper() == 'TRUE' else 'reset'} {a[1]} on {edge}"
            for a in _ASSIGN.finditer(m["body"])]

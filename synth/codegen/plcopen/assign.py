"""The right side of an assignment read from an ST action body (``synth import``): a sum of
integer literals, constants and integer internal variables, or for a Boolean internal variable
``TRUE``/``FALSE``, another one, or a Boolean expression of them.

Example
-------
>>> scope = DataScope("P", lambda el: None)
>>> a, b = (DataVar(n, "BOOL", 0, 1, 0, False, None) for n in "AB")
>>> scope.vars.update({"A": a, "B": b})
>>> sum_text(scope, a, "B XOR A", lambda o, w: None), sum_text(scope, b, "TRUE", lambda o, w: None)
('(B & !A | !B & A)', '1')
"""

from __future__ import annotations

import re
from typing import Callable

from synth.codegen.plcopen.data import DataScope, DataVar
from synth.codegen.plcopen.st_condition import ExprReader
from synth.errors import InputError, Location

__all__ = ["sum_text"]


def sum_text(scope: DataScope, target: DataVar, rhs: str, where: Callable[[int, int], Location]) -> str:
    """The ``.g7`` right side of ``target := rhs`` (``rhs``: ST text): a sum of integer
    literals and integer internal variables, or for a Boolean ``TRUE``/``FALSE``/another one."""
    text = rhs.strip()
    lead = len(rhs) - len(rhs.lstrip())
    if target.boolean:
        if text.upper() in ("TRUE", "FALSE"):
            return "1" if text.upper() == "TRUE" else "0"
        other = scope.find(text) if re.fullmatch(r"\w+", text) else None
        if other is not None and other.boolean:
            return other.name
        return _boolean_rhs(scope, target, text, lambda off, w: where(lead + off, w))
    out = ""
    pos = 0
    for i, m in enumerate(re.finditer(r"\s*([-+]?)\s*(\w+#)?(\w+)\s*", text)):
        if m.start() != pos or (i and not m[1]):
            break
        pos = m.end()
        term = m[3]
        if re.fullmatch(r"\d+", term.replace("_", "")):
            term = term.replace("_", "")
        elif term.upper() in scope.constants and not m[2] and scope.vars.get(term.upper()) is None:
            term = str(scope.constants[term.upper()])
            if term.startswith("-"):
                m_sign = "+" if m[1] == "-" else "-"
                out += (f" {m_sign} " if out else ("-" if m_sign == "-" else "")) + term[1:]
                continue
        else:
            v = scope.find(term)
            if v is None or v.boolean or m[2]:
                raise InputError(f"'{term}' in the assignment to {target.name}: .g7 adds integer internal variables "
                                 "and integer constants", where(lead + m.start(3), len(term)))
            term = v.name
        sign = m[1] or "+"
        out += (f" {sign} " if out else ("-" if sign == "-" else "")) + term
    if pos != len(text) or not out:
        raise InputError(f"the assignment to {target.name} is not a sum of integers and internal variables "
                         f"('{text}'): .g7 assigns sums such as {target.name} + 1", where(lead + pos, 1))
    return out


def _boolean_rhs(scope: DataScope, target: DataVar, text: str, where: Callable[[int, int], Location]) -> str:
    """A Boolean expression of Boolean internal variables (``QX2 XOR QX1``) as the ``.g7`` right
    side ``(…)``; anything else it reads is a located error."""
    g7 = ExprReader(text, where, {}, f"the assignment to {target.name}").whole()
    for name in dict.fromkeys(re.findall(r"[A-Za-z_]\w*", g7)):
        v = scope.find(name)
        if v is None or not v.boolean:
            at = text.upper().find(name.upper())
            raise InputError(f"{target.name} is a Boolean internal variable: its right side reads Boolean internal "
                             f"variables only, not '{name}'", where(max(0, at), max(1, len(name))))
    return g7 if g7.startswith("(") and g7.endswith(")") else f"({g7})"

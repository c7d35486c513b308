"""Steps a PLC leaves at the first evaluation of their transitions (``synth import``): the
receptivities of the transitions leaving step ``S`` (``S`` their only source) always hold
together, because one is ``TRUE`` or because they compare one integer internal variable
with constants over its whole range (``enum < 4``, ``enum > 6``, ``enum >= 4 AND enum <= 6``).
Such a step is active for one PLC scan, so an ``N`` action body that assigns data (``enum :=
enum + 1``, run at every scan while the step is active) runs once: it is the ``.g7``
assignment on activation, with a located warning.

Example
-------
>>> always("1", {}), always("cnt < 4 | cnt >= 4", {"cnt": (0, 9)}), always("cnt < 4", {"cnt": (0, 9)})
(True, True, False)
"""

from __future__ import annotations

import re
from typing import Any

from synth.codegen.plcopen_data import DataScope

__all__ = ["always", "one_scan_steps"]

_PY = {"&": " and ", "|": " or ", "!": " not ", "=": "==", "<>": "!=", "(": "(", ")": ")", ">=": ">=", "<=": "<=",
       ">": ">", "<": "<"}
_LIMIT = 70_000  # values of the one variable tried


def always(expr: str, ranges: dict[str, tuple[int, int]]) -> bool:
    """Whether the ``.g7`` receptivity ``expr`` (constants, comparisons of at most one integer
    internal variable of ``ranges`` with integers, ``& | !``) holds for every value."""
    tokens = re.findall(r"<>|>=|<=|[&|!()<>=]|-?\d+|[A-Za-z_]\w*|\S", expr)
    names = {t for t in tokens if re.fullmatch(r"[A-Za-z_]\w*", t)}
    if len(names) > 1 or any(n not in ranges for n in names):
        return False
    if any(t not in _PY and not re.fullmatch(r"-?\d+|[A-Za-z_]\w*", t) for t in tokens):
        return False
    code = "".join(_PY.get(t, f" {t} ") for t in tokens).strip()
    try:
        compiled = compile(code, "<receptivity>", "eval")
    except SyntaxError:
        return False
    low, high = next(iter(ranges[n] for n in names)) if names else (0, 0)
    if high - low > _LIMIT:
        return False
    name = next(iter(names), "_")
    return all(bool(eval(compiled, {"__builtins__": {}}, {name: v})) for v in range(low, high + 1))  # noqa: S307


def one_scan_steps(transitions: list[tuple[str, list[str], list[str], str, Any]], scope: DataScope) -> dict[str, str]:
    """Step -> the receptivities that make it last one PLC scan (see the module doc)."""
    ranges = {v.name: (v.low, v.high) for v in scope.vars.values() if not v.boolean}
    leaving: dict[str, list[str]] = {}
    for _, sources, _, expr, _ in transitions:
        if len(sources) == 1:
            leaving.setdefault(sources[0], []).append(expr)
    return {step: " | ".join(exprs) for step, exprs in leaving.items()
            if always(" | ".join(f"({e})" for e in exprs), ranges)}

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
>>> always("cnt < 4 | cnt > 6 & !(cnt < 4) | cnt < 7 & cnt > 3", {"cnt": (0, 9)})  # an atom read twice
True
"""

from __future__ import annotations

from typing import Any

from synth.codegen.plcopen.data import DataScope
from synth.errors import SynthError
from synth.grafcet.language_reader import parse_receptivity
from synth.logic.expr import Compare, evaluate, names

__all__ = ["always", "one_scan_steps"]

_LIMIT = 70_000  # values of the one variable tried


def always(expr: str, ranges: dict[str, tuple[int, int]]) -> bool:
    """Whether the ``.g7`` receptivity ``expr`` (constants, comparisons of at most one integer
    internal variable of ``ranges`` with integers, ``& | !``) holds for every value."""
    try:
        e = parse_receptivity(expr, "<receptivity>")
    except SynthError:
        return False
    atoms = list(names(e))
    comparisons = {a.name: a for a in atoms if isinstance(a, Compare)}
    variables = {x for c in comparisons.values() for x in c.operands()}
    if not all(isinstance(a, Compare) for a in atoms) or len(variables) > 1 or not variables <= ranges.keys():
        return False  # a level, an edge, a step, or two variables: not decided here
    name = next(iter(variables), "")
    low, high = ranges[name] if name else (0, 0)
    if high - low > _LIMIT:
        return False

    def holds_for(v: int) -> bool:
        return bool(evaluate(e, lambda n: comparisons[n].holds({name: v})))

    return all(holds_for(v) for v in range(low, high + 1))


def one_scan_steps(transitions: list[tuple[str, list[str], list[str], str, Any]], scope: DataScope) -> dict[str, str]:
    """Step -> the receptivities that make it last one PLC scan (see the module doc)."""
    ranges = {v.name: (v.low, v.high) for v in scope.vars.values() if not v.boolean}
    leaving: dict[str, list[str]] = {}
    for _, sources, _, expr, _ in transitions:
        if len(sources) == 1:
            leaving.setdefault(sources[0], []).append(expr)
    return {step: " | ".join(exprs) for step, exprs in leaving.items()
            if always(" | ".join(f"({e})" for e in exprs), ranges)}

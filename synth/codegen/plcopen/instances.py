"""Several POUs imported into one ``.g7`` (``synth import`` of a whole file): each POU's own
variables are its own on the PLC (each PROGRAM, each function-block instance has its storage),
while the ``.g7`` has one name space. A name that two or more imported POUs declare in their
interfaces (``VAR_INPUT``, ``VAR_OUTPUT``, ``VAR``…; not ``VAR_EXTERNAL``, which is shared) is
prefixed with its POU's name in each chart that declares it, with a located warning, so that
``Crane.StartVar`` and ``Magazin.StartVar`` stay two variables.

Example
-------
>>> rename_in("set StartVar on ↑go & XCrane_Init", {"StartVar": "Crane_StartVar"})
'set Crane_StartVar on ↑go & XCrane_Init'
"""

from __future__ import annotations

import re
from typing import Any, Callable, Mapping

from synth.codegen.plcopen.sfc import Chart
from synth.errors import InputError, Location, Severity

__all__ = ["own_names", "rename_in", "separate_instances"]

_OWN = ("inputVars", "outputVars", "inOutVars", "localVars", "tempVars")


def own_names(pou: Any, q: Callable[[str], str]) -> dict[str, Any]:
    """The variables ``pou`` declares for itself (upper-cased name → its XML element)."""
    return {str(v.get("name")).upper(): v for s in _OWN for v in pou.iterfind(f"{q('interface')}/{q(s)}/{q('variable')}")}


def rename_in(text: str, renames: Mapping[str, str]) -> str:
    """``text`` (a receptivity, an action) with each whole name of ``renames`` replaced."""
    if not renames:
        return text
    pattern = re.compile(r"(?<![\w/])(" + "|".join(re.escape(n) for n in sorted(renames, key=len, reverse=True))
                         + r")(?!\w)")
    return pattern.sub(lambda m: renames[m[1]], text)


def separate_instances(charts: list[Chart], pous: list[Any], q: Callable[[str], str],
                       at: Callable[[Any], Location]) -> None:
    """Prefix, in each of ``charts`` (read from ``pous``, in the same order), the names that
    several of the POUs declare; a warning at each first declaration."""
    owned = [own_names(p, q) for p in pous]
    shared = {n for i, names in enumerate(owned) for n in names if any(n in other for other in owned[:i])}
    for chart, pou, names in zip(charts, pous, owned):
        declared = [str(v.get("name")) for n, v in names.items() if n in shared]
        renames = {n: f"{pou.get('name')}_{n}" for n in declared}
        if not renames:
            continue
        chart.inputs[:] = [renames.get(n, n) for n in chart.inputs]
        chart.outputs[:] = [renames.get(n, n) for n in chart.outputs]
        chart.transitions[:] = [(label, s, t, rename_in(expr, renames), el) for label, s, t, expr, el in chart.transitions]
        for st in chart.steps:
            st.actions = [rename_in(a, renames) for a in st.actions]
        chart.internals[:] = [rename_in(d, renames) for d in chart.internals]
        for old, new in renames.items():
            others = [str(p.get("name")) for p, o in zip(pous, owned) if old.upper() in o and p is not pou]
            chart.warnings.append(InputError(
                f"'{old}' is declared by POU {pou.get('name')} and by {', '.join(others)}: each has its own on the "
                f"PLC, so this chart's is named {new} in the .g7", at(names[old.upper()]), severity=Severity.WARNING))

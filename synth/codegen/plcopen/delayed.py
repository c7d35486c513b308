"""A local Boolean that is only the time-delayed (``D``) action of one step (``synth
import``), as the Beremiz traffic-light example writes its step durations::

    step ORANGE  --  D T#2s  STOP_CARS        transition ORANGE -> RED when STOP_CARS

IEC 61131-3 makes ``STOP_CARS`` TRUE from 2 s after the activation of ``ORANGE`` until its
deactivation: the ``.g7`` step timer ``2s/XORANGE``. Such a variable (declared in
``localVars`` as ``BOOL``, the reference of exactly one action of the chart, qualified ``D``
with a constant duration, and assigned by no ST body of the POU) is read as that step timer
wherever a condition reads it; its action is nothing in ``.g7`` (it is no output), with a
located warning.

Example
-------
>>> from lxml import etree
>>> pou = etree.fromstring('<pou name="P"><interface><localVars><variable name="Done"><type><BOOL/></type>'
...                        '</variable></localVars></interface></pou>')
>>> sfc = etree.fromstring('<SFC><step localId="1" name="S2"/><actionBlock localId="2"><connectionPointIn>'
...                        '<connection refLocalId="1"/></connectionPointIn><action qualifier="D" '
...                        'duration="T#3s"><reference name="Done"/></action></actionBlock></SFC>')
>>> from synth.codegen.plcopen.data import DataScope
>>> scope = DataScope("P", lambda el: None)  # type: ignore[arg-type,return-value]
>>> delayed_flags(pou, sfc, lambda t: t, lambda el: None, "", scope)  # type: ignore[arg-type,return-value]
>>> scope.timers
{'DONE': '3s/X2'}
"""

from __future__ import annotations

import re
from typing import Any, Callable

from synth.codegen.plcopen.data import DataScope, assigned_names, duration
from synth.codegen.plcopen.st_condition import st_text
from synth.errors import InputError, Location, Severity

__all__ = ["delayed_flags"]


def delayed_flags(pou: Any, sfc: Any, q: Callable[[str], str], at: Callable[[Any], Location], prefix: str,
                  scope: DataScope) -> None:
    """The local Booleans of ``pou`` that are only the ``D`` action of a step of ``sfc``: their
    step timers in ``scope.timers``, with a warning each."""
    local = {}
    for var in pou.iterfind(f"{q('interface')}/{q('localVars')}/{q('variable')}"):
        if var.find(f"{q('type')}/{q('BOOL')}") is not None:
            local[str(var.get("name", "")).upper()] = var
    if not local:
        return
    assigned: set[str] = set()
    for st in pou.iter(q("ST")):
        assigned |= assigned_names(st_text(st))
    steps = {str(s.get("localId")): s for s in sfc.iterfind(q("step"))}
    refs: dict[str, list[tuple[Any, Any]]] = {}  # upper-case name -> (action, step)
    for block in sfc.iterfind(q("actionBlock")):
        owner = next((steps[c.get("refLocalId")] for c in block.iter(q("connection")) if c.get("refLocalId") in steps),
                     None)
        for a in block.iterfind(q("action")):
            ref = a.find(q("reference"))
            if ref is not None:
                refs.setdefault(str(ref.get("name", "")).upper(), []).append((a, owner))
    for name, uses in refs.items():
        if name not in local or name in assigned or len(uses) != 1 or uses[0][1] is None:
            continue
        action, step = uses[0]
        d = duration(str(action.get("duration", ""))) if action.get("qualifier") == "D" else None
        if d is None:
            continue
        sname = str(step.get("name", ""))
        timer = f"{d}/X{prefix}{sname[1:] if re.fullmatch(r'S[0-9]+', sname) else sname}"
        scope.timers[name] = timer
        scope.warnings.append(InputError(
            f"{local[name].get('name')}, a local Boolean that is only the action D {action.get('duration')} of step "
            f"{sname}, is read as the step timer {timer}: IEC 61131-3 makes it TRUE from {d} after the "
            "step's activation until its deactivation, as the timer (on MATIEC, the compiler of Beremiz and OpenPLC, "
            "it turns TRUE one scan after the timer)", at(action), severity=Severity.WARNING))

"""Function blocks wired in an FBD transition condition (``synth import``) that have a
Boolean or step-timer meaning in ``.g7``:

* ``SEL(G, IN0, IN1)`` of Booleans is ``!G & IN0 | G & IN1``;
* ``R_TRIG``/``F_TRIG`` of an input is its edge ``↑x``/``↓x`` (a conjunction of inputs: the
  edge of the conjunction), with a located warning (the PLC's instance remembers ``CLK`` from
  its last call, made only while the transition is evaluated);
* ``TON(IN:=c, PT:=D).Q`` is a step timer: ``D/XS`` when ``c`` is the activity of the
  transition's source step ``S`` (``TRUE``, ``S.X``, or a Boolean variable that is only the
  continuous action of ``S``), else the timer of step ``T_on`` of a two-step partial grafcet
  ``T_TON`` active while ``S`` is and ``c`` holds (as :mod:`synth.codegen.plcopen.timers`
  reads a TON called in a step action), with the same located warning.

Example
-------
>>> sel("g", "(a)", "b | c")
'!g & a | g & (b | c)'
"""

from __future__ import annotations

import re
from typing import Any, Callable

from synth.codegen.plcopen.actions import rising
from synth.codegen.plcopen.data import DATA, duration
from synth.errors import InputError, Location, Severity

__all__ = ["FBD_FUNCTION_BLOCKS", "sel", "trigger", "ton_output", "warn_block", "step_flag"]

FBD_FUNCTION_BLOCKS = ("SEL", "R_TRIG", "F_TRIG", "TON")
"""The blocks other than AND/OR/NOT read in an FBD transition condition."""


def sel(g: str, in0: str, in1: str) -> str:
    """``SEL(G, IN0, IN1)`` of Booleans (``.g7`` texts)."""
    g, in0, in1 = (x if re.fullmatch(r"[!\w↑↓/.]+", x := _bare(y)) else f"({x})" for y in (g, in0, in1))
    return f"!{g} & {in0} | {g} & {in1}" if not g.startswith("!") else f"!({g}) & {in0} | {g} & {in1}"


def _bare(text: str) -> str:
    """``text`` without the parentheses around a name or a negated name."""
    while re.fullmatch(r"\(!?\(?[↑↓\w/.]+\)?\)", text):
        text = text[1:-1]
    return text


def warn_block(message: str, where: Location) -> None:
    scope = DATA.get()
    if scope is not None and not any(w.message == message for w in scope.warnings):  # a block shared by transitions
        scope.warnings.append(InputError(message, where, severity=Severity.WARNING))


def trigger(kind: str, instance: str, clk: str, where: Location) -> str:
    """``R_TRIG``/``F_TRIG`` (``kind``) of ``clk`` (``.g7`` text): its edge."""
    inner = _bare(clk)
    if re.fullmatch(r"[A-Za-z_]\w*", inner):
        edge = ("↑" if kind == "R_TRIG" else "↓") + inner
    elif kind == "R_TRIG" and (found := rising(inner)):
        edge = found
    else:
        raise InputError(f"{kind} {instance} of '{clk}': .g7 has the edges of inputs (↑x, ↓x) and the rising edge of "
                         "a conjunction of inputs", where)
    if re.search(r"\bX\w+\b|/X", edge):
        raise InputError(f"{kind} {instance} of a step's activity or timer ({clk}): .g7 edges are input events", where)
    warn_block(f"{kind} {instance} is read as {edge}: the PLC's instance remembers CLK from its last call (made while the "
          "transition is evaluated, i.e. while its step is active), so a change of CLK while the step was inactive "
          "is seen at its activation by the PLC, never by .g7", where)
    return edge


def step_flag(name: str, sfc_elements: dict[int, Any], steps: dict[str, str]) -> str | None:
    """``XS`` when the Boolean ``name`` is only the continuous (N) action of the one step ``S``."""
    from lxml import etree

    owners = set()
    for el in sfc_elements.values():
        if etree.QName(el).localname != "actionBlock":
            continue
        for a in el:
            if not isinstance(a.tag, str) or not a.tag.endswith("action"):
                continue
            ref = next((c for c in a if isinstance(c.tag, str) and c.tag.endswith("reference")), None)
            body = "".join(a.itertext())
            if re.search(rf"(?<![\w.]){re.escape(name)}\s*:=", body, re.I):
                return None  # assigned by an ST body as well
            if ref is None or str(ref.get("name", "")).upper() != name.upper():
                continue
            if a.get("qualifier", "N") != "N":
                return None
            for c in el.iter():
                if isinstance(c.tag, str) and c.tag.endswith("connection") and c.get("refLocalId", "").isdigit():
                    step = sfc_elements.get(int(c.get("refLocalId")))
                    if step is not None and etree.QName(step).localname == "step":
                        owners.add(steps.get(str(step.get("name", "")), ""))
    return f"X{owners.pop()}" if len(owners) == 1 and "" not in owners else None


def ton_output(instance: str, c: str, pt_text: str, sources: list[str], where: Location,
               sfc_elements: dict[int, Any], steps: dict[str, str], pt_at: Location) -> str:
    """``instance.Q`` of ``TON(IN:=c, PT:=pt_text)`` wired to the condition of a transition
    leaving ``sources``: a ``.g7`` step timer (see the module doc)."""
    scope = DATA.get()
    pt = duration(pt_text)
    if pt is None and scope is not None:
        pt = scope.constant_durations.get(pt_text.strip().upper())
    if pt is None:
        raise InputError(f"the PT of TON {instance} is '{pt_text.strip()}': a step timer needs a constant duration "
                         "such as T#2s", pt_at)
    c = given = _bare(c)
    if re.fullmatch(r"[A-Za-z_]\w*", c) and (flag := step_flag(c, sfc_elements, steps)) is not None:
        c, given = flag, f"{c} (only the continuous action of step {flag[1:]}: {flag})"
    if scope is None or len(sources) != 1:
        raise InputError(f"TON {instance} in the condition of a transition with {len(sources)} source steps: a .g7 "
                         "step timer times one step", where)
    step = sources[0]
    if c in ("1", f"X{step}"):
        timer = f"{pt}/X{step}"
        what = f"the step timer {timer}"
    else:
        on = f"{scope.prefix}{instance}_on"
        timer = f"{pt}/X{on}"
        both = f"X{step} & " + (c if re.fullmatch(r"[!\w]+", c) else f"({c})")
        if (chart := (f"{instance}_TON", f"{scope.prefix}{instance}_off", on, both)) not in scope.helper_charts:
            scope.helper_charts.append(chart)  # read twice: an SR latch's loop
        what = (f"{timer}, the timer of step {on} of the partial grafcet {instance}_TON, active while step {step} is "
                f"and {c} holds")
    warn_block(f"the TON {instance} wired with IN:={given} to the condition of a transition leaving step {step}: {instance}.Q "
          f"is read as {what} (a TON keeps Q until it is called with IN FALSE; a .g7 timer restarts at each "
          "activation of its step)", where)
    return timer

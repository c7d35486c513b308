"""An LD action that blinks a light (``synth import``), as the Beremiz traffic-light example
draws it in its action ``BLINK_ORANGE_LIGHT``, run (qualifier ``N``) while step
``Standstill`` is active::

    |--[/ORANGE_LIGHT]--TON1(PT:=T#500ms)--R_TRIG1--(S ORANGE_LIGHT)--|
    |--[ ORANGE_LIGHT]--TON2(PT:=T#500ms)--R_TRIG0--(R ORANGE_LIGHT)--|

Two TONs in a loop through the light ``V``: the one timing ``NOT V`` sets it, the one timing
``V`` resets it (each through an ``R_TRIG`` or directly). The action is a two-step partial
grafcet named after it: step ``A_off`` (initial) and step ``A_on``, which sets ``V`` on
activation and resets it on deactivation; they alternate after the two durations while the
enable (the activity of the steps running the action) holds::

    transition A_off -> A_on when XStandstill & 500ms/XA_off
    transition A_on -> A_off when XStandstill & 500ms/XA_on

with a located warning (the PLC's phase is the light itself, which other steps may set or
reset; the grafcet's phase is its step, and its timers run while the enable is false, as a
TON called again with ``IN`` still TRUE counts from when ``IN`` rose). An LD body of any
other shape is left to the error of :mod:`synth.codegen.plcopen.importer`.

Example
-------
>>> from lxml import etree
>>> ld = etree.fromstring('<LD><leftPowerRail localId="1"/></LD>')
>>> blinker(ld, lambda t: t) is None
True
"""

from __future__ import annotations

import re
from typing import Any, Callable

from synth.codegen.plcopen.data import DataScope, duration
from synth.codegen.plcopen.latch import conjunction
from synth.codegen.plcopen.vendor import IecQualifier, StepAction, step_actions
from synth.errors import InputError, Location, Severity

__all__ = ["blinker", "blink_charts"]


Rung = tuple[Any, str, str, str]
"""One rung of a blinker: its TON, the PT text, the duration, the R_TRIG between the TON and
the coil (its instance name, or ``""`` when the TON drives the coil directly)."""


def blinker(ld: Any, q: Callable[[str], str]) -> tuple[str, Rung, Rung] | None:
    """``(V, rung setting V, rung resetting V)`` when the LD body ``ld`` is a blinker of ``V``
    (see the module doc), else None."""
    from lxml import etree

    elements = {int(str(el.get("localId"))): el for el in ld
                if isinstance(el.tag, str) and str(el.get("localId", "")).isdigit()}

    def kind(el: Any) -> str:
        return str(etree.QName(el).localname)

    def feed(holder: Any) -> Any:
        conns = [] if holder is None else holder.findall(f"{q('connectionPointIn')}/{q('connection')}")
        ref = conns[0].get("refLocalId", "") if len(conns) == 1 else ""
        return elements.get(int(ref)) if ref.strip().isdigit() else None

    def block_input(block: Any, formal: str) -> Any:
        var = next((v for v in block.iterfind(f"{q('inputVariables')}/{q('variable')}")
                    if str(v.get("formalParameter", "")).upper() == formal), None)
        return feed(var)

    coils = [el for el in elements.values() if kind(el) == "coil"]
    names = {(c.findtext(q("variable")) or "").strip() for c in coils}
    if len(coils) != 2 or {c.get("storage") for c in coils} != {"set", "reset"} or len(names) != 1:
        return None
    light = names.pop()
    used: set[int] = set()

    def rung(coil: Any) -> Rung | None:
        used.add(id(coil))
        x = feed(coil)
        trig = ""
        if x is not None and kind(x) == "block" and str(x.get("typeName", "")).upper() == "R_TRIG":
            used.add(id(x))
            trig = str(x.get("instanceName", "") or "R_TRIG")
            x = block_input(x, "CLK")
        if x is None or kind(x) != "block" or str(x.get("typeName", "")).upper() != "TON":
            return None
        contact, pt = block_input(x, "IN"), block_input(x, "PT")
        if contact is None or kind(contact) != "contact" or pt is None or kind(pt) != "inVariable":
            return None
        rail = feed(contact)
        wanted = "true" if coil.get("storage") == "set" else "false"
        if (contact.findtext(q("variable")) or "").strip().upper() != light.upper() or rail is None or \
                kind(rail) != "leftPowerRail" or contact.get("negated", "false") != wanted or \
                contact.get("edge", "none") != "none":
            return None
        text = (pt.findtext(q("expression")) or "").strip()
        d = duration(text)
        if d is None:
            return None
        used.update({id(x), id(contact), id(pt), id(rail)})
        return x, text, d, trig

    by_storage = {c.get("storage"): rung(c) for c in coils}
    on, off = by_storage["set"], by_storage["reset"]
    left = [el for el in elements.values() if id(el) not in used and kind(el) not in ("rightPowerRail", "comment")]
    return (light, on, off) if on is not None and off is not None and not left else None


def _through(trig: str) -> str:
    """How a rung's TON reaches its coil, for the warning: through an R_TRIG (on the rising
    edge of its Q, as the step's activation does), or directly."""
    return f" on the rising edge of its Q (R_TRIG {trig})" if trig else ""


def blink_charts(pou: Any, sfc: Any, q: Callable[[str], str], at: Callable[[Any], Location], prefix: str,
                 scope: DataScope) -> None:
    """The LD blinkers of ``pou`` run by an ``N`` action of a step: their partial grafcets in
    ``scope.extra_charts``, their action names in ``scope.blink_actions``."""
    bodies = {str(a.get("name")): ld for a in pou.iterfind(f"{q('actions')}/{q('action')}")
              if (ld := a.find(f"{q('body')}/{q('LD')}")) is not None}
    if not bodies:
        return
    enables: dict[str, list[str]] = {}
    for step in sfc.iterfind(q("step")):
        sname = str(step.get("name", ""))
        g7 = prefix + (sname[1:] if re.fullmatch(r"S\d+", sname) else sname)
        runs = [n for k, n, _ in step_actions(step, q) if k is StepAction.ACTIVE]
        for block in sfc.iterfind(q("actionBlock")):
            if any(c.get("refLocalId") == step.get("localId") for c in block.iter(q("connection"))):
                runs += [str(ref.get("name")) for a in block.iterfind(q("action"))
                         if a.get("qualifier", "N") == IecQualifier.N and (ref := a.find(q("reference"))) is not None]
        for name in runs:
            if name in bodies and g7 not in enables.setdefault(name, []):
                enables[name].append(g7)
    for name, steps in enables.items():
        found = blinker(bodies[name], q)
        if found is None:
            continue
        light, (ton_set, pt_set, d_set, trig_set), (ton_reset, pt_reset, d_reset, trig_reset) = found
        off, on = f"{prefix}{name}_off", f"{prefix}{name}_on"
        enable = f"X{steps[0]}" if len(steps) == 1 else "(" + " | ".join(f"X{s}" for s in steps) + ")"
        scope.extra_charts.append((name, [(off, True, []), (on, False, [f"set {light} on activation",
                                                                        f"reset {light} on deactivation"])],
                                   [([off], [on], conjunction(enable, f"{d_set}/X{off}")),
                                    ([on], [off], conjunction(enable, f"{d_reset}/X{on}"))]))
        scope.blink_actions.add(name.upper())
        if light not in scope.action_refs:
            scope.action_refs.append(light)
        scope.warnings.append(InputError(
            f"the LD action {name} (run while {enable} holds) blinks {light}: {ton_set.get('instanceName')} "
            f"(IN:=NOT {light}, PT:={pt_set}) sets it{_through(trig_set)}, {ton_reset.get('instanceName')} "
            f"(IN:={light}, PT:={pt_reset}) resets it{_through(trig_reset)}; read as the partial grafcet {name}, "
            f"whose steps {off} and {on} ({light} set on its activation, reset on its deactivation) alternate after "
            f"{d_set} and {d_reset} while {enable} holds (the "
            f"PLC's phase is {light} itself, which other steps may set or reset; the grafcet's phase is its step, and "
            "its timers run while the action is not called, as a TON called again with IN still TRUE counts from "
            "when IN rose)", at(ton_set), severity=Severity.WARNING))

"""The data scope of an SFC POU before its chart is read (``synth import``), and the
CODESYS/PPU timer idiom in it: an ``N`` action of step ``S`` whose body is

    T(IN:=TRUE, PT:=D);
    V := T.Q;

(``T`` a ``TON`` local, ``D`` a ``TIME`` local with an initial value such as ``TIME#50ms``,
or a literal ``T#2s``) times the activity of ``S``: the action is nothing in ``.g7`` and every
read of ``V`` in a transition is the step timer ``50ms/XS``, with a located warning (a TON
keeps ``Q`` until it is called with ``IN`` FALSE; a ``.g7`` step timer restarts at each
activation of ``S``). Calls of ``T`` elsewhere (``T(IN:=FALSE, …)``, its reset) are left out.

Example
-------
>>> duration("TIME#50ms"), duration("T#2S"), duration("T#1s500ms")
('50ms', '2s', '1500ms')
"""

from __future__ import annotations

import re
from typing import Any, Callable

from synth.codegen.plcopen_data import DataScope, data_scope, strip_comments
from synth.codegen.plcopen_vendor import IecQualifier, StepAction, step_actions
from synth.codegen.st_condition import st_text
from synth.errors import InputError, Location, Severity

__all__ = ["duration", "prepare_scope", "ton_chart"]

_MS = {"ms": 1, "s": 1000, "m": 60_000, "h": 3_600_000, "d": 86_400_000}


def duration(text: str) -> str | None:
    """A TIME literal as a ``.g7`` duration, or None when ``text`` is not one."""
    m = re.fullmatch(r"\s*(?:T|TIME)#((?:\d+(?:\.\d+)?(?:ms|s|m|h|d)_?)+)\s*", text, re.I)
    if m is None:
        return None
    parts = re.findall(r"(\d+(?:\.\d+)?)(ms|s|m|h|d)", m[1].lower())
    if len(parts) == 1 and parts[0][1] != "d":
        number, unit = parts[0]
        return f"{number}{'min' if unit == 'm' else unit}"
    total = sum(float(n) * _MS[u] for n, u in parts)
    return f"{int(total)}ms" if total == int(total) else None


def _locals(pou: Any, q: Callable[[str], str]) -> dict[str, tuple[str, Any]]:
    """Local variables (upper-case name -> (type name, element))."""
    out: dict[str, tuple[str, Any]] = {}
    for var in pou.iterfind(f"{q('interface')}/{q('localVars')}/{q('variable')}"):
        typ = var.find(q("type"))
        kinds = [c for c in (typ if typ is not None else []) if isinstance(c.tag, str)]
        if len(kinds) == 1:
            k = kinds[0]
            name = str(k.get("name", "")) if k.tag.endswith("derived") else k.tag.rsplit("}", 1)[-1]
            out[str(var.get("name", "")).upper()] = (name.upper(), var)
    return out


def _timer_idiom(text: str, local: dict[str, tuple[str, Any]],
                 q: Callable[[str], str]) -> tuple[str, str, str, str] | None:
    """(T, V, duration, IN) when ``text`` calls the TON ``T(IN:=x, PT:=D)`` (x not FALSE)
    and assigns ``V := T.Q``."""
    statements = [" ".join(s.split()) for s in strip_comments(text).split(";") if s.strip()]
    for i, statement in enumerate(statements):
        call = re.fullmatch(r"(\w+) ?\( ?IN ?:= ?(.+?) ?, ?PT ?:= ?([\w#.]+) ?\)", statement, re.I)
        if call is None or call[2].upper() == "FALSE" or local.get(call[1].upper(), ("",))[0] != "TON":
            continue
        alias = [m for s in statements[i + 1:] if (m := re.fullmatch(r"(\w+) ?:= ?(\w+)\.Q", s, re.I))
                 and m[2].upper() == call[1].upper()]
        pt = duration(call[3])
        if pt is None and local.get(call[3].upper(), ("",))[0] == "TIME":
            init = local[call[3].upper()][1].find(f"{q('initialValue')}/{q('simpleValue')}")
            pt = duration(str(init.get("value", ""))) if init is not None else None
        if len(alias) == 1 and pt is not None:
            return call[1], alias[0][1], pt, call[2]
    return None


def prepare_scope(pou: Any, sfc: Any, q: Callable[[str], str], at: Callable[[Any], Location], prefix: str,
                  where_text: Callable[[Any, str, int, int], Location]) -> DataScope:
    """The data scope of ``pou`` (its SFC body ``sfc``): its step timers first, then the
    local variables its action bodies assign."""
    actions = {str(a.get("name")): a for a in pou.iterfind(f"{q('actions')}/{q('action')}")}
    bodies = {n: st_text(st) for n, a in actions.items() if (st := a.find(f"{q('body')}/{q('ST')}")) is not None}
    inline = [st for st in sfc.iter(q("ST")) if st.getparent() is not None and st.getparent().tag == q("inline")
              and st.getparent().getparent() is not None and st.getparent().getparent().tag == q("action")]
    local = _locals(pou, q)
    found: dict[str, list[tuple[str, str, str, Any, str, str, str]]] = {}  # V -> (T, step, duration, action, text, IN, V)
    for step in sfc.iterfind(q("step")):
        sname = str(step.get("name", ""))
        g7 = prefix + (sname[1:] if re.fullmatch(r"S\d+", sname) else sname)
        runs: list[tuple[str, Any]] = [(n, attr) for k, n, attr in step_actions(step, q) if k is StepAction.ACTIVE]
        for block in sfc.iterfind(q("actionBlock")):
            if not any(c.get("refLocalId") == step.get("localId") for c in block.iter(q("connection"))):
                continue
            for a in block.iterfind(q("action")):
                ref = a.find(q("reference"))
                if a.get("qualifier", "N") == IecQualifier.N and ref is not None:
                    runs.append((str(ref.get("name")), a))
        for name, el in runs:
            idiom = _timer_idiom(bodies.get(name, ""), local, q)
            if idiom is not None:
                t, v, pt, cond = idiom
                found.setdefault(v.upper(), []).append((t, g7, pt, actions[name], bodies[name], cond, v))
    scope = DataScope(str(pou.get("name", "")), at)
    for v, uses in found.items():
        if len({(u[0].upper(), u[1]) for u in uses}) != 1:
            continue  # one alias timing two steps: not a step timer
        t, step, pt, el, text, cond, alias = uses[0]
        st = el.find(f"{q('body')}/{q('ST')}")
        where = where_text(st, text, text.upper().find(t.upper()), len(t))
        if cond.upper() == "TRUE":
            scope.timers[v] = f"{pt}/X{step}"
            what = f"the step timer {pt}/X{step}"
        else:  # the TON as a partial grafcet: its step on is active while step and IN hold
            on = f"{prefix}{t}_on"
            scope.timers[v] = f"{pt}/X{on}"
            scope.ton_charts.append((f"{t}_TON", f"{prefix}{t}_off", on, step, cond, st, text))
            what = (f"{pt}/X{on}, the timer of step {on} of the partial grafcet {t}_TON, active while step "
                    f"{step} is and {cond} holds")
        scope.timer_blocks.add(t.upper())
        scope.warnings.append(InputError(
            f"the TON {t} called with IN:={cond} in action {el.get('name')} of step {step}: {alias} is read as {what} (a "
            "TON keeps Q until it is called with IN FALSE; a .g7 timer restarts at each activation of its step)",
            where, severity=Severity.WARNING))
    full = data_scope(pou, q, at, list(bodies.values()) + [st_text(st) for st in inline], set(scope.timers))
    full.timers, full.timer_blocks, full.ton_charts = scope.timers, scope.timer_blocks, scope.ton_charts
    full.warnings = scope.warnings + full.warnings
    return full


def ton_chart(scope: DataScope, steps: dict[str, str], at: Callable[[Any, str, int, int], Location]
              ) -> list[tuple[str, list[tuple[str, bool]], list[tuple[list[str], list[str], str]]]]:
    """The partial grafcets of the TONs called with ``IN:=c`` (not TRUE): (name, steps
    (name, initial), transitions (sources, targets, receptivity))."""
    from synth.codegen.st_condition import ExprReader

    out = []
    for name, off, on, step, cond, st, text in scope.ton_charts:
        start = text.upper().find("IN")
        c = ExprReader(cond, lambda o, w, h=st, t=text, s=start: at(h, t, s + o, w), steps, "a TON's IN").whole()
        both = f"X{step} & " + (c if re.fullmatch(r"[!\w]+", c) else f"({c})")
        out.append((name, [(off, True), (on, False)], [([off], [on], both), ([on], [off], f"!({both})")]))
    return out

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

from synth.codegen.plcopen.blink import blink_charts
from synth.codegen.plcopen.delayed import delayed_flags
from synth.codegen.plcopen.data import DataScope, HelperChart, data_scope, duration, strip_comments
from synth.codegen.plcopen.vendor import IecQualifier, StepAction, step_actions
from synth.codegen.plcopen.st_condition import st_text
from synth.errors import InputError, Location, Severity

__all__ = ["duration", "prepare_scope", "ton_chart"]

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


def _same(a: str, b: str) -> bool:
    """Two ST conditions equal up to spaces, case, outer parentheses and ``= TRUE``."""
    def norm(x: str) -> str:
        x = re.sub(r"\s+", "", x).upper()
        while True:
            y = re.sub(r"=TRUE$", "", x)
            if y.startswith("(") and y.endswith(")") and _balanced(y[1:-1]):
                y = y[1:-1]
            if y == x:
                return x
            x = y
    return norm(a) == norm(b)


def _balanced(x: str) -> bool:
    depth = 0
    for ch in x:
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if depth < 0:
            return False
    return depth == 0


def _timer_idiom(text: str, local: dict[str, tuple[str, Any]],
                 q: Callable[[str], str]) -> tuple[str, str, str, str, bool] | None:
    """(T, V, duration, IN, guarded) when ``text`` calls the TON ``T(IN:=x, PT:=D)`` (x not
    FALSE) and assigns ``V := T.Q``, alone or as the whole of ``IF c THEN … END_IF`` (then
    IN is ``c AND x``, or ``x`` when ``c`` is ``x``, and ``guarded`` is true)."""
    clean = strip_comments(text).strip()
    guard = re.fullmatch(r"IF\b(.*?)\bTHEN\b(.*?)\bEND_IF\s*;?", clean, re.I | re.S)
    statements = [" ".join(s.split()) for s in (guard[2] if guard else clean).split(";") if s.strip()]
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
            cond = call[2]
            if guard is not None and not _same(guard[1], cond):
                cond = f"({' '.join(guard[1].split())}) AND ({cond})"
            return call[1], alias[0][1], pt, cond, guard is not None
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
    found: dict[str, list[tuple[str, str, str, Any, str, str, str, bool]]] = {}  # V -> (T, step, PT, action, text, IN, V, IF)
    blocks_of: dict[str | None, list[Any]] = {}  # localId -> the action blocks connected to it, in file order
    for block in sfc.iterfind(q("actionBlock")):
        for ref in dict.fromkeys(c.get("refLocalId") for c in block.iter(q("connection"))):
            blocks_of.setdefault(ref, []).append(block)
    for step in sfc.iterfind(q("step")):
        sname = str(step.get("name", ""))
        g7 = prefix + (sname[1:] if re.fullmatch(r"S\d+", sname) else sname)
        runs: list[tuple[str, Any]] = [(n, attr) for k, n, attr in step_actions(step, q) if k is StepAction.ACTIVE]
        for block in blocks_of.get(step.get("localId"), ()):
            for a in block.iterfind(q("action")):
                ref = a.find(q("reference"))
                if a.get("qualifier", "N") == IecQualifier.N and ref is not None:
                    runs.append((str(ref.get("name")), a))
        for name, el in runs:
            idiom = _timer_idiom(bodies.get(name, ""), local, q)
            if idiom is not None:
                t, v, pt, cond, guarded = idiom
                found.setdefault(v.upper(), []).append((t, g7, pt, actions[name], bodies[name], cond, v, guarded))
    scope = DataScope(str(pou.get("name", "")), at)
    for v, uses in found.items():
        by_step = {u[1]: u for u in uses}
        if len({(u[0].upper(), u[1]) for u in uses}) != len(by_step):
            continue  # two TONs behind one alias in one step: not a step timer
        several = len(by_step) > 1  # the alias is read after each step: the timer of the step left
        for step, (t, _, pt, el, text, cond, alias, guarded) in by_step.items():
            st = el.find(f"{q('body')}/{q('ST')}")
            where = where_text(st, text, text.upper().find(t.upper()), len(t))
            if _same(cond, "TRUE"):
                timer = f"{pt}/X{step}"
                what = f"the step timer {timer}"
            else:  # the TON as a partial grafcet: its step on is active while step and IN hold
                base = f"{t}_{step}" if several else f"{prefix}{t}"
                on = f"{base}_on"
                timer = f"{pt}/X{on}"
                scope.ton_charts.append((f"{base.removeprefix(prefix)}_TON", f"{base}_off", on, step, cond, st, text))
                what = (f"{timer}, the timer of step {on} of the partial grafcet {base.removeprefix(prefix)}_TON, "
                        f"active while step {step} is and {cond} holds")
            if several:
                scope.step_timers.setdefault(v, {})[step] = timer
                what += f" in the transitions leaving step {step}"
            else:
                scope.timers[v] = timer
            scope.timer_blocks.add(t.upper())
            scope.warnings.append(InputError(
                f"the TON {t} called with IN:={cond} in action {el.get('name')} of step {step}: {alias} is read as "
                f"{what} (a TON keeps Q until it is called with IN FALSE; a .g7 timer restarts at each activation of "
                "its step" + ("; the PLC calls it only while the IF condition holds, so it does not restart when the "
                              "condition falls" if guarded else "") + ")", where, severity=Severity.WARNING))
    delayed_flags(pou, sfc, q, at, prefix, scope)
    full = data_scope(pou, q, at, list(bodies.values()) + [st_text(st) for st in inline],
                      set(scope.timers) | set(scope.step_timers))
    full.timers, full.timer_blocks, full.ton_charts = scope.timers, scope.timer_blocks, scope.ton_charts
    full.step_timers = scope.step_timers
    full.prefix = prefix
    full.warnings = scope.warnings + full.warnings
    blink_charts(pou, sfc, q, at, prefix, full)
    return full


def ton_chart(scope: DataScope, steps: dict[str, str], at: Callable[[Any, str, int, int], Location]
              ) -> list[HelperChart]:
    """The partial grafcets the import adds: those of the TONs called with ``IN:=c`` (not
    TRUE), then the latches and blinkers of ``scope.extra_charts``."""
    from synth.codegen.plcopen.st_condition import ExprReader

    out: list[HelperChart] = []
    for name, off, on, step, cond, st, text in scope.ton_charts:
        start = text.upper().find("IN")
        c = ExprReader(cond, lambda o, w, h=st, t=text, s=start: at(h, t, s + o, w), steps, "a TON's IN").whole()
        both = f"X{step} & " + (c if re.fullmatch(r"[!\w]+", c) else f"({c})")
        out.append((name, [(off, True, []), (on, False, [])], [([off], [on], both), ([on], [off], f"!({both})")]))
    for name, off, on, both in scope.helper_charts:
        out.append((name, [(off, True, []), (on, False, [])], [([off], [on], both), ([on], [off], f"!({both})")]))
    return out + scope.extra_charts

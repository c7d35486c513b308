"""A transition condition wired as FBD or LD (``synth import``): the TC6 specification's own
SFC example and every CODESYS V3.5 export connect the condition of a transition to an
``<inVariable>`` (an ST expression), or to a small network of ``AND``/``OR``/``NOT`` blocks
over such variables; Beremiz draws LD contacts from a power rail (in series: AND, in
parallel: OR). :func:`fbd_condition` reads that network back into one ``.g7``
receptivity; any other construct (an LD contact, another block, a loop) is an
:class:`~synth.errors.InputError` at its element. In a file written by Beremiz or the OpenPLC
editor, the blocks are read as Beremiz calls them, at every scan after the transitions
(:mod:`synth.codegen.plcopen.fbscan`).

Example
-------
>>> sorted(FBD_ELEMENTS)
['block', 'contact', 'inVariable', 'leftPowerRail']
"""

from __future__ import annotations

import re
from functools import partial
from typing import Any, Callable

from synth.codegen.plcopen.blocks import FBD_FUNCTION_BLOCKS, sel, step_flag, ton_output, trigger
from synth.codegen.plcopen.fbscan import SCAN_BLOCKS, every_scan, lagging, negation, scan_block
from synth.codegen.plcopen.latch import LATCH_BLOCKS, latch_chart, latch_step
from synth.codegen.plcopen.st_condition import ExprReader
from synth.errors import InputError, Location

__all__ = ["FBD_ELEMENTS", "fbd_condition", "fbd_transition"]

FBD_ELEMENTS = frozenset({"inVariable", "block", "contact", "leftPowerRail"})
"""The FBD elements an SFC body may hold as the sources of transition conditions."""

_BLOCKS = {"AND": " & ", "OR": " | ", "NOT": ""}


def _negated(el: Any) -> bool:
    return el is not None and el.get("negated", "false") in ("true", "1")


def fbd_condition(cond: Any, elements: dict[int, Any], q: Callable[[str], str], src: Any,
                  steps: dict[str, str], sources: tuple[str, ...] = ()) -> str:
    """The receptivity of ``<condition><connectionPointIn>`` wired to an FBD network."""
    from lxml import etree

    latches: dict[int, str] = {}  # an SR/RS block being read -> its output (its state: no loop)

    def one_source(cp: Any, owner: Any) -> str:
        conns = cp.findall(q("connection"))
        if len(conns) != 1:
            raise InputError(f"a condition input with {len(conns)} connections (one is expected)", src.at(owner))
        text = conns[0].get("refLocalId", "")
        if not text.strip().isdigit() or int(text) not in elements:
            raise InputError(f"connection to unknown localId {text}", src.at(conns[0]))
        return node(int(text), frozenset())

    def source(var: Any) -> Any:
        """The element wired to the block input ``var``."""
        cp = var.find(q("connectionPointIn"))
        if cp is None:
            raise InputError("an unconnected block input", src.at(var))
        conns = cp.findall(q("connection"))
        if len(conns) != 1 or not conns[0].get("refLocalId", "").strip().isdigit():
            raise InputError("a block input must be connected to one element", src.at(var))
        ref = int(conns[0].get("refLocalId"))
        if ref not in elements:
            raise InputError(f"connection to unknown localId {ref}", src.at(conns[0]))
        return elements[ref]

    def argument(var: Any, inner: frozenset[int], by_block: bool, wrap: bool = True) -> str:
        fed = source(var)
        ex = fed.find(q("expression"))
        name = (ex.text or "").strip() if ex is not None and by_block else ""
        flag = step_flag(name, elements, steps) if re.fullmatch(r"[A-Za-z_]\w*", name) else None
        arg = flag or node(int(fed.get("localId")), inner, by_block)
        if every_scan() and var.get("edge", "none") in ("rising", "falling") and not _negated(var):
            arg = scan_block(var, {"CLK": (partial(str, arg), fed)}, by_block, src.at(var), None,
                             partial(lagging, steps=steps), str(var.get("edge")))
        if not wrap:
            return negation(arg) if _negated(var) else arg
        return f"!({arg})" if _negated(var) else f"({arg})"

    def pt_of(block: Any) -> tuple[str, Location]:
        """The text of the inVariable wired to the ``PT`` of ``block``, and where it is."""
        var = next((v for v in block.iterfind(f"{q('inputVariables')}/{q('variable')}")
                    if str(v.get("formalParameter", "")).upper() == "PT"), None)
        if var is None:
            raise InputError("an FBD TON block without its input PT", src.at(block))
        ex = source(var).find(q("expression"))
        return (ex.text or "") if ex is not None else "", src.at(source(var))

    def node(lid: int, seen: frozenset[int], by_block: bool = False) -> str:
        el = elements[lid]
        kind = etree.QName(el).localname
        if lid in latches:
            return latches[lid]
        if lid in seen:
            raise InputError("an FBD condition that loops back on itself", src.at(el))
        if kind == "inVariable":
            ex = el.find(q("expression"))
            text = (ex.text or "") if ex is not None else ""
            if not text.strip():
                raise InputError("an <inVariable> without an expression", src.at(el))
            reader = ExprReader(text, lambda off, w, h=ex, t=text: src.text_at(h, t, off, w), steps)
            expr = reader.whole()
            return f"!({expr})" if _negated(el) else expr
        if kind == "block":
            name = (el.get("typeName") or "").upper()
            if every_scan():
                if name not in SCAN_BLOCKS:
                    raise InputError(f"an FBD block {el.get('typeName')} in a transition condition: only "
                                     f"{', '.join(SCAN_BLOCKS)} have a Boolean or timer meaning in .g7", src.at(el),
                                     expected=tuple(SCAN_BLOCKS))
                outs = el.find(f"{q('outputVariables')}/{q('variable')}")
                ins = list(el.iterfind(f"{q('inputVariables')}/{q('variable')}"))
                readers: dict[str, tuple[Callable[[], str], Any]] = {
                    str(v.get("formalParameter", "")).upper() or f"IN{i + 1}":
                    (partial(argument, v, frozenset(), True, False), v) for i, v in enumerate(ins)}
                value = scan_block(el, readers, by_block, src.at(el), partial(pt_of, el), partial(lagging, steps=steps))
                return f"!({value})" if _negated(outs) else value
            if name not in _BLOCKS and name not in FBD_FUNCTION_BLOCKS and name not in LATCH_BLOCKS:
                raise InputError(f"an FBD block {el.get('typeName')} in a transition condition: only AND, OR, NOT, "
                                 "SEL, R_TRIG, F_TRIG, TON, SR and RS have a Boolean or step-timer meaning in .g7",
                                 src.at(el), expected=(*_BLOCKS, *FBD_FUNCTION_BLOCKS, *LATCH_BLOCKS))
            outs = el.find(f"{q('outputVariables')}/{q('variable')}")
            inner = seen | {lid}
            if name in LATCH_BLOCKS:  # its inputs may read its output back
                latches[lid] = latch_step(str(el.get("instanceName") or name))
                latches[lid] = f"!({latches[lid]})" if _negated(outs) else latches[lid]
                inner = frozenset({lid})
            args: list[str] = []
            params: dict[str, tuple[str, Any]] = {}
            for var in el.iterfind(f"{q('inputVariables')}/{q('variable')}"):
                if name == "TON" and str(var.get("formalParameter", "")).upper() == "PT":
                    params["PT"] = pt_of(el)
                    continue
                args.append(argument(var, inner, False))
                params[str(var.get("formalParameter", "")).upper()] = (args[-1], var)
            out = _function_block(name, el, args, params)
            if name in LATCH_BLOCKS:
                return latches[lid]
            return f"!({out})" if _negated(outs) else out
        if kind == "leftPowerRail":
            return "1"
        if kind == "contact":  # LD: this contact in series after what feeds it (several feeds: in parallel)
            var = el.find(q("variable"))
            name = (var.text or "").strip() if var is not None else ""
            if not name:
                raise InputError("an LD contact without a variable", src.at(el))
            reader = ExprReader(name, lambda off, w, h=var, t=name: src.text_at(h, t, off, w), steps)
            literal = reader.whole()
            edge = el.get("edge", "none")
            if edge in ("rising", "falling") and every_scan() and not _negated(el):  # Beremiz: an R_TRIG/F_TRIG
                literal = scan_block(el, {"CLK": (partial(str, literal), var)}, False, src.at(el), None,
                                     partial(lagging, steps=steps), edge)
            elif edge in ("rising", "falling") and not every_scan():
                literal = ("↑" if edge == "rising" else "↓") + literal
            if _negated(el):
                literal = f"!{literal}" if edge == "none" else f"!({literal})"
            cp = el.find(q("connectionPointIn"))
            feeds = [] if cp is None else cp.findall(q("connection"))
            before = []
            for c in feeds:
                ref = c.get("refLocalId", "")
                if not ref.strip().isdigit() or int(ref) not in elements:
                    raise InputError(f"connection to unknown localId {ref}", src.at(c))
                before.append(node(int(ref), seen | {lid}))
            before = [b for b in before if b != "1"]
            if not feeds:
                raise InputError("an LD contact not fed by the power rail or another contact", src.at(el))
            if not before or len(before) < len(feeds):  # fed by the rail (alone or in parallel): just this contact
                return literal
            fed = before[0] if len(before) == 1 else "(" + " | ".join(f"({b})" for b in before) + ")"
            return f"({fed}) & {literal}"
        raise InputError(f"<{kind}> in a transition condition: .g7 reads inVariables, AND/OR/NOT blocks and LD "
                         "contacts", src.at(el))

    def _function_block(name: str, el: Any, args: list[str], params: dict[str, tuple[str, Any]]) -> str:
        if name in _BLOCKS:
            if not args or (name == "NOT" and len(args) != 1):
                raise InputError(f"an FBD {name} block with {len(args)} inputs", src.at(el))
            return f"!{args[0]}" if name == "NOT" else _BLOCKS[name].join(args)
        wanted = {"SEL": ("G", "IN0", "IN1"), "R_TRIG": ("CLK",), "F_TRIG": ("CLK",), "TON": ("IN", "PT"),
                  **LATCH_BLOCKS}[name]
        missing = [p for p in wanted if p not in params]
        if missing:
            raise InputError(f"an FBD {name} block without its input {missing[0]}", src.at(el))
        instance = str(el.get("instanceName") or name)
        if name == "SEL":
            return sel(*(params[p][0] for p in wanted))
        if name in LATCH_BLOCKS:
            latch_chart(name, instance, params[wanted[0]][0], params[wanted[1]][0], list(sources), src.at(el))
            return ""
        if name == "TON":
            return ton_output(instance, params["IN"][0], params["PT"][0], list(sources), src.at(el), elements,
                              steps, params["PT"][1])
        return trigger(name, instance, params["CLK"][0], src.at(el))

    cp = cond.find(q("connectionPointIn"))
    return one_source(cp if cp is not None else cond, cond)  # TC6 1.0: <condition><connection> directly


def fbd_transition(transition: Any, fbd: Any, q: Callable[[str], str], src: Any, steps: dict[str, str],
                   sources: tuple[str, ...] = ()) -> str:
    """The receptivity of a named transition whose body is FBD: the network wired to the
    ``<outVariable>`` that carries the transition's name."""
    from lxml import etree

    name = str(transition.get("name", ""))
    elements: dict[int, Any] = {}
    target = None
    for el in fbd:
        if not isinstance(el.tag, str) or el.get("localId") is None or not el.get("localId").isdigit():
            continue
        elements[int(el.get("localId"))] = el
        kind = etree.QName(el).localname
        ex = el.find(q("expression" if kind == "outVariable" else "variable"))
        if kind in ("outVariable", "coil") and ex is not None and (ex.text or "").strip().upper() == name.upper():
            target = el
    if target is None:
        raise InputError(f"the FBD/LD body of transition {name} has no <outVariable> or <coil> {name}",
                         src.at(transition))
    expr = fbd_condition(target, elements, q, src, steps, sources)
    return f"!({expr})" if etree.QName(target).localname == "coil" and _negated(target) else expr

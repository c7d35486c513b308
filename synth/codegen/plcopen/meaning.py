"""What carries meaning in an SFC POU of a PLCopen project, read straight from the XML (no
import involved): each action qualifier and the variable it drives, each assignment of an ST
action body, each selection divergence's order (its transitions' ``priority``), each block
call in a transition or action network, each timer. :mod:`synth.codegen.plcopen.accounting`
matches every item to the imported ``.g7`` or to a located warning of the import; an item
matched by neither is a silent change.

Example
-------
>>> xml = ('<project xmlns="http://www.plcopen.org/xml/tc6_0201"><types><pous>'
...        '<pou name="P" pouType="program"><body><SFC>'
...        '<step localId="1" name="S0" initialStep="true"/>'
...        '<actionBlock localId="2"><connectionPointIn><connection refLocalId="1"/></connectionPointIn>'
...        '<action qualifier="S"><reference name="pump"/></action></actionBlock>'
...        '</SFC></body></pou></pous></types></project>')
>>> [(i.kind.value, i.step, i.what) for i in meaning_items(xml, "p.xml")]
[('qualifier', 'S0', 'S action on pump')]
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import StrEnum
from typing import Any, Callable

from synth.codegen.plcopen.project import pous_of, read_project
from synth.codegen.plcopen.sfc import Source
from synth.codegen.plcopen.st_condition import st_text
from synth.codegen.plcopen.vendor import IecQualifier, step_actions
from synth.errors import Location

__all__ = ["ItemKind", "MeaningItem", "meaning_items", "TIMER_TYPES", "STATELESS"]


class ItemKind(StrEnum):
    """What a meaning-carrying item of an SFC POU is."""

    QUALIFIER = "qualifier"  # an action block's line naming a variable: N/S/R/D/L ... on it
    ASSIGNMENT = "assignment"  # NAME := value; in an action body run by a step
    PRIORITY = "priority"  # the order of a selection divergence's branches
    BLOCK = "block"  # a function block or function called in a network or a body
    TIMER = "timer"  # a TON/TOF/TP, or a step's elapsed time S.T compared with a TIME


TIMER_TYPES = frozenset({"TON", "TOF", "TP"})
"""The IEC 61131-3 timer blocks."""

STATELESS = frozenset({"AND", "OR", "NOT", "XOR", "SEL", "GT", "GE", "LT", "LE", "EQ", "NE", "MOVE"})
"""Blocks without memory: their meaning is the Boolean expression they compute."""


@dataclass(frozen=True)
class MeaningItem:
    """One item: its kind, POU, the step (or the divergence's source steps) it belongs to, what
    it is in words, the variables it drives or reads (``names``), its qualifier (actions), its
    value text (assignments), whether it runs under an ``IF`` (assignments), its duration text
    (timers), and where it is (``lines``: its own line and those of the elements around it
    that a warning may point at)."""

    kind: ItemKind
    pou: str
    step: str
    what: str
    location: Location
    names: tuple[str, ...] = ()
    qualifier: str = ""
    value: str = ""
    conditional: bool = False
    duration: str = ""
    lines: tuple[int, ...] = ()


_COMMENT = re.compile(r"\(\*.*?\*\)|//[^\n]*", re.S)
_STATEMENT = re.compile(r"\s*(?:IF\b(?P<cond>.*?)\bTHEN\b(?P<body>.*?)\bEND_IF\s*;?|(?P<plain>[^;]*;?))", re.I | re.S)


def _blanked(text: str) -> str:
    """``text`` with its comments replaced by spaces (offsets kept)."""
    return _COMMENT.sub(lambda m: re.sub(r"[^\n]", " ", m[0]), text)


class _Pou:
    """The reading of one SFC POU: its steps, actions, transitions and declared types."""

    def __init__(self, pou: Any, sfc: Any, q: Callable[[str], str], src: Source) -> None:
        self.pou, self.sfc, self.q, self.src = pou, sfc, q, src
        self.name = str(pou.get("name", ""))
        self.actions = {str(a.get("name")): a for a in pou.iterfind(f"{q('actions')}/{q('action')}")}
        self.types = {str(v.get("name", "")).upper(): self._type(v)
                      for v in pou.iterfind(f"{q('interface')}//{q('variable')}")}
        self.items: list[MeaningItem] = []

    def _type(self, v: Any) -> str:
        t = v.find(self.q("type"))
        if t is None or not len(t):
            return ""
        child = t[0]
        name = child.get("name") if child.tag == self.q("derived") else re.sub(r"^\{.*\}", "", str(child.tag))
        return str(name or "").upper()

    def add(self, kind: ItemKind, step: str, what: str, where: Location, around: tuple[Any, ...] = (),
            **more: Any) -> None:
        lines = (where.line, *(int(e.sourceline or 0) for e in around))
        self.items.append(MeaningItem(kind, self.name, step, what, where, lines=tuple(dict.fromkeys(lines)), **more))

    def body(self, st: Any, step: str, qualifier: str, around: tuple[Any, ...], owner: str) -> None:
        """The assignments and calls of an ST body run by ``step`` under ``qualifier``."""
        text = st_text(st)
        clean = _blanked(text)

        def at(off: int, width: int) -> Location:
            return self.src.text_at(st, text, off, width)

        for m in _STATEMENT.finditer(clean):
            if m["plain"] is not None and m["plain"].strip():
                self.statement(clean, m.start("plain"), m["plain"], step, qualifier, at, around, owner, False)
            elif m["body"] is not None:
                for s in re.finditer(r"[^;]+;?", m["body"]):
                    if s[0].strip():
                        self.statement(clean, m.start("body") + s.start(), s[0], step, qualifier, at, around, owner,
                                       True)

    def statement(self, clean: str, pos: int, text: str, step: str, qualifier: str, at: Callable[[int, int], Location],
                  around: tuple[Any, ...], owner: str, conditional: bool) -> None:
        lead = len(text) - len(text.lstrip())
        pos, text = pos + lead, text.strip().rstrip(";").strip()
        assign = re.fullmatch(r"([\w.]+)\s*:=\s*(.*)", text, re.S)
        call = re.fullmatch(r"([\w.]+)\s*\((.*)\)", text, re.S)
        if assign:
            value = " ".join(assign[2].split())
            self.add(ItemKind.ASSIGNMENT, step, f"{assign[1]} := {value} ({qualifier} {owner})", at(pos, len(assign[1])),
                     around, names=(assign[1],), qualifier=qualifier, value=value, conditional=conditional)
        elif call:
            self.call(call[1], call[2], step, at(pos, len(call[1])), around)

    def call(self, instance: str, args: str, step: str, where: Location, around: tuple[Any, ...]) -> None:
        kind = self.types.get(instance.upper(), instance.upper())
        if kind in TIMER_TYPES:
            pt = re.search(r"\bPT\s*:=\s*([^,)]+)", args, re.I)
            self.add(ItemKind.TIMER, step, f"{kind} {instance}", where, around, names=(instance,),
                     duration=pt[1].strip() if pt else "")
        else:
            self.add(ItemKind.BLOCK, step, f"{kind} {instance}", where, around, names=(instance,))

    def network(self, body: Any, step: str, around: tuple[Any, ...]) -> None:
        """The blocks of an FBD/LD network (or of the SFC body itself)."""
        q = self.q
        reads = {str(v.get("localId")): " ".join(st_text(e).split()) for v in body.iter(q("inVariable"))
                 if (e := v.find(q("expression"))) is not None}
        for b in body.iter(q("block")):
            kind = str(b.get("typeName", "")).upper()
            instance = str(b.get("instanceName", "") or "")  # a function (AND, OR) has none
            fed = [reads[c.get("refLocalId")] for c in b.iter(q("connection")) if c.get("refLocalId") in reads]
            args = {str(v.get("formalParameter", "")).upper(): reads.get(str(c.get("refLocalId")), "")
                    for v in b.iterfind(f"{q('inputVariables')}/{q('variable')}")
                    for c in v.iter(q("connection"))}
            where = self.src.at(b)
            if kind in TIMER_TYPES:
                self.add(ItemKind.TIMER, step, f"{kind} {instance}", where, around, names=(instance,),
                         duration=args.get("PT", ""))
            else:
                self.add(ItemKind.BLOCK, step, f"{kind} {instance}".strip(), where, around, names=(instance, *fed),
                         qualifier=kind)

    def step_time(self, text: str, holder: Any, step: str) -> None:
        """``S.T > T#2s`` in an ST condition: a timer on step S."""
        for m in re.finditer(r"\b(\w+)\.T\s*(>=|<=|>|<|=)\s*(T#[\w.]+)|(T#[\w.]+)\s*(>=|<=|>|<|=)\s*(\w+)\.T\b",
                             _blanked(text), re.I):
            target, literal = (m[1], m[3]) if m[1] else (m[6], m[4])
            self.add(ItemKind.TIMER, target, f"{target}.T compared with {literal}",
                     self.src.text_at(holder, text, m.start(), len(m[0])), (), names=(target,), duration=literal)

    def action(self, a: Any, step: str, qualifier: str, name: str | None, around: tuple[Any, ...]) -> None:
        """An action of ``step``: a POU action's body, a variable under a qualifier, or an inline body."""
        q = self.q
        inline = a.find(q("inline")) if name is None else None
        if name is not None and name in self.actions:
            act = self.actions[name]
            body = act.find(q("body"))
            st = body.find(q("ST")) if body is not None else None
            if st is not None:
                self.body(st, step, qualifier, (*around, act), f"action {name}")
            for net in ("FBD", "LD"):
                if body is not None and (n := body.find(q(net))) is not None:
                    self.network(n, step, (*around, act))
        elif name is not None:
            timed = a.get("duration", "") if qualifier in ("D", "L", "SD", "DS", "SL") else ""
            self.add(ItemKind.QUALIFIER, step, f"{qualifier} action on {name}" + (f" {timed}" if timed else ""),
                     self.src.at(a), around, names=(name,), qualifier=qualifier, duration=timed)
        elif inline is not None and (st := inline.find(q("ST"))) is not None:
            self.body(st, step, qualifier, around, "inline action")

    def read(self) -> list[MeaningItem]:
        q, sfc = self.q, self.sfc
        steps = {str(s.get("localId")): str(s.get("name", "")) for s in sfc.iterfind(q("step"))}
        for s in sfc.iterfind(q("step")):
            for which, name, attr in step_actions(s, q):
                self.action(attr, str(s.get("name", "")), which.qualifier.value, name, (s,))
        for block in sfc.iterfind(q("actionBlock")):
            owner = next((steps[c.get("refLocalId")] for c in block.iter(q("connection"))
                          if c.get("refLocalId") in steps), "")
            for a in block.iterfind(q("action")):
                ref = a.find(q("reference"))
                qualifier = str(a.get("qualifier", "N"))
                qualifier = IecQualifier.P1.value if qualifier == IecQualifier.P.value else qualifier
                self.action(a, owner, qualifier, str(ref.get("name")) if ref is not None else None, (a,))
        self.network(sfc, "", ())
        self.divergences(steps)
        for t in [*sfc.iter(q("transition")), *self.pou.iterfind(f"{q('transitions')}/{q('transition')}")]:
            for st in t.iter(q("ST")):
                self.step_time(st_text(st), st, "")
            body = t.find(q("body"))
            for net in ("FBD", "LD"):
                if body is not None and (n := body.find(q(net))) is not None:
                    self.network(n, "", (t,))
        return self.items

    def upstream(self, el: Any, steps: dict[str, str], by_id: dict[str, Any], seen: frozenset[str] = frozenset()) \
            -> list[str]:
        """The steps in front of ``el`` through divergences and convergences (a divergence may
        follow a branch of another)."""
        out: list[str] = []
        for c in el.iterfind(f"{self.q('connectionPointIn')}/{self.q('connection')}"):
            ref = str(c.get("refLocalId"))
            if ref in steps:
                out.append(steps[ref])
            elif ref in by_id and ref not in seen and re.sub(r"^\{.*\}", "", str(by_id[ref].tag)).startswith("selection"):
                out += self.upstream(by_id[ref], steps, by_id, seen | {ref})
        return list(dict.fromkeys(out))

    def divergences(self, steps: dict[str, str]) -> None:
        """One item per selection divergence with two branches or more: their order."""
        q = self.q
        by_id = {str(e.get("localId")): e for e in self.sfc if isinstance(e.tag, str)}
        for d in self.sfc.iterfind(q("selectionDivergence")):
            lid = str(d.get("localId"))
            branches = [t for t in self.sfc.iterfind(q("transition"))
                        if any(c.get("refLocalId") == lid for c in t.iter(q("connection")))]
            if len(branches) < 2:
                continue
            sources = self.upstream(d, steps, by_id)
            priorities = [t.get("priority") for t in branches]
            order = "priorities " + ", ".join(p or "-" for p in priorities) if any(priorities) else "left to right"
            self.add(ItemKind.PRIORITY, ", ".join(sources), f"selection divergence after {', '.join(sources)} "
                     f"({len(branches)} branches, {order})", self.src.at(d), tuple(branches), names=tuple(sources))
        for s in self.sfc.iterfind(q("step")):  # transitions wired to a step without a divergence
            lid = str(s.get("localId"))
            direct = [t for t in self.sfc.iterfind(q("transition"))
                      if any(c.get("refLocalId") == lid for c in t.iter(q("connection")))]
            if len(direct) > 1:
                name = str(s.get("name", ""))
                self.add(ItemKind.PRIORITY, name, f"{len(direct)} transitions wired to step {name} without a "
                         "divergence", self.src.at(s), tuple(direct), names=(name,))


def meaning_items(data: bytes | str, file: str = "<xml>", pou: str | None = None) -> list[MeaningItem]:
    """The meaning-carrying items of the SFC POUs of a PLCopen project (``pou``: that one
    only), in file order per POU."""
    root, src, q = read_project(data, file)
    out: list[MeaningItem] = []
    for p in pous_of(root, q):
        sfc = p.find(f"{q('body')}/{q('SFC')}")
        if sfc is not None and (pou is None or p.get("name") == pou):
            out += _Pou(p, sfc, q, src).read()
    return out

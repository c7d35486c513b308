"""PLCopen TC6 XML (v2.01): ST programs and the Grafcet as an SFC out, SFCs in.

* :func:`st_project_xml` wraps Structured Text POUs (``synth st --xml``) in a project: each
  ``PROGRAM``/``FUNCTION_BLOCK`` becomes a ``<pou>`` with its interface and an ``<ST>`` body;
* :func:`sfc_project_xml` writes a Grafcet as one SFC ``<pou>`` (``synth sfc``): a ``<step>``
  per step (``initialStep``), a ``<transition>`` per transition with an inline ST condition,
  ``selectionDivergence``/``selectionConvergence`` for OR, ``simultaneousDivergence``/
  ``simultaneousConvergence`` for AND, an ``actionBlock`` per step with actions;
* :func:`import_sfc` reads an SFC (as synth or a PLC IDE writes it: layout positions,
  comments, vendor ``addData``, ``jumpStep``) back into ``.g7`` text (``synth import``); what
  ``.g7`` cannot represent is an :class:`~synth.errors.InputError` at its line.

Mapping (both ways):

=====================================  ==========================================
``.g7``                                SFC
=====================================  ==========================================
step ``12`` / ``wait``                  ``<step name="S12">`` / ``name="wait"``
``X12``                                 ``S12.X``
``2s/X12``                              ``(S12.T >= T#2s)``
``↑x`` / ``↓x``                         ``_RE_x`` / ``_FE_x`` (edge flags, see docs/codegen.md)
``A`` (continuous)                      qualifier ``N``, reference ``A``
``A if c``                              qualifier ``N``, inline ST ``A := c;``
``set A`` / ``reset A`` on activation   qualifier ``S`` / ``R``, reference ``A``
``set A on deactivation``               qualifier ``P0``, inline ST ``A := TRUE;``
``set A on ↑p``                         qualifier ``N``, inline ``IF _RE_p THEN A := TRUE; END_IF;``
=====================================  ==========================================

Nothing written depends on the time of day: ``creationDateTime`` is a fixed date.

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet("grafcet G { initial step 0 step 1: A "
...                   "transition 0 -> 1 when ↑a transition 1 -> 0 when !a }", "g.g7")
>>> xml = sfc_project_xml(g, version="0.1.0")
>>> validation_errors(xml)
[]
>>> print(import_sfc(xml, "g.xml").split("\\n", 1)[1])
inputs a
outputs A
<BLANKLINE>
grafcet G {
  initial step 0
  step 1: A
  transition 0 -> 1 when ↑a
  transition 1 -> 0 when !a
}
<BLANKLINE>
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import StrEnum
from functools import lru_cache

from synth.version import version as synth_version
from synth.errors import InputError, Location, close_names
from synth.grafcet.language import (
    CONDITIONAL,
    CONTINUOUS,
    ON_ACTIVATION,
    ON_DEACTIVATION,
    ON_EVENT,
    Grafcet,
)
from synth.logic.expr import And, Const, Edge, Expr, Not, Or, Var, names as expr_names

__all__ = [
    "NS",
    "XHTML",
    "CREATION_DATE",
    "Qualifier",
    "schema",
    "validation_errors",
    "st_project_xml",
    "sfc_project_xml",
    "import_sfc",
]

NS = "http://www.plcopen.org/xml/tc6_0201"
XHTML = "http://www.w3.org/1999/xhtml"
CREATION_DATE = "2000-01-01T00:00:00"  # fixed: same input, same bytes
SYNTH_DATA = "urn:synth:partial-grafcet"  # our addData: the partial grafcet of a step


class Qualifier(StrEnum):
    """IEC 61131-3 action qualifiers that ``.g7`` actions map to."""

    N = "N"
    S = "S"
    R = "R"
    P1 = "P1"
    P0 = "P0"


@lru_cache(maxsize=1)
def schema():  # -> lxml.etree.XMLSchema
    """The PLCopen TC6 XML v2.01 schema shipped with synth (``tc6_xml_v201.xsd``)."""
    from importlib.resources import files

    from lxml import etree

    with files("synth.codegen").joinpath("tc6_xml_v201.xsd").open("rb") as fh:
        return etree.XMLSchema(etree.parse(fh))


def validation_errors(xml: bytes) -> list[str]:
    """The TC6 schema's complaints about ``xml`` (empty when valid)."""
    from lxml import etree

    s = schema()
    s.validate(etree.fromstring(xml))
    return [f"{e.line}: {e.message}" for e in s.error_log]


# --------------------------------------------------------------------------- building


def _E(tag: str, attrib: dict[str, str] | None = None, *children):  # noqa: N802 - an element factory
    from lxml import etree

    el = etree.Element(f"{{{NS}}}{tag}", {k: v for k, v in (attrib or {}).items()})
    for c in children:
        if c is not None:
            el.append(c)
    return el


def _xhtml(text: str, cdata: bool = True):
    from lxml import etree

    p = etree.Element(f"{{{XHTML}}}p", nsmap={"xhtml": XHTML})
    p.text = etree.CDATA(text) if cdata else text
    return p


def _pos(x: int, y: int, tag: str = "position"):
    return _E(tag, {"x": str(x), "y": str(y)})


def _project(name: str, version: str, comment: str, pous: list) -> bytes:
    from lxml import etree

    root = etree.Element(f"{{{NS}}}project", nsmap={None: NS, "xhtml": XHTML})
    root.append(_E("fileHeader", {"companyName": "synth", "productName": "synth", "productVersion": version,
                                  "creationDateTime": CREATION_DATE}))
    coord = _E("coordinateInfo", None, *[_E(k, None, _E("scaling", {"x": "1", "y": "1"})) for k in ("fbd", "ld", "sfc")])
    header = _E("contentHeader", {"name": name})
    c = _E("Comment")
    c.text = comment
    header.append(c)
    header.append(coord)
    root.append(header)
    root.append(_E("types", None, _E("dataTypes"), _E("pous", None, *pous)))
    root.append(_E("instances", None, _E("configurations")))
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)


_ELEMENTARY = {"BOOL", "BYTE", "WORD", "DWORD", "LWORD", "SINT", "INT", "DINT", "LINT", "USINT", "UINT",
               "UDINT", "ULINT", "REAL", "LREAL", "TIME", "DATE", "DT", "TOD"}


def _type(text: str):
    text = text.strip()
    m = re.fullmatch(r"ARRAY\s*\[\s*(-?\d+)\s*\.\.\s*(-?\d+)\s*\]\s*OF\s+(\w+)", text, re.I)
    if m:
        return _E("array", None, _E("dimension", {"lower": m[1], "upper": m[2]}), _E("baseType", None, _type(m[3])))
    if text.upper() in _ELEMENTARY:
        return _E(text.upper())
    return _E("derived", {"name": text})


# --------------------------------------------------------------------------- ST POUs


@dataclass(frozen=True)
class _Var:
    name: str
    type: str
    initial: str | None
    comment: str | None


@dataclass(frozen=True)
class _StPou:
    kind: str  # "program" | "functionBlock"
    name: str
    sections: tuple[tuple[str, bool, tuple[_Var, ...]], ...]  # (xml list name, constant, variables)
    body: str


_SECTION = {"VAR_INPUT": "inputVars", "VAR_OUTPUT": "outputVars", "VAR_IN_OUT": "inOutVars", "VAR": "localVars",
            "VAR_TEMP": "tempVars"}
_POU_RE = re.compile(r"^(PROGRAM|FUNCTION_BLOCK)\s+(\w+)(.*?)^(END_PROGRAM|END_FUNCTION_BLOCK)\b", re.M | re.S)
_SEC_RE = re.compile(r"\b(VAR_INPUT|VAR_OUTPUT|VAR_IN_OUT|VAR_TEMP|VAR(?:\s+CONSTANT)?)\b(.*?)\bEND_VAR\b", re.S)
_DECL_RE = re.compile(r"([A-Za-z_]\w*(?:\s*,\s*[A-Za-z_]\w*)*)\s*:\s*([^;]+?)\s*(?::=\s*([^;]+?))?\s*;"
                      r"[ \t]*(?:\(\*\s*(.*?)\s*\*\))?")


def _split_st(text: str) -> list[_StPou]:
    """The POUs of generated ST: declarations (one ``name : TYPE [:= init];`` each) and body."""
    pous = []
    for m in _POU_RE.finditer(text):
        kind = "program" if m[1] == "PROGRAM" else "functionBlock"
        inner = m[3]
        sections = []
        last = 0
        for s in _SEC_RE.finditer(inner):
            head = s[1].split()
            key = _SECTION[head[0]]
            variables = []
            for d in _DECL_RE.finditer(s[2]):
                for n in d[1].split(","):
                    variables.append(_Var(n.strip(), d[2], d[3], d[4]))
            sections.append((key, len(head) > 1, tuple(variables)))
            last = s.end()
        pous.append(_StPou(kind, m[2], tuple(sections), inner[last:].strip("\n") + "\n"))
    return pous


def _interface(sections) -> object:
    iface = _E("interface")
    for key, constant, variables in sections:
        vl = _E(key, {"constant": "true"} if constant else None)
        for v in variables:
            var = _E("variable", {"name": v.name}, _E("type", None, _type(v.type)))
            if v.initial is not None:
                var.append(_E("initialValue", None, _E("simpleValue", {"value": v.initial})))
            if v.comment:
                var.append(_E("documentation", None, _xhtml(v.comment, cdata=False)))
            vl.append(var)
        iface.append(vl)
    return iface


def st_project_xml(text: str, *, name: str = "synth", version: str | None = None, comment: str = "") -> bytes:
    """PLCopen XML of the ``PROGRAM``/``FUNCTION_BLOCK`` POUs of generated ST ``text``.

    >>> xml = st_project_xml("PROGRAM P\\nVAR_INPUT\\n  a : BOOL;\\nEND_VAR\\nVAR_OUTPUT\\n  y : BOOL;\\nEND_VAR\\n"
    ...                      "y := a;\\nEND_PROGRAM\\n", version="0.1.0")
    >>> validation_errors(xml), b'<pou name="P" pouType="program">' in xml
    ([], True)
    """
    pous = []
    for p in _split_st(text):
        body = _E("body", None, _E("ST", None, _xhtml(p.body)))
        pous.append(_E("pou", {"name": p.name, "pouType": p.kind}, _interface(p.sections), body))
    return _project(name, version or synth_version(), comment, pous)


# --------------------------------------------------------------------------- Grafcet -> SFC


def sfc_step_name(step: str) -> str:
    """The SFC name of a ``.g7`` step: ``S12`` for a number (IEC names start with a letter).

    >>> sfc_step_name("12"), sfc_step_name("wait")
    ('S12', 'wait')
    """
    return f"S{step}" if step.isdigit() else step


def _duration_literal(timer_id: str) -> str:
    """``2s/X1`` → ``T#2s``; ``2min/X1`` → ``T#2m``."""
    number, unit = re.fullmatch(r"([0-9.]+)(ms|s|min|h)/X.*", timer_id).groups()  # type: ignore[union-attr]
    return f"T#{number}{'m' if unit == 'min' else unit}"


def _sfc_expr(e: Expr, steps: set[str], timers: dict[str, str], parent: int = 0) -> str:
    prec = {Or: 1, And: 2, Not: 3}
    if isinstance(e, Const):
        return "TRUE" if e.value else "FALSE"
    if isinstance(e, Edge):
        return ("_RE_" if e.rising else "_FE_") + e.name
    if isinstance(e, Var):
        if e.name in timers:
            return f"({sfc_step_name(timers[e.name])}.T >= {_duration_literal(e.name)})"
        if e.name.startswith("X") and e.name[1:] in steps:
            return f"{sfc_step_name(e.name[1:])}.X"
        return e.name
    if isinstance(e, Not):
        text = "NOT " + _sfc_expr(e.arg, steps, timers, 4)
    else:
        op = " AND " if isinstance(e, And) else " OR "
        text = op.join(_sfc_expr(a, steps, timers, prec[type(e)]) for a in e.args)
    return f"({text})" if prec[type(e)] < parent else text


class _Ids:
    def __init__(self) -> None:
        self.n = 0

    def __call__(self) -> int:
        self.n += 1
        return self.n


def _conn_in(*producers: tuple[int, str | None]):
    cp = _E("connectionPointIn")
    for ref, formal in producers:
        attrib = {"refLocalId": str(ref)}
        if formal is not None:
            attrib["formalParameter"] = formal
        cp.append(_E("connection", attrib))
    return cp


def sfc_project_xml(g: Grafcet, *, name: str | None = None, version: str | None = None, comment: str = "") -> bytes:
    """The Grafcet ``g`` as one PLCopen SFC ``PROGRAM`` (see the module doc for the mapping)."""
    from synth.codegen.grafcet_st import program_name

    steps = {s.name for s in g.steps}
    timers = {t.id: t.step for t in g.timers}
    seen: dict[str, str] = {}
    for s in g.steps:  # step 12 is S12 in the SFC: a step named S12 as well would be the same
        other = seen.setdefault(sfc_step_name(s.name).upper(), s.name)
        if other != s.name:
            raise InputError(f"steps {other} and {s.name} would both be the SFC step {sfc_step_name(s.name)}", s.loc,
                             notes=("rename one of them",))
    ids = _Ids()
    step_id = {s.name: ids() for s in g.steps}
    trans_id = [ids() for _ in g.transitions]
    outgoing = {s: [i for i, t in enumerate(g.transitions) if s in t.sources] for s in steps}
    incoming = {s: [i for i, t in enumerate(g.transitions) if s in t.targets] for s in steps}
    sel_div = {s: ids() for s in steps if len(outgoing[s]) > 1}
    sel_conv = {s: ids() for s in steps if len(incoming[s]) > 1}
    sim_conv = {i: ids() for i, t in enumerate(g.transitions) if len(t.sources) > 1}
    sim_div = {i: ids() for i, t in enumerate(g.transitions) if len(t.targets) > 1}

    def producer_of_step(s: str, i: int) -> tuple[int, str | None]:
        """What transition ``i`` connects to, upstream of it, for its source step ``s``."""
        if s in sel_div:
            return sel_div[s], str(outgoing[s].index(i))
        return step_id[s], None

    def producer_of_transition(i: int, s: str) -> tuple[int, str | None]:
        """What step ``s`` (or its convergence) connects to, for its incoming transition ``i``."""
        if i in sim_div:
            return sim_div[i], str(g.transitions[i].targets.index(s))
        return trans_id[i], None

    body = _E("SFC")
    column: dict[str, int] = {p.name: k for k, p in enumerate(g.grafcets)}
    row: dict[str, int] = {}
    for p in g.grafcets:
        for r, s in enumerate(p.steps):
            row[s.name] = r
    for s in g.steps:
        x, y = 40 + 400 * column[s.grafcet], 40 + 160 * row[s.name]
        el = _E("step", {"localId": str(step_id[s.name]), "name": sfc_step_name(s.name),
                         "initialStep": "true" if s.initial else "false"}, _pos(x, y))
        if s.name in sel_conv:
            el.append(_conn_in((sel_conv[s.name], None)))
        elif incoming[s.name]:
            el.append(_conn_in(producer_of_transition(incoming[s.name][0], s.name)))
        el.append(_E("connectionPointOut", {"formalParameter": ""}))
        if s.actions:
            el.append(_E("connectionPointOutAction", {"formalParameter": ""}))
        data = _E("data", {"name": SYNTH_DATA, "handleUnknown": "discard"}, _E("grafcet", {"name": s.grafcet}))
        el.append(_E("addData", None, data))
        body.append(el)
        if s.name in sel_conv:
            producers = [producer_of_transition(i, s.name) for i in incoming[s.name]]
            body.append(_E("selectionConvergence", {"localId": str(sel_conv[s.name])}, _pos(x, y - 30),
                           _conn_in(*producers), _E("connectionPointOut")))
        if s.name in sel_div:
            div = _E("selectionDivergence", {"localId": str(sel_div[s.name])}, _pos(x, y + 50),
                     _conn_in((step_id[s.name], None)))
            for k in range(len(outgoing[s.name])):
                div.append(_E("connectionPointOut", {"formalParameter": str(k)}))
            body.append(div)
        if s.actions:
            block = _E("actionBlock", {"localId": str(ids())}, _pos(x + 120, y), _conn_in((step_id[s.name], None)))
            for k, a in enumerate(s.actions):
                block.append(_action(a, ids(), k, steps, timers))
            body.append(block)
    for i, t in enumerate(g.transitions):
        col = column[t.grafcet]
        first = t.sources[0] if t.sources else (t.targets[0] if t.targets else None)
        x = 40 + 400 * col + (120 if t.sources and len(outgoing[t.sources[0]]) > 1
                              and outgoing[t.sources[0]].index(i) else 0)
        y = 40 + 160 * (row.get(first, 0) if first else 0) + 90
        if i in sim_conv:
            body.append(_E("simultaneousConvergence", {"localId": str(sim_conv[i])}, _pos(x, y - 20),
                           _conn_in(*[producer_of_step(s, i) for s in t.sources]), _E("connectionPointOut")))
        el = _E("transition", {"localId": str(trans_id[i])}, _pos(x, y))
        if i in sim_conv:
            el.append(_conn_in((sim_conv[i], None)))
        elif t.sources:
            el.append(_conn_in(producer_of_step(t.sources[0], i)))
        el.append(_E("connectionPointOut"))
        label = t.label or ""
        inline = _E("inline", {"name": label}, _E("ST", None, _xhtml(_sfc_expr(t.receptivity, steps, timers))))
        el.append(_E("condition", None, inline))
        body.append(el)
        if i in sim_div:
            div = _E("simultaneousDivergence", {"localId": str(sim_div[i])}, _pos(x, y + 20),
                     _conn_in((trans_id[i], None)))
            for k in range(len(t.targets)):
                div.append(_E("connectionPointOut", {"formalParameter": str(k)}))
            body.append(div)
    pou_name = name or program_name(g.path)
    iface = _E("interface")
    for key, names in (("inputVars", g.inputs), ("outputVars", g.outputs)):
        vl = _E(key)
        for n in names:
            vl.append(_E("variable", {"name": n}, _E("type", None, _E("BOOL"))))
        iface.append(vl)
    edges = sorted({(n.rising, n.name) for x in g.expressions() for n in expr_names(x) if isinstance(n, Edge)}, key=lambda e: (e[1], not e[0]))
    if edges:
        vl = _E("localVars")
        for rising, n in edges:
            v = _E("variable", {"name": ("_RE_" if rising else "_FE_") + n}, _E("type", None, _E("BOOL")),
                   _E("documentation", None, _xhtml(f"{'rising' if rising else 'falling'} edge of {n}, computed "
                                                    "by the caller each cycle (R_TRIG/F_TRIG)", cdata=False)))
            vl.append(v)
        iface.append(vl)
    pou = _E("pou", {"name": pou_name, "pouType": "program"}, iface, _E("body", None, body))
    return _project(pou_name, version or synth_version(), comment, [pou])


def _action(a, local_id: int, k: int, steps: set[str], timers: dict[str, str]):
    el = _E("action", {"localId": str(local_id)})
    el.append(_pos(0, 30 * k, "relPosition"))
    value = "TRUE" if a.value else "FALSE"
    if a.kind == CONTINUOUS:
        el.set("qualifier", Qualifier.N)
        el.append(_E("reference", {"name": a.order}))
    elif a.kind == CONDITIONAL:
        el.set("qualifier", Qualifier.N)
        el.append(_E("inline", None, _E("ST", None, _xhtml(f"{a.order} := {_sfc_expr(a.condition, steps, timers)};"))))
    elif a.when == ON_ACTIVATION:
        el.set("qualifier", Qualifier.S if a.value else Qualifier.R)
        el.append(_E("reference", {"name": a.order}))
    elif a.when == ON_DEACTIVATION:
        el.set("qualifier", Qualifier.P0)
        el.append(_E("inline", None, _E("ST", None, _xhtml(f"{a.order} := {value};"))))
    else:
        assert a.when == ON_EVENT and a.condition is not None
        el.set("qualifier", Qualifier.N)
        text = f"IF {_sfc_expr(a.condition, steps, timers)} THEN {a.order} := {value}; END_IF;"
        el.append(_E("inline", None, _E("ST", None, _xhtml(text))))
    return el


# --------------------------------------------------------------------------- SFC -> .g7

_SUPPORTED = {"step", "transition", "selectionDivergence", "selectionConvergence", "simultaneousDivergence",
              "simultaneousConvergence", "actionBlock", "jumpStep", "comment"}
_WHAT = {"macroStep": "a macro-step", "inVariable": "an FBD variable", "outVariable": "an FBD variable",
         "inOutVariable": "an FBD variable", "block": "an FBD block", "connector": "a connector",
         "continuation": "a continuation", "contact": "an LD contact", "coil": "an LD coil",
         "leftPowerRail": "an LD power rail", "rightPowerRail": "an LD power rail", "label": "a label",
         "jump": "an FBD jump", "return": "a return", "error": "a conversion error", "vendorElement": "vendor data"}


class _Source:
    """The XML file's text, for locations: ``file:line:col`` of an element or of a text."""

    def __init__(self, file: str, text: str) -> None:
        self.file = file
        self.lines = text.split("\n")

    def at(self, el, width: int | None = None) -> Location:
        from lxml import etree

        line = el.sourceline or 1
        tag = etree.QName(el).localname
        raw = self.lines[line - 1] if 0 < line <= len(self.lines) else ""
        col = raw.find("<" + tag) + 1 if ("<" + tag) in raw else 1
        return Location(self.file, line, max(1, col), raw, width or len(tag) + 1)

    def text_at(self, el, text: str, offset: int, width: int = 1) -> Location:
        """Where character ``offset`` of ``text`` (the text of ``el`` or of its child) is."""
        start = el.sourceline or 1
        first = text.lstrip().split("\n")[0].strip()
        for n in range(start - 1, min(start + 20, len(self.lines))):
            if first and first in self.lines[n]:
                base_line, base_col = n + 1, self.lines[n].find(first) + 1
                lead = len(text) - len(text.lstrip())
                rel = text[lead:offset]
                if "\n" in rel:
                    line = base_line + rel.count("\n")
                    col = len(rel.rsplit("\n", 1)[1]) + 1
                else:
                    line, col = base_line, base_col + len(rel)
                raw = self.lines[line - 1] if line <= len(self.lines) else ""
                return Location(self.file, line, col, raw, width)
        return self.at(el)


def _st_text(el) -> str:
    """The text of a formattedText-like element (``<ST><xhtml:p>…</xhtml:p></ST>`` or plain text)."""
    return "".join(el.itertext())


# A tiny reader for the ST expressions of conditions: NOT, AND/&, OR, parentheses, TRUE/FALSE,
# names, S12.X, S12.T >= T#2s, _RE_x/_FE_x.
_TOKEN = re.compile(r"\s*(?:(?P<dur>T#[0-9A-Za-z_.]+)|(?P<name>[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)?)|(?P<num>\d+)"
                    r"|(?P<op>>=|<=|<>|:=|[()&>=<;+\-*/]))", re.I)
_UNIT = {"ms": "ms", "s": "s", "m": "min", "h": "h"}


class _ExprReader:
    def __init__(self, text: str, where, steps: dict[str, str]) -> None:
        # comments become spaces, so that offsets still point into the original text
        text = re.sub(r"\(\*.*?\*\)|//[^\n]*", lambda m: re.sub(r"[^\n]", " ", m[0]), text, flags=re.S)
        self.text, self.where, self.steps = text, where, steps
        self.tokens: list[tuple[str, str, int]] = []
        pos = 0
        while pos < len(text):
            if not text[pos:].strip():
                break
            m = _TOKEN.match(text, pos)
            if not m or m.end() == pos:
                raise self.error(len(text) - len(text[pos:].lstrip()), "unexpected character in an ST condition")
            kind = m.lastgroup or ""
            self.tokens.append((kind, m[kind], m.start(kind)))
            pos = m.end()
        self.i = 0

    def error(self, offset: int, message: str, width: int = 1, **kw) -> InputError:
        return InputError(message, self.where(offset, width), **kw)

    def peek(self) -> tuple[str, str, int]:
        return self.tokens[self.i] if self.i < len(self.tokens) else ("end", "", len(self.text.rstrip()))

    def take(self) -> tuple[str, str, int]:
        tok = self.peek()
        self.i += 1
        return tok

    def expr(self) -> str:
        parts = [self.conj()]
        while self.peek()[1].upper() == "OR":
            self.take()
            parts.append(self.conj())
        return " | ".join(parts)

    def conj(self) -> str:
        parts = [self.unary()]
        while self.peek()[1].upper() in ("AND", "&"):
            self.take()
            parts.append(self.unary())
        return " & ".join(f"({p})" if " | " in p else p for p in parts)

    def unary(self) -> str:
        if self.peek()[1].upper() == "NOT":
            self.take()
            inner = self.unary()
            return "!" + (inner if re.fullmatch(r"[!\w↑↓/.]+", inner) else f"({inner})")
        return self.primary()

    def primary(self) -> str:
        kind, value, offset = self.take()
        if value == "(":
            inner = self.expr()
            k, v, o = self.take()
            if v != ")":
                raise self.error(o, "expected ')' in an ST condition", expected=("')'",))
            return inner if re.fullmatch(r"[!\w↑↓/.]+", inner) else f"({inner})"
        if kind == "num" and value in ("0", "1"):
            return value
        if kind == "name":
            up = value.upper()
            if up in ("TRUE", "FALSE"):
                return "1" if up == "TRUE" else "0"
            if up in ("AND", "OR", "NOT", "XOR", "MOD"):
                raise self.error(offset, f"{up} is not supported in a .g7 receptivity" if up in ("XOR", "MOD")
                                 else f"expected a variable, not {up}", width=len(value))
            if "." in value:
                step_name, member = value.split(".")
                step = self.steps.get(step_name)
                if step is None:
                    raise self.error(offset, f"unknown step '{step_name}'", width=len(step_name),
                                     suggestions=close_names(step_name, self.steps))
                if member.upper() == "X":
                    return f"X{step}"
                if member.upper() == "T":
                    k, v, o = self.take()
                    if v != ">=":
                        raise self.error(o, f"a step time {value} is read as '{value} >= T#…' (a timer)",
                                         expected=("'>='",))
                    k, dur, o = self.take()
                    m = re.fullmatch(r"T#(\d+(?:\.\d+)?)(ms|s|m|h)", dur, re.I)
                    if not m:
                        raise self.error(o, "expected a duration such as T#2s or T#500ms", width=max(1, len(dur)))
                    return f"{m[1]}{_UNIT[m[2].lower()]}/X{step}"
                raise self.error(offset, f"unsupported step member .{member} (use .X or .T)", width=len(value))
            if value.startswith("_RE_") or value.startswith("_FE_"):
                return ("↑" if value.startswith("_RE_") else "↓") + value[4:]
            return value
        raise self.error(offset, f"expected a variable, a step flag or '(' in an ST condition, not '{value or 'end'}'",
                         width=max(1, len(value)))

    def whole(self) -> str:
        out = self.expr()
        kind, value, offset = self.peek()
        if kind != "end":
            raise self.error(offset, f"unexpected '{value}' in an ST condition", width=len(value))
        return out


@dataclass
class _ImportedStep:
    name: str
    initial: bool
    actions: list[str]
    grafcet: str | None
    el: object


def import_sfc(data: bytes | str, file: str = "<xml>") -> str:
    """The ``.g7`` text of the (first) SFC POU of a PLCopen XML file.

    Layout (positions), comments, documentation and vendor ``addData`` are ignored;
    ``jumpStep`` is a link to its target step. Elements ``.g7`` cannot represent (macro-steps,
    FBD/LD objects, qualifiers other than N/S/R/P0/P1, conditions given as connections) are
    an :class:`~synth.errors.InputError` at their line.
    """
    from lxml import etree

    raw = data if isinstance(data, bytes) else data.encode("utf-8")
    text = raw.decode("utf-8", errors="replace")
    src = _Source(file, text)
    try:
        root = etree.fromstring(raw, etree.XMLParser(remove_blank_text=False, resolve_entities=False))
    except etree.XMLSyntaxError as err:
        line, col = err.position if hasattr(err, "position") else (err.lineno, 1)
        raw_line = src.lines[line - 1] if 0 < line <= len(src.lines) else ""
        message = re.sub(r", line \d+, column \d+$", "", str(err.msg))
        raise InputError(f"not well-formed XML: {message}", Location(file, line, max(1, col), raw_line)) from None
    if etree.QName(root).namespace != NS or etree.QName(root).localname != "project":
        raise InputError(f"not a PLCopen TC6 XML v2.01 project (root element {root.tag})", src.at(root),
                         notes=(f"expected <project xmlns=\"{NS}\">",))
    q = lambda tag: f"{{{NS}}}{tag}"  # noqa: E731
    sfc = None
    pou = None
    names = []
    for p in root.iter(q("pou")):
        names.append(p.get("name", ""))
        found = p.find(f"{q('body')}/{q('SFC')}")
        if found is not None:
            pou, sfc = p, found
            break
    if sfc is None:
        raise InputError("no POU with an SFC body in this file", src.at(root),
                         notes=(("POUs: " + ", ".join(names)) if names else "the file has no POU",))
    assert pou is not None
    inputs = [v.get("name") for v in pou.iterfind(f"{q('interface')}/{q('inputVars')}/{q('variable')}")]
    outputs = [v.get("name") for v in pou.iterfind(f"{q('interface')}/{q('outputVars')}/{q('variable')}")]
    named_conditions = {}
    for t in pou.iterfind(f"{q('transitions')}/{q('transition')}"):
        body = t.find(q("body"))
        st = body.find(q("ST")) if body is not None else None
        if st is None:
            raise InputError("a named transition whose body is not ST", src.at(t))
        named_conditions[t.get("name")] = (st, _st_text(st))

    elements: dict[int, object] = {}
    for el in sfc:
        if not isinstance(el.tag, str):
            continue  # an XML comment or processing instruction
        local = etree.QName(el).localname
        if local in ("addData", "documentation"):
            continue
        if local not in _SUPPORTED:
            what = _WHAT.get(local, "an element")
            raise InputError(f"unsupported SFC element <{local}> ({what}): .g7 cannot represent it", src.at(el),
                             expected=tuple(f"<{s}>" for s in sorted(_SUPPORTED)))
        if local == "comment":
            continue
        lid = el.get("localId")
        if lid is None or not lid.isdigit():
            raise InputError(f"<{local}> without a numeric localId", src.at(el))
        elements[int(lid)] = el

    def kind(el) -> str:
        return etree.QName(el).localname

    def producers(el) -> list[tuple[int, object]]:
        out = []
        for cp in el.iterfind(q("connectionPointIn")):
            if cp.find(q("expression")) is not None:
                raise InputError("a connection given as an expression cannot be read", src.at(cp))
            for c in cp.iterfind(q("connection")):
                ref = int(c.get("refLocalId", "-1"))
                if ref not in elements:
                    raise InputError(f"connection to unknown localId {c.get('refLocalId')}", src.at(c))
                out.append((ref, c))
        return out

    consumers: dict[int, list[int]] = {}
    for lid, el in elements.items():
        if kind(el) == "actionBlock":
            continue
        for ref, _ in producers(el):
            consumers.setdefault(ref, []).append(lid)

    # steps
    steps: dict[int, _ImportedStep] = {}
    sfc_names: dict[str, str] = {}  # SFC step name -> .g7 step name
    for lid, el in elements.items():
        if kind(el) != "step":
            continue
        sname = el.get("name", "")
        g7 = sname[1:] if re.fullmatch(r"S\d+", sname) else sname
        if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*|\d+", g7):
            raise InputError(f"step name '{sname}' is not a .g7 step name (letters, digits, _)", src.at(el))
        if g7 in sfc_names.values():
            raise InputError(f"duplicate step '{sname}'", src.at(el))
        sfc_names[sname] = g7
        gdata = el.find(f"{q('addData')}/{q('data')}[@name='{SYNTH_DATA}']/{q('grafcet')}")
        steps[lid] = _ImportedStep(g7, el.get("initialStep", "false") in ("true", "1"), [],
                                   gdata.get("name") if gdata is not None else None, el)
    by_sfc_name = {sfc: g7 for sfc, g7 in sfc_names.items()}

    def back(lid: int, seen: frozenset[int] = frozenset()) -> list[str]:
        """Source steps upstream of a transition's input."""
        el = elements[lid]
        k = kind(el)
        if lid in seen:
            raise InputError("a cycle of divergences/convergences without a step", src.at(el))
        if k == "step":
            return [steps[lid].name]
        if k in ("selectionDivergence", "simultaneousConvergence"):
            out: list[str] = []
            for ref, _ in producers(el):
                out += [s for s in back(ref, seen | {lid}) if s not in out]
            return out
        raise InputError(f"a transition cannot follow <{k}>", src.at(el))

    def fwd(lid: int, seen: frozenset[int] = frozenset()) -> list[str]:
        """Target steps downstream of a transition's output."""
        out: list[str] = []
        for c in consumers.get(lid, []):
            el = elements[c]
            k = kind(el)
            if c in seen:
                raise InputError("a cycle of divergences/convergences without a step", src.at(el))
            if k == "step":
                found = [steps[c].name]
            elif k == "jumpStep":
                target = el.get("targetName", "")
                if target not in by_sfc_name:
                    raise InputError(f"jump to unknown step '{target}'", src.at(el),
                                     suggestions=close_names(target, by_sfc_name))
                found = [by_sfc_name[target]]
            elif k in ("selectionConvergence", "simultaneousDivergence"):
                found = fwd(c, seen | {lid})
            elif k == "transition":
                raise InputError("two transitions in a row (a step is missing between them)", src.at(el))
            else:
                raise InputError(f"a transition cannot lead to <{k}>", src.at(el))
            out += [s for s in found if s not in out]
        return out

    # transitions
    transitions: list[tuple[str, list[str], list[str], str, object]] = []
    for lid, el in elements.items():
        if kind(el) != "transition":
            continue
        sources: list[str] = []
        for ref, _ in producers(el):
            sources += [s for s in back(ref) if s not in sources]
        targets = fwd(lid)
        cond = el.find(q("condition"))
        if cond is None:
            raise InputError("a transition without a condition", src.at(el))
        negate = cond.get("negated", "false") in ("true", "1")
        inline, ref, label = cond.find(q("inline")), cond.find(q("reference")), ""
        if inline is not None:
            st = inline.find(q("ST"))
            if st is None:
                raise InputError("a condition in a language other than ST", src.at(inline))
            label = inline.get("name", "")
            holder, ctext = st, _st_text(st)
        elif ref is not None:
            label = ""
            if ref.get("name") not in named_conditions:
                raise InputError(f"condition '{ref.get('name')}' is not defined in the POU's <transitions>",
                                 src.at(ref), suggestions=close_names(ref.get("name", ""), named_conditions))
            holder, ctext = named_conditions[ref.get("name")]
            m = re.fullmatch(r"\s*\w+\s*:=\s*(.*?);?\s*", ctext, re.S)
            if m:
                ctext = m[1]
        else:
            raise InputError("a condition given as a connection (FBD/LD) cannot be read; use inline ST",
                             src.at(cond))
        reader = _ExprReader(ctext, lambda off, w, h=holder, t=ctext: src.text_at(h, t, off, w), by_sfc_name)
        expr = reader.whole()
        if negate:
            expr = f"!({expr})"
        transitions.append((label, sources, targets, expr, el))

    # actions
    for lid, el in elements.items():
        if kind(el) != "actionBlock":
            continue
        owners = [ref for ref, _ in producers(el) if ref in steps]
        if len(owners) != 1:
            raise InputError("an action block must be connected to exactly one step", src.at(el))
        owner = steps[owners[0]]
        for a in el.iterfind(q("action")):
            owner.actions.append(_read_action(a, src, by_sfc_name, q))

    # partial grafcets: synth's addData, else the connected components
    parent: dict[str, str] = {s.name: s.name for s in steps.values()}

    def find(x: str) -> str:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for _, sources, targets, _, _ in transitions:
        linked = sources + targets
        for a in linked[1:]:
            parent[find(a)] = find(linked[0])
    order = [s for s in sorted(steps.values(), key=lambda s: int(s.el.sourceline or 0))]  # type: ignore[attr-defined]
    groups: dict[str, str] = {}
    for s in order:
        if s.grafcet:
            groups.setdefault(find(s.name), s.grafcet)
    for s in order:
        if find(s.name) not in groups:
            groups[find(s.name)] = f"G{len(set(groups.values())) + 1}"
    lines = [f"# Imported by synth {synth_version()} from {file} (POU {pou.get('name')}): PLCopen SFC.", ""]
    if inputs:
        lines.insert(1, "inputs " + ", ".join(inputs))
    if outputs:
        lines.insert(1 + bool(inputs), "outputs " + ", ".join(outputs))
    for gname in dict.fromkeys(groups[find(s.name)] for s in order):
        members = [s for s in order if groups[find(s.name)] == gname]
        lines.append(f"grafcet {gname} {{")
        for s in members:
            head = ("initial " if s.initial else "") + f"step {s.name}"
            lines.append("  " + head + (": " + ", ".join(s.actions) if s.actions else ""))
        names_in = {s.name for s in members}
        for label, sources, targets, expr, _ in transitions:
            if set(sources + targets) & names_in:
                lab = f"{label}: " if label and re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*|\d+", label) else ""
                lines.append(f"  transition {lab}{', '.join(sources)} -> {', '.join(targets)} when {expr}")
        lines.append("}")
    return "\n".join(lines) + "\n"


def _read_action(a, src: _Source, steps: dict[str, str], q) -> str:
    qualifier = a.get("qualifier", "N")
    ref, inline = a.find(q("reference")), a.find(q("inline"))
    if qualifier not in set(Qualifier):
        raise InputError(f"action qualifier {qualifier} cannot be represented in .g7", src.at(a),
                         expected=tuple(Qualifier))
    if ref is not None:
        name = ref.get("name", "")
        if qualifier == Qualifier.N:
            return name
        if qualifier == Qualifier.S:
            return f"set {name}"
        if qualifier == Qualifier.R:
            return f"reset {name}"
        raise InputError(f"qualifier {qualifier} with a reference: use an inline body '{name} := TRUE;'", src.at(a))
    if inline is None or inline.find(q("ST")) is None:
        raise InputError("an action without a reference or an inline ST body", src.at(a))
    st = inline.find(q("ST"))
    body = _st_text(st).strip()
    where = lambda off, w, h=st, t=_st_text(st): src.text_at(h, t, off, w)  # noqa: E731
    m = re.fullmatch(r"(\w+)\s*:=\s*(TRUE|FALSE)\s*;?", body, re.I)
    if qualifier in (Qualifier.P0, Qualifier.P1):
        if not m:
            raise InputError(f"a {qualifier} action body must be 'NAME := TRUE;' or 'NAME := FALSE;'", where(0, 1))
        verb = "set" if m[2].upper() == "TRUE" else "reset"
        return f"{verb} {m[1]} on {'deactivation' if qualifier == Qualifier.P0 else 'activation'}"
    if qualifier == Qualifier.N:
        ev = re.fullmatch(r"IF\s+(.*?)\s+THEN\s+(\w+)\s*:=\s*(TRUE|FALSE)\s*;\s*END_IF\s*;?", body, re.I | re.S)
        if ev:
            raw = _st_text(st)
            off = raw.find(ev[1])
            cond = _ExprReader(ev[1], lambda o, w: where(off + o, w), steps).whole()
            verb = "set" if ev[3].upper() == "TRUE" else "reset"
            return f"{verb} {ev[2]} on {cond}"
        cm = re.fullmatch(r"(\w+)\s*:=\s*(.*?)\s*;?", body, re.S)
        if cm:
            raw = _st_text(st)
            off = raw.find(cm[2])
            cond = _ExprReader(cm[2], lambda o, w: where(off + o, w), steps).whole()
            return f"{cm[1]} if {cond}"
    raise InputError(f"a {qualifier} action body that .g7 cannot represent (expected 'NAME := condition;')",
                     where(0, 1))

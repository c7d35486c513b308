"""PLCopen TC6 XML (v2.01) in: an SFC back into ``.g7`` text (``synth import``).

:func:`import_sfc` reads an SFC as synth or a PLC IDE writes it (layout positions,
comments, vendor ``addData``, ``jumpStep``); what ``.g7`` cannot represent is an
:class:`~synth.errors.InputError` at its line in the XML. The mapping is the exporter's
(:mod:`synth.codegen.plcopen_export`).

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> from synth.codegen.plcopen_export import sfc_project_xml
>>> g = parse_grafcet("grafcet G { initial step 0 step 1: A if b "
...                   "transition 0 -> 1 when ↑a transition 1 -> 0 when !a }", "g.g7")
>>> print(import_sfc(sfc_project_xml(g, version="0.1.0"), "g.xml").split("\\n", 1)[1])
inputs a, b
outputs A_1
<BLANKLINE>
grafcet G {
  initial step 0
  step 1: A_1 if b
  transition 0 -> 1 when ↑a
  transition 1 -> 0 when !a
}
<BLANKLINE>
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from synth.codegen.plcopen_xml import NS, SYNTH_DATA, Qualifier
from synth.codegen.st_condition import ExprReader, st_text
from synth.errors import InputError, Location, close_names
from synth.version import version as synth_version

__all__ = ["import_sfc"]


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
        named_conditions[t.get("name")] = (st, st_text(st))

    elements: dict[int, Any] = {}  # localId -> lxml element
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
        if lid is None or not re.fullmatch(r"[0-9]+", lid):
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
                text = c.get("refLocalId", "")
                if not re.fullmatch(r"\s*-?[0-9]+\s*", text):
                    raise InputError(f"a connection's refLocalId must be a number, not '{text[:40]}'", src.at(c))
                ref = int(text)
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
            holder, ctext = st, st_text(st)
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
        reader = ExprReader(ctext, lambda off, w, h=holder, t=ctext: src.text_at(h, t, off, w), by_sfc_name)
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
            actions = _paired(s.actions)
            lines.append("  " + head + (": " + ", ".join(actions) if actions else ""))
        names_in = {s.name for s in members}
        for label, sources, targets, expr, _ in transitions:
            if set(sources + targets) & names_in:
                lab = f"{label}: " if label and re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*|\d+", label) else ""
                lines.append(f"  transition {lab}{', '.join(sources)} -> {', '.join(targets)} when {expr}")
        lines.append("}")
    return "\n".join(lines) + "\n"


def _paired(actions: list[str]) -> list[str]:
    """``A if c`` is exported as an ``N`` body and a ``P0`` body ``A := FALSE;`` (its IEC
    meaning: reset when the step is left); read back, the pair is ``A if c`` alone."""
    conditional = {a.split(" if ", 1)[0] for a in actions if " if " in a}
    return [a for a in actions if not (a.startswith("reset ") and a.endswith(" on deactivation")
                                       and a[len("reset "):-len(" on deactivation")] in conditional)]


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
    body = st_text(st).strip()
    where = lambda off, w, h=st, t=st_text(st): src.text_at(h, t, off, w)  # noqa: E731
    m = re.fullmatch(r"(\w+)\s*:=\s*(TRUE|FALSE)\s*;?", body, re.I)
    if qualifier in (Qualifier.P0, Qualifier.P1):
        if not m:
            raise InputError(f"a {qualifier} action body must be 'NAME := TRUE;' or 'NAME := FALSE;'", where(0, 1))
        verb = "set" if m[2].upper() == "TRUE" else "reset"
        return f"{verb} {m[1]} on {'deactivation' if qualifier == Qualifier.P0 else 'activation'}"
    if qualifier == Qualifier.N:
        ev = re.fullmatch(r"IF\s+(.*?)\s+THEN\s+(\w+)\s*:=\s*(TRUE|FALSE)\s*;\s*END_IF\s*;?", body, re.I | re.S)
        if ev:
            raw = st_text(st)
            off = raw.find(ev[1])
            cond = ExprReader(ev[1], lambda o, w: where(off + o, w), steps).whole()
            verb = "set" if ev[3].upper() == "TRUE" else "reset"
            return f"{verb} {ev[2]} on {cond}"
        cm = re.fullmatch(r"(\w+)\s*:=\s*(.*?)\s*;?", body, re.S)
        if cm:
            raw = st_text(st)
            off = raw.find(cm[2])
            cond = ExprReader(cm[2], lambda o, w: where(off + o, w), steps).whole()
            return f"{cm[1]} if {cond}"
    raise InputError(f"a {qualifier} action body that .g7 cannot represent (expected 'NAME := condition;')",
                     where(0, 1))

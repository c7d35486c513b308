"""A PLCopen TC6 XML project as ``synth import`` opens it: the namespaces read, the root with
located errors, and the list of POUs with what the import does with each (``import --list``).

Example
-------
>>> xml = '<project xmlns="http://www.plcopen.org/xml/tc6_0201"><types><pous><pou name="P" pouType="program">' \\
...       '<body><ST/></body></pou></pous></types></project>'
>>> [s.text() for s in list_pous(xml)]
['P\\tprogram\\tST\\tnot imported: an ST body: .g7 holds SFC charts only']
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from synth.codegen.plcopen.sfc import Source
from synth.errors import InputError, Location

__all__ = ["NAMESPACES", "PouSummary", "body_language", "list_pous", "pous_of", "read_project", "summaries"]

NAMESPACES = {
    "http://www.plcopen.org/xml/tc6_0201": "TC6 2.01",
    "http://www.plcopen.org/xml/tc6_0200": "TC6 2.00",
    "http://www.plcopen.org/xml/tc6.xsd": "TC6 1.0",
}
"""The PLCopen namespaces read, with the version they name."""

_LANGUAGES = ("SFC", "ST", "IL", "FBD", "LD")


@dataclass(frozen=True)
class PouSummary:
    """What ``synth import --list`` prints for one POU."""

    name: str
    kind: str  # program, functionBlock, function
    language: str
    imported: bool
    note: str

    def text(self) -> str:
        return f"{self.name}\t{self.kind}\t{self.language}\t{'imported' if self.imported else 'not imported'}" + \
            (f": {self.note}" if self.note else "")


def read_project(data: bytes | str, file: str) -> tuple[Any, Source, Any]:
    """The root element, the located source and the namespace function ``q``."""
    from lxml import etree

    raw = data if isinstance(data, bytes) else data.encode("utf-8")
    src = Source(file, raw.decode("utf-8", errors="replace"))
    try:
        root = etree.fromstring(raw, etree.XMLParser(remove_blank_text=False, resolve_entities=False))
    except etree.XMLSyntaxError as err:
        line, col = err.position if hasattr(err, "position") else (err.lineno, 1)
        raw_line = src.lines[line - 1] if 0 < line <= len(src.lines) else ""
        message = re.sub(r", line \d+, column \d+$", "", str(err.msg))
        from synth.syntax import file_kind_hint

        hint = file_kind_hint("xml", file, "\n".join(src.lines[:200]))
        raise InputError(f"not well-formed XML: {message}", Location(file, line, max(1, col), raw_line),
                         notes=(hint,) if hint else ()) from None
    ns = etree.QName(root).namespace
    if ns not in NAMESPACES or etree.QName(root).localname != "project":
        raise InputError(f"not a PLCopen TC6 XML project (root element {root.tag})", src.at(root),
                         expected=tuple(f'<project xmlns="{n}">' for n in NAMESPACES))
    _check_numbers(root, src)
    return root, src, lambda tag: f"{{{ns}}}{tag}"


_IDS = ("localId", "refLocalId", "executionOrderId")
_COORDINATES = ("x", "y", "width", "height")


def _check_numbers(root: Any, src: Source) -> None:
    """Identifiers of at most 18 digits and finite coordinates, before anything reads them
    as numbers (a 4 300-digit ``localId`` is past what Python converts; ``x="1e400"`` is
    infinite): a located error at the element otherwise."""
    for el in root.iter():
        if not isinstance(el.tag, str):  # comments, processing instructions
            continue
        for name in _IDS:
            value = el.get(name)
            if value is not None and value.strip().isdigit() and len(value.strip()) > 18:
                raise InputError(f"{name} of {len(value.strip())} digits: synth reads identifiers of at most 18",
                                 src.at(el))
        for name in _COORDINATES:
            value = el.get(name)
            if value is None or len(value) <= 24:
                try:
                    if value is None or abs(float(value)) < 1e15:
                        continue
                except ValueError:
                    continue  # not a number: left to the reader of that attribute
            raise InputError(f"{name}=\"{value[:24]}{'…' if len(value) > 24 else ''}\" is not a coordinate "
                             f"(a finite number below 10^15)", src.at(el))


def body_language(pou: Any, q: Any) -> str:
    body = pou.find(q("body"))
    if body is None:
        return "none"
    for lang in _LANGUAGES:
        if body.find(q(lang)) is not None:
            return lang
    return "other"


def pous_of(root: Any, q: Any) -> list[Any]:
    # CODESYS exports with a device put POUs in the resource's addData as well as in types/pous
    return list(root.iter(q("pou")))


def list_pous(data: bytes | str, file: str = "<xml>") -> list[PouSummary]:
    """Every POU of the project: its kind, body language and whether ``import`` reads it."""
    root, _, q = read_project(data, file)
    return summaries(root, q)


def summaries(root: Any, q: Any) -> list[PouSummary]:
    """:func:`list_pous` of a project already read (``root``, namespace function ``q``)."""
    out = []
    for pou in pous_of(root, q):
        lang = body_language(pou, q)
        note = "" if lang == "SFC" else f"an {lang} body: .g7 holds SFC charts only"
        if pou.find(q("actions")) is not None and lang == "SFC":
            note = "POU actions are read where an action block references them"
        charts = [str(a.get("name", "")) for a in pou.findall(f"{q('actions')}/{q('action')}")
                  if a.find(f"{q('body')}/{q('SFC')}") is not None]
        if charts:
            note += ("; " if note else "") + (f"SFC in its action{'s' if len(charts) > 1 else ''} {', '.join(charts)}: "
                                              "not imported (.g7 reads the SFC body of a POU, not a chart inside "
                                              "an action of a function block)")
        out.append(PouSummary(str(pou.get("name", "")), str(pou.get("pouType", "")), lang, lang == "SFC", note))
    return out

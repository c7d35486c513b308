"""PLCopen TC6 XML v2.01, the common ground of the exporter and the importer: the
namespace, element builders, the project frame, variable
types and interfaces, the SFC name of a step.

Nothing written depends on the time of day: ``creationDateTime`` is a fixed date.

Example
-------
>>> from synth.codegen.st import Declaration, SectionKind, VarSection
>>> iface = interface((VarSection(SectionKind.INPUT, (Declaration("a", comment="start"),)),))
>>> [c.tag.split("}")[1] for c in iface], sfc_step_name("12")
(['inputVars'], 'S12')
"""

from __future__ import annotations

import re
from enum import StrEnum
from typing import Any, Sequence

from synth.codegen.st import SectionKind, VarSection

__all__ = ["NS", "XHTML", "CREATION_DATE", "SYNTH_DATA", "Qualifier", "element",
           "xhtml", "position", "project", "plc_type", "interface", "sfc_step_name"]

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


def element(tag: str, attrib: dict[str, str] | None = None, *children: Any) -> Any:
    """A TC6 element with its attributes and children (``None`` children are skipped)."""
    from lxml import etree

    el = etree.Element(f"{{{NS}}}{tag}", {k: v for k, v in (attrib or {}).items()})
    for c in children:
        if c is not None:
            el.append(c)
    return el


def xhtml(text: str, cdata: bool = True):
    from lxml import etree

    p = etree.Element(f"{{{XHTML}}}p", nsmap={"xhtml": XHTML})
    p.text = etree.CDATA(text) if cdata else text
    return p


def position(x: int, y: int, tag: str = "position"):
    return element(tag, {"x": str(x), "y": str(y)})


def project(name: str, version: str, comment: str, pous: list, configurations: Sequence[Any] = (),
            data: Sequence[Any] = ()) -> bytes:
    from lxml import etree

    root = etree.Element(f"{{{NS}}}project", nsmap={None: NS, "xhtml": XHTML})
    root.append(element("fileHeader", {"companyName": "synth", "productName": "synth", "productVersion": version,
                                  "creationDateTime": CREATION_DATE}))
    coord = element("coordinateInfo", None, *[element(k, None, element("scaling", {"x": "1", "y": "1"})) for k in ("fbd", "ld", "sfc")])
    header = element("contentHeader", {"name": name})
    c = element("Comment")
    c.text = comment
    header.append(c)
    header.append(coord)
    root.append(header)
    root.append(element("types", None, element("dataTypes"), element("pous", None, *pous)))
    root.append(element("instances", None, element("configurations", None, *configurations)))
    if data:
        root.append(element("addData", None, *data))
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)


_ELEMENTARY = {"BOOL", "BYTE", "WORD", "DWORD", "LWORD", "SINT", "INT", "DINT", "LINT", "USINT", "UINT",
               "UDINT", "ULINT", "REAL", "LREAL", "TIME", "DATE", "DT", "TOD"}


def plc_type(text: str):
    text = text.strip()
    m = re.fullmatch(r"ARRAY\s*\[\s*(-?\d+)\s*\.\.\s*(-?\d+)\s*\]\s*OF\s+(\w+)", text, re.I)
    if m:
        return element("array", None, element("dimension", {"lower": m[1], "upper": m[2]}), element("baseType", None, plc_type(m[3])))
    if text.upper() in _ELEMENTARY:
        return element(text.upper())
    return element("derived", {"name": text})



_SECTION_TAG = {SectionKind.INPUT: "inputVars", SectionKind.OUTPUT: "outputVars", SectionKind.IN_OUT: "inOutVars",
                SectionKind.LOCAL: "localVars", SectionKind.CONSTANT: "localVars", SectionKind.TEMP: "tempVars"}


def interface(sections: Sequence[VarSection]) -> Any:
    """The ``<interface>`` of a POU's variable sections (a constant section is flagged)."""
    iface = element("interface")
    for section in sections:
        vl = element(_SECTION_TAG[section.kind], {"constant": "true"} if section.kind is SectionKind.CONSTANT else None)
        for d in section.declarations:
            attrs = {"name": d.name} if d.location is None else {"name": d.name, "address": d.location}
            var = element("variable", attrs, element("type", None, plc_type(d.type)))
            if d.init is not None:
                var.append(element("initialValue", None, element("simpleValue", {"value": d.init})))
            if d.comment:
                var.append(element("documentation", None, xhtml(d.comment, cdata=False)))
            vl.append(var)
        iface.append(vl)
    return iface


def sfc_step_name(step: str) -> str:
    """The SFC name of a ``.g7`` step: ``S12`` for a number (IEC names start with a letter).

    >>> sfc_step_name("12"), sfc_step_name("wait")
    ('S12', 'wait')
    """
    return f"S{step}" if step.isdigit() else step

"""The formats ``synth st`` and ``synth filter st`` write (``--target``), chosen above the
writers, and the way back from each to one Structured Text for ``st --check``.

================  =====================================================================
``iec``           IEC 61131-3 Structured Text, one file (the default)
``plcopen``       PLCopen TC6 XML 2.01, one project (``--xml`` is its short form)
``codesys``       the same project with the ``addData`` CODESYS V3.5 reads: each POU's
                  ``ObjectId`` and the ``ProjectStructure`` that lists them
``twincat``       one TwinCAT 3 ``.TcPOU`` file per POU (:mod:`synth.codegen.twincat`)
================  =====================================================================

:func:`render` returns the files as (name, bytes), nothing is written here; :func:`st_of`
reads each target's files back into one ST text — the XML targets by their ``<pou>``
elements (interface and body), TwinCAT files through blark's TwinCAT loader — so the
execution proof runs on what was written.

Example
-------
>>> from synth.codegen.st import Declaration, Pou, PouKind, SectionKind, VarSection
>>> pou = Pou(PouKind.PROGRAM, "P", (VarSection(SectionKind.INPUT, (Declaration("a", init="TRUE"),)),), ("y := a;",))
>>> files = render(Target.CODESYS, [pou], text="", name="P", header=["made by synth"], version="0.1.0")
>>> [n for n, _ in files]
['P.xml']
>>> print(st_of(Target.CODESYS, files, "P.xml"))
PROGRAM P
VAR_INPUT
    a : BOOL := TRUE;
END_VAR
y := a;
END_PROGRAM
<BLANKLINE>
"""

from __future__ import annotations

from enum import StrEnum
from typing import Any, Sequence

from synth.codegen.program import Configuration
from synth.codegen.st import Declaration, Pou, PouKind, SectionKind, VarSection, pou_lines
from synth.errors import InputError, Location

__all__ = ["Target", "render", "st_of"]


class Target(StrEnum):
    """What ``--target`` names."""

    IEC = "iec"
    PLCOPEN = "plcopen"
    CODESYS = "codesys"
    TWINCAT = "twincat"


def render(target: Target, pous: Sequence[Pou], *, text: str, name: str, header: Sequence[str],
           config: Configuration | None = None, version: str | None = None) -> list[tuple[str, bytes]]:
    """The files of ``target``: (file name, bytes). ``text`` is the ST file (``iec``), ``pous``
    the same code as data (the other targets), ``header`` the provenance lines."""
    if target is Target.IEC:
        if config is not None:
            text += "\n" + "\n".join(config.lines()) + "\n"
        return [(f"{name}.st", text.encode("utf-8"))]
    if target is Target.TWINCAT:
        from synth.codegen.twincat import tcpou

        if config is not None:
            raise InputError("--task writes a CONFIGURATION: a TwinCAT task is set in the PLC project (its .TcTTO), "
                             "not in a POU file", Location("--task", 1, 1, "", 1),
                             notes=("drop --task, or write --target iec, plcopen or codesys",))
        return [(f"{p.name}.TcPOU", tcpou(p, header)) for p in pous]
    from synth.codegen.plcopen.export import st_project_xml

    xml = st_project_xml(pous, name=name, version=version, comment="\n".join(header), config=config,
                         codesys=target is Target.CODESYS)
    return [(f"{name}.xml", xml)]


def st_of(target: Target, files: Sequence[tuple[str, bytes]], where: str) -> str:
    """One ST text with every POU of ``files``, read back as the target's readers read them."""
    if target is Target.IEC:
        return b"".join(data for _, data in files).decode("utf-8")
    if target is Target.TWINCAT:
        from synth.codegen.twincat import st_of_tcpou

        return "\n".join(st_of_tcpou(data, f"{where}/{n}") for n, data in files)
    return "\n".join("\n".join(pou_lines(p)) + "\n" for _, data in files for p in _pous_of_project(data, where))


_KIND = {"program": PouKind.PROGRAM, "functionBlock": PouKind.FUNCTION_BLOCK}
_SECTION = {"inputVars": SectionKind.INPUT, "outputVars": SectionKind.OUTPUT, "inOutVars": SectionKind.IN_OUT,
            "localVars": SectionKind.LOCAL, "tempVars": SectionKind.TEMP}


def _type_text(t: Any) -> str:
    from lxml import etree

    (inner,) = [c for c in t if isinstance(c.tag, str)]
    tag = etree.QName(inner).localname
    if tag == "derived":
        return str(inner.get("name"))
    if tag == "array":
        dim = inner.find("{*}dimension")
        base = inner.find("{*}baseType")
        return f"ARRAY[{dim.get('lower')}..{dim.get('upper')}] OF {_type_text(base)}"
    return tag


def _pous_of_project(data: bytes, where: str) -> list[Pou]:
    """The ST POUs of a TC6 project, as the XML holds them (interface and ``<ST>`` body)."""
    from lxml import etree

    root = etree.fromstring(data)
    out = []
    for pou in root.iterfind(".//{*}pous/{*}pou"):
        sections = []
        iface = pou.find("{*}interface")
        for vl in (iface if iface is not None else ()):
            kind = _SECTION[etree.QName(vl).localname]
            if vl.get("constant") == "true":
                kind = SectionKind.CONSTANT
            decls = []
            for v in vl.iterfind("{*}variable"):
                init = v.find("{*}initialValue/{*}simpleValue")
                decls.append(Declaration(str(v.get("name")), _type_text(v.find("{*}type")),
                                         None if init is None else str(init.get("value")), location=v.get("address")))
            sections.append(VarSection(kind, tuple(decls)))
        st = pou.find("{*}body/{*}ST")
        if st is None:
            raise InputError(f"POU {pou.get('name')} has no ST body", Location(where, pou.sourceline or 1, 1, "", 1))
        holder = next((c for c in st if isinstance(c.tag, str)), st)  # <xhtml:p> holds the text, as synth writes it
        body = (holder.text or "").rstrip("\n")
        out.append(Pou(_KIND[str(pou.get("pouType"))], str(pou.get("name")), tuple(sections),
                       tuple(body.split("\n"))))
    return out

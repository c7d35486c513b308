"""Vendor ``addData`` that carries SFC meaning (``synth import``): CODESYS V3.5 (and TwinCAT 3,
built on it) keep a step's *step actions* (entry, active, exit) not in an ``<actionBlock>``
but in the step's ``<addData><data name=".../plcopenxml/sfc/element">`` as attributes keyed
by a GUID. Ignoring them would drop the step's actions silently; they are read as
references to POU actions with the IEC 61131-3 qualifier that runs them the same way:
entry ``P1``, active ``N``, exit ``P0``. Every other ``addData`` is layout or bookkeeping.

Example
-------
>>> [k.name for k in StepAction]
['ENTRY', 'ACTIVE', 'EXIT']
>>> StepAction.EXIT.qualifier
<IecQualifier.P0: 'P0'>
"""

from __future__ import annotations

from enum import Enum, StrEnum
from typing import Any, Callable

from synth.errors import InputError, Location, Severity

__all__ = ["IecQualifier", "StepAction", "SFC_ELEMENT_DATA", "step_actions", "CHART_FLAGS", "chart_flag_warnings",
           "Dialect", "dialect_of"]


class IecQualifier(StrEnum):
    """Every IEC 61131-3 action qualifier an imported action block may carry."""

    N = "N"
    S = "S"
    R = "R"
    P = "P"
    P1 = "P1"
    P0 = "P0"
    D = "D"
    L = "L"
    SD = "SD"
    DS = "DS"
    SL = "SL"

class Dialect(Enum):
    """The tool that wrote a PLCopen file, as far as the meaning of its SFC bodies differs: when
    the blocks wired in a transition network are called (docs/codegen.md)."""

    BEREMIZ = "Beremiz or the OpenPLC editor"  # called at every scan, after the transitions
    CODESYS = "CODESYS or TwinCAT"  # called while the transition is evaluated
    OTHER = "another tool"  # read as CODESYS does


_BEREMIZ_DEFAULTS = ("Unknown", "Unnamed")
"""The ``fileHeader`` companyName and productName of a new project in Beremiz and in the OpenPLC
editor (its fork)."""


def dialect_of(root: Any, q: Callable[[str], str]) -> tuple[Dialect, str]:
    """The tool that wrote the project ``root`` and the ``fileHeader`` words that say so."""
    header = root.find(q("fileHeader"))
    company = str(header.get("companyName", "")) if header is not None else ""
    product = str(header.get("productName", "")) if header is not None else ""
    said = f'fileHeader companyName="{company}" productName="{product}"'
    words = f"{company} {product}".lower()
    if any(w in words for w in ("codesys", "twincat", "beckhoff", "3s-smart")) or \
            any(str(d.get("name", "")).startswith("http://www.3s-software.com") for d in root.iter(q("data"))):
        return Dialect.CODESYS, said
    if "beremiz" in words or "openplc" in words or (company, product) == _BEREMIZ_DEFAULTS:
        return Dialect.BEREMIZ, said
    return Dialect.OTHER, said


SFC_ELEMENT_DATA = "/plcopenxml/sfc/element"
"""How the name of a CODESYS (``http://www.3s-software.com``) or TwinCAT SFC element's
``<data>`` ends."""


class StepAction(Enum):
    """A CODESYS step action: its attribute GUID and the qualifier that runs it alike."""

    ENTRY = ("a6b08bd8-b696-47e3-9cbf-7408b61c9ff8", IecQualifier.P1)
    ACTIVE = ("700a583f-b4d4-43e4-8c14-629c7cd3bec8", IecQualifier.N)
    EXIT = ("a2621e18-7de3-4ea6-ae6d-89e9e0b7befd", IecQualifier.P0)

    @property
    def guid(self) -> str:
        return self.value[0]

    @property
    def qualifier(self) -> IecQualifier:
        return self.value[1]


def step_actions(step: Any, q: Callable[[str], str]) -> list[tuple[StepAction, str, Any]]:
    """The step actions of a CODESYS/TwinCAT ``<step>``: (kind, action name, the
    ``<attribute>`` element that names it), entry first, in :class:`StepAction` order."""
    found: dict[StepAction, tuple[str, Any]] = {}
    by_guid = {k.guid: k for k in StepAction}
    for data in step.iterfind(f"{q('addData')}/{q('data')}"):
        if not str(data.get("name", "")).endswith(SFC_ELEMENT_DATA):
            continue
        for attr in data.iter():
            if not isinstance(attr.tag, str) or not attr.tag.endswith("attribute"):
                continue
            kind = by_guid.get(str(attr.get("guid", "")).lower())
            name = (attr.text or "").strip()
            if kind is not None and name:
                found[kind] = (name, attr)
    return [(k, *found[k]) for k in StepAction if k in found]


CHART_FLAGS = {
    "SFCINIT": "puts the chart back to its initial step and holds it there while it is TRUE",
    "SFCRESET": "puts the chart back to its initial step while it is TRUE",
    "SFCPAUSE": "freezes the chart while it is TRUE",
}
"""CODESYS's implicit SFC flags that change what the chart does (declared by the user in the
POU, set by the calling program, typically on an emergency stop). The others (``SFCError``,
``SFCCurrentStep``, ...) only report."""


def chart_flag_warnings(pou: Any, q: Callable[[str], str], at: Callable[[Any], Location]) -> list[InputError]:
    """A located warning for each CODESYS implicit flag the POU declares: ``.g7`` has no forcing
    of a chart from outside, so the import cannot keep what the flag does on the PLC."""
    out = []
    for v in pou.iterfind(f"{q('interface')}/*/{q('variable')}"):
        name = str(v.get("name"))
        if name.upper() in CHART_FLAGS:
            out.append(InputError(
                f"'{name}' is CODESYS's implicit SFC flag: on the PLC it {CHART_FLAGS[name.upper()]}; the .g7 has no "
                "such forcing, so the import reads it as a plain variable and the chart ignores it",
                at(v), severity=Severity.WARNING,
                notes=("validate the emergency stop separately, or model it as transitions back to the initial "
                       "steps guarded by the flag",)))
    return out

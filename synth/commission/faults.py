"""Faults a worn machine shows, played by the plant between the automaton and the wire
(``synth commission --fault``): a stuck sensor (``v11=0``), a lost order (``AVANCER2``), a late
sensor edge (``↑v21+500ms``).

Example
-------
>>> [f.text for f in parse_faults(["v11=0", "AVANCER2", "^v21+500ms"], ["v11", "v21"], ["AVANCER2"])]
['v11=0', 'AVANCER2', '↑v21+500ms']
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import StrEnum
from fractions import Fraction
from typing import Mapping, Sequence

from synth.errors import InputError, Location, close_names
from synth.logic.events import FALL_MARKS, RISE_MARKS

__all__ = ["FaultKind", "Fault", "parse_faults", "wire_values"]

_LATE = re.compile(r"(.)([A-Za-z_][A-Za-z0-9_]*)\+(\d+(?:\.\d+)?)(ms|s)\Z")


class FaultKind(StrEnum):
    STUCK = "stuck sensor"
    LOST = "lost order"
    LATE = "late sensor"


@dataclass(frozen=True)
class Fault:
    """One fault: its kind, the sensor or order, the stuck value or the edge and its delay."""

    kind: FaultKind
    name: str
    value: bool = False  # stuck: the value; late: the edge (True: rising)
    delay_ms: int = 0
    loc: Location | None = None

    @property
    def text(self) -> str:
        if self.kind is FaultKind.STUCK:
            return f"{self.name}={int(self.value)}"
        if self.kind is FaultKind.LOST:
            return self.name
        return f"{'↑' if self.value else '↓'}{self.name}+{self.delay_ms}ms"


def parse_faults(texts: Sequence[str], sensors: Sequence[str], orders: Sequence[str]) -> tuple[Fault, ...]:
    """``--fault`` options → faults; a name that is no sensor (or order) is a located error."""
    out: list[Fault] = []
    for text in texts:
        item = text.strip()
        loc = Location("--fault", 1, 1, text, max(1, len(text)))

        def known(name: str, pool: Sequence[str], what: str) -> None:
            if name not in pool:
                raise InputError(f"unknown {what} '{name}'", loc, suggestions=close_names(name, pool),
                                 notes=("faults: a stuck sensor v11=0, a lost order AVANCER2, a late sensor ↑v21+500ms",))

        late = _LATE.match(item)
        if late and late[1] in RISE_MARKS + FALL_MARKS:
            known(late[2], sensors, "sensor")
            ms = Fraction(late[3]) * (1000 if late[4] == "s" else 1)
            out.append(Fault(FaultKind.LATE, late[2], late[1] in RISE_MARKS, int(ms), loc))
        elif "=" in item:
            name, _, value = (x.strip() for x in item.partition("="))
            known(name, sensors, "sensor")
            if value not in ("0", "1"):
                raise InputError(f"a stuck sensor is 0 or 1, not '{value}'", loc)
            out.append(Fault(FaultKind.STUCK, name, value == "1", 0, loc))
        else:
            known(item, orders, "order")
            out.append(Fault(FaultKind.LOST, item, False, 0, loc))
    return tuple(out)


def wire_values(values: Mapping[str, bool], faults: Sequence[Fault]) -> dict[str, bool]:
    """What the PLC reads: the plant's values with every stuck sensor forced."""
    out = dict(values)
    for f in faults:
        if f.kind is FaultKind.STUCK:
            out[f.name] = f.value
    return out

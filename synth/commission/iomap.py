"""I/O maps: where each plant sensor and order lives in a PLC's process image, and how a
Modbus peer reaches it (``synth st --io``, ``synth commission --io``).

A map names every located variable of the generated program (``AT %IX0.0``) and, for the
closed loop, the two handshake registers (``@grant``, ``@done``: docs/commissioning.md).
Three layouts are built in; a user's CSV file (``name,address`` per line) is the fourth:

=================  ==========================  ==============  ============  ================
layout             sensors                     orders          handshake     Modbus
=================  ==========================  ==============  ============  ================
``plain``          ``%IX0.0`` …                ``%QX0.0`` …    none          none (real I/O)
``openplc-server`` ``%QX0.0`` … (coils)        next byte on    ``%MW0`` /    synth is the client
                                                               ``%IW0``
``openplc-device`` ``%IX100.0`` … (polled)     ``%QX100.0`` …  ``%IW100`` /  synth is the server
                                                               ``%QW100``
=================  ==========================  ==============  ============  ================

The Modbus numbering is OpenPLC v3's: as a server, ``%IX a.b`` is discrete input ``8a+b``,
``%QX a.b`` coil ``8a+b``, ``%IW n`` input register ``n``, ``%QW n`` holding register ``n`` and
``%MW n`` holding register ``1024+n``; polling a device, ``%IX100.0`` is that device's
discrete input 0, ``%QX100.0`` its coil 0, ``%IW100`` its input register 0, ``%QW100`` its
holding register 0.

Example
-------
>>> m = layout_map(Layout.OPENPLC_SERVER, ["dcy", "v10"], ["TAPIS"])
>>> [(e.name, e.address.text, m.slot(e)) for e in m.entries]
[('dcy', '%QX0.0', ('coil', 0)), ('v10', '%QX0.1', ('coil', 1)), ('TAPIS', '%QX1.0', ('coil', 8)), ('@grant', '%MW0', ('holding', 1024)), ('@done', '%IW0', ('input', 0))]
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass
from enum import StrEnum
from typing import Sequence

from synth.errors import InputError, Location, close_names

__all__ = ["Area", "Address", "parse_address", "Role", "Layout", "Coupling", "Table", "IoEntry", "IoMap",
           "layout_map", "parse_map", "io_map", "GRANT", "DONE", "DEVICE_BASE"]

GRANT, DONE = "@grant", "@done"
DEVICE_BASE = 100
"""OpenPLC places what it polls from slave devices at ``%IX100.0``/``%QX100.0``/``%IW100``/``%QW100`` on."""
_ADDRESS = re.compile(r"%([IQM])([XW]?)(\d+)(?:\.(\d+))?\Z")


class Area(StrEnum):
    """The process image an address lies in."""

    INPUT = "I"
    OUTPUT = "Q"
    MEMORY = "M"


@dataclass(frozen=True)
class Address:
    """A directly represented variable: ``%IX0.3`` (a bit: byte and bit) or ``%MW0`` (a word)."""

    area: Area
    word: bool
    index: int
    bit: int = 0

    @property
    def text(self) -> str:
        return f"%{self.area}W{self.index}" if self.word else f"%{self.area}X{self.index}.{self.bit}"


def parse_address(text: str, loc: Location | None) -> Address:
    """``%IX0.3``, ``%QX100.0``, ``%MW0``, ``%IW100`` (``%I0.3`` is ``%IX0.3``); else a located error.

    >>> parse_address("%I1.2", None).text, parse_address("%MW3", None).text
    ('%IX1.2', '%MW3')
    """
    found = _ADDRESS.match(text.strip().upper())
    expected = ("%IX<byte>.<bit>", "%QX<byte>.<bit>", "%IW<n>", "%QW<n>", "%MW<n>")
    if found is None:
        raise InputError(f"'{text}' is not a directly represented variable", loc, expected=expected)
    area, size, index, bit = found[1], found[2] or "X", int(found[3]), found[4]
    if size == "X":
        if bit is None or not 0 <= int(bit) <= 7 or area == "M":
            raise InputError(f"'{text}' is not a bit address: %IX or %QX, a byte and a bit 0..7", loc,
                             expected=expected)
        return Address(Area(area), False, index, int(bit))
    if bit is not None:
        raise InputError(f"'{text}' is a word address: no bit", loc, expected=expected)
    return Address(Area(area), True, index)


class Role(StrEnum):
    """What an address carries."""

    SENSOR = "sensor"  # the plant writes it, the program reads it
    ORDER = "order"  # the program writes it, the plant reads it
    GRANT = "grant"  # lock-step: scans granted, written by the plant
    DONE = "done"  # lock-step: scans done, written by the runtime


class Layout(StrEnum):
    """What ``--io`` names (a file name is a map)."""

    PLAIN = "plain"
    OPENPLC_SERVER = "openplc-server"
    OPENPLC_DEVICE = "openplc-device"
    MAP = "map"


class Coupling(StrEnum):
    """Who serves Modbus: the runtime (synth connects to it) or synth (the runtime polls it)."""

    NONE = "none"
    CLIENT = "client"
    SERVER = "server"


class Table(StrEnum):
    """The four Modbus data tables."""

    COIL = "coil"
    DISCRETE = "discrete"
    HOLDING = "holding"
    INPUT = "input"


@dataclass(frozen=True)
class IoEntry:
    """One line of a map: a plant name (or ``@grant``/``@done``), its role and address, where it was read."""

    name: str
    role: Role
    address: Address
    loc: Location | None = None


_TABLE_NAME = {"coil": "coil", "discrete": "discrete input", "holding": "holding register", "input": "input register"}


def _device(a: Address) -> bool:
    return a.index >= DEVICE_BASE and a.area is not Area.MEMORY


@dataclass(frozen=True)
class IoMap:
    """A checked map: its layout, its entries (sensors, orders, then the handshake), its coupling."""

    layout: Layout
    entries: tuple[IoEntry, ...]
    where: str = "--io"

    @property
    def coupling(self) -> Coupling:
        if self.layout is Layout.PLAIN:
            return Coupling.NONE
        if all(_device(e.address) for e in self.entries if e.role in (Role.SENSOR, Role.ORDER)):
            return Coupling.SERVER
        return Coupling.CLIENT

    def of(self, role: Role) -> tuple[IoEntry, ...]:
        return tuple(e for e in self.entries if e.role is role)

    def entry(self, name: str) -> IoEntry | None:
        return next((e for e in self.entries if e.name == name), None)

    @property
    def locations(self) -> dict[str, str]:
        """Plant name → address text, for the program's located variables (no handshake)."""
        return {e.name: e.address.text for e in self.entries if e.role in (Role.SENSOR, Role.ORDER)}

    def slot(self, e: IoEntry) -> tuple[str, int] | None:
        """The Modbus table and index of ``e`` seen by the plant (None: not reachable over Modbus)."""
        a = self.coupling
        d = e.address
        if a is Coupling.NONE:
            return None
        if a is Coupling.SERVER:
            if not _device(d):
                return None
            base = d.index - DEVICE_BASE
            if d.word:
                return (Table.INPUT if d.area is Area.INPUT else Table.HOLDING).value, base
            return (Table.DISCRETE if d.area is Area.INPUT else Table.COIL).value, 8 * base + d.bit
        if d.word:
            if d.area is Area.INPUT:
                return Table.INPUT.value, d.index
            return Table.HOLDING.value, d.index + (1024 if d.area is Area.MEMORY else 0)
        return (Table.DISCRETE if d.area is Area.INPUT else Table.COIL).value, 8 * d.index + d.bit

    def check_plant(self) -> None:
        """Every address the plant writes (sensors, ``@grant``) is writable by it, every one
        it reads exists, over this map's coupling: located errors otherwise."""
        if self.coupling is Coupling.NONE:
            raise InputError("layout plain puts the sensors on real inputs (%IX), which no Modbus peer can write",
                             Location(self.where, 1, 1, self.layout.value, len(self.layout.value)),
                             notes=("generate the program with --io openplc-server or --io openplc-device",))
        server = self.coupling is Coupling.SERVER
        for e in self.entries:
            slot = self.slot(e)
            if slot is None:
                raise InputError(f"{e.name} at {e.address.text}: the runtime exchanges only %IX100.0, %QX100.0, "
                                 "%IW100, %QW100 and above with a device it polls", e.loc)
            writes = e.role in (Role.SENSOR, Role.GRANT)
            # client: the plant writes coils and holding registers; server: the runtime reads inputs from synth
            ok = (slot[0] in (Table.DISCRETE, Table.INPUT)) if server else (slot[0] in (Table.COIL, Table.HOLDING))
            if writes and not ok:
                how = "a device the runtime polls serves" if server else "a Modbus client can write"
                raise InputError(f"read-only area written: {e.name} at {e.address.text} is a {_TABLE_NAME[slot[0]]} the plant "
                                 f"cannot write ({how} {'%IX100.x and %IW100' if server else 'coils %QX and registers %QW, %MW'})",
                                 e.loc, notes=("sensors go on coils with --io openplc-server, or on %IX100.x with "
                                               "--io openplc-device",))
            if not writes and server and slot[0] not in (Table.COIL, Table.HOLDING):
                raise InputError(f"{e.name} at {e.address.text}: the runtime cannot write it to a polled device", e.loc)

    def table_rows(self) -> list[dict[str, object]]:
        """The address table: one row per entry (name, role, address, Modbus table and index)."""
        rows: list[dict[str, object]] = []
        for e in self.entries:
            slot = self.slot(e)
            rows.append({"name": e.name, "role": e.role.value, "address": e.address.text,
                         "modbus_table": slot[0] if slot else None, "modbus_index": slot[1] if slot else None})
        return rows

    def table_json(self) -> dict[str, object]:
        return {"layout": self.layout.value, "coupling": self.coupling.value, "variables": self.table_rows()}

    def table_csv(self) -> str:
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(["name", "role", "address", "modbus_table", "modbus_index"])
        for r in self.table_rows():
            writer.writerow(["" if v is None else v for v in r.values()])
        return out.getvalue()


def _bits(base: int, start: int, names: Sequence[str], area: Area, role: Role) -> list[IoEntry]:
    return [IoEntry(n, role, Address(area, False, base + (start + k) // 8, (start + k) % 8)) for k, n in enumerate(names)]


def layout_map(layout: Layout, sensors: Sequence[str], orders: Sequence[str]) -> IoMap:
    """The map of a built-in layout (see the module docstring), in the names' order."""
    if layout is Layout.PLAIN:
        return IoMap(layout, (*_bits(0, 0, sensors, Area.INPUT, Role.SENSOR), *_bits(0, 0, orders, Area.OUTPUT, Role.ORDER)))
    if layout is Layout.OPENPLC_SERVER:
        first = 8 * -(-len(sensors) // 8)  # orders start on the byte after the sensors
        return IoMap(layout, (*_bits(0, 0, sensors, Area.OUTPUT, Role.SENSOR), *_bits(0, first, orders, Area.OUTPUT, Role.ORDER),
                              IoEntry(GRANT, Role.GRANT, Address(Area.MEMORY, True, 0)),
                              IoEntry(DONE, Role.DONE, Address(Area.INPUT, True, 0))))
    assert layout is Layout.OPENPLC_DEVICE
    return IoMap(layout, (*_bits(DEVICE_BASE, 0, sensors, Area.INPUT, Role.SENSOR),
                          *_bits(DEVICE_BASE, 0, orders, Area.OUTPUT, Role.ORDER),
                          IoEntry(GRANT, Role.GRANT, Address(Area.INPUT, True, DEVICE_BASE)),
                          IoEntry(DONE, Role.DONE, Address(Area.OUTPUT, True, DEVICE_BASE))))


def parse_map(text: str, path: str, sensors: Sequence[str], orders: Sequence[str]) -> IoMap:
    """A user's map: ``name,address`` per line (a header row ``name,…,address,…`` chooses the
    columns, so the table ``synth st --io`` writes reads back), ``#`` comments, ``@grant`` and
    ``@done`` for the handshake. Unknown names (with the close ones), an address used twice
    and an order placed on an input are located errors."""
    lines = text.splitlines()
    name_col, addr_col = 0, 1
    entries: list[IoEntry] = []
    seen: dict[tuple[Area, bool, int, int], IoEntry] = {}
    known = [*sensors, *orders, GRANT, DONE]
    for number, line in enumerate(lines, 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        cells = next(csv.reader([line]))
        heads = [c.strip().lower() for c in cells]
        if "name" in heads and "address" in heads:
            name_col, addr_col = heads.index("name"), heads.index("address")
            continue
        if len(cells) <= max(name_col, addr_col):
            raise InputError("expected name,address", Location(path, number, 1, line, max(1, len(line))))
        name, addr = cells[name_col].strip(), cells[addr_col].strip()
        name_at = line.find(name) + 1
        loc = Location(path, number, name_at, line, max(1, len(name)))
        addr_loc = Location(path, number, line.find(addr, name_at) + 1, line, max(1, len(addr)))
        if name not in known:
            raise InputError(f"unknown name '{name}': not an input or output of the program", loc,
                             suggestions=close_names(name, known))
        if any(e.name == name for e in entries):
            raise InputError(f"{name} is mapped twice", loc)
        address = parse_address(addr, addr_loc)
        role = (Role.GRANT if name == GRANT else Role.DONE if name == DONE
                else Role.SENSOR if name in sensors else Role.ORDER)
        key = (address.area, address.word, address.index, address.bit)
        if key in seen:
            first = seen[key]
            raise InputError(f"address {address.text} used twice: {first.name} (line {first.loc.line if first.loc else '?'}) "
                             f"and {name}", addr_loc)
        if role is Role.ORDER and (address.area is Area.INPUT or address.word):
            raise InputError(f"read-only area written: the program cannot write order {name} to {address.text}",
                             addr_loc, notes=("an order goes on an output bit %QX<byte>.<bit>",))
        if role is Role.SENSOR and address.word:
            raise InputError(f"sensor {name} is a BOOL: it needs a bit address, not {address.text}", addr_loc)
        entry = IoEntry(name, role, address, Location(path, number, name_at, line, max(1, len(name))))
        seen[key] = entry
        entries.append(entry)
    order = {n: k for k, n in enumerate(known)}
    return IoMap(Layout.MAP, tuple(sorted(entries, key=lambda e: order[e.name])), path)


def io_map(spec: str, sensors: Sequence[str], orders: Sequence[str]) -> IoMap:
    """``--io``: a layout's name, else a map file (a missing file is a located error)."""
    try:
        layout = Layout(spec)
    except ValueError:
        layout = Layout.MAP
    if layout is not Layout.MAP:
        built = layout_map(layout, sensors, orders)
        return IoMap(built.layout, built.entries, "--io")
    try:
        with open(spec, encoding="utf-8") as fh:
            text = fh.read()
    except OSError as err:
        raise InputError(f"cannot read the I/O map {spec}: {err.strerror}", Location("--io", 1, 1, spec, len(spec)),
                         expected=tuple(x.value for x in Layout if x is not Layout.MAP) + ("a map file .csv",)) from None
    return parse_map(text, spec, sensors, orders)

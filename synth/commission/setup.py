"""Everything a commissioning run needs before its first step, read with located errors: the
plant and SUP's constraints, the reference Grafcet, the I/O map, the faults, the period, and the
link to the runtime (Modbus TCP or OPC UA).
"""

from __future__ import annotations

from typing import Sequence

from synth.commission.device import Timing
from synth.commission.faults import Fault, parse_faults
from synth.commission.iomap import IoMap, Role, io_map
from synth.commission.links import Link
from synth.commission.loop import Setup
from synth.errors import InputError, Location
from synth.plant.rules import RuleSet

__all__ = ["prepare", "period_ms", "open_link"]


def prepare(grafcet_path: str | None, plant_path: str, io_spec: str | None, fault_texts: Sequence[str],
            blocked_after: int, keep_going: bool = False) -> tuple[Setup, RuleSet, IoMap | None, tuple[Fault, ...]]:
    """The run's :class:`~synth.commission.loop.Setup`, rules, map (None: by name, OPC UA) and faults.
    The map is built on the Grafcet's inputs and outputs, as ``synth st --io`` built the program's."""
    from synth.grafcet.language_check import load_grafcet
    from synth.plant.composition import plant
    from synth.plant.rules_check import load_rules
    from synth.sup.constraints import CompiledConstraints

    rules = load_rules(plant_path)
    p = plant(rules)
    grafcet = None
    if grafcet_path is not None:
        grafcet = load_grafcet(grafcet_path, inputs=rules.inputs, outputs=rules.outputs)
        inputs, outputs = list(grafcet.inputs), list(grafcet.outputs)
    else:
        inputs, outputs = list(p.inputs), list(p.outputs)
    io = io_map(io_spec, inputs, outputs) if io_spec is not None else None
    if io is not None:
        sensors = tuple(e.name for e in io.of(Role.SENSOR) if e.name in p.inputs)
        orders = tuple(e.name for e in io.of(Role.ORDER) if e.name in p.outputs)
    else:
        sensors, orders = tuple(inputs), tuple(outputs)
    faults = parse_faults(fault_texts, sensors, orders)
    if blocked_after < 1:
        raise InputError("--blocked-after must be at least 1", Location("--blocked-after", 1, 1, str(blocked_after)))
    setup = Setup(p, CompiledConstraints(p, rules.constraints), grafcet, sensors, orders, (), blocked_after, keep_going)
    return setup, rules, io, faults


def period_ms(text: str) -> int:
    """``--period 10ms`` → 10; a located error for anything but a whole number of milliseconds."""
    from synth.grafcet.language import DURATION_RE, duration_seconds

    where = Location("--period", 1, 1, text, max(1, len(text)))
    found = DURATION_RE.fullmatch(text.strip())
    ms = duration_seconds(found[1], found[2]) * 1000 if found else None
    if ms is None or ms.denominator != 1 or ms <= 0:
        raise InputError("not a period of whole milliseconds", where, expected=("10ms", "0.5s"))
    return int(ms)


def open_link(io: IoMap | None, modbus: str | None, opcua: str | None, *, timing: Timing, period: int,
              timeout: float, names: tuple[Sequence[str], Sequence[str]] = ((), ()), prefix: str | None = None) -> Link:
    """The link to the runtime: ``--modbus HOST:PORT`` with a map, or ``--opcua URL`` by name
    (node ids ``prefix`` + name)."""
    from synth.commission.modbus import split_host_port

    if (modbus is None) == (opcua is None):
        raise InputError("give the runtime's address: --modbus HOST:PORT or --opcua URL (one of them)", None)
    if modbus is not None:
        if io is None:
            raise InputError("--modbus needs --io: the layout the program was generated with, or its map", None)
        try:
            host, port = split_host_port(modbus)
        except ValueError:
            raise InputError("not HOST:PORT", Location("--modbus", 1, 1, modbus, max(1, len(modbus)))) from None
        from synth.commission.links import ModbusLink

        return ModbusLink(io, host, port, timing=timing, period_ms=period, timeout=timeout)
    from synth.commission.opcua import DEFAULT_PREFIX, OpcUaLink

    assert opcua is not None
    return OpcUaLink(opcua, names[0], names[1], timing=timing, period_ms=period, timeout=timeout,
                     prefix=DEFAULT_PREFIX if prefix is None else prefix)

"""The device under test CI can run without fetching anything: synth's own generated program,
executed by its ST interpreter (:mod:`synth.codegen.interpreter`), behind real Modbus TCP —
a runtime in miniature that implements the scan handshake of docs/commissioning.md:

* the plant writes the ``@grant`` register; ``0`` holds the runtime in reset (a fresh program,
  the PLC clock at 0, ``@done := 0``); leaving ``0`` lets it run;
* **lock-step**: the runtime runs one scan each time ``@grant`` differs from ``@done`` and then
  copies it (``@grant`` counts 1, 2, … 65535, 1, …; the plant may grant several scans at once);
  the PLC clock advances by the task period per scan, so a 2 s timer is 200 scans at 10 ms;
* **real time**: the runtime scans every period on the wall clock and counts its scans in
  ``@done`` (1 … 65535, 1, …), so the plant can wait for whole scans.

A scan reads the sensors, runs the program once, writes the orders. For the ``openplc-server``
layout the device is the Modbus server (the plant its client); for ``openplc-device`` it polls
the plant's server as OpenPLC polls a slave device. ``drop_after`` and ``stall_after`` make it
misbehave after that many scans (drop the connection; stop scanning), for the tests of a PLC
that fails.
"""

from __future__ import annotations

import threading
import time
from enum import StrEnum
from typing import Protocol, Sequence

from synth.codegen.interpreter.machine import Module
from synth.commission.iomap import Coupling, IoMap, Role
from synth.commission.modbus import LinkError, ModbusClient, ModbusServer, spans

__all__ = ["Timing", "next_count", "ScannedProgram", "Port", "ScanLoop", "InterpretedPlc", "located_program"]

POLL_S = 0.0002


class Timing(StrEnum):
    """How scans are paced."""

    LOCKSTEP = "lock-step"
    REALTIME = "real-time"


def next_count(n: int) -> int:
    """The counter after ``n``: 1 … 65535, then 1 again (0 means reset).

    >>> next_count(0), next_count(7), next_count(65535)
    (1, 8, 1)
    """
    return n % 65535 + 1


class ScannedProgram:
    """A PROGRAM of a parsed module, its own clock, one instance restarted by :meth:`reset`."""

    def __init__(self, parsed: Module, pou: str, sensors: Sequence[str], orders: Sequence[str], period_ms: int,
                 timing: Timing) -> None:
        self.parsed, self.pou, self.period_ms, self.timing = parsed, pou, period_ms, timing
        self.sensors, self.orders = list(sensors), list(orders)
        self.reset()

    def reset(self) -> None:
        self.module = Module(self.parsed.file, self.parsed.source, self.parsed.pous)
        self.instance = self.module.instance(self.pou)
        self.started = time.monotonic()

    def scan(self, sensors: dict[str, bool]) -> dict[str, bool]:
        if self.timing is Timing.LOCKSTEP:
            self.module.advance(self.period_ms)
        else:
            self.module.clock_ms = int((time.monotonic() - self.started) * 1000)
        self.instance.cycle(sensors)
        return {o: bool(self.instance[o]) for o in self.orders}


class Port(Protocol):
    """How a runtime reaches its process image and the two handshake counters."""

    def grant(self) -> int: ...

    def set_done(self, n: int) -> None: ...

    def sensors(self) -> dict[str, bool]: ...

    def set_orders(self, values: dict[str, bool]) -> None: ...


class _Image(Protocol):
    def read(self, table: str, index: int, count: int = 1) -> list[int]: ...

    def write(self, table: str, index: int, values: Sequence[int]) -> None: ...


class _Local:
    """The device's own tables (it serves them)."""

    def __init__(self, server: ModbusServer) -> None:
        self.server = server

    def read(self, table: str, index: int, count: int = 1) -> list[int]:
        return self.server.get(table, index, count)

    def write(self, table: str, index: int, values: Sequence[int]) -> None:
        self.server.set(table, index, values)


class _ModbusPort:
    """The process image over Modbus tables, by the map: each run of addresses in one request."""

    def __init__(self, image: _Image, io: IoMap, sensors: Sequence[str], orders: Sequence[str]) -> None:
        def slot(name: str) -> tuple[str, int]:
            e = io.entry(name)
            assert e is not None and io.slot(e) is not None
            return io.slot(e)  # type: ignore[return-value]

        self.image, self.names, self.outs = image, list(sensors), list(orders)
        self.grant_at, self.done_at = slot("@grant"), slot("@done")
        self.reading, self.writing = spans([slot(n) for n in sensors]), spans([slot(n) for n in orders])

    def grant(self) -> int:
        return self.image.read(*self.grant_at)[0]

    def set_done(self, n: int) -> None:
        self.image.write(*self.done_at, [n])

    def sensors(self) -> dict[str, bool]:
        values: dict[str, bool] = {}
        for table, first, ks in self.reading:
            got = self.image.read(table, first, len(ks))
            values.update({self.names[k]: bool(v) for k, v in zip(ks, got)})
        return values

    def set_orders(self, values: dict[str, bool]) -> None:
        for table, first, ks in self.writing:
            self.image.write(table, first, [int(values[self.outs[k]]) for k in ks])


class ScanLoop:
    """A runtime: the scan thread of the handshake (module docstring) over a :class:`Port`, from
    :meth:`start` to :meth:`stop` (a context manager). ``drop_after``/``stall_after``: misbehave."""

    def __init__(self, program: ScannedProgram, *, drop_after: int | None = None, stall_after: int | None = None) -> None:
        self.program = program
        self.drop_after, self.stall_after = drop_after, stall_after
        self.scans = 0
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self._loop, daemon=True, name="plc-scans")
        self.error: BaseException | None = None

    def start(self) -> ScanLoop:
        self.serve()
        self.thread.start()
        return self

    def stop(self) -> None:
        self.stopping.set()
        self.thread.join(10)
        self.close()

    def __enter__(self) -> ScanLoop:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # the protocol's part
    def serve(self) -> None:
        """Start serving the process image (when the runtime is the server)."""

    def close(self) -> None:
        """Stop serving."""

    def port(self) -> Port:
        raise NotImplementedError

    def drop(self) -> None:
        """Drop the connection (a failing runtime)."""

    def reconnects(self) -> bool:
        """Whether the runtime polls again when its peer goes away."""
        return False

    def _loop(self) -> None:
        while not self.stopping.is_set():
            try:
                self._run(self.port())
                return
            except LinkError as err:
                if not self.reconnects() or self.stopping.is_set():
                    self.error = None if self.stopping.is_set() else err
                    return
                time.sleep(0.05)  # the device it polls went away: poll again, as a runtime does

    def _run(self, port: Port) -> None:
        done, held, tick = 0, False, time.monotonic()
        port.set_done(0)
        while not self.stopping.is_set():
            grant = port.grant()
            if grant == 0:
                if not held:
                    self.program.reset()
                    done, held = 0, True
                    port.set_done(0)
                time.sleep(POLL_S)
                continue
            if held:
                held, tick = False, time.monotonic()
                self.program.reset()
            if self.program.timing is Timing.LOCKSTEP:
                if grant == done:
                    time.sleep(POLL_S)
                    continue
            else:
                tick += self.program.period_ms / 1000
                time.sleep(max(0.0, tick - time.monotonic()))
            if self.stall_after is not None and self.scans >= self.stall_after:
                time.sleep(POLL_S)
                continue
            if self.drop_after is not None and self.scans >= self.drop_after:
                self.drop()
                return
            port.set_orders(self.program.scan(port.sensors()))
            done = next_count(done)
            port.set_done(done)
            self.scans += 1


class InterpretedPlc(ScanLoop):
    """The interpreter as a Modbus TCP runtime on ``host:port``: its server for ``openplc-server``,
    polling synth's server for ``openplc-device``."""

    def __init__(self, parsed: Module, pou: str, io: IoMap, host: str, port: int, *, period_ms: int = 10,
                 timing: Timing = Timing.LOCKSTEP, drop_after: int | None = None,
                 stall_after: int | None = None) -> None:
        sensors, orders = [e.name for e in io.of(Role.SENSOR)], [e.name for e in io.of(Role.ORDER)]
        super().__init__(ScannedProgram(parsed, pou, sensors, orders, period_ms, timing),
                         drop_after=drop_after, stall_after=stall_after)
        self.io, self.host, self.where = io, host, port
        self.server: ModbusServer | None = None
        self.client: ModbusClient | None = None

    def serve(self) -> None:
        if self.io.coupling is Coupling.CLIENT:
            self.server = ModbusServer(self.host, self.where).start()

    def close(self) -> None:
        if self.server is not None:
            self.server.stop()
        if self.client is not None:
            self.client.close()

    def reconnects(self) -> bool:
        return self.io.coupling is Coupling.SERVER

    def port(self) -> Port:
        p = self.program
        if self.server is not None:
            return _ModbusPort(_Local(self.server), self.io, p.sensors, p.orders)
        while not self.stopping.is_set():  # polling the plant's server: wait until it serves
            try:
                self.client = ModbusClient(self.host, self.where, timeout=2.0)
                return _ModbusPort(self.client, self.io, p.sensors, p.orders)
            except LinkError:
                time.sleep(0.05)
        raise LinkError("stopped")

    def drop(self) -> None:
        self.close()
        self.server = self.client = None


def located_program(grafcet_path: str, plant_path: str | None, io_spec: str) -> tuple[Module, str, IoMap]:
    """``synth st --io`` 's program for a Grafcet, parsed once (the slow part): the module, the
    PROGRAM's name, the map. :class:`InterpretedPlc` runs it as a runtime."""
    from synth.codegen.grafcet_st import generate_program
    from synth.codegen.interpreter.machine import load_st
    from synth.codegen.program import with_locations
    from synth.commission.iomap import io_map
    from synth.grafcet.language_check import load_grafcet

    if plant_path is not None:
        from synth.plant.rules_check import load_rules

        rules = load_rules(plant_path)
        g = load_grafcet(grafcet_path, inputs=rules.inputs, outputs=rules.outputs)
    else:
        g = load_grafcet(grafcet_path)
    io = io_map(io_spec, g.inputs, g.outputs)
    program = with_locations(generate_program(g, comments=False), io.locations)
    return load_st(program.text, grafcet_path + ".st"), program.program, io

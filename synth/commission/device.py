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

__all__ = ["Timing", "next_count", "ScannedProgram", "InterpretedPlc", "located_program"]

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

    def __init__(self, parsed: Module, pou: str, io: IoMap, period_ms: int, timing: Timing) -> None:
        self.parsed, self.pou, self.io, self.period_ms, self.timing = parsed, pou, io, period_ms, timing
        self.sensors = [e.name for e in io.of(Role.SENSOR)]
        self.orders = [e.name for e in io.of(Role.ORDER)]
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


class InterpretedPlc:
    """The interpreter as a PLC runtime on ``host:port`` (see the module docstring); a context
    manager: the scan thread runs from :meth:`start` to :meth:`stop`."""

    def __init__(self, parsed: Module, pou: str, io: IoMap, host: str, port: int, *, period_ms: int = 10,
                 timing: Timing = Timing.LOCKSTEP, drop_after: int | None = None,
                 stall_after: int | None = None) -> None:
        self.program = ScannedProgram(parsed, pou, io, period_ms, timing)
        self.io, self.host, self.port = io, host, port
        self.drop_after, self.stall_after = drop_after, stall_after
        self.scans = 0
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self._loop, daemon=True, name=f"plc-{port}")
        self.server: ModbusServer | None = None
        self.error: BaseException | None = None

    def slot(self, name: str) -> tuple[str, int]:
        e = self.io.entry(name)
        assert e is not None and self.io.slot(e) is not None
        return self.io.slot(e)  # type: ignore[return-value]

    def start(self) -> InterpretedPlc:
        if self.io.coupling is Coupling.CLIENT:
            self.server = ModbusServer(self.host, self.port).start()
        self.thread.start()
        return self

    def stop(self) -> None:
        self.stopping.set()
        self.thread.join(10)
        if self.server is not None:
            self.server.stop()

    def __enter__(self) -> InterpretedPlc:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _connect(self) -> _Image:
        if self.server is not None:
            return _Local(self.server)
        while not self.stopping.is_set():  # polling the plant's server: wait until it serves
            try:
                return ModbusClient(self.host, self.port, timeout=2.0)
            except LinkError:
                time.sleep(0.05)
        raise LinkError("stopped")

    def _loop(self) -> None:
        while not self.stopping.is_set():
            try:
                self._run(self._connect())
                return
            except LinkError as err:
                if self.server is not None or self.stopping.is_set():
                    self.error = None if self.stopping.is_set() else err
                    return
                time.sleep(0.05)  # the device it polls went away: poll again, as a runtime does

    def _run(self, image: _Image) -> None:
        grant_at, done_at = self.slot("@grant"), self.slot("@done")
        sensors = [(n, self.slot(n)) for n in self.program.sensors]
        orders = [(n, self.slot(n)) for n in self.program.orders]
        reading, writing = spans([at for _, at in sensors]), spans([at for _, at in orders])
        done, held, tick = 0, False, time.monotonic()
        image.write(*done_at, [0])
        while not self.stopping.is_set():
            grant = image.read(*grant_at)[0]
            if grant == 0:
                if not held:
                    self.program.reset()
                    done, held = 0, True
                    image.write(*done_at, [0])
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
                self._drop(image)
                return
            values: dict[str, bool] = {}
            for table, first, ks in reading:
                got = image.read(table, first, len(ks))
                values.update({sensors[k][0]: bool(v) for k, v in zip(ks, got)})
            out = self.program.scan(values)
            for table, first, ks in writing:
                image.write(table, first, [int(out[orders[k][0]]) for k in ks])
            done = next_count(done)
            image.write(*done_at, [done])
            self.scans += 1

    def _drop(self, image: _Image) -> None:
        if self.server is not None:
            self.server.stop()
            self.server = None
        elif isinstance(image, ModbusClient):
            image.close()


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

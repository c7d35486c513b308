"""The plant's side of the wire, one interface for every protocol: write the sensors, let the
runtime run whole scans (lock-step grants or real time), read the orders, restart it.

:class:`ModbusLink` speaks Modbus TCP by an :class:`~synth.commission.iomap.IoMap` (as the
runtime's client, or as the device it polls); :class:`~synth.commission.opcua.OpcUaLink` speaks
OPC UA by variable names. Every wait has a deadline: a runtime that does not answer, answers
too slowly or drops the connection is a :class:`~synth.commission.modbus.LinkError`, never a hang.
"""

from __future__ import annotations

import time
from typing import Mapping, Protocol, Sequence

from synth.commission.device import POLL_S, Timing, next_count
from synth.commission.iomap import Coupling, IoMap, Role
from synth.commission.modbus import LinkError, ModbusClient, ModbusServer, spans

__all__ = ["Link", "ModbusLink", "Counters"]


class Link(Protocol):
    """What the closed loop needs from a runtime."""

    timing: Timing
    period_ms: int

    def reset(self, sensors: Mapping[str, bool]) -> None:
        """Restart the runtime (a fresh program, its clock at 0) with these sensor values."""

    def write_sensors(self, values: Mapping[str, bool]) -> None: ...

    def scans(self, n: int) -> None:
        """Let ``n`` whole scans run after the last write (lock-step: grant them)."""

    def read_orders(self) -> dict[str, bool]: ...

    def close(self) -> None: ...


class Counters:
    """The handshake over two registers read and written by callables: shared by the protocols."""

    def __init__(self, read_done: object, write_grant: object, timing: Timing, timeout: float, where: str) -> None:
        self.read_done, self.write_grant = read_done, write_grant
        self.timing, self.timeout, self.where = timing, timeout, where
        self.grant = 0
        self.scans_done = 0  # whole scans since the last reset, as the plant saw them

    def _wait(self, ok: object, what: str) -> int:
        """Poll ``@done`` until ``ok``; the deadline moves on while the counter does (a runtime
        running many granted scans slowly is alive; one that stops counting is not)."""
        deadline, seen = time.monotonic() + self.timeout, None
        while True:
            done = int(self.read_done())  # type: ignore[operator]
            if ok(done):  # type: ignore[operator]
                return done
            if done != seen:
                deadline, seen = time.monotonic() + self.timeout, done
            if time.monotonic() > deadline:
                raise LinkError(f"{self.where}: the runtime did not {what}: @done stayed {done} for {self.timeout:g} s "
                                f"({self.scans_done} scans reached since the last reset)")
            time.sleep(POLL_S)

    def hold(self) -> None:
        self.write_grant(0)  # type: ignore[operator]
        self._wait(lambda d: d == 0, "acknowledge the reset (@grant 0 → @done 0)")
        self.grant, self.scans_done = 0, 0

    def release(self) -> None:
        if self.timing is Timing.REALTIME:
            self.grant = 1
            self.write_grant(1)  # type: ignore[operator]

    def scans(self, n: int) -> None:
        if n <= 0:
            return
        if self.timing is Timing.LOCKSTEP:
            want = self.grant
            for _ in range(n):
                want = next_count(want)
            self.grant = want
            self.write_grant(want)  # type: ignore[operator]
            self._wait(lambda d: d == want, f"run the {n} scan(s) granted (@grant {want})")
        else:  # a whole scan starts after the write and ends: the counter moves by n + 1
            start = int(self.read_done())  # type: ignore[operator]
            self._wait(lambda d: (d - start) % 65535 >= n + 1, f"count {n + 1} scans in real time")
        self.scans_done += n


class ModbusLink:
    """Modbus TCP by an I/O map: synth is the runtime's client (``openplc-server``) or the
    device the runtime polls (``openplc-device``: synth serves ``host:port``)."""

    def __init__(self, io: IoMap, host: str, port: int, *, timing: Timing, period_ms: int, timeout: float) -> None:
        io.check_plant()
        self.io, self.timing, self.period_ms = io, timing, period_ms
        self.where = f"Modbus TCP {host}:{port}"
        self.server: ModbusServer | None = None
        self.client: ModbusClient | None = None
        if io.coupling is Coupling.SERVER:
            self.server = ModbusServer(host, port).start()
        else:
            self.client = ModbusClient(host, port, timeout)
        self.sensors = [e.name for e in io.of(Role.SENSOR)]
        self.orders = [e.name for e in io.of(Role.ORDER)]
        slot = self._slot
        self.sensor_spans = spans([slot(n) for n in self.sensors])
        self.order_spans = spans([slot(n) for n in self.orders])
        grant, done = slot("@grant"), slot("@done")
        self.counters = Counters(lambda: self._read(*done)[0], lambda v: self._write(*grant, [v]), timing, timeout,
                                 self.where)

    def _slot(self, name: str) -> tuple[str, int]:
        e = self.io.entry(name)
        if e is None:
            raise LinkError(f"the I/O map has no {name} register: the handshake needs @grant and @done")
        return self.io.slot(e)  # type: ignore[return-value]  # check_plant: every entry has a slot

    def _read(self, table: str, index: int, count: int = 1) -> list[int]:
        if self.server is not None:
            return self.server.get(table, index, count)
        assert self.client is not None
        return self.client.read(table, index, count)

    def _write(self, table: str, index: int, values: Sequence[int]) -> None:
        if self.server is not None:
            self.server.set(table, index, values)
        else:
            assert self.client is not None
            self.client.write(table, index, values)

    def reset(self, sensors: Mapping[str, bool]) -> None:
        self.counters.hold()
        self.write_sensors(sensors)
        self.counters.release()

    def write_sensors(self, values: Mapping[str, bool]) -> None:
        for table, first, ks in self.sensor_spans:
            self._write(table, first, [int(values.get(self.sensors[k], False)) for k in ks])

    def scans(self, n: int) -> None:
        self.counters.scans(n)

    def read_orders(self) -> dict[str, bool]:
        out: dict[str, bool] = {}
        for table, first, ks in self.order_spans:
            got = self._read(table, first, len(ks))
            out.update({self.orders[k]: bool(v) for k, v in zip(ks, got)})
        return out

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
        if self.server is not None:
            self.server.stop()

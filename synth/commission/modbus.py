"""Modbus TCP through pymodbus (``synth[commission]``, pinned to the version whose server API
the tests run): a server on a thread of its own, with its four data tables, and a client whose
every failure (refused, timed out, dropped) is one :class:`LinkError`.

Both sides of the closed loop use it: synth's plant as client of a runtime that serves
(``openplc-server``) or as the device a runtime polls (``openplc-device``), and the device
under test CI runs (:mod:`synth.commission.device`) in the other role.
"""

from __future__ import annotations

import asyncio
import socket
import threading
from typing import Any, Sequence

from synth.errors import SynthError

__all__ = ["LinkError", "FUNCTION", "TABLE_SIZE", "ModbusServer", "ModbusClient", "free_port", "split_host_port", "spans"]

FUNCTION = {"coil": 1, "discrete": 2, "holding": 3, "input": 4}
"""The read function code of each table: pymodbus's data store is addressed by it."""
TABLE_SIZE = 4096


def _quiet() -> None:
    """pymodbus logs every refused connection and late frame; synth reports them itself."""
    import logging

    log = logging.getLogger("pymodbus")
    log.setLevel(logging.CRITICAL)
    log.propagate = False


class LinkError(SynthError):
    """The PLC did not answer, answered too slowly, refused or dropped the connection."""


def free_port() -> int:
    """A TCP port free on 127.0.0.1 now (for the tests and the benchmark)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def split_host_port(text: str, default_port: int = 502) -> tuple[str, int]:
    """``HOST:PORT`` (or ``HOST``) → (host, port); ValueError on a bad port."""
    host, _, port = text.rpartition(":")
    if not host:
        return text, default_port
    return host, int(port)


class ModbusServer:
    """A Modbus TCP server holding coils, discrete inputs, holding and input registers
    (:data:`TABLE_SIZE` each, from address 0), served on a thread until :meth:`stop`."""

    def __init__(self, host: str, port: int) -> None:
        from pymodbus.datastore import ModbusDeviceContext, ModbusSequentialDataBlock, ModbusServerContext

        _quiet()
        def block() -> Any:
            return ModbusSequentialDataBlock(0, [0] * TABLE_SIZE)

        self.store = ModbusDeviceContext(di=block(), co=block(), hr=block(), ir=block())
        self.context = ModbusServerContext(devices=self.store, single=True)
        self.host, self.port = host, port
        self.loop = asyncio.new_event_loop()
        self.server: Any = None
        self.ready = threading.Event()
        self.failed: BaseException | None = None
        self.thread = threading.Thread(target=self._run, daemon=True, name=f"modbus-server-{port}")

    def _run(self) -> None:
        from pymodbus.server import ModbusTcpServer

        asyncio.set_event_loop(self.loop)

        async def serve() -> None:
            self.server = ModbusTcpServer(self.context, address=(self.host, self.port))
            if not await self.server.listen():
                raise OSError("the address is in use or cannot be bound")
            self.ready.set()
            await self.server.serving

        try:
            self.loop.run_until_complete(serve())
        except BaseException as err:  # reported by start(): a port in use, say
            self.failed = err
            self.ready.set()

    def start(self, timeout: float = 5.0) -> ModbusServer:
        self.thread.start()
        if not self.ready.wait(timeout) or self.failed is not None:
            raise LinkError(f"cannot serve Modbus TCP on {self.host}:{self.port}: {self.failed or 'timed out'}")
        return self

    def stop(self) -> None:
        if self.server is not None and self.loop.is_running():
            future = asyncio.run_coroutine_threadsafe(self.server.shutdown(), self.loop)
            try:
                future.result(5)
            except Exception:  # already closing: nothing more to do
                pass
        self.thread.join(5)

    def get(self, table: str, index: int, count: int = 1) -> list[int]:
        values = self.store.getValues(FUNCTION[table], index, count)
        if not isinstance(values, list):  # an exception code: outside the tables
            raise LinkError(f"Modbus {table} {index}..{index + count - 1} is outside the tables ({values})")
        return [int(v) for v in values]

    def set(self, table: str, index: int, values: Sequence[int]) -> None:
        self.store.setValues(FUNCTION[table], index, [int(v) for v in values])


class ModbusClient:
    """A synchronous Modbus TCP client; every request either answers within ``timeout``
    seconds or raises :class:`LinkError` naming the request."""

    def __init__(self, host: str, port: int, timeout: float) -> None:
        from pymodbus.client import ModbusTcpClient

        _quiet()
        self.where = f"{host}:{port}"
        self.client = ModbusTcpClient(host, port=port, timeout=timeout, retries=0)
        try:
            connected = self.client.connect()
        except Exception as err:  # pymodbus raises its own ConnectionException
            raise LinkError(f"no Modbus TCP server at {self.where}: {err}") from None
        if not connected:
            raise LinkError(f"no Modbus TCP server at {self.where} (connection refused or timed out)")

    def _call(self, what: str, fn: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            reply = fn(*args, **kwargs)
        except Exception as err:
            raise LinkError(f"Modbus TCP {self.where}: {what} failed: {err}") from None
        if reply.isError():
            raise LinkError(f"Modbus TCP {self.where}: {what} answered {reply}")
        return reply

    def read(self, table: str, index: int, count: int = 1) -> list[int]:
        fn = {"coil": self.client.read_coils, "discrete": self.client.read_discrete_inputs,
              "holding": self.client.read_holding_registers, "input": self.client.read_input_registers}[table]
        reply = self._call(f"reading {count} {table}(s) at {index}", fn, index, count=count)
        values = reply.bits if table in ("coil", "discrete") else reply.registers
        return [int(v) for v in values[:count]]

    def write(self, table: str, index: int, values: Sequence[int]) -> None:
        if table == "coil":
            self._call(f"writing coils at {index}", self.client.write_coils, index, [bool(v) for v in values])
        elif table == "holding":
            self._call(f"writing registers at {index}", self.client.write_registers, index, [int(v) for v in values])
        else:
            raise LinkError(f"Modbus TCP {self.where}: a client cannot write {table}s")

    def close(self) -> None:
        self.client.close()


def spans(slots: Sequence[tuple[str, int]]) -> list[tuple[str, int, list[int]]]:
    """Slots grouped into runs of consecutive addresses of one table: (table, first index,
    positions in ``slots``), so a scan reads or writes each run in one request.

    >>> spans([("coil", 0), ("coil", 1), ("coil", 8), ("holding", 2)])
    [('coil', 0, [0, 1]), ('coil', 8, [2]), ('holding', 2, [3])]
    """
    out: list[tuple[str, int, list[int]]] = []
    for k, (table, index) in sorted(enumerate(slots), key=lambda p: p[1]):
        if out and out[-1][0] == table and out[-1][1] + len(out[-1][2]) == index:
            out[-1][2].append(k)
        else:
            out.append((table, index, [k]))
    return out

"""OPC UA (asyncua, ``synth[commission]``): variables by name instead of addresses, the natural
coupling for CODESYS, TwinCAT and S7 runtimes.

A variable's node id is a prefix and its name: ``ns=2;s=dcy`` by default (``--node-prefix``
sets the prefix a runtime uses, as CODESYS's ``ns=4;s=|var|…Application.PLC_PRG.``); the
handshake is the two UInt16 variables ``_grant`` and ``_done`` beside them, with the meaning
of docs/commissioning.md. :class:`OpcUaLink` is the plant's side, :class:`InterpretedUaPlc` the
device under test (the interpreter behind an asyncua server).
"""

from __future__ import annotations

import logging
from typing import Any, Mapping, Sequence

from synth.codegen.interpreter.machine import Module
from synth.commission.device import ScanLoop, ScannedProgram, Timing
from synth.commission.links import Counters
from synth.commission.modbus import LinkError

__all__ = ["OpcUaLink", "InterpretedUaPlc", "DEFAULT_PREFIX", "NAMESPACE", "GRANT", "DONE"]

DEFAULT_PREFIX = "ns=2;s="
NAMESPACE = "urn:synth:commission"
GRANT, DONE = "_grant", "_done"


def _quiet() -> None:
    for name in ("asyncua", "asyncio"):
        logging.getLogger(name).setLevel(logging.CRITICAL)


def _variant(value: int | bool, counter: bool) -> Any:
    from asyncua import ua

    if counter:
        return ua.DataValue(ua.Variant(int(value), ua.VariantType.UInt16))
    return ua.DataValue(ua.Variant(bool(value), ua.VariantType.Boolean))


class OpcUaLink:
    """The plant's side over OPC UA: one request writes every sensor, one reads every order."""

    def __init__(self, url: str, sensors: Sequence[str], orders: Sequence[str], *, timing: Timing, period_ms: int,
                 timeout: float, prefix: str = DEFAULT_PREFIX) -> None:
        from asyncua.sync import Client

        _quiet()
        self.timing, self.period_ms, self.where = timing, period_ms, f"OPC UA {url}"
        self.sensors, self.orders = list(sensors), list(orders)
        self.client: Any = Client(url, timeout=timeout)
        try:
            self.client.connect()
        except Exception as err:  # refused, timed out, not OPC UA: asyncua raises many kinds
            self.client.tloop.stop()  # its thread would keep the process alive
            self.client = None
            raise LinkError(f"no OPC UA server at {url}: {err or type(err).__name__}") from None
        node = self.client.get_node
        self.sensor_nodes = [node(prefix + n) for n in self.sensors]
        self.order_nodes = [node(prefix + n) for n in self.orders]
        grant, done = node(prefix + GRANT), node(prefix + DONE)
        self.counters = Counters(lambda: self._call("reading _done", self.client.read_values, [done])[0],
                                 lambda v: self._call("writing _grant", self.client.write_values, [grant],
                                                      [_variant(v, True)]), timing, timeout, self.where)

    def _call(self, what: str, fn: Any, *args: Any) -> Any:
        try:
            return fn(*args)
        except Exception as err:
            raise LinkError(f"{self.where}: {what} failed: {err or type(err).__name__}") from None

    def reset(self, sensors: Mapping[str, bool]) -> None:
        self.counters.hold()
        self.write_sensors(sensors)
        self.counters.release()

    def write_sensors(self, values: Mapping[str, bool]) -> None:
        if self.sensor_nodes:
            self._call("writing the sensors", self.client.write_values, self.sensor_nodes,
                       [_variant(values.get(n, False), False) for n in self.sensors])

    def scans(self, n: int) -> None:
        self.counters.scans(n)

    def read_orders(self) -> dict[str, bool]:
        if not self.order_nodes:
            return {}
        got = self._call("reading the orders", self.client.read_values, self.order_nodes)
        return {o: bool(v) for o, v in zip(self.orders, got)}

    def close(self) -> None:
        if self.client is not None:
            try:
                self.client.disconnect()
            except Exception:  # the server is gone already: stop the client's thread alone
                self.client.tloop.stop()


class _UaPort:
    """The device's own variables, read and written in the server's address space."""

    def __init__(self, nodes: dict[str, Any], sensors: Sequence[str], orders: Sequence[str]) -> None:
        self.nodes, self.names, self.outs = nodes, list(sensors), list(orders)

    def grant(self) -> int:
        return int(self.nodes[GRANT].read_value())

    def set_done(self, n: int) -> None:
        self.nodes[DONE].write_value(_variant(n, True))

    def sensors(self) -> dict[str, bool]:
        return {n: bool(self.nodes[n].read_value()) for n in self.names}

    def set_orders(self, values: dict[str, bool]) -> None:
        for o in self.outs:
            self.nodes[o].write_value(_variant(values[o], False))


class InterpretedUaPlc(ScanLoop):
    """The interpreter behind an asyncua server at ``url``: one Boolean variable per sensor and
    order, named ``ns=2;s=<name>``, and the handshake counters."""

    def __init__(self, parsed: Module, pou: str, sensors: Sequence[str], orders: Sequence[str], url: str, *,
                 period_ms: int = 10, timing: Timing = Timing.LOCKSTEP, **options: Any) -> None:
        super().__init__(ScannedProgram(parsed, pou, sensors, orders, period_ms, timing), **options)
        self.url = url
        self.server: Any = None
        self.nodes: dict[str, Any] = {}

    def serve(self) -> None:
        from asyncua import ua
        from asyncua.sync import Server

        _quiet()
        self.server = Server()
        self.server.set_endpoint(self.url)
        idx = self.server.register_namespace(NAMESPACE)
        plc = self.server.nodes.objects.add_object(idx, "PLC")
        for n in [*self.program.sensors, *self.program.orders, GRANT, DONE]:
            counter = n in (GRANT, DONE)
            value = ua.Variant(0, ua.VariantType.UInt16) if counter else False
            self.nodes[n] = plc.add_variable(ua.NodeId(ua.String(n), idx), n, value)
            self.nodes[n].set_writable()
        self.server.start()

    def port(self) -> _UaPort:
        return _UaPort(self.nodes, self.program.sensors, self.program.orders)

    def close(self) -> None:
        if self.server is not None:
            self.server.stop()
            self.server = None

    def drop(self) -> None:
        self.close()

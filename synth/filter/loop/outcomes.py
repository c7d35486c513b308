"""The outcomes of one PLC cycle in ``synth filter verify``'s exploration: an outcome
(the orders written, the memory after the cycle, the flags), the arrays over every
outcome found so far, the distinct outcomes among the lanes of
:meth:`~synth.filter.cycle.FilterCycle.lanes` (:func:`first_lanes`), the Grafcet's reaction to a cycle's events and a trace row.

Example
-------
>>> first_lanes([0b0110, 0b0100], 4)
[0, 1, 2]
>>> arrays = OutcomeArrays(2)
>>> oc = Outcome((True, False), 0, False, False, (True, True), ("K",))
>>> targets, fallback, outside, aux, requests = arrays.update([oc])
>>> targets.tolist(), requests.tolist()
([[True, False]], [[True, True]])
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, NamedTuple, Sequence

import numpy as np

from synth.filter.cycle import ACK, Lanes, Memory, Mode
from synth.filter.loop.verification import TraceRow
from synth.logic.events import Event, EventKind
from synth.logic.lanes import lane_mask

TYPE_CHECKING = False
if TYPE_CHECKING:
    from synth.filter.loop.product import Product

__all__ = ["ClassLanes", "Outcome", "OutcomeArrays", "class_lanes", "distinct_lanes", "first_lanes",
           "react", "situation_text", "trace_row"]


@dataclass(frozen=True)
class Outcome:
    """What one cycle does to the product; the requests are one witness (not compared:
    request vectors that give the same outputs, memory and flags are one outcome)."""

    targets: tuple[bool, ...]  # every plant order, in plant output order
    aux: int
    fallback: bool
    outside_care: bool
    requests: tuple[bool, ...] = field(compare=False)  # every plant order's request
    violated: tuple[str, ...] = field(compare=False)  # filter constraints the requests violate


def first_lanes(masks: Sequence[int], count: int) -> list[int]:
    """The first lane (ascending) of each distinct column of ``masks``' bits over ``count`` lanes."""
    if not masks:
        return [0] if count else []
    size = (count + 7) // 8
    raw = np.frombuffer(b"".join(m.to_bytes(size, "little") for m in masks), dtype=np.uint8)
    bits = np.unpackbits(raw.reshape(len(masks), size), axis=1, bitorder="little")[:, :count]
    if len(masks) < 63:  # each lane's column as one integer
        keys = (bits.astype(np.int64) << np.arange(len(masks), dtype=np.int64)[:, None]).sum(axis=0)
        _, firsts = np.unique(keys, return_index=True)
    else:
        _, firsts = np.unique(bits.T, axis=0, return_index=True)
    return sorted(firsts.tolist())


def distinct_lanes(rows: Sequence[Sequence[int]], count: int) -> list[tuple[list[int], list[int] | None]]:
    """:func:`first_lanes` of every row of masks at once (rows of one length, ``count``
    lanes each), with the key of each lane kept: its column of bits as one integer (bit
    i: ``row[i]``), or None when a row has 63 masks or more (then one row at a time)."""
    if not rows:
        return []
    m = len(rows[0])
    if not m or m >= 63:
        return [(first_lanes(r, count), None) for r in rows]
    size = (count + 7) // 8
    out: list[tuple[list[int], list[int] | None]] = []
    for lo in range(0, len(rows), 4096):  # a bounded block of rows at a time
        block = rows[lo:lo + 4096]
        raw = np.frombuffer(b"".join(x.to_bytes(size, "little") for r in block for x in r), dtype=np.uint8)
        bits = np.unpackbits(raw.reshape(len(block), m, size), axis=2, bitorder="little")[:, :, :count]
        keys = (bits.astype(np.int64) << np.arange(m, dtype=np.int64)[None, :, None]).sum(axis=1)
        order = np.argsort(keys, axis=1, kind="stable")  # equal keys: the first lane first
        ranked = np.take_along_axis(keys, order, axis=1)
        new = np.ones(ranked.shape, dtype=bool)
        new[:, 1:] = ranked[:, 1:] != ranked[:, :-1]
        mark = np.zeros(keys.shape, dtype=bool)
        row, col = np.nonzero(new)
        mark[row, order[row, col]] = True
        row, lane = np.nonzero(mark)  # row by row, lanes ascending
        bounds = np.concatenate(([0], np.cumsum(np.bincount(row, minlength=len(block))))).tolist()
        lanes, found = lane.tolist(), keys[row, lane].tolist()
        out += [(lanes[a:b], found[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]
    return out


class ClassLanes(NamedTuple):
    """One class's cycle over every request vector: the lanes, each plant order's mask
    (passed-through orders included), the filter memory the explorer keeps after the cycle,
    and the masks that make an outcome (orders, that memory, blocked, fallback, outside care)."""

    lanes: Lanes
    out: dict[str, int]
    memory_after: list[int]
    masks: list[int]


def class_lanes(pr: "Product", ybits: int, aux: tuple, sit: Any) -> ClassLanes:
    """The cycle of the class (Y read ``ybits``, ``aux`` = (memory used, blocked, situation)
    before, situation ``sit`` after the controller's reaction) on every request vector (and Ack)."""
    cyc = pr.cycle
    mem_used, blocked, _ = aux
    values = {n: bool((ybits >> i) & 1) for i, n in enumerate(pr.ynames)}
    fixed = {n: values[n] for n in pr.filter.inputs}
    free: list[str] = []
    passed: dict[str, bool] = {}
    requested = pr.requested(sit, values)
    if requested is not None:
        fixed.update(requested[0])
        fixed.update({r: requested[1][o] for o, r in zip(cyc.outputs, cyc.requests)})
        passed = {o: requested[1][o] for o in pr.passthrough}
    else:
        fixed.update({r: pr.held[o] for o, r in zip(cyc.outputs, cyc.requests) if o in pr.held})
        passed = {o: pr.held[o] for o in pr.passthrough if o in pr.held}
        free = [r for o, r in zip(cyc.outputs, cyc.requests) if o not in pr.held]
        free += [o for o in pr.passthrough if o not in pr.held]
    if cyc.mode is Mode.BLOCKING:
        free.append(ACK)
    previous = [False] * len(cyc.remembered)
    for i, v in zip(pr.used_index, mem_used):
        previous[i] = v
    lanes = cyc.lanes(Memory(tuple(previous), blocked), fixed, free, diagnose=False)
    n = lanes.count
    out = dict(zip(cyc.outputs, lanes.outputs))  # lane masks
    for o in pr.passthrough:
        out[o] = ((1 << n) - 1 if passed[o] else 0) if o in passed else lane_mask(free.index(o), n)
    memory_after = [lanes.previous[i] for i in pr.used_index]
    masks = [*(out[o] for o in pr.orders), *memory_after, lanes.blocked, lanes.fallback, lanes.outside_care]
    return ClassLanes(lanes, out, memory_after, masks)


class OutcomeArrays:
    """Arrays over the outcomes found so far, extended with the new ones only."""

    def __init__(self, width: int) -> None:
        self.targets = np.zeros((0, width), dtype=bool)
        self.fallback = np.zeros(0, dtype=bool)
        self.outside = np.zeros(0, dtype=bool)
        self.aux = np.zeros(0, dtype=np.int64)
        self.requests = np.zeros((0, width), dtype=bool)

    def update(self, outcomes: Sequence[Outcome]
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        new = outcomes[self.aux.size:]
        if new:
            self.requests = np.concatenate((self.requests, np.array([o.requests for o in new], dtype=bool)
                                            .reshape(len(new), self.requests.shape[1])))
            self.targets = np.concatenate((self.targets, np.array([o.targets for o in new], dtype=bool)
                                           .reshape(len(new), self.targets.shape[1])))
            self.fallback = np.concatenate((self.fallback, np.array([o.fallback for o in new], dtype=bool)))
            self.outside = np.concatenate((self.outside, np.array([o.outside_care for o in new], dtype=bool)))
            self.aux = np.concatenate((self.aux, np.array([o.aux for o in new], dtype=np.int64)))
        return self.targets, self.fallback, self.outside, self.aux, self.requests


def react(pr: "Product", sit: Any, events: tuple[str, ...], ybits: int) -> Any:
    """The Grafcet's stable situation after a cycle's ``events``: a timer, or plant events
    (none, one, or up to ``--events-per-cycle``); the Grafcet reacts to each event on one
    of its inputs in turn, with the inputs as they were just after it. An ST program
    (``--control``) runs one scan on the inputs after the events."""
    values = {n: bool((ybits >> i) & 1) for i, n in enumerate(pr.ynames)}
    inputs = {n: values[n] for n in pr.grafcet_inputs}
    if pr.control is not None:  # one scan on the inputs after every event (or a timer)
        return pr.control.react(sit, events, inputs)
    assert pr.machine is not None
    if len(events) == 1 and Event(events[0]).kind is EventKind.TIMER:
        return pr.machine.fire_timer(sit, events[0], inputs)
    after: list[dict[str, bool]] = []
    for e in reversed(events):  # the inputs after each event, from the last one back
        after.append(dict(inputs))
        ev = Event(e)
        if ev.name in inputs:
            inputs[ev.name] = not ev.rising
    for e, seen in zip(events, reversed(after)):
        if Event(e).name in seen:
            sit = pr.machine.react_event(sit, Event(e), seen)[0]
    return sit


def situation_text(sit: Any) -> str:
    return "" if sit is None else sit.text()


def trace_row(pr: "Product", oc: Outcome, event: str, code: int, sit: Any, note: str = "") -> TraceRow:
    """One cycle of a trace: its events, the plant state after the write, the requests and orders."""
    req = tuple(o for o, v in zip(pr.orders, oc.requests) if v)
    out = tuple(o for o, v in zip(pr.orders, oc.targets) if v)
    extra = []
    if oc.violated:
        extra.append("requests violate " + ", ".join(oc.violated))
    if note:
        extra.append(note)
    return TraceRow(event, pr.label(code), situation_text(sit), req, out, "; ".join(extra))

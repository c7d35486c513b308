"""The closed loop: synth's plant automaton is the machine a real PLC runtime drives.

One step: fire one uncontrollable plant event (a sensor change, a free input) or let a timer of
the reference Grafcet elapse on the PLC's clock; write the sensors as the PLC sees them (faults
applied); wait whole scans (:class:`~synth.commission.links.Link`); read the orders; compare them
with the reference Grafcet's (:class:`~synth.grafcet.machine.GrafcetMachine`, what ``synth run``
steps): a difference is a **mismatch**; apply each changed order as the plant's controllable move:
a move the rules refuse or SUP forbids is **unsafe**. A walk where for ``blocked_after``
steps no event on offer could change the reference's situation (with no reference: where the
orders did not change), or a plant with no event left, is **blocked**
(:mod:`synth.commission.run` diagnoses it as ``validate`` does). With ``keep_going`` an unsafe
move is refused (the plant stays, as ``validate`` keeps a prohibited order unapplied), counted,
and the walk goes on.

Time: in lock-step the PLC clock is the scans granted times the task period, so a timer's
deadline is a number of scans; in real time it is the wall clock. A timer that would elapse
in the next scan is the next event, whatever the walk wanted, so the reference never falls
behind the PLC.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from enum import StrEnum
from typing import Callable, Sequence

from synth.commission.device import Timing
from synth.commission.faults import Fault, FaultKind, wire_values
from synth.commission.links import Link
from synth.commission.modbus import LinkError
from synth.grafcet.language import Grafcet
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.logic.events import Event
from synth.plant.composition import LocalTransition, Plant
from synth.sup.constraints import CompiledConstraints

WAIT = "+1s"
"""Without a reference Grafcet, the event "one second of PLC time passes"."""

__all__ = ["WAIT", "Outcome", "LoopStep", "Walk", "Stop", "Setup", "Choice", "ClosedLoop"]


class Outcome(StrEnum):
    """How a walk ended."""

    PASS = "pass"
    UNSAFE = "unsafe"
    MISMATCH = "mismatch"
    BLOCKED = "blocked"


@dataclass(frozen=True)
class LoopStep:
    """One closed-loop step: the event, the PLC's orders after it, the reference's (None without
    one), the reference's active steps, the plant state, the PLC scans since the reset."""

    event: str
    orders: tuple[str, ...]
    expected: tuple[str, ...] | None
    steps: tuple[str, ...]
    plant: str
    scans: int

    def as_dict(self) -> dict[str, object]:
        return {"event": self.event, "orders": list(self.orders),
                "expected": None if self.expected is None else list(self.expected),
                "steps": list(self.steps), "plant": self.plant, "scans": self.scans}


@dataclass(frozen=True)
class Walk:
    """A walk: its number and seed, its steps, how it ended and why."""

    index: int
    seed: int | None
    steps: tuple[LoopStep, ...]
    outcome: Outcome
    message: str = ""
    details: tuple[str, ...] = ()

    @property
    def trace(self) -> tuple[str, ...]:
        return tuple(s.event for s in self.steps[1:])


class Stop(Exception):
    """A walk ends: its outcome, the message and details."""

    def __init__(self, outcome: Outcome, message: str, details: Sequence[str] = ()) -> None:
        super().__init__(message)
        self.outcome, self.message, self.details = outcome, message, tuple(details)


@dataclass(frozen=True)
class Setup:
    """What every walk shares: the plant and its constraints, the reference Grafcet (or None),
    the sensors and orders on the wire, the faults, the blocked threshold."""

    plant: Plant
    oracle: CompiledConstraints
    grafcet: Grafcet | None
    sensors: tuple[str, ...]
    orders: tuple[str, ...]
    faults: tuple[Fault, ...] = ()
    blocked_after: int = 50
    keep_going: bool = False


@dataclass(frozen=True)
class Choice:
    """A possible next event: a plant transition (and its target) or a timer and its deadline (ms)."""

    label: str
    move: tuple[LocalTransition, tuple[int, ...]] | None = None
    deadline: int = 0


class ClosedLoop:
    """One walk's state: the plant, the reference, the PLC behind ``link``."""

    def __init__(self, setup: Setup, link: Link) -> None:
        self.s, self.link = setup, link
        self.lost = {f.name for f in setup.faults if f.kind is FaultKind.LOST}
        self.late = {(f.name, f.value): f.delay_ms for f in setup.faults if f.kind is FaultKind.LATE}
        self.machine = GrafcetMachine(setup.grafcet) if setup.grafcet is not None else None
        self.steps: list[LoopStep] = []
        self.unchanged = 0
        self.last: object = None
        self.fired: list[LocalTransition] = []
        self.refused: list[str] = []  # keep_going: the unsafe moves refused, with their traces

    # ------------------------------------------------------------------ time
    def clock(self) -> int:
        """The PLC's time since the reset, in ms (scans × period in lock-step)."""
        if self.link.timing is Timing.LOCKSTEP:
            return self.scans * self.link.period_ms
        return int((time.monotonic() - self.t0) * 1000)

    def run_scans(self, n: int) -> None:
        self.link.scans(n)
        self.scans += n

    def wait_until(self, deadline_ms: int) -> None:
        """Let the PLC's clock reach ``deadline_ms``, then one whole scan more."""
        if self.link.timing is Timing.LOCKSTEP:
            self.run_scans(max(1, math.ceil((deadline_ms - self.clock()) / self.link.period_ms)))
        else:
            time.sleep(max(0.0, (deadline_ms - self.clock()) / 1000))
            self.run_scans(1)

    # ------------------------------------------------------------------ the walk
    def start(self) -> None:
        p = self.s.plant
        self.local = p.initial
        self.values = p.valuation(self.local)
        self.wire = wire_values({n: self.values[n] for n in self.s.sensors}, self.s.faults)
        self.scans = 0
        self.link.reset(self.wire)
        self.t0 = time.monotonic()
        if not self.s.oracle.kept(self.local):
            raise Stop(Outcome.UNSAFE, "the plant's initial state is outside SUP")
        if self.machine is not None:
            self.inputs = {i: self.wire.get(i, self.values.get(i, False)) for i in self.machine.grafcet.inputs}
            self.sit: Situation = self.machine.initial(self.inputs)
        self.run_scans(1)
        if self.machine is not None:
            self.since = {s: self.clock() for s in self.sit.steps}
        self.after_scan("initial")

    def choices(self) -> list[Choice]:
        """The next possible events, in a stable order; a timer due in the next scan alone."""
        out = [Choice(str(t.event), (t, nxt)) for t, nxt in self.s.plant.successors(self.local) if not t.controllable]
        if self.machine is None:  # no reference, no timers known: time may pass, one second at a time
            out.append(Choice(WAIT, None, self.clock() + 1000))
        timer = self.next_timer()
        if timer is not None:
            margin = self.link.period_ms * (1 if self.link.timing is Timing.LOCKSTEP else 3) + \
                (0 if self.link.timing is Timing.LOCKSTEP else 50)
            if timer.deadline <= self.clock() + margin:
                return [timer]
            out.append(timer)
        return out

    def next_timer(self) -> Choice | None:
        if self.machine is None:
            return None
        g = self.machine.grafcet
        allowed = set(self.machine.timers(self.sit))
        due = sorted((self.since.get(t.step, 0) + int(t.seconds * 1000), t.id) for t in g.timers
                     if self.machine.timer_event(t.id) == t.id and Event.timer(t.id) in allowed)
        return Choice(due[0][1], None, due[0][0]) if due else None

    def fire(self, c: Choice) -> None:
        """Play ``c``: the plant's move or the time passing, the scans, the orders."""
        if c.move is None and self.machine is None:
            self.wait_until(c.deadline)
            self.after_scan(c.label)
            return
        if c.move is None:
            assert self.machine is not None
            self.wait_until(c.deadline)
            before = self.sit
            self.sit = self.machine.fire_timer(self.sit, c.label, self.inputs)
            self.entered(before)
            self.after_scan(c.label)
            return
        t, nxt = c.move
        self.fired.append(t)
        self.local = nxt
        self.values = self.s.plant.valuation(nxt)
        wire = wire_values({n: self.values[n] for n in self.s.sensors}, self.s.faults)
        delay = self.late.get((t.event.name, t.event.rising)) if wire != self.wire else None
        if delay:
            self.wait_until(self.clock() + delay)  # the PLC scans on with the old value
        self.link.write_sensors(wire)
        self.wire = wire
        self.run_scans(1)
        if self.machine is not None:
            after = {i: wire.get(i, self.inputs[i]) for i in self.inputs}
            if after != self.inputs:
                before = self.sit
                self.sit = self.machine.react(self.sit, self.inputs, after)
                self.inputs = after
                self.entered(before)
        self.after_scan(str(t.event))

    def entered(self, before: Situation) -> None:
        """Steps activated by the last reaction start their timers at this scan's clock."""
        now = self.clock()
        self.since = {s: (self.since[s] if s in before.steps and s in self.since else now) for s in self.sit.steps}

    def after_scan(self, event: str) -> None:
        got = self.link.read_orders()
        on = tuple(o for o in self.s.orders if got.get(o))
        expected = None
        steps: tuple[str, ...] = ()
        if self.machine is not None:
            emitted = self.machine.orders(self.sit, self.inputs)
            expected = tuple(o for o in self.s.orders if o in emitted)
            steps = tuple(self.sit.steps)
        self.steps.append(LoopStep(event, on, expected, steps, self.s.plant.label(self.local), self.scans))
        if expected is not None and on != expected:
            raise Stop(Outcome.MISMATCH, f"after {event} the PLC orders {_set(on)}, the Grafcet (synth run) "
                                         f"orders {_set(expected)}", (f"situation {self.sit.text()}",))
        self.apply(got)
        if self.machine is None:  # no reference: the orders tell whether anything moves
            self.unchanged = self.unchanged + 1 if on == self.last else 0
            self.last = on

    def moves(self, options: list[Choice]) -> bool:
        """Whether one of ``options`` would change the reference's situation (or its orders): a
        timer always does; a plant move does when the inputs the PLC then reads make it react."""
        assert self.machine is not None
        orders = self.machine.orders(self.sit, self.inputs)
        for c in options:
            if c.move is None:
                return True
            values = self.s.plant.valuation(c.move[1])
            wire = wire_values({n: values[n] for n in self.s.sensors}, self.s.faults)
            after = {i: wire.get(i, self.inputs[i]) for i in self.inputs}
            if after == self.inputs:
                continue
            sit = self.machine.react(self.sit, self.inputs, after)
            if sit != self.sit or self.machine.orders(sit, after) != orders:
                return True
        return False

    def apply(self, got: dict[str, bool]) -> None:
        """The PLC's orders as the plant's controllable moves, checked by the rules and SUP."""
        p = self.s.plant
        for o in self.s.orders:
            want = bool(got.get(o)) and o not in self.lost
            if o not in self.values or self.values[o] == want:
                continue
            event = Event.edge(o, want)
            move = next(((t, nxt) for t, nxt in p.successors(self.local) if t.controllable and t.event == event), None)
            why: list[str] = []
            if move is None:
                problem = f"the plant's rules refuse {event} in state {p.label(self.local)}"
            else:
                ok, why = self.s.oracle.move(move[0], self.local)
                problem = "" if ok else (f"{event} leaves SUP in state {p.label(self.local)}: constraint "
                                         f"{', '.join(why)} can then be violated")
            if problem and not self.s.keep_going:
                raise Stop(Outcome.UNSAFE, problem)
            if problem or move is None:
                trace = " ".join(st.event for st in self.steps[1:])
                self.refused.append(f"{problem} (trace {trace})")
                continue
            self.local = move[1]
            self.values = p.valuation(self.local)

    def walk(self, index: int, seed: int | None, steps: int, choose: Callable[[list[Choice]], Choice | None]) -> Walk:
        """Up to ``steps`` events chosen by ``choose`` (None: the script ended)."""
        try:
            self.start()
            for _ in range(steps):
                options = self.choices()
                if not options:
                    raise Stop(Outcome.BLOCKED, "no plant event can happen")
                if self.machine is not None:  # stuck: no event on offer would move the Grafcet
                    self.unchanged = 0 if self.moves(options) else self.unchanged + 1
                if self.unchanged >= self.s.blocked_after:
                    raise Stop(Outcome.BLOCKED, f"for {self.unchanged} steps no plant event could change the "
                                                f"{'situation' if self.machine else 'orders'}")
                c = choose(options)
                if c is None:
                    break
                self.fire(c)
        except Stop as stop:
            return self.ended(Walk(index, seed, tuple(self.steps), stop.outcome, stop.message, stop.details))
        except LinkError as err:  # what was reached, for the exit-2 message
            trace = " ".join(s.event for s in self.steps[1:]) or "-"
            raise LinkError(f"{err}; reached walk {index}, step {max(0, len(self.steps) - 1)} (trace {trace}), "
                            f"{self.scans} scans since its reset") from None
        return self.ended(Walk(index, seed, tuple(self.steps), Outcome.PASS))

    def ended(self, walk: Walk) -> Walk:
        """``keep_going``: a walk with refused moves is unsafe, its first refusal the message."""
        if not self.refused:
            return walk
        count = f"{len(self.refused)} step(s) with an unsafe move refused; the first: {self.refused[0]}"
        if walk.outcome is Outcome.PASS:
            return Walk(walk.index, walk.seed, walk.steps, Outcome.UNSAFE, self.refused[0].split(" (trace ")[0], (count,))
        return Walk(walk.index, walk.seed, walk.steps, walk.outcome, walk.message, (*walk.details, count))


def _set(names: Sequence[str]) -> str:
    return "{" + ", ".join(names) + "}"

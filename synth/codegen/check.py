"""The proof by execution: the generated ST, run by the interpreter, against ``synth run``.

:func:`differential_check` explores every sequence of events up to ``depth`` from the initial
situation and plays each one on both sides:

* synth's :class:`~synth.grafcet.machine.GrafcetMachine` (what ``synth run`` steps), one input
  event (``↑x``/``↓x``) or timer event (``2s/X101``) at a time;
* the generated program (:func:`~synth.codegen.grafcet_st.generate_program`) parsed into blark's tree and
  run by :mod:`synth.codegen.interpreter.machine`, one PLC cycle per event; a timer event is the clock
  advanced to 1 ms before the timer's preset, one cycle with unchanged inputs in which nothing
  may change (a timer that fires early is seen there), then 1 ms more and one cycle in which the
  timer fires (a timer that fires late is seen there). Where an idle scan would evolve the
  situation (``--semantics sfc``), the clock jumps to the preset at once.

After every cycle the active steps (``X<step>``) and the outputs must be equal; a transient
cycle that never stabilises (an :class:`~synth.errors.InputError` of the machine) must set the
program's ``Unstable`` flag. Time is real on the ST side, so a timer event is played only when
it is the next to elapse (timers of different steps elapsing at the same instant are one PLC
event but two machine events: such states are not extended by a timer event).

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet("grafcet G { initial step 0 step 1: A transition 0 -> 1 when ↑a "
...                   "transition 1 -> 0 when 2s/X1 }", "g.g7")
>>> report = differential_check(g, {"a": False}, depth=3)
>>> report.ok, report.sequences, report.cycles
(True, 3, 9)
>>> report.text().splitlines()[0]
'g.g7: the ST program equals synth run on 3 event sequences (9 PLC cycles, depth 3): 0 mismatches'
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Callable, Mapping, Protocol, Sequence

from synth.codegen.grafcet_st import generate_program
from synth.codegen.program import StProgram
from synth.errors import InputError, SynthError
from synth.grafcet.language import Grafcet
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.grafcet.situation import OutOfRange
from synth.logic.events import Event, EventKind

__all__ = ["Aspect", "Mismatch", "DifferentialReport", "ProgramRunner", "InterpretedProgram", "differential_check",
           "require_blark"]


class Aspect(StrEnum):
    """What differs between the program and ``synth run``."""

    STEPS = "active steps"
    OUTPUTS = "outputs"
    STABILITY = "stability"
    DATA = "internal values"


@dataclass(frozen=True)
class Mismatch:
    """One difference after the last event of ``events`` (``initial`` alone: the first cycle)."""

    events: tuple[str, ...]
    aspect: Aspect
    expected: str
    got: str

    def text(self) -> str:
        seq = "after " + ", ".join(self.events) if self.events else "initially"
        return f"{seq}: {self.aspect} of synth run {self.expected}, of the ST program {self.got}"


@dataclass(frozen=True)
class DifferentialReport:
    """The outcome of a differential check: counts and the first mismatches."""

    grafcet: str
    depth: int
    sequences: int
    cycles: int
    mismatches: tuple[Mismatch, ...] = field(default=())
    out_of_range: int = 0  # sequences ended by an assignment out of its range (synth refuses them)

    @property
    def ok(self) -> bool:
        return not self.mismatches

    def text(self) -> str:
        head = (f"{self.grafcet}: the ST program {'equals' if self.ok else 'differs from'} synth run on "
                f"{self.sequences} event sequences ({self.cycles} PLC cycles, depth {self.depth}): "
                f"{len(self.mismatches)} mismatch{'es' if len(self.mismatches) != 1 else ''}")
        if self.out_of_range:
            head += f" ({self.out_of_range} end in an assignment out of range, which synth refuses)"
        return "\n".join([head] + ["  " + m.text() for m in self.mismatches]) + "\n"


def _data_text(data: Sequence[tuple[str, int]]) -> str:
    return " ".join(f"{n}={v}" for n, v in data)


def _set_text(names: Sequence[str]) -> str:
    return "{" + ", ".join(names) + "}"


@dataclass
class _Side:
    """The machine's state along one sequence: situation, inputs, clock, step activation times."""

    sit: Situation
    inputs: dict[str, bool]
    now: int
    since: dict[str, int]  # active step -> clock (ms) of its last activation


class ProgramRunner(Protocol):
    """One side of the check: a PLC program that runs cycles on a clock, whose state can be
    saved and restored (the exploration backtracks). Names are the program's ST names."""

    def cycle(self, inputs: Mapping[str, bool]) -> None:
        """Set ``inputs`` (the others keep their values) and run one PLC cycle."""

    def value(self, name: str) -> bool:
        """A Boolean variable of the program after the last cycle."""

    def number(self, name: str) -> int:
        """An integer variable of the program after the last cycle."""

    def advance(self, ms: int) -> None:
        """Move the PLC clock on by ``ms`` milliseconds."""

    def save(self) -> object:
        """The program's whole state (variables, timers, clock)."""

    def restore(self, saved: object) -> None:
        """Go back to a state :meth:`save` returned."""


class InterpretedProgram:
    """The generated program parsed into blark's tree and run by :mod:`synth.codegen.interpreter.machine`."""

    def __init__(self, program: StProgram, file: str) -> None:
        from synth.codegen.interpreter.machine import load_st

        self.module = load_st(program.text, file)
        self.inst = self.module.instance(program.program)
        self.memo_base: dict[int, object] = {id(self.module): self.module}
        for unit in self.module.pous.values():
            self.memo_base[id(unit)] = unit

    def cycle(self, inputs: Mapping[str, bool]) -> None:
        self.inst.cycle(dict(inputs))

    def value(self, name: str) -> bool:
        return bool(self.inst[name])

    def number(self, name: str) -> int:
        return int(self.inst[name])

    def advance(self, ms: int) -> None:
        self.module.advance(ms)

    def save(self) -> object:
        return copy.deepcopy(self.inst, dict(self.memo_base)), self.module.clock_ms

    def restore(self, saved: object) -> None:
        self.inst, self.module.clock_ms = saved  # type: ignore[misc]


class _Checker:
    def __init__(self, g: Grafcet, initial: Mapping[str, bool], depth: int, program: StProgram,
                 runner: ProgramRunner, max_mismatches: int) -> None:
        self.g = g
        self.depth = depth
        self.program = program
        self.machine = GrafcetMachine(g)
        self.runner = runner
        self.initial = {n: bool(initial.get(n, False)) for n in g.inputs}
        self.max_mismatches = max_mismatches
        self.mismatches: list[Mismatch] = []
        self.sequences = 0
        self.cycles = 0
        self.out_of_range = 0
        self.report: Callable[[str], None] | None = None  # progress lines (the CLI's live line)
        self.started = time.monotonic()
        self.ms = {t.id: int(t.seconds * 1000) for t in g.timers}
        self.step_of = {t.id: t.step for t in g.timers}

    # ------------------------------------------------------------------ both sides
    def compare(self, events: tuple[str, ...], side: _Side | None) -> bool:
        """Compare after a cycle; False when the branch must stop (a mismatch or instability)."""
        run, p = self.runner, self.program
        self.cycles += 1
        if self.report is not None and self.cycles % 8 == 0:
            rate = self.cycles / max(time.monotonic() - self.started, 1e-6)
            self.report(f"ST against synth run: {self.sequences} event sequences, {self.cycles} PLC cycles "
                        f"({rate:.0f} cycles/s), {len(self.mismatches)} mismatches")
        unstable = run.value("Unstable")
        if side is None:  # the machine found a transient cycle that never stabilises
            if not unstable:
                self.mismatch(events, Aspect.STABILITY, "never stabilises", "stable (Unstable = FALSE)")
            return False
        if unstable:
            self.mismatch(events, Aspect.STABILITY, "stable", "Unstable = TRUE")
            return False
        want = tuple(side.sit.step_variables)
        got = tuple(s.variable for s in self.g.steps if run.value(p.st_name(s.variable)))
        if sorted(want) != sorted(got):
            self.mismatch(events, Aspect.STEPS, _set_text(want), _set_text(got))
            return False
        if side.sit.data:
            got_d = tuple((n, run.number(p.st_name(n))) for n, _ in side.sit.data)
            if got_d != side.sit.data:
                self.mismatch(events, Aspect.DATA, _data_text(side.sit.data), _data_text(got_d))
                return False
        orders = self.machine.orders(side.sit, side.inputs)
        want_o = tuple(o for o in self.g.outputs if o in orders)
        got_o = tuple(o for o in self.g.outputs if run.value(p.st_name(o)))
        if want_o != got_o:
            self.mismatch(events, Aspect.OUTPUTS, _set_text(want_o), _set_text(got_o))
            return False
        return True

    def mismatch(self, events: tuple[str, ...], aspect: Aspect, expected: str, got: str) -> None:
        if len(self.mismatches) < self.max_mismatches:
            self.mismatches.append(Mismatch(events, aspect, expected, got))

    def run(self) -> None:
        try:
            sit = self.machine.initial(self.initial)
            side: _Side | None = _Side(sit, dict(self.initial), 0, {s: 0 for s in sit.steps})
        except OutOfRange:  # synth refuses the initial situation itself
            self.out_of_range += 1
            self.sequences += 1
            return
        except InputError:
            side = None
        self.runner.cycle({self.program.st_name(n): v for n, v in self.initial.items()})
        if self.compare((), side) and side is not None:
            self.explore(side, ())
        else:
            self.sequences += 1

    # ------------------------------------------------------------------ exploration
    def events(self, side: _Side) -> list[tuple[Event, int]]:
        """Input events (every input), then the next timer to elapse with its delay, then (IEC
        61131-3 SFC) a scan without input change when one would evolve the situation."""
        out = [(Event.edge(n, not side.inputs[n]), 0) for n in self.g.inputs]
        if self.machine.scans(side.sit, side.inputs):
            out.append((Event.scan(), 0))
        running = [t for t in self.machine.timers(side.sit)]
        if running:
            elapsed = set(side.sit.elapsed)
            due = {t.id: side.since[t.step] + self.ms[t.id] for t in self.g.timers
                   if t.step in side.since and t.id not in elapsed}
            first = min(due.values())
            groups = {self.machine.timer_event(t) for t, d in due.items() if d == first}
            if len(groups) == 1:
                (event,) = groups
                if event in running:
                    out.append((event, first - side.now))
        return out

    def step(self, side: _Side, event: Event, delay: int) -> _Side | None:
        """The machine after ``event`` (``delay`` ms after the last one); None when it never
        stabilises; :class:`OutOfRange` (the model refuses the event) goes up."""
        try:
            if event.is_edge:
                after = dict(side.inputs)
                after[event.name] = event.rising
                sit, rounds = self.machine.react_with_trace(side.sit, side.inputs, after)
                inputs, now = after, side.now
            elif event.kind is EventKind.SCAN:
                sit, rounds = self.machine.scan(side.sit, side.inputs)
                inputs, now = side.inputs, side.now
            else:
                inputs = side.inputs
                now = side.now + delay
                sit, rounds = self.machine.fire_timer_with_trace(side.sit, event, inputs)
        except OutOfRange:
            raise
        except InputError:
            return None
        restarted = set(sit.steps) - set(side.sit.steps)
        for fire in rounds:
            deact = {s for t in fire for s in t.sources}
            act = {s for t in fire for s in t.targets}
            restarted |= deact - act
        since = {s: (now if s in restarted else side.since[s]) for s in sit.steps}
        return _Side(sit, inputs, now, since)

    def before_preset(self, side: _Side, events: tuple[str, ...], event: Event, delay: int) -> bool:
        """One PLC cycle 1 ms before the timer event's preset (the clock advanced ``delay - 1``
        ms, inputs unchanged): nothing may have changed yet, so a timer that fires early is
        seen (its own cycle at the preset then shows one that fires late). False on a mismatch."""
        self.runner.advance(delay - 1)
        self.runner.cycle({})
        return self.compare(events + (f"{delay - 1} ms before {event}",), side)

    def explore(self, side: _Side, events: tuple[str, ...]) -> None:
        if len(events) == self.depth or len(self.mismatches) >= self.max_mismatches:
            self.sequences += 1
            return
        for event, delay in self.events(side):
            try:
                nxt = self.step(side, event, delay)
            except OutOfRange:  # synth refuses the assignment: no behaviour to compare with
                self.sequences += 1
                self.out_of_range += 1
                continue
            saved = self.runner.save()
            probe = delay > 1 and not self.machine.scans(side.sit, side.inputs)
            if probe and not self.before_preset(side, events, event, delay):
                self.sequences += 1
                self.runner.restore(saved)
                continue
            if delay:
                self.runner.advance(1 if probe else delay)
            if event.is_edge:
                self.runner.cycle({self.program.st_name(event.name): event.rising})
            else:
                self.runner.cycle({})
            seq = events + (str(event),)
            if self.compare(seq, nxt) and nxt is not None:
                self.explore(nxt, seq)
            else:
                self.sequences += 1
            self.runner.restore(saved)


def differential_check(
    g: Grafcet,
    initial: Mapping[str, bool] | None = None,
    *,
    depth: int = 4,
    program: StProgram | None = None,
    max_mismatches: int = 10,
    runner: Callable[[StProgram], ProgramRunner] | None = None,
    report: Callable[[str], None] | None = None,
) -> DifferentialReport:
    """Play every event sequence of length ``depth`` on ``synth run``'s machine and on the
    generated program (``program``, else :func:`generate_program` of ``g``), comparing active
    steps, outputs and stability after every cycle. ``initial``: the input values at start
    (missing ones are 0). ``runner`` runs the program (default: :class:`InterpretedProgram`;
    the tests also plug in the C that MATIEC's ``iec2c`` compiles); ``report`` receives
    progress lines. Without blark (a test extra), a :class:`~synth.errors.SynthError` that
    says how to install it."""
    program = program or generate_program(g, version="check")
    if runner is None:
        require_blark("synth st --check")
        side: ProgramRunner = InterpretedProgram(program, f"{g.path}.st")
    else:
        side = runner(program)
    checker = _Checker(g, initial or {}, depth, program, side, max_mismatches)
    checker.report = report
    checker.run()
    return DifferentialReport(g.path, depth, checker.sequences, checker.cycles, tuple(checker.mismatches),
                              checker.out_of_range)


def require_blark(what: str) -> None:
    """``what`` runs generated Structured Text through blark (the IEC 61131-3 parser the ST
    interpreter reads): stop with a message naming the extra when it is not installed."""
    import importlib.util

    if importlib.util.find_spec("blark") is None:
        raise SynthError(f"{what} needs blark, the IEC 61131-3 parser it runs the generated code with: "
                         "pip install blark (a dependency of synth: install synth again)")

"""A commissioning run: walks of the closed loop (scripted, seeded, or aimed at what is not yet
covered), once without faults and once per fault; blocked walks diagnosed as ``validate`` does;
the coverage of the plant transitions and Grafcet steps reachable under the Grafcet.
"""

from __future__ import annotations

import random
import time
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Callable, Sequence

from synth.commission.faults import Fault
from synth.commission.links import Link
from synth.commission.loop import Choice, ClosedLoop, Outcome, Setup, Walk
from synth.errors import InputError, Location
from synth.grafcet.simulation import comma_items
from synth.logic.events import RISE_MARKS, FALL_MARKS, Event
from synth.plant.composition import LocalTransition
from synth.plant.rules import RuleSet

__all__ = ["FaultRun", "Coverage", "CommissionResult", "Commissioning"]

Key = tuple[int, int, int, str]


def _key(t: LocalTransition) -> Key:
    return (t.axis, t.src, t.dst, str(t.event))


@dataclass(frozen=True)
class FaultRun:
    """The walks run under one fault (None: the machine as modelled)."""

    fault: Fault | None
    walks: tuple[Walk, ...]

    @property
    def failed(self) -> tuple[Walk, ...]:
        """Walks that fail the run: any finding without a fault; under a fault, an unsafe move or
        a mismatch (a worn machine may block the line, never make it unsafe)."""
        bad = (Outcome.UNSAFE, Outcome.MISMATCH) if self.fault else (Outcome.UNSAFE, Outcome.MISMATCH, Outcome.BLOCKED)
        return tuple(w for w in self.walks if w.outcome in bad)


@dataclass(frozen=True)
class Coverage:
    """Plant transitions (element moves on uncontrollable events) and Grafcet steps seen,
    against those reachable under the Grafcet (``validate``'s SYNC)."""

    transitions: tuple[str, ...]  # every reachable one, as "element: event (src -> dst)"
    transitions_seen: tuple[str, ...]
    steps: tuple[str, ...]
    steps_seen: tuple[str, ...]

    def as_dict(self) -> dict[str, object]:
        return {"plant_transitions": {"reachable": len(self.transitions), "seen": len(self.transitions_seen),
                                      "missing": [t for t in self.transitions if t not in self.transitions_seen]},
                "grafcet_steps": {"reachable": len(self.steps), "seen": len(self.steps_seen),
                                  "missing": [s for s in self.steps if s not in self.steps_seen]}}


@dataclass(frozen=True)
class CommissionResult:
    """Everything one ``synth commission`` found."""

    target: str
    protocol: str
    timing: str
    runs: tuple[FaultRun, ...]
    coverage: Coverage | None
    seconds: float

    @property
    def ok(self) -> bool:
        return not any(r.failed for r in self.runs)

    @property
    def steps(self) -> int:
        return sum(len(w.steps) for r in self.runs for w in r.walks)


class Commissioning:
    """The walks of one run over ``link``; ``validation`` (a function) gives ``validate``'s result
    for the diagnoses and the coverage target, computed once when first needed."""

    def __init__(self, setup: Setup, link: Link, rules: RuleSet,
                 progress: Callable[[str], None] | None = None) -> None:
        self.setup, self.link, self.rules, self.progress = setup, link, rules, progress

    @cached_property
    def validation(self) -> object:
        from synth.validation.validate import validate_loaded

        assert self.setup.grafcet is not None
        return validate_loaded(self.rules, self.setup.plant, self.setup.grafcet)

    def label(self, t: LocalTransition) -> str:
        e = self.setup.plant.elements[t.axis]
        return f"{e.name}: {t.event} ({t.src} -> {t.dst})"

    def reachable(self) -> tuple[list[LocalTransition], list[str]]:
        """The uncontrollable plant transitions on SYNC's edges, the steps of its situations."""
        v = self.validation
        p = self.setup.plant
        found: dict[Key, LocalTransition] = {}
        for e in v.sync.edges:  # type: ignore[attr-defined]
            if not e.event.is_edge:
                continue
            local = v.sync.nodes[e.source].plant  # type: ignore[attr-defined]
            axis = p.owner.get(e.event.name)
            for t in p.transitions:
                if t.axis == axis and t.src == local[axis] and t.event == e.event and not t.controllable:
                    found.setdefault(_key(t), t)
        steps = sorted({s for n in v.sync.nodes for s in n.situation.steps},  # type: ignore[attr-defined]
                       key=lambda s: (len(s), s))
        return [found[k] for k in sorted(found)], steps

    def one(self, index: int, seed: int | None, steps: int, choose: Callable[[list[Choice]], Choice | None],
            fault: Fault | None) -> tuple[Walk, ClosedLoop]:
        setup = replace(self.setup, faults=(fault,) if fault else ())
        loop = ClosedLoop(setup, self.link)
        walk = loop.walk(index, seed, steps, choose)
        if walk.outcome is Outcome.BLOCKED and setup.grafcet is not None:
            walk = replace(walk, details=walk.details + self.diagnosis(walk))
        if self.progress is not None:
            self.progress(f"walk {index}{' under ' + fault.text if fault else ''}: {walk.outcome}, "
                          f"{len(walk.steps) - 1} steps, {loop.scans} scans")
        return walk, loop

    def diagnosis(self, walk: Walk) -> tuple[str, ...]:
        """``validate``'s diagnosis of the blocking situation whose steps the walk ended in."""
        v = self.validation
        steps = set(walk.steps[-1].steps)
        for b in v.analysis.blocking:  # type: ignore[attr-defined]
            members = v.analysis.components.get(b, (b,))  # type: ignore[attr-defined]
            if any(set(v.sync.nodes[m].situation.steps) == steps for m in members):  # type: ignore[attr-defined]
                d = v.diagnoses[b]  # type: ignore[attr-defined]
                trace = " ".join(v.analysis.traces[b].events)  # type: ignore[attr-defined]
                return (f"diagnosis [{d.verdict}]: {d.summary}", *d.details, f"validate's trace: {trace}")
        return ("validate finds no blocking situation with these steps",)

    def scripted(self, text: str, faults: Sequence[Fault]) -> list[FaultRun]:
        items = list(comma_items(text))
        wanted = [(str(_event(item)), Location("--events", 1, col, text, len(item))) for item, col in items]

        def choose(options: list[Choice]) -> Choice | None:
            if not wanted:
                return None
            label, loc = wanted.pop(0)
            for c in options:
                if c.label == label:
                    return c
            raise InputError(f"{label} cannot happen now", loc, suggestions=tuple(c.label for c in options)[:6])

        runs = []
        for fault in (None, *faults):
            wanted[:] = [(str(_event(item)), Location("--events", 1, col, text, len(item))) for item, col in items]
            walk = self.one(1, None, len(items), choose, fault)[0]
            if walk.outcome is Outcome.PASS and self.setup.grafcet is not None:  # where the script left the PLC
                found = self.diagnosis(walk)
                if found[0].startswith("diagnosis"):
                    walk = replace(walk, outcome=Outcome.BLOCKED, details=found,
                                   message="the script ends in a blocking situation (validate's)")
            runs.append(FaultRun(fault, (walk,)))
        return runs

    def walks(self, count: int, steps: int, seed: int, faults: Sequence[Fault], cover: bool) -> tuple[list[FaultRun], Coverage | None]:
        target: set[Key] = set()
        if cover and self.setup.grafcet is not None:
            reach, _ = self.reachable()
            target = {_key(t) for t in reach}
        seen: set[Key] = set()
        seen_steps: set[str] = set()
        runs = []
        for fault in (None, *faults):
            out = []
            for k in range(1, count + 1):
                rng = random.Random(seed * 1_000_003 + k)

                def choose(options: list[Choice]) -> Choice | None:
                    fresh = [c for c in options if c.move is not None and _key(c.move[0]) in target - seen]
                    c = rng.choice(fresh or options)
                    if c.move is not None and fault is None:
                        seen.add(_key(c.move[0]))
                    return c

                walk, loop = self.one(k, seed, steps, choose, fault)
                if fault is None:
                    seen_steps.update(s for st in walk.steps for s in st.steps)
                out.append(walk)
            runs.append(FaultRun(fault, tuple(out)))
        coverage = None
        if cover and self.setup.grafcet is not None:
            reach, steps_all = self.reachable()
            coverage = Coverage(tuple(self.label(t) for t in reach), tuple(self.label(t) for t in reach if _key(t) in seen),
                                tuple(steps_all), tuple(s for s in steps_all if s in seen_steps))
        return runs, coverage


def _event(item: str) -> Event:
    if item[0] in RISE_MARKS + FALL_MARKS:
        return Event.edge(item[1:].strip(), item[0] in RISE_MARKS)
    return Event.timer(item)


def run_commission(c: Commissioning, *, target: str, protocol: str, events: str | None, walks: int, steps: int,
                   seed: int, faults: Sequence[Fault], cover: bool) -> CommissionResult:
    """The whole run: ``events`` (a script) or ``walks`` seeded walks of ``steps`` events."""
    start = time.monotonic()
    coverage = None
    if events is not None:
        runs = c.scripted(events, faults)
    else:
        runs, coverage = c.walks(walks, steps, seed, faults, cover)
    return CommissionResult(target, protocol, str(c.link.timing), tuple(runs), coverage, time.monotonic() - start)

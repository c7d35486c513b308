"""``validate --engine auto``'s probe: the first SYNC states of the explicit exploration,
counted breadth-first layer by layer, within a budget.

The explicit engine pays per SYNC state (a plant state of SUP paired with a stable
situation, docs/method.md); the symbolic one per breadth-first level and per BDD node,
whatever the number of states a level holds. Which one is faster thus depends on how many
SYNC states there are, which no count read off the inputs tells (plant states × steps
overestimates by orders of magnitude, and the Grafcet's concurrency says how wide a region
is, not how many situations follow each other). The probe measures it: it explores SYNC as
the explicit engine does (:func:`synth.validation.sync.region` for each situation's
region, the plant's uncontrollable moves and the timers between regions, breadth-first
over the aggregated states) and stops once it has met ``budget`` SYNC states. It keeps
counts only: the SYNC states of each complete layer, the states met in all, whether the
exploration ended within the budget. :mod:`synth.engines` decides on those counts
(never on time, so the choice is the same on every machine and every run).

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> rs, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> g1 = probe(p, rs.constraints, g, budget=10_000)
>>> g1.stop, g1.states, g1.widest
(<Stop.DONE: 'done'>, 150, 15)
>>> g2 = probe(p, rs.constraints, g, budget=40)
>>> g2.stop, g2.layers
(<Stop.BUDGET: 'budget'>, (1, 2, 3, 6, 6, 9, 9, 5))
>>> probe(p, rs.constraints, g, budget=10_000, wide=5).stop
<Stop.WIDE: 'wide'>
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, replace
from enum import Enum
from typing import Sequence

from synth.errors import LimitExceeded
from synth.grafcet.language import Grafcet
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.grafcet.situation import OutOfRange
from synth.plant.composition import Plant
from synth.plant.rules import Constraint, RuleSet
from synth.sup.constraints import CompiledConstraints
from synth.validation.result import Validation
from synth.validation.sync import grafcet_inputs, moves_by_order, region
from synth.validation.validate import validate_loaded

__all__ = ["Stop", "Growth", "probe", "measure"]

Local = tuple[int, ...]


class Stop(Enum):
    """Why the probe stopped."""

    RAN = "ran"  # the explicit engine itself explored SYNC whole (``layers``: its size alone)
    DONE = "done"  # SYNC explored whole: ``states`` is its size
    WIDE = "wide"  # a layer holds more than ``wide`` SYNC states
    BUDGET = "budget"  # more than ``budget`` SYNC states met, every layer narrower
    ERROR = "error"  # an internal variable out of range: the engine that runs says where


@dataclass(frozen=True)
class Growth:
    """What the probe met: ``layers``, the SYNC states first met in each breadth-first layer
    of aggregated states (the initial region's first, the layer it stopped in last);
    ``states``, their sum; ``stop``, why it stopped; ``per_situation``, set by the chooser: the symbolic engine would
    explore this Grafcet one stable situation at a time (timers, stored actions, …)."""

    layers: tuple[int, ...]
    stop: Stop
    per_situation: bool = False

    @property
    def states(self) -> int:
        return sum(self.layers)

    @property
    def widest(self) -> int:
        return max(self.layers, default=0)


def probe(p: Plant, constraints: Sequence[Constraint], g: Grafcet, budget: int, wide: int | None = None) -> Growth:
    """SYNC of ``g`` against ``p`` and ``constraints``, explored breadth-first until it ends,
    more than ``budget`` SYNC states are met, or one layer holds more than ``wide`` (see the
    module docstring)."""
    oracle = CompiledConstraints(p, constraints)  # cached per plant: the engine that runs reuses it
    if not oracle.kept(p.initial):
        return Growth((), Stop.DONE)
    machine = GrafcetMachine(g)
    moves = moves_by_order(p)
    uncontrollable = [t for t in p.transitions if not t.controllable]
    seen: set[tuple[Situation, Local]] = set()  # SYNC states
    entered: set[tuple[Situation, Local]] = set()  # regions entered
    nodes: set[tuple[Situation, Local]] = set()  # aggregated states
    layers: list[int] = [0]
    queue: deque[tuple[int, Situation, Local]] = deque()
    read: dict[Local, dict[str, bool]] = {}  # the Grafcet's inputs per plant state, read once

    def inputs(local: Local) -> dict[str, bool]:
        hit = read.get(local)
        if hit is None:
            hit = read[local] = grafcet_inputs(p, machine, local)
        return hit

    def enter(sit: Situation, entry: Local, depth: int) -> None:
        if (sit, entry) in entered:
            return
        entered.add((sit, entry))
        members, settled = region(p, oracle, entry, machine.orders(sit, inputs(entry)), moves)
        fresh = [m for m in members if (sit, m) not in seen]
        seen.update((sit, m) for m in fresh)
        if depth == len(layers):
            layers.append(0)
        layers[depth] += len(fresh)
        for q, _ in settled:
            if (sit, q) not in nodes:
                nodes.add((sit, q))
                queue.append((depth, sit, q))

    try:
        enter(machine.initial(inputs(p.initial)), p.initial, 0)
        while queue:
            depth, sit, cur = queue.popleft()
            before = inputs(cur)
            for t in uncontrollable:
                if t.src != cur[t.axis] or not p.enabled(t, cur):
                    continue
                n = cur[: t.axis] + (t.dst,) + cur[t.axis + 1:]
                if oracle.kept(n):
                    enter(machine.react(sit, before, inputs(n)), n, depth + 1)
            for timer in machine.timers(sit):
                enter(machine.fire_timer(sit, timer, before), cur, depth + 1)
            if wide is not None and layers[-1] > wide:
                return Growth(tuple(layers), Stop.WIDE)
            if sum(layers) > budget:
                return Growth(tuple(layers), Stop.BUDGET)
    except OutOfRange:
        return Growth(tuple(layers), Stop.ERROR)
    return Growth(tuple(layers), Stop.DONE)


def measure(rs: RuleSet, p: Plant, g: Grafcet, limits: tuple[int, int, int, int], *, expert: bool = False,
            homes: Sequence[str] = (), max_states: int | None = None) -> tuple[Growth, Validation | None]:
    """What ``validate --engine auto`` measures, ``limits`` being (nodes, budget, layer, steep):
    the explicit engine first, within ``nodes`` aggregated states (and ``max_states``); when
    SYNC ends there, :attr:`Stop.RAN` and its result, to be kept. Else the probe's counts
    (``budget``, ``layer``), marked :attr:`Growth.per_situation` when its wide layer came
    after ``steep`` states and the symbolic engine would explore one situation at a time."""
    nodes, budget, layer, steep = limits
    try:
        done = validate_loaded(rs, p, g, expert=expert, homes=homes, max_states=min(nodes, max_states or nodes))
        return Growth((done.sync.sync_states,), Stop.RAN), done
    except LimitExceeded:
        pass
    counts = probe(p, rs.constraints, g, budget, layer)
    if counts.stop is Stop.WIDE and counts.states > steep:
        from synth.symbolic.validate import SymbolicPath, choose_path  # dd: the symbolic engine likely runs next

        if choose_path(GrafcetMachine(g), p).path is SymbolicPath.SITUATIONS:
            return replace(counts, per_situation=True), None
    return counts, None

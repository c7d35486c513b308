"""``validate --engine auto``'s measure: the explicit engine's own run, watched.

The explicit engine pays per SYNC state (a plant state of SUP paired with a stable
situation, docs/method.md); the symbolic one per breadth-first level and per BDD node,
whatever the number of states a level holds. Which one is faster depends on how SYNC
grows, which no count read off the inputs tells (plant states × steps overestimates by
orders of magnitude). So ``auto`` starts the explicit engine itself and watches its
exploration (:func:`synth.validation.validate.explore`'s ``watch``: after each state, or
each breadth-first frontier, expanded, the aggregated states met and those still waiting):

- SYNC explored whole before the decision point: that run's result is the one kept
  (:attr:`Stop.RAN`); nothing runs twice and ``dd`` is never imported;
- at the decision point (``nodes`` aggregated states met), the share of those met that
  still wait says how steeply SYNC grows: above ``share`` percent (``machine_share`` where
  the explicit engine explores state by state, about five times slower per state:
  :func:`synth.validation.frontier.reason` says so) the run stops and the symbolic engine
  runs (:attr:`Stop.STEEP`); otherwise the same run goes on to the end and its result is
  kept (:attr:`Stop.NARROW`): the explicit engine chosen has lost nothing.

Counts only, never time: the same choice on every machine and every run. :mod:`synth.engines`
holds the constants and words the reason.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> rs, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> counts, done = measure(rs, p, g, Points(400, 45, 30, 50))
>>> counts.stop, counts.sync_states, done.sync.sync_states
(<Stop.RAN: 'ran'>, 150, 150)
"""

from __future__ import annotations

from enum import Enum
from typing import TYPE_CHECKING, Callable, Sequence

from synth.errors import LimitExceeded
from synth.frozen import frozen

if TYPE_CHECKING:  # pragma: no cover - imported when measuring: synth.engines reads Points at start-up
    from synth.grafcet.language import Grafcet
    from synth.plant.composition import Plant
    from synth.plant.rules import RuleSet
    from synth.validation.result import Validation
    from synth.validation.sync import Exploration

__all__ = ["Stop", "Points", "Growth", "measure"]


class Stop(Enum):
    """How the watched explicit run ended."""

    RAN = "ran"  # SYNC explored whole before the decision point: ``sync_states`` is its size
    NARROW = "narrow"  # at the decision point, no more than the share waiting: the run went on, kept
    STEEP = "steep"  # at the decision point, more than the share waiting: the run stopped
    ERROR = "error"  # an internal variable out of range: the explicit engine says where


@frozen
class Points:
    """Where and on what the run is judged: after ``nodes`` aggregated states, steep when
    more than ``share`` percent of them wait (``machine_share`` where the explicit engine
    explores state by state; ``situation_share`` where the symbolic engine would explore one
    stable situation at a time: timers, stored actions, internal variables)."""

    nodes: int
    share: int
    machine_share: int
    situation_share: int


@frozen
class Growth:
    """What the watched run met: at the decision point (or where it ended before),
    ``met`` aggregated states, ``waiting`` of them not yet expanded; ``stop``, how it ended;
    ``machine``: why the explicit engine explored state by state (None: a frontier at a
    time); ``per_situation``: the symbolic engine would explore one stable situation at a
    time; ``sync_states``: SYNC's size, when explored whole; ``share``: the percent it was
    judged against."""

    met: int
    waiting: int
    stop: Stop
    machine: str | None = None
    per_situation: bool = False
    sync_states: int = 0
    share: int = 0


class _Steep(Exception):
    """Stops the watched run: the symbolic engine runs instead."""


class _Watch:
    """The explicit run's watcher: decides once, at the first decision point passed."""

    def __init__(self, p: Plant, g: Grafcet, points: Points) -> None:
        self.p, self.g, self.points = p, g, points
        self.growth: Growth | None = None
        self.path: tuple[str | None] | None = None  # the frontier's reason, once asked
        self.last = (0, 0)

    def machine(self) -> str | None:
        """Why the explicit engine explores this model state by state (None: a frontier at a time)."""
        if self.path is None:
            from synth.grafcet.machine import GrafcetMachine
            from synth.validation.frontier import reason

            self.path = (reason(self.p, GrafcetMachine(self.g)),)
        return self.path[0]

    def __call__(self, met: int, waiting: int) -> None:
        self.last = (met, waiting)
        if self.growth is not None or met < self.points.nodes:
            return
        self.judge(met, waiting)
        if self.growth is not None and self.growth.stop is Stop.STEEP:
            raise _Steep

    def judge(self, met: int, waiting: int) -> None:
        """Decide on the counts at the decision point."""
        why = self.machine()
        self.growth = self.judged(met, waiting, why, self.points.share if why is None else self.points.machine_share)

    def judged(self, met: int, waiting: int, why: str | None, share: int) -> Growth:
        """Steep when more than ``share`` percent of ``met`` wait (and, where the symbolic
        engine would explore per stable situation, more than its own share)."""
        if 100 * waiting <= share * met:
            return Growth(met, waiting, Stop.NARROW, why, share=share)
        if 100 * waiting <= self.points.situation_share * met:
            from synth.grafcet.machine import GrafcetMachine
            from synth.symbolic.validate import SymbolicPath, choose_path  # dd: the symbolic engine likely runs next

            if choose_path(GrafcetMachine(self.g), self.p).path is SymbolicPath.SITUATIONS:
                return Growth(met, waiting, Stop.NARROW, why, per_situation=True, share=share)
        return Growth(met, waiting, Stop.STEEP, why, share=share)


def measure(rs: RuleSet, p: Plant, g: Grafcet, points: Points, *, expert: bool = False, homes: Sequence[str] = (),
            how: Exploration | None = None) -> tuple[Growth, Validation | None]:
    """What ``validate --engine auto`` measures (see the module docstring): the counts, and
    the explicit engine's result when it is the one to keep (:attr:`Stop.RAN`,
    :attr:`Stop.NARROW`); None when the symbolic engine is to run (:attr:`Stop.STEEP`) or
    the explicit engine is to run again and say where a variable went out of range
    (:attr:`Stop.ERROR`). ``how``: the explicit engine's exploration (watched here): its
    ``max_states`` bounds the run as it bounds the explicit engine (met before the decision
    point, the counts there decide; the explicit engine, chosen, says it is over), its
    ``progress`` gets the explicit engine's progress."""
    from dataclasses import replace

    from synth.grafcet.situation import OutOfRange
    from synth.validation.sync import Exploration
    from synth.validation.validate import validate_loaded

    watch = _Watch(p, g, points)
    try:
        done = validate_loaded(rs, p, g, expert=expert, homes=homes, how=replace(how or Exploration(), watch=watch))
    except _Steep:
        assert watch.growth is not None
        return watch.growth, None
    except OutOfRange:
        return Growth(*watch.last, Stop.ERROR), None
    except LimitExceeded:
        if watch.growth is None:
            watch.judge(*watch.last)
        assert watch.growth is not None
        if watch.growth.stop is Stop.STEEP:
            return watch.growth, None
        raise
    if watch.growth is None:
        return Growth(len(done.sync.nodes), 0, Stop.RAN, sync_states=done.sync.sync_states), done
    return watch.growth, done

"""OR-divergence conflicts: transitions leaving one step fired in the same round, so every
branch of the divergence became active (their receptivities were meant to exclude each
other). Both engines note them while exploring SYNC, once per (step, transitions).

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet("grafcet G { initial step 0 step 1 step 2 "
...                   "transition 0 -> 1 when a  transition 0 -> 2 when a }")
>>> log = ConflictLog()
>>> log.fresh([list(g.transitions)]), log.fresh([list(g.transitions)])
([('0', ('0->1', '0->2'))], [])
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

from synth.frozen import frozen
from synth.grafcet.language import Transition
from synth.logic.events import Event

__all__ = ["Conflict", "ConflictLog"]


@frozen
class Conflict:
    """Transitions leaving the same step fired together (an OR divergence whose
    receptivities were true at once): every branch became active."""

    node: int  # the aggregated state the event left
    event: Event
    step: str
    transitions: tuple[str, ...]


@dataclass
class ConflictLog:
    """The (step, transitions) conflicts met so far, each reported once."""

    seen: set[tuple[str, tuple[str, ...]]] = field(default_factory=set)

    def fresh(self, rounds: Sequence[Sequence[Transition]]) -> list[tuple[str, tuple[str, ...]]]:
        """The conflicts of ``rounds`` (the transitions fired, round by round) not met
        before, in order: per round, each step several fired transitions leave."""
        out = []
        for fired in rounds:
            by_step: dict[str, list[str]] = {}
            for tr in fired:
                for st in tr.sources:
                    by_step.setdefault(st, []).append(tr.name)
            for st, names in by_step.items():
                key = (st, tuple(names))
                if len(names) > 1 and key not in self.seen:
                    self.seen.add(key)
                    out.append(key)
        return out

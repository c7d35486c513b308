"""The stable situations of a symbolic SYNC, numbered as they are met.

A report names a node ``(situation index, plant state)``
(:class:`~synth.symbolic.explicit.ExplicitNodes`). The per-situation path numbers its
situations while exploring (:class:`~synth.symbolic.situations.sync.SymbolicSync`); the
step path has them as step variables and numbers one when a search first names it, here.

Example
-------
>>> from synth.grafcet.machine import Situation
>>> n = SituationIndex(None, None)  # type: ignore[arg-type]
>>> n.situation(Situation(("1",))), n.situation(Situation(("2",))), n.situation(Situation(("1",)))
(0, 1, 0)
>>> n.situations
[Situation(steps=('1',), stored=(), elapsed=(), data=()), Situation(steps=('2',), stored=(), elapsed=(), data=())]
"""

from __future__ import annotations

from synth.grafcet.machine import GrafcetMachine, Situation
from synth.plant.composition import Plant

__all__ = ["SituationIndex"]


class SituationIndex:
    """Situations of ``machine`` over ``plant``, each with the index it was first asked for."""

    def __init__(self, plant: Plant, machine: GrafcetMachine) -> None:
        self.plant = plant
        self.machine = machine
        self.situations: list[Situation] = []
        self._index: dict[Situation, int] = {}

    def situation(self, sit: Situation) -> int:
        """The index of ``sit`` (a new one the first time it is asked for)."""
        if sit not in self._index:
            self._index[sit] = len(self.situations)
            self.situations.append(sit)
        return self._index[sit]

"""The explicit engine's order among the nodes one edge enters, for the step path's first
nodes (:mod:`synth.symbolic.stepreach`, :mod:`synth.symbolic.stepbatch`).

The explicit engine numbers SYNC's nodes breadth-first: it expands the nodes in the
order it numbered them, each node's events in the plant's order, and an event's target
region gives its settled states in the order its own breadth-first search over the
controllable moves (orders sorted by name) settled them. So the node it numbers first in
a set at depth d is reached by a chain of single nodes, each the first the previous one
enters: the event smallest in the plant's order, then the settled state that region
settles first. Where a region settles in one state, the event decides; where it settles
in several (interlocks: `branches_KxM`), :class:`Settled` runs that one region
explicitly, as the explicit engine does, and gives each settled state its rank.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> from synth.sup.constraints import CompiledConstraints
>>> from synth.symbolic.stepsync import step_sync
>>> rs, p, g = load_model(_plants("../tests/data/home/production_loop.g7"), _plants("../tests/data/home/cylinder.rules"))
>>> s = step_sync(p, rs.constraints, GrafcetMachine(g))
>>> settled = Settled(s, CompiledConstraints(p, rs.constraints))
>>> sit, order = settled.order(None, None)
>>> sit, order == [p.initial]
(0, True)
"""

from __future__ import annotations

from synth.errors import LimitExceeded
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.explicit import Key
from synth.symbolic.relation import Move
from synth.symbolic.stepsync import StepSync
from synth.validation.sync import _grafcet_inputs, _order_moves, region

__all__ = ["Settled", "REGION_LIMIT"]

Local = tuple[int, ...]

REGION_LIMIT = 100_000
"""A region of more states is not run explicitly (the symbolic engine is there for them):
its tie is broken by the smallest situation, then state, and the rank is 0."""


class Settled:
    """The settled states of the region a node enters by a move (or of the initial
    region), in the explicit engine's order, computed once per (node, move)."""

    def __init__(self, s: StepSync, oracle: CompiledConstraints) -> None:
        self.s = s
        self.p = s.plant
        self.oracle = oracle
        self.moves = _order_moves(self.p)
        self._found: dict[tuple[Key | None, int | None], tuple[int, list[Local] | None]] = {}

    def order(self, parent: Key | None, move: Move | None) -> tuple[int, list[Local] | None]:
        """The situation (its index in the nodes' numbering) of the region ``parent``
        enters by ``move`` (None, None: the initial region) and its settled plant states
        in the explicit engine's order (None past :data:`REGION_LIMIT` states)."""
        key = (parent, None if move is None else move.key)
        found = self._found.get(key)
        if found is None:
            found = self._found[key] = self._order(parent, move)
        return found

    def _order(self, parent: Key | None, move: Move | None) -> tuple[int, list[Local] | None]:
        p, machine = self.p, self.s.machine
        if parent is None or move is None:
            entry = p.initial
            sit = machine.initial(_grafcet_inputs(p, machine, entry))
        else:
            before, local = self.s.helper.situations[parent[0]], parent[1]
            t = next(t for t in move.transitions if t.src == local[t.axis] and p.enabled(t, local))
            entry = local[:t.axis] + (t.dst,) + local[t.axis + 1:]
            sit, _ = machine.react_with_trace(before, _grafcet_inputs(p, machine, local),
                                              _grafcet_inputs(p, machine, entry))
        wanted = machine.orders(sit, _grafcet_inputs(p, machine, entry))
        try:
            _, settled = region(p, self.oracle, entry, wanted, self.moves, REGION_LIMIT)
        except LimitExceeded:
            return self.s.helper.situation(sit), None
        return self.s.helper.situation(sit), [q for q, _ in settled]

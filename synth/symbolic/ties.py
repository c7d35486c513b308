"""The explicit engine's order among the nodes one edge enters, for the first nodes of both
symbolic paths (:func:`synth.symbolic.searches.first_of`, and its batched twin
:mod:`synth.symbolic.steps.batch`).

The explicit engine numbers SYNC's nodes breadth-first: it expands the nodes in the
order it numbered them, each node's events in the plant's order (then its timers), and an event's target
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
>>> from synth.symbolic.steps.sync import step_sync
>>> rs, p, g = load_model(_plants("../tests/data/home/production_loop.g7"), _plants("../tests/data/home/cylinder.rules"))
>>> s = step_sync(p, rs.constraints, GrafcetMachine(g))
>>> settled = Settled(s.helper, CompiledConstraints(p, rs.constraints))
>>> sit, order = settled.order(None, None, None)
>>> sit, order == [p.initial]
(0, True)
"""

from __future__ import annotations

from typing import Callable

from synth.errors import LimitExceeded
from synth.logic.events import Event
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.interface import Key, Local, Numbered
from synth.symbolic.relation import Move
from synth.validation.sync import grafcet_inputs, moves_by_order, region

__all__ = ["Settled", "REGION_LIMIT"]

REGION_LIMIT = 100_000
"""A region of more states is not run explicitly (the symbolic engine is there for them):
its tie is broken by the smallest situation, then state, and the rank is 0."""


class Settled:
    """The settled states of the region a node enters by an event (or of the initial
    region), in the explicit engine's order, computed once per (node, event). ``sync``
    numbers the situations (the step path's :class:`~synth.symbolic.numbering.SituationIndex`,
    or the per-situation path's :class:`~synth.symbolic.situations.sync.SymbolicSync`)."""

    def __init__(self, sync: Numbered, oracle: CompiledConstraints) -> None:
        self.sync = sync
        self.p = sync.plant
        self.oracle = oracle
        self.moves = moves_by_order(self.p)
        self._found: dict[tuple[Key | None, Event | None], tuple[int, list[Local] | None]] = {}

    def order(self, parent: Key | None, event: Event | None, move: Move | None) -> tuple[int, list[Local] | None]:
        """The situation (its index in the nodes' numbering) of the region ``parent``
        enters by ``event``, the plant ``move`` or a timer (``move`` None; ``parent`` None:
        the initial region), and its settled plant states in the explicit engine's order
        (None past :data:`REGION_LIMIT` states)."""
        key = (parent, event)
        found = self._found.get(key)
        if found is None:
            found = self._found[key] = self._order(parent, event, move)
        return found

    def first(self, parent: Key | None, event: Event | None, move: Move | None,
              among: Callable[[Key], bool]) -> tuple[Key, int] | None:
        """The first node of that region (see :meth:`order`) for which ``among`` holds,
        and its rank among the region's settled states; None past :data:`REGION_LIMIT`."""
        sit, order = self.order(parent, event, move)
        if order is None:
            return None
        for rank, q in enumerate(order):
            if among((sit, q)):
                return (sit, q), rank
        raise AssertionError("the explicit region settles elsewhere than the symbolic one")

    def _order(self, parent: Key | None, event: Event | None, move: Move | None) -> tuple[int, list[Local] | None]:
        p, machine = self.p, self.sync.machine

        def inputs(local: Local) -> dict[str, bool]:
            return grafcet_inputs(p, machine, local)

        if parent is None or event is None:
            entry = p.initial
            sit = machine.initial(inputs(entry))
        else:
            before, local = self.sync.situations[parent[0]], parent[1]
            if move is None:  # a timer: the plant stays
                entry = local
                sit, _ = machine.fire_timer_with_trace(before, event, inputs(local))
            else:
                t = next(t for t in move.transitions if t.src == local[t.axis] and p.enabled(t, local))
                entry = local[:t.axis] + (t.dst,) + local[t.axis + 1:]
                sit, _ = machine.react_with_trace(before, inputs(local), inputs(entry))
        wanted = machine.orders(sit, inputs(entry))
        try:
            _, settled = region(p, self.oracle, entry, wanted, self.moves, REGION_LIMIT)
        except LimitExceeded:
            return self.sync.situation(sit), None
        return self.sync.situation(sit), [q for q, _ in settled]

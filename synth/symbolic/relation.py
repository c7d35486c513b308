"""The plant's transition relation, partitioned: one relation per element and event.

A *move* is every local transition of one element that flips one variable in one
direction (``↑a1_0`` of cylinder C1): its relation ``src(x_i) ∧ dst(x_i')`` speaks of
that element's current and next variables only, the others being unchanged by
construction. The plant's relation is their disjunction; images are computed move by
move, quantifying only the moving element's variables.

Example
-------
>>> from synth.plant.rules import load_rules
>>> from synth.plant.composition import plant, _plants
>>> from synth.symbolic.encoding import PlantEncoding
>>> enc = PlantEncoding(plant(load_rules(_plants("tri.rules"))))
>>> moves = plant_moves(enc)
>>> sum(m.controllable for m in moves) > 0, len({m.event for m in moves}) == len(moves)
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass

from synth.filter.bdd import Function
from synth.logic.events import Event
from synth.plant.composition import LocalTransition
from synth.symbolic.encoding import Copy, PlantEncoding

__all__ = ["Move", "plant_moves", "image", "preimage"]


@dataclass(frozen=True)
class Move:
    """All local transitions of element ``axis`` with one ``event`` (``↑x`` or ``↓x``).

    ``key`` is the position of its first local transition in ``Plant.transitions``
    (the explicit engine's exploration order); ``relation`` is over the element's
    current and next variables; ``transitions`` are the local transitions it gathers.
    """

    axis: int
    event: Event
    controllable: bool
    key: int
    relation: Function
    transitions: tuple[LocalTransition, ...]

    @property
    def variable(self) -> str:
        return self.event.name


def plant_moves(enc: PlantEncoding) -> tuple[Move, ...]:
    """Every move of the plant, in the order of ``Plant.transitions``."""
    groups: dict[tuple[int, Event], list[tuple[int, LocalTransition]]] = {}
    for k, t in enumerate(enc.plant.transitions):
        groups.setdefault((t.axis, t.event), []).append((k, t))
    out = []
    for (axis, event), ts in groups.items():
        rel = enc.engine.disjunction(
            enc.local_state(axis, t.src) & enc.local_state(axis, t.dst, Copy.NEXT) for _, t in ts
        )
        out.append(Move(axis, event, ts[0][1].controllable, ts[0][0], rel, tuple(t for _, t in ts)))
    return tuple(sorted(out, key=lambda m: m.key))


def image(enc: PlantEncoding, states: Function, move: Move, relation: Function | None = None) -> Function:
    """States reached from ``states`` by ``move`` (``relation``: the move restricted further)."""
    names = enc.element_variables[move.axis]
    r = move.relation if relation is None else relation
    both = states & r
    if both == enc.engine.false:
        return both
    return enc.rename(enc.exists(both, Copy.CURRENT, names), Copy.NEXT, Copy.CURRENT, names)


def preimage(enc: PlantEncoding, states: Function, move: Move, relation: Function | None = None) -> Function:
    """States from which ``move`` leads into ``states``."""
    names = enc.element_variables[move.axis]
    r = move.relation if relation is None else relation
    return enc.exists(enc.rename(states, Copy.CURRENT, Copy.NEXT, names) & r, Copy.NEXT, names)

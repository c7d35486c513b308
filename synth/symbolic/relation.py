"""The plant's transition relation, partitioned: one relation per element and event.

A *move* is every local transition of one element that flips one variable in one
direction (``↑a1_0`` of cylinder C1): its relation ``src(x_i) ∧ dst(x_i')`` speaks of
that element's current and next variables only, the others being unchanged by
construction. The plant's relation is their disjunction.

Since a move flips one variable ``v`` (its ``guard`` is the set of its sources, where
``v`` has the value it leaves), images need no second copy of the variables:
``image(S) = (S ∧ guard)[v := ¬v]`` and ``preimage(S) = guard ∧ (S ∧ v⁺)[v := ¬v]``,
``v⁺`` being the literal of ``v`` after the move: a conjunction and a composition
instead of a relational product and a renaming.

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> from synth.symbolic.encoding import PlantEncoding
>>> enc = PlantEncoding(plant(load_rules(_plants("tri.rules"))))
>>> moves = plant_moves(enc)
>>> sum(m.controllable for m in moves) > 0, len({m.event for m in moves}) == len(moves)
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass

from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.plant.composition import LocalTransition
from synth.symbolic.encoding import Copy, PlantEncoding

__all__ = ["Move", "plant_moves", "image", "preimage", "pair_preimage", "flipped"]


@dataclass(frozen=True)
class Move:
    """All local transitions of element ``axis`` with one ``event`` (``↑x`` or ``↓x``).

    ``key`` is the position of its first local transition in ``Plant.transitions``
    (the explicit engine's exploration order); ``relation`` is over the element's
    current and next variables; ``transitions`` are the local transitions it gathers;
    ``guard`` is the sources (current copy), ``after`` the literal of the flipped
    variable once moved.
    """

    axis: int
    event: Event
    controllable: bool
    key: int
    relation: Function
    transitions: tuple[LocalTransition, ...]
    guard: Function
    after: Function
    flip: tuple[str, Function]  # the BDD variable of ``variable`` and its negation: u[v := ¬v]

    @property
    def variable(self) -> str:
        return self.event.name


def plant_moves(enc: PlantEncoding) -> tuple[Move, ...]:
    """Every move of the plant, in the order of ``Plant.transitions``; a local transition of
    an element that reads others' variables only where its guard allows it."""
    e = enc.engine
    groups: dict[tuple[int, Event], list[tuple[int, LocalTransition]]] = {}
    for k, t in enumerate(enc.plant.transitions):
        groups.setdefault((t.axis, t.event), []).append((k, t))
    out = []
    for (axis, event), ts in groups.items():
        reads = enc.plant.elements[axis].reads

        def source(t: LocalTransition) -> Function:
            here = enc.local_state(axis, t.src)
            if t.guard is None:
                return here
            return here & e.disjunction(e.cube({r: bool((c >> j) & 1) for j, r in enumerate(reads)})
                                        for c, ok in enumerate(t.guard) if ok)

        sources = [source(t) for _, t in ts]
        rel = e.disjunction(s & enc.local_state(axis, t.dst, Copy.NEXT) for s, (_, t) in zip(sources, ts))
        codes = enc.plant.elements[axis].codes
        bit = 1 << enc.element_variables[axis].index(event.name)
        for _, t in ts:  # a move flips its own variable, in its own direction, and nothing else
            if int(codes[t.dst]) != int(codes[t.src]) ^ bit or bool(int(codes[t.dst]) & bit) != event.rising:
                raise AssertionError(f"local transition {t} does not only flip {event.name}")
        guard = e.disjunction(sources)
        var = e.var(event.name)
        out.append(Move(axis, event, ts[0][1].controllable, ts[0][0], rel, tuple(t for _, t in ts),
                        guard, var if event.rising else ~var, (e.declare(event.name), ~var)))
    return tuple(sorted(out, key=lambda m: m.key))


def image(enc: PlantEncoding, states: Function, move: Move) -> Function:
    """States reached from ``states`` by ``move``: those of its guard, the variable flipped."""
    both = states & move.guard  # most moves cannot happen from most sets: tested first
    if both == enc.engine.false:
        return both
    return flipped(enc, both, move)


def preimage(enc: PlantEncoding, states: Function, move: Move) -> Function:
    """States from which ``move`` leads into ``states``."""
    return flipped(enc, states & move.after, move) & move.guard


def pair_preimage(enc: PlantEncoding, entries: Function, pairs: Function, move: Move) -> Function:
    """``{(x, x') : (n, x') ∈ pairs, n ∈ entries}`` with ``n`` = x moved by ``move``, for
    ``entries`` inside the image of ``move`` (so x is in its guard: only the flipped
    variable goes back)."""
    return flipped(enc, entries & pairs, move)


def flipped(enc: PlantEncoding, u: Function, move: Move) -> Function:
    """``u`` with the move's variable negated (current copy): one composition."""
    name, negation = move.flip
    return enc.bdd.let({name: negation}, u)

"""The chain of narrowings of ``synth filter solve`` (:mod:`synth.filter.solve`): the
admissible set ``S_0 = A ∧ ¬F`` narrowed by each criterion read as ``Max(g)``
(``Min(c)`` as ``Max(!c)``): ``S_{j+1} = S_j ∧ (g_j ↔ b_j)``, ``b_j = ∃O.(S_j ∧ g_j)``;
whether each criterion narrows where it stands and whether the final filter differs
without it (the "no effect" race, :func:`_race_monolithic`); the final care set and each
output's ``∃O.(S ∧ o)`` and ``∃O.(S ∧ !o)``.

Two ways give the same BDDs: :func:`monolithic` keeps each ``S_j`` as one BDD;
:func:`partitioned` (the default) never builds it. ``S_0`` is the conjunction of the
constraints' complements and the assumptions, and each narrowing adds a factor on the
outputs of its criterion (one output for the priorities and the sims), so every ``S_j``
is a :class:`~synth.logic.partition.Partition` state and each ``∃O`` eliminates the
outputs one at a time, reusing the messages of the states before it; the races run on
the same states, each first at a few single valuations of Y (:func:`_shown_at_points`,
:mod:`synth.filter.points`). On the grid of 64 outputs ``S_j`` reaches 0.86 M nodes as one
BDD, the largest message 13 k.

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> from synth.filter.model import functions
>>> m = functions(parse_filter("inputs i\\noutputs a, b\\nsafety K: a & b\\nmaximize a\\nmaximize b & i", "x.filter"))
>>> goods = [m.engine.var("a"), m.engine.var("b") & m.engine.var("i")]
>>> n = partitioned(m, goods)
>>> n.narrows, n.effects, m.engine.text(n.ones["b"]), n == monolithic(m, goods)
([True, False], [True, False], '0', True)
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Sequence

from synth.filter import points
from synth.filter.at_point import AtPoint
from synth.filter.language import request_name
from synth.filter.model import FilterFunctions
from synth.logic.bdd import Function
from synth.logic.partition import Partition, State

__all__ = ["Narrowing", "monolithic", "partitioned", "layout", "against", "decided"]


@dataclass(eq=False)
class Narrowing:
    """What the chain gives the synthesis: per criterion, whether it narrows and whether it
    has an effect; the care set ``∃O.S``; per output ``∃O.(S ∧ o)`` and ``∃O.(S ∧ !o)``;
    the final S itself, built when first asked (:attr:`admissible`)."""

    narrows: list[bool]
    effects: list[bool]
    care: Function
    ones: dict[str, Function]
    zeros: dict[str, Function]
    relation: Callable[[], Function] = field(repr=False)

    @cached_property
    def admissible(self) -> Function:
        """The final S as one BDD (0.6 CPU s on the grid of 64 outputs: only the free outputs
        and the tests need it)."""
        return self.relation()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Narrowing) and all(
            getattr(self, a) == getattr(other, a) for a in ("narrows", "effects", "care", "ones", "zeros", "admissible"))


def monolithic(m: FilterFunctions, goods: Sequence[Function]) -> Narrowing:
    """The chain with each ``S_j`` one BDD."""
    e, outs = m.engine, m.outputs
    inner = [e.declare(o) for o in outs]
    states, bests = [m.assumed & ~m.forbidden], []
    for g in goods:  # Max(g): S := S ∧ (g ↔ ∃O.(S∧g)), the ∃ in one and-abstract pass
        bests.append(e.and_exists(states[-1], g, inner))
        states.append(states[-1] & g.equiv(bests[-1]))
    narrows = [states[i + 1] != states[i] for i in range(len(goods))]
    effects = [narrows[i] and _race_monolithic(i, goods, states, bests, m) for i in range(len(goods))]
    final = states[-1]
    ones = {o: e.and_exists(final, e.var(o), inner) for o in outs}
    zeros = {o: e.and_exists(final, ~e.var(o), inner) for o in outs}
    return Narrowing(narrows, effects, e.exists(outs, final), ones, zeros, lambda: final)


def _race_monolithic(i: int, goods: Sequence[Function], states: Sequence[Function], bests: Sequence[Function],
                     m: FilterFunctions) -> bool:
    """Whether the final filter differs without criterion ``i``, which narrows.

    Narrowing acts on each Y alone. Criterion ``i`` splits ``S_i(Y)`` into the kept
    part (the chain goes on with it) and the dropped part ``Z``; without ``i`` the later
    criteria narrow their union, and they keep the chain's part alone (no effect there) as
    soon as a criterion finds a solution in the chain's part and none in ``Z``, while the
    filter differs as soon as one finds a solution in ``Z`` and none in the chain's part,
    or when ``Z`` survives to the end. So ``Z`` is narrowed alongside the chain, each Y
    dropped once decided: most criteria are decided within a step or two."""
    e = m.engine
    inner = [e.declare(o) for o in m.outputs]
    dropped = states[i] & ~states[i + 1]
    for j in range(i + 1, len(goods)):
        own = e.and_exists(dropped, goods[j], inner)
        if (own & ~bests[j]) != e.false:
            return True
        dropped &= ~(bests[j] & ~own) & goods[j].equiv(own)
        if dropped == e.false:
            return False
    return True


def partitioned(m: FilterFunctions, goods: Sequence[Function], order: Sequence[str] | None = None,
                partition: Partition | None = None) -> Narrowing:
    """The chain with each ``S_j`` a partition state, the same BDDs as :func:`monolithic`.
    The outputs are eliminated in ``order``, by default in the order the criteria name them
    (so that a race moves along it), unless the BDDs' variable order gives smaller bags;
    ``partition``: the one :func:`layout` gave already (``order`` is then not read)."""
    e, outs = m.engine, m.outputs
    if not outs:
        return monolithic(m, goods)
    p = layout(m, goods, order) if partition is None else partition
    order = list(p.anchors)
    where = [p.position(g) for g in goods]
    states: list[State] = [p.initial]
    bests: list[Function] = []
    drops: list[Function] = []
    for g, k in zip(goods, where):
        s = states[-1]
        best = p.project(s, k, g)
        bests.append(best)
        drops.append(best & p.project(s, k, ~g))  # the Y where S ∧ !g ∧ best, what it drops, is not empty
        states.append(p.refine(s, k, g.equiv(best)) if drops[-1] != e.false else s)
    narrows = [d != e.false for d in drops]
    races = [_Race(i, p.refine(states[i], where[i], ~goods[i] & drops[i]), drops[i]) for i in range(len(goods))
             if narrows[i]]
    _shown_at_points(p, goods, races)
    for r in races:  # the races no point decided, on every Y at once
        if r.effect is None:
            mark = p.mark()
            r.framed(p, goods, where, bests, states)
            if r.effect is None:
                r.advance(p, goods, where, bests)
            p.forget(mark)
    effects = [False] * len(goods)
    for r in races:
        effects[r.i] = bool(r.effect)
    final = states[-1]
    care, ones, zeros = decided(p, final, order)
    if all((ones[o] & zeros[o]) == e.false for o in outs):  # functional: S is care ∧ ⋀ o ↔ one_o, built if asked
        def relation() -> Function:  # the partition and its messages are not kept for it
            return care & e.conjunction(e.var(o).equiv(ones[o]) for o in order)
    else:
        admissible = p.relation(final)

        def relation() -> Function:
            return admissible

    return Narrowing(narrows, effects, care, {o: ones[o] for o in outs}, {o: zeros[o] for o in outs}, relation)


def layout(m: FilterFunctions, goods: Sequence[Function], order: Sequence[str] | None = None) -> Partition:
    """The partition of ``S_0`` for the chain of ``goods``: the outputs eliminated in
    ``order``, by default as the criteria name them unless the variable order gives
    narrower bags; each criterion's outputs in one bag."""
    e, outs = m.engine, m.outputs
    factors = [~u for u in m.constraint.values()] + [m.assumed]
    named = [[o for o in e.support(g) if o in outs] for g in goods]
    if order is not None:
        return Partition(e, order, factors, named)
    mentioned = list(dict.fromkeys(o for n in named for o in n))
    candidates = [Partition(e, mentioned + [o for o in e.variable_order if o in outs and o not in mentioned],
                            factors, named),
                  Partition(e, [o for o in e.variable_order if o in outs], factors, named)]
    return min(candidates, key=lambda c: c.width)


def against(p: Partition, goods: Sequence[Function]) -> tuple[int, int]:
    """How much the chain of ``goods`` on ``p`` decides against its elimination order: the
    size ``Σ (2^n − 1)`` over the cuts between two bags, ``n`` the outputs after the cut that
    some criterion decides from the request of an output before it, and the largest ``n``.
    A priority ``Min(R_a ∧ R_b ∧ ¬b)`` (keep ``b``) decides ``b``, and ``a`` yields to it: when
    ``b`` is eliminated after ``a``, ``a``'s value at each Y waits on ``b``'s, so the chain's
    messages carry ``b`` back across every cut between them (docs/filter.md, "The chain on
    tables"). A criterion decides the outputs it reads at t, and yields those whose request it
    reads and not the output itself. Read on the filter and the partition alone, no chain run.

    >>> from synth.filter.language_check import parse_filter
    >>> from synth.filter.model import functions
    >>> from synth.filter.solve import criteria
    >>> f = parse_filter("outputs a, b, c\\nsafety K: a & b  keep b\\nsafety L: a & c  keep c", "x.filter")
    >>> m = functions(f)
    >>> goods = [~m.engine.expr(c.expr) for c in criteria(f)[:2]]  # the two priorities (Min)
    >>> against(layout(m, goods, ["a", "b", "c"]), goods)  # b and c carried back across a's cut, c across b's
    (4, 2)
    >>> p = layout(m, goods)  # by default the order the criteria name the outputs in: b, c, then a
    >>> p.anchors, against(p, goods)
    (('b', 'c', 'a'), (0, 0))
    """
    e = p.engine
    position = {o: p.anchor_position(o) for o in p.anchors}
    yields = {request_name(o): o for o in p.anchors}
    behind: list[set[str]] = [set() for _ in p.anchors]
    for g in goods:
        read = e.support(g)
        decides = [o for o in read if o in position]
        for y in (yields[r] for r in read if r in yields and yields[r] not in decides):
            for o in decides:
                for k in range(position[y], position[o]):
                    behind[k].add(o)
    return sum((1 << len(b)) - 1 for b in behind), max(len(b) for b in behind)


def decided(p: Partition, s: State, outputs: Sequence[str]) -> tuple[Function, dict[str, Function], dict[str, Function]]:
    """The care set ``∃O.S`` and each output's ``∃O.(S ∧ o)`` and ``∃O.(S ∧ !o)`` of state ``s``."""
    e = p.engine
    ones = {o: p.project(s, p.anchor_position(o), e.var(o)) for o in outputs}
    zeros = {o: p.project(s, p.anchor_position(o), ~e.var(o)) for o in outputs}
    return p.project(s, 0), ones, zeros


class _Race:
    """:func:`_race_monolithic` on partition states, run a few steps at a time: ``Z`` is
    ``S_i ∧ !g_i ∧ b_i``, whose projection on Y, ``undecided``, is where the race is not
    decided yet; each step narrows Z to the Y still undecided,
    ``own ∨ (∃O.(Z ∧ !g_j) ∧ !b_j)``, so that the messages shrink with it."""

    def __init__(self, i: int, z: State, undecided: Function) -> None:
        self.i, self.next, self.z, self.undecided = i, i + 1, z, undecided
        self.effect: bool | None = None
        self.skipped = 0
        """Steps :meth:`framed` found unchanged without projecting (for tests and benchmarks)."""

    def framed(self, p: Partition, goods: Sequence[Function], where: Sequence[int], bests: Sequence[Function],
               states: Sequence[State]) -> None:
        """Run the race in the chain's frame while its undecided part stays ``U``; leave
        ``z`` and ``next`` for :meth:`advance` where it changes (docs/filter.md, "The race in
        the chain's frame"). While it stays, ``Z_j = U ∧ S'_j``, ``S'_j`` the chain's
        ``S_j`` with the domain of criterion i's bag ``k_i`` swapped (``¬g_i`` for
        ``g_i ↔ b_i``): its messages on the far side of ``k_i`` are the chain's, and where
        the message on the near side is the chain's on ``U`` too, step j changes nothing."""
        e, ki, u = p.engine, where[self.i], self.undecided
        swapped = self.z.domains[ki]  # S_i's domain ∧ ¬g_i ∧ U
        n = len(self.z.domains)
        equal: set[tuple[int, int]] = set()  # (chain's key, frame's key) of messages equal on U
        while self.next < len(goods):
            j = self.next
            g, k, best, s = goods[j], where[j], bests[j], states[j]
            z = State(s.domains[:ki] + (swapped,) + s.domains[ki + 1:], [None] * n, [None] * n)
            if k != ki and self._unchanged(p, z, s, k, ki, equal):
                self.next += 1  # own = best ∧ U, the same care: nothing decided, Z_{j+1} = U ∧ S'_{j+1}
                self.skipped += 1
                continue
            own = p.project(z, k, g) & u
            if (own & ~best) != e.false:
                self.next, self.effect = j + 1, True
                return
            if (own | (p.project(z, k, ~g) & u & ~best)) != u:  # some Y decided: the race goes on alone
                self.z = z
                return
            self.next += 1  # own = best on U
            if k == ki:
                swapped &= g.equiv(best)
        self.effect = True

    def _unchanged(self, p: Partition, z: State, s: State, k: int, ki: int, equal: set[tuple[int, int]]) -> bool:
        """Whether the message across ``ki`` into bag ``k`` (backward for ``k < ki``, forward
        after it) is the same for the frame ``z`` and the chain's ``s`` on ``U``. The two
        share every domain but ``ki``'s, so equal messages at a bag between ``ki`` and ``k``
        stay equal up to ``k``: they are computed from ``ki`` on, and only until one is."""
        u, forward = self.undecided, k > ki
        between = range(ki, k) if forward else range(ki, k, -1)  # the messages F_m, or B_m, from ki towards k
        if any((p.message_key(s, m, forward), p.message_key(z, m, forward)) in equal for m in between):
            return True
        message = p.forward if forward else p.backward
        for m in between:
            if (message(z, m) & u) == (message(s, m) & u):
                equal.add((p.message_key(s, m, forward), p.message_key(z, m, forward)))
                return True
        return False

    def advance(self, p: Partition, goods: Sequence[Function], where: Sequence[int], bests: Sequence[Function]) -> None:
        """Run the race to its verdict, ``effect``."""
        e = p.engine
        while self.next < len(goods):
            j = self.next
            self.next += 1
            g, k, best = goods[j], where[j], bests[j]
            own = p.project(self.z, k, g)
            if (own & ~best) != e.false:
                self.effect = True
                return
            self.undecided = own | (p.project(self.z, k, ~g) & ~best)
            if self.undecided == e.false:
                self.effect = False
                return
            self.z = p.refine(self.z, k, self.undecided & g.equiv(own))
        self.effect = True


def _shown_at_points(p: Partition, goods: Sequence[Function], races: Sequence[_Race]) -> None:
    """Set ``effect`` on the races that, run at one valuation Y0 of the variables other
    than the outputs (:mod:`synth.filter.points`), show an effect there (the symbolic race
    would too: it is the same race on every Y at once).

    At Y0 the chain and every race that drops something there are run. Each race not shown
    yet gives one Y0, taken where it is still undecided: the free variables all false, all
    true, then random (:data:`~synth.filter.points.POINT_ROUNDS`)."""
    at = points.Points(p, goods)
    false = p.engine.false

    def run(point: dict[str, bool]) -> int:
        """Run the chain and the undecided races at ``point``: how many it shows."""
        here = AtPoint(at, point)  # the chain there, the criteria restricted: outputs only
        shown = 0
        for r in races:
            i = r.i
            if r.effect is None and here.bests[i] and (z := here.dropped(i)).rest != false and \
                    here.race(i, z):
                r.effect = True
                shown += 1
        return shown

    for first, default in ((r, d) for d in points.POINT_DEFAULTS for r in races):
        if first.effect is None:
            run(at.point(at.bdd.pick(first.undecided), default))
    rng = random.Random(points.POINT_SEED)
    for _ in range(points.POINT_ROUNDS):
        shown = sum(run(at.random(r.undecided, rng)) for r in races if r.effect is None)
        if not shown:
            break

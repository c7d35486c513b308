"""The chain of narrowings at one valuation ``Y0`` of everything a filter reads (its inputs,
requests, observers and previous values), the outputs left free: there each ``S_j`` is a
small relation on the outputs alone, so a chain, or a chain that differs from it, runs in
a few BDD operations per criterion. What a point shows, the symbolic chain would show too
(it is the same chain on every Y at once): the "no effect" races
(:mod:`synth.filter.narrowing`) and the keep/force spellings (:mod:`synth.filter.reliefs`)
try points before they run symbolically.

Example
-------
>>> from synth.logic.bdd import Engine
>>> from synth.logic.partition import Partition
>>> e = Engine(["i", "a", "b"])
>>> a, b, i = (e.var(n) for n in "abi")
>>> goods = [a & i, b]
>>> at = Points(Partition(e, ["a", "b"], [~(a & b)]), goods)
>>> states, bests, _ = at.chain(at.point({e.declare("i"): True}, default=False))
>>> bests, e.text(states[-1])
([True, False], 'a & !b')
"""

from __future__ import annotations

import random
from operator import itemgetter
from typing import Any, Callable, Mapping, Sequence

from synth.logic.bdd import Function
from synth.logic.native import native
from synth.logic.partition import Partition

__all__ = ["Points", "race_at_point", "POINT_DEFAULTS", "POINT_ROUNDS", "POINT_SEED", "random_point"]

POINT_DEFAULTS = (False, True)
"""The first points tried: one of a region, the variables it leaves free first all false,
then all true (requests and sensors on: where the priorities meet)."""
POINT_ROUNDS = 4
"""Then at most this many rounds of one random point per question still open, taken in
its region (a seeded generator: the same points for the same filter), while a round
answers some: on the grid of 64 outputs they leave 10 of 83 races to the symbolic race
instead of 83, for 0.4 CPU s."""
POINT_SEED = 60848


class Points:
    """The chain of ``goods`` on the partition ``p``'s relation, run at points. A point
    maps each internal variable other than the outputs (:attr:`others`) to a value."""

    def __init__(self, p: Partition, goods: Sequence[Function]) -> None:
        e = self.engine = p.engine
        self.bdd = e.bdd
        anchors = {e.declare(o) for o in p.anchors}
        self.others = [e.declare(n) for n in e.names if e.declare(n) not in anchors]
        self._anchors = anchors
        self.goods = list(goods)
        self._base = p.relation(p.initial)
        self._reads: dict[Function, tuple[list[str], Callable[[Mapping[str, bool]], tuple[bool, ...]]]] = {}
        self._restricted: dict[tuple[Function, tuple[bool, ...]], Function] = {}  # (g, its reads' values) -> g there
        self.anchors = sorted(anchors)
        self._outputs_read: dict[Function, frozenset[str]] = {}
        self._last: tuple[dict[str, bool], tuple[Function, ...]] | None = None  # the last point and its criteria there
        self._readers: dict[str, list[int]] = {}  # a variable -> the criteria (positions) reading it
        self._shapes: dict[Function, tuple[str, bool] | bool | None] = {}
        self._fast = fast = native(self.bdd) if e.cudd else None
        self.cofactor: Callable[[Function, str, bool], Function] = fast.cofactor if fast is not None else \
            (lambda u, v, value: self.bdd.let({v: value}, u))
        """``u`` with the variable ``v`` (internal name) at ``value``: CUDD's cofactor on the literal."""
        self._assign = self.assigner(self.others)

    def point(self, picked: Mapping[str, bool], default: bool) -> dict[str, bool]:
        """``picked`` completed with ``default`` for the variables it leaves free."""
        return {v: picked.get(v, default) for v in self.others}

    def at(self, g: Function, point: Mapping[str, bool]) -> Function:
        """``g`` at ``point``: a function of the outputs alone (cached per valuation of
        the variables ``g`` reads)."""
        reading = self._reads.get(g)
        if reading is None:
            reading = self._reads[g] = _reader(sorted(v for v in self.bdd.support(g) if v not in self._anchors))
        values = reading[1](point)
        found = self._restricted.get((g, values))
        if found is None:
            found = self._restricted[(g, values)] = self.bdd.let(dict(zip(reading[0], values)), g) if values else g
        return found

    def chain(self, point: Mapping[str, bool]) -> tuple[list[Function], list[bool], list[Function]]:
        """The chain at ``point``: ``S_0 … S_n`` on the outputs, whether each criterion
        finds a solution there (its ``b_j`` at Y0), and the criteria there (:meth:`at`),
        each relation one BDD. The races and the spellings run it as
        :class:`synth.filter.at_point.AtPoint` (the outputs fixed kept apart: the same
        relations, in fewer steps); this is the tests' oracle."""
        s = self.base_at(point)
        states, bests, there = [s], [], self.there(point)
        for g in there:
            s, best = narrow(s, g, self.engine.false)
            states.append(s)
            bests.append(best)
        return states, bests, there

    def there(self, point: Mapping[str, bool]) -> list[Function]:
        """The criteria at ``point`` (:meth:`at`), only those reading a variable that
        differs from the last point's asked again (the others' values, so their cached
        restrictions, are the same): the witnesses change a few variables at a time."""
        last = self._last
        if last is None or last[0].keys() != point.keys():
            there = [self.at(g, point) for g in self.goods]
            if not self._readers:
                for i, g in enumerate(self.goods):
                    for v in self._reads[g][0]:
                        self._readers.setdefault(v, []).append(i)
        else:
            before, there = last[0], list(last[1])
            changed = sorted({i for v, x in point.items() if before[v] != x for i in self._readers.get(v, ())})
            for i in changed:
                there[i] = self.at(self.goods[i], point)
        self._last = (dict(point), tuple(there))
        return there

    def holds(self, u: Function, point: Mapping[str, bool]) -> bool:
        """Whether ``u`` (a function of :attr:`others`) is true at ``point``: its one path
        there walked, no BDD operation."""
        flips = u.negated  # dd's cofactors are the node's, its complement edges read on the way
        while u.var is not None:
            u = u.high if point[u.var] else u.low
            flips ^= u.negated
        return not flips  # the one terminal is true, reached through an even number of complements

    def random(self, region: Function, rng: random.Random) -> dict[str, bool]:
        """A random point in ``region`` (not false, a function of :attr:`others`)."""
        return random_point(self.bdd, region, self.others, rng)

    def reads(self, g: Function) -> frozenset[str]:
        """The variables (internal names) ``g`` reads: at a point, outputs only."""
        found = self._outputs_read.get(g)
        if found is None:
            found = self._outputs_read[g] = frozenset(self.bdd.support(g))
        return found

    def shape(self, g: Function) -> tuple[str, bool] | bool | None:
        """What ``g`` (a criterion at a point) is: its value when constant, ``(v, value)`` when
        the literal ``v`` (``value``: positive), else None (remembered per function: dd reads
        a node's children as new objects)."""
        try:
            return self._shapes[g]
        except KeyError:
            pass
        found: tuple[str, bool] | bool | None = None
        if g.var is None:
            found = g == self.bdd.true
        elif g.low.var is None and g.high.var is None:
            found = (g.var, g == self.bdd.var(g.var))
        self._shapes[g] = found
        return found

    def base_at(self, point: Mapping[str, bool]) -> Function:
        """``S_0`` at ``point``: a relation on the outputs alone."""
        return self._assign(self._base, point)

    def partial(self, values: Mapping[str, bool]) -> Function:
        """``S_0`` with the variables of ``values`` set: :meth:`restrict` sets the others at a
        point (a cofactor walks the whole of ``S_0``, 7 000–8 400 nodes on grid_edges 8 × 8,
        where a witness is made sparse by a few thousand trials a few variables apart)."""
        return self.bdd.let(dict(values), self._base) if values else self._base

    def restrict(self, u: Function, names: Sequence[str], point: Mapping[str, bool]) -> Function:
        """``u`` with the variables ``names`` at their values at ``point``."""
        return self.assigner(names)(u, point) if names else u

    def assigner(self, names: Sequence[str]) -> Callable[[Function, Mapping[str, bool]], Function]:
        """A function giving ``u`` with the variables ``names`` at their values at a point:
        CUDD's cofactor on their cube (:meth:`synth.logic.native.Native.assigner`), dd's
        ``let`` without CUDD."""
        names = list(names)
        if self._fast is None:
            return lambda u, point: self.bdd.let({v: point[v] for v in names}, u)
        cofactor = self._fast.assigner(names)
        return lambda u, point: cofactor(u, [point[v] for v in names])


def narrow(s: Function, g: Function, false: Function) -> tuple[Function, bool]:
    """``Max(g)`` on ``s`` at a point: ``s ∧ g`` where it is not empty, else ``s ∧ ¬g``;
    and whether it was not. A criterion constant at the point (most priorities, whose
    requests are off there) leaves ``s`` as it is, without a BDD operation."""
    if g.var is None:  # the constant true or false
        return (s, False) if g == false else (s, s != false)
    kept = s & g
    if kept != false:
        return kept, True
    return s & ~g, False


def _reader(reads: list[str]) -> tuple[list[str], Callable[[Mapping[str, bool]], tuple[bool, ...]]]:
    """``reads`` and the function giving their values at a point, as a tuple."""
    if not reads:
        return reads, lambda point: ()
    if len(reads) == 1:
        only = reads[0]
        return reads, lambda point: (point[only],)
    return reads, itemgetter(*reads)


def random_point(bdd: Any, u: Function, names: Sequence[str], rng: random.Random) -> dict[str, bool]:
    """A valuation of ``names`` (internal) in ``u`` (not false, on those variables): random
    values, each of ``u``'s variables in turn changed where the random one leaves ``u``."""
    point = {v: rng.random() < 0.5 for v in names}
    for v in sorted(bdd.support(u), key=bdd.level_of_var):
        rest = bdd.let({v: point[v]}, u)
        if rest == bdd.false:
            point[v] = not point[v]
            rest = bdd.let({v: point[v]}, u)
        u = rest
    return point


def race_at_point(z: Function, at: Sequence[Function], bests: Sequence[bool], false: Function) -> bool:
    """The "no effect" race of :mod:`synth.filter.narrowing` at one Y0, step by step on single
    BDDs: whether Y0 shows the effect (``z``: what the criterion drops there; ``at``,
    ``bests``: the criteria after it there and the chain's verdicts).
    :meth:`synth.filter.at_point.AtPoint.race` gives the same verdict in fewer steps (the
    tests hold it to this one)."""
    for g, best in zip(at, bests):
        own = (z & g) != false
        if own and not best:
            return True
        if best and not own:
            return False
        z &= g if own else ~g
    return True

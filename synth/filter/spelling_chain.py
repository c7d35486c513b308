"""The chain of narrowings ``filter check`` compares the keep/force spellings of the reliefs
on (:mod:`synth.filter.reliefs` words the warnings): the file's criteria in one partition,
each relief's other spelling as an *alternative* criterion at its position. Points first
(:meth:`SpellingChain.at_points`: at one valuation of what the filter reads both chains are
small, :mod:`synth.filter.points`), each witness made sparse; then on every input
(:meth:`SpellingChain.differ`: the alternative's chain on a
:class:`~synth.logic.partition.Walk`, from the state before its criterion), within a limit
on :meth:`SpellingChain.size`, read on the filter and its chain alone."""

from __future__ import annotations

import dataclasses
import functools
import random
from typing import Sequence

from synth.filter import points
from synth.filter.at_point import AtPoint
from synth.filter.language import Criterion, Filter, Safety, Sense
from synth.filter.narrowing import decided, layout
from synth.logic.bdd import Function
from synth.logic.partition import State
from synth.logic.past import pre_name

__all__ = ["SpellingChain", "TooWide", "Witness"]


class SpellingChain:
    """The chain of narrowings of ``f``'s criteria in one engine and one partition, each
    relief's other spelling run from the state before its criterion (the states before
    it and their messages are shared): its care set and each output's function (None
    where the output is not determined), what ``solve`` prints its equations from."""

    def __init__(self, f: Filter, swapped: Sequence[tuple[Safety, Safety]]) -> None:
        from synth.filter.model import functions
        from synth.filter.solve import criteria, priority_criterion

        self.m = m = functions(f)
        written = criteria(f)
        self.goods = [self._good(c) for c in written]
        self.alternatives: list[tuple[int, Function] | None] = []
        # the priority criteria come first, one per relief in file order, unless the file states
        # its criteria (then no spelling changes them): a relief written the other way changes its
        # own criterion only
        stated = any(isinstance(c, Criterion) for c in f.criteria)
        index = {id(s): i for i, s in enumerate(s for s in f.combined if s.has_priority)}
        outputs = frozenset(f.outputs)
        for s, t in swapped:  # its position and its good, where the criterion differs
            i = None if stated else index[id(s)]
            other = None if i is None else priority_criterion(t, outputs)
            good = None if i is None or other is None or other == written[i] else self._good(other)
            self.alternatives.append(None if i is None or good is None or good == self.goods[i] else (i, good))
        self.p = layout(m, self.goods + [a[1] for a in self.alternatives if a is not None])
        self.where = [self.p.position(g) for g in self.goods]
        self.states: list[State] = [self.p.initial]
        self.bests: list[Function] = []
        self._regions: dict[int, Function] = {}
        self.budget: int | None = None
        """While set, the size past which running the chain gives up: the BDD nodes of the
        local relation (:meth:`Partition.local <synth.logic.partition.Partition.local>`) at the
        criterion it is to apply next."""
        self.coarse = False
        """Whether the regions are taken on ``S_0`` (:meth:`sparse_points`)."""

    def _upto(self, j: int) -> State:
        """The chain's ``S_j``, the chain run that far if it is not yet (the points need it
        only up to the last relief's criterion)."""
        while len(self.states) <= j:
            n = len(self.bests)
            if self.budget is not None and len(self.p.local(self.states[-1], self.where[n])) > self.budget:
                raise TooWide
            state, best = self._step(self.states[-1], self.where[n], self.goods[n])
            self.states.append(state)
            self.bests.append(best)
        return self.states[j]

    @functools.cached_property
    def base(self) -> tuple[Function, dict[str, Function], dict[str, Function]]:
        """The file's filter: what :meth:`_outcome` gives at the end of the chain."""
        return self._outcome(self._upto(len(self.goods)))

    def _good(self, c: Criterion) -> Function:
        u = self.m.engine.expr(c.expr)
        return u if c.sense is Sense.MAX else ~u

    def _step(self, s: State, k: int, g: Function) -> tuple[State, Function]:
        """``Max(g)`` on ``s`` (``g`` in bag ``k``): the state after it, and ``b = ∃O.(s ∧ g)``."""
        best = self.p.project(s, k, g)
        return self.p.refine(s, k, g.equiv(best)), best

    def _outcome(self, s: State) -> tuple[Function, dict[str, Function], dict[str, Function]]:
        return decided(self.p, s, self.m.outputs)

    def _region(self, n: int) -> Function:
        """Where alternative ``n`` may differ from the chain: the Y where its criterion or
        the file's narrows ``S_i`` (elsewhere both leave it as it is, and so the rest)."""
        found = self._regions.get(n)
        if found is None:
            found = self._regions[n] = self._initial_region(n) if self.coarse else self._narrowed(n)
        return found

    def _initial_region(self, n: int) -> Function:
        """:meth:`_narrowed` on ``S_0`` instead of ``S_i``: the Y where criterion i or its
        other spelling narrows ``S_0``, which holds those where they narrow ``S_i``
        (``S_i ⊆ S_0``); no chain is run."""
        alternative = self.alternatives[n]
        assert alternative is not None
        i, g = alternative
        p, s, good = self.p, self.p.initial, self.goods[i]
        k = p.position(g)
        return (p.project(s, self.where[i], good) & p.project(s, self.where[i], ~good)) | \
            (p.project(s, k, g) & p.project(s, k, ~g))

    def sparse_points(self, candidates: Sequence[int], size: int) -> dict[int, Witness]:
        """:meth:`at_points` with the free variables 0, its regions on the chain's ``S_i``
        while the chain's local relation at each criterion on the way there has at most
        ``size`` nodes (:attr:`budget`); past it, on ``S_0`` (:meth:`_initial_region`,
        :attr:`coarse`: the chain is not run further, and
        :func:`synth.filter.reliefs.spelling_warnings` compares nothing on every input)."""
        self.budget = size
        try:
            return self.at_points(candidates, points.POINT_DEFAULTS[:1], 0)
        except TooWide:
            self.coarse = True
            self._regions.clear()
            return self.at_points(candidates, points.POINT_DEFAULTS[:1], 0)
        finally:
            self.budget = None

    def _narrowed(self, n: int) -> Function:
        alternative = self.alternatives[n]
        assert alternative is not None
        i, g = alternative
        self._upto(i + 1)  # S_i and b_i
        p, s = self.p, self.states[i]
        k = p.position(g)
        return (self.bests[i] & p.project(s, self.where[i], ~self.goods[i])) | \
            (p.project(s, k, g) & p.project(s, k, ~g))

    def at_points(self, candidates: Sequence[int], defaults: Sequence[bool], rounds: int) -> dict[int, Witness]:
        """Those of the alternatives ``candidates`` some point shows different
        (:mod:`synth.filter.points`), each with its witness. The points are taken in the
        regions the alternatives may differ in (:meth:`_region`): one per alternative not
        shown yet, its free variables set to each of ``defaults`` in turn, then ``rounds``
        rounds of random ones; a point showing several alternatives serves them all. Each
        witness is the first point that showed it, made sparse (fewer variables at 1)."""
        e, at = self.m.engine, self._at
        todo = [n for n in candidates if self.alternatives[n] is not None and self._region(n) != e.false]
        shown: dict[int, dict[str, bool]] = {}

        def run(point: dict[str, bool]) -> int:
            # outside its region an alternative leaves S_i as the file's criterion does: no chain needed
            asked = [n for n in todo if n not in shown and at.holds(self._region(n), point)]
            here = AtPoint(at, point) if asked else None
            found = [n for n in asked if here is not None and self._differ_at(here, n)]
            shown.update((n, point) for n in found)
            return len(found)

        for default in defaults:
            for n in todo:
                if n not in shown:
                    run(at.point(e.bdd.pick(self._region(n)), default))
        rng = random.Random(points.POINT_SEED)
        for _ in range(rounds):
            if not sum(run(at.random(self._region(n), rng)) for n in todo if n not in shown):
                break
        return {n: self._witness(at, n, shown[n]) for n in sorted(shown)}

    @functools.cached_property
    def _at(self) -> points.Points:
        return points.Points(self.p, self.goods)

    def _differ_at(self, here: AtPoint, n: int, like: AtPoint | None = None) -> list[str]:
        """The outputs alternative ``n`` drives differently at the point ``here`` (the chain
        there), none where it rejoins the chain; ``like``: the chain at a point that asked it
        before (:meth:`AtPoint.differ <synth.filter.at_point.AtPoint.differ>`)."""
        alternative = self.alternatives[n]
        assert alternative is not None
        i, g = alternative
        return here.differ(i, g, self.m.outputs, like)

    def _witness(self, at: points.Points, n: int, point: dict[str, bool]) -> Witness:
        """``point`` made sparse: its variables at 1 set to 0, all of a group at once (the
        whole set, then halves, and so on), wherever alternative ``n`` still differs; the
        outputs it drives differently at the point left."""
        point = dict(point)
        region = self._region(n)
        ones = [v for v in at.others if point[v]]
        root = at.partial({v: False for v in at.others if not point[v]})  # they stay 0
        here = AtPoint(at, dict(point), base=at.restrict(root, ones, point))  # the chain at the point so far
        # a stack, not a recursive closure (no cycle to collect): each group with S_0 set outside
        # its parent group, and the parent's other half, to set when the group is reached (after
        # the first half's trials: its variables then have their values for good)
        groups: list[tuple[list[str], Function, list[str]]] = [(ones, root, [])]
        while groups:
            group, parent, other = groups.pop()
            outside = at.restrict(parent, other, point)  # S_0 with every variable outside the group set
            for v in group:
                point[v] = False
            if at.holds(region, point):
                trial = AtPoint(at, dict(point), like=here, base=at.restrict(outside, group, point))
                if self._differ_at(trial, n, here):
                    here = trial
                    continue
            for v in group:
                point[v] = True
            if len(group) > 1:
                first, second = group[:len(group) // 2], group[len(group) // 2:]
                groups += [(second, outside, first), (first, outside, second)]
        e = self.m.engine
        value = {x: point[e.declare(x)] for x in e.names if e.declare(x) in point}
        integers: list[tuple[str, int]] = []
        for i in self.m.filter.integer_observers:  # their bits read as the integer (and its ^-1)
            for name, bits in ((i.name, i.bits), (pre_name(i.name), [pre_name(b) for b in i.bits])):
                if all(b in value for b in bits):
                    integers.append((name, i.low + sum(value.pop(b) << k for k, b in enumerate(bits))))
        return Witness(tuple(self._differ_at(here, n)), tuple(x for x, v in value.items() if v), tuple(integers))

    def differ(self, n: int) -> list[str] | None:
        """The outputs alternative ``n`` drives differently (another ``∃O.(S∧o)`` or
        ``∃O.(S∧!o)``; every output when only the care set differs), None when the two
        spellings give the same filter.

        Its chain runs from ``S_i`` on a :class:`~synth.logic.partition.Walk`, whose messages
        are keyed by value: where one equals the file's chain's at the same step (the walk
        of :attr:`_walked` computed them), the messages after it are that chain's too and are
        not computed again. It stops where its domains are the chain's (it rejoined); at the
        end, an output whose bag sees the same messages and domain as in the file's filter is
        not projected (its functions are the file's)."""
        alternative = self.alternatives[n]
        if alternative is None:  # the criteria are the file's: the spelling changes none
            return None
        i, g = alternative
        base = self.base  # before the mark: the chain's messages are kept
        final = self._walked
        p, states, where, goods = self.p, self.states, self.where, self.goods
        mark = p.mark()
        try:
            w = p.walk(states[i])
            k = p.position(g)
            w.refine(k, g.equiv(w.project(k, g)))
            apart = {m for m in (k, where[i]) if w.domains[m] != states[i + 1].domains[m]}
            for j in range(i + 1, len(goods)):
                if not apart:  # the chain rejoined: the same filter from here
                    return None
                m = where[j]
                w.refine(m, goods[j].equiv(w.project(m, goods[j])))
                if w.domains[m] == states[j + 1].domains[m]:
                    apart.discard(m)
                else:
                    apart.add(m)
            if not apart:
                return None
            same = [w.around(m) == there for m, there in enumerate(final)]
            care = base[0] if same[0] else w.project(0)
            differ = []
            for o in self.m.outputs:
                m = p.anchor_position(o)
                if same[m]:
                    continue
                x = self.m.engine.var(o)
                if w.project(m, x) != base[1][o] or w.project(m, ~x) != base[2][o]:
                    differ.append(o)
        finally:
            p.forget(mark)
        if not differ and care == base[0]:
            return None
        return differ or list(self.m.outputs)

    def size(self, n: int) -> int:
        """The size of alternative ``n``'s comparison on every input, read on the filter and
        the file's chain alone (not on the work the comparison does, so that no faster
        comparison changes which reliefs are compared): the BDD nodes of the chain's local
        relations (each criterion's relation around its outputs, :meth:`Partition.local
        <synth.logic.partition.Partition.local>`) from its criterion to the last, which its
        other spelling runs again, times the variables its region reads (where the two
        spellings may differ). 0 where the criteria are the file's."""
        alternative = self.alternatives[n]
        if alternative is None:
            return 0
        return self._after[alternative[0]] * len(self.m.engine.bdd.support(self._region(n)))

    @functools.cached_property
    def _after(self) -> list[int]:
        """Per criterion i: the nodes of the chain's local relations at criteria i to the last."""
        self._upto(len(self.goods))
        sizes = [len(self.p.local(s, k)) for s, k in zip(self.states, self.where)]
        return [sum(sizes[i:]) for i in range(len(sizes))]

    @functools.cached_property
    def _walked(self) -> list[tuple[Function, Function, Function]]:
        """The file's chain run once more on a :class:`~synth.logic.partition.Walk`, so that
        its messages at every step are kept by value (the alternatives of :meth:`differ`
        meet them); what each bag's local relation is made of at its end."""
        w = self.p.walk(self.states[len(self.goods)])
        return [w.around(m) for m in range(len(w.domains))]


class TooWide(Exception):
    """Running the chain passed :attr:`SpellingChain.budget`."""


@dataclasses.dataclass(frozen=True)
class Witness:
    """Where a point shows two spellings different: the outputs they drive differently
    there, the Boolean variables read that are 1 at the point (the others are 0), and the
    integer observers' values there.

    >>> Witness(("push",), ("R_push", "ready"), (("cpt", 3), ("cpt^-1", 0))).text()
    'it drives push differently when only R_push, ready are 1, cpt = 3, cpt^-1 = 0'
    """

    outputs: tuple[str, ...]
    ones: tuple[str, ...]
    integers: tuple[tuple[str, int], ...] = ()
    """The integer observers (and their previous values) at the point: every one, by name."""

    def text(self) -> str:
        """``it drives o differently when only a, b are 1`` (``…, cpt = 2`` with integers)."""
        where = f"only {', '.join(self.ones)} {'is' if len(self.ones) == 1 else 'are'} 1" if self.ones \
            else ("no Boolean it reads is 1" if self.integers else "all it reads is 0")
        where += "".join(f", {n} = {v}" for n, v in self.integers)
        return f"it drives {', '.join(self.outputs)} differently when {where}"

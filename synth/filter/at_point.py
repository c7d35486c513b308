"""The chain of narrowings at one point (:mod:`synth.filter.points`) with each relation kept
as the outputs it fixes and the rest: a Sim criterion, or a priority whose requests meet
at the point, is one literal there, and ``S ∧ o`` as one BDD keeps a node per output fixed
before, above the rest; a chain of N outputs then walks N/2 of them at each of its N Sim
steps (quadratic per point, cubic over the races' points). Kept apart, a literal is a
cofactor of the rest, a step or two when its output is the rest's first.

:class:`Fixed` is one relation (``fixed``: output -> value, ``rest``: a function of the
other outputs, the relation ``⋀ fixed ∧ rest``); :class:`AtPoint` runs the chain at a point
on them (:meth:`AtPoint.narrow` is ``Max(g)``, :meth:`AtPoint.same` compares two as
relations), the "no effect" races there (:mod:`synth.filter.narrowing`) and the keep/force
spellings' comparison (:meth:`AtPoint.differ`, :mod:`synth.filter.reliefs`). Cofactors are
CUDD's and-abstract over a one-variable cube (dd's ``let`` walks every declared variable:
0.13 ms a call with 1 000 of them). They give what
:meth:`synth.filter.points.Points.chain` and :func:`synth.filter.points.narrow` give on
the relations as single BDDs (``tests/test_filter_at_point.py``).

Example
-------
>>> from synth.logic.bdd import Engine
>>> from synth.logic.partition import Partition
>>> from synth.filter.points import Points
>>> e = Engine(["i", "a", "b"])
>>> a, b, i = (e.var(n) for n in "abi")
>>> here = AtPoint(Points(Partition(e, ["a", "b"], [~(a & b)]), [a & i, b]), {e.declare("i"): True})
>>> here.bests, e.text(here.states[-1].relation(e.bdd))
([True, False], 'a & !b')
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping, Sequence

from synth.filter.points import Points
from synth.logic.bdd import Function

__all__ = ["Fixed", "AtPoint"]


class Fixed:
    """A relation on the outputs at a point: ``⋀ fixed ∧ rest``, ``rest`` reading none of
    the outputs ``fixed`` (internal names) fixes; ``horizon``: the last step of the chain
    that reads one of them (-1 for none); ``added``: the output this relation fixes that the
    one it was narrowed from did not (its ``fixed`` is then a new dictionary), else None."""

    __slots__ = ("fixed", "rest", "horizon", "added")

    def __init__(self, fixed: dict[str, bool], rest: Function, horizon: int = -1, added: str | None = None) -> None:
        self.fixed = fixed
        self.rest = rest
        self.horizon = horizon
        self.added = added

    def relation(self, bdd: Any) -> Function:
        """The relation as one BDD."""
        u = self.rest
        for v, value in self.fixed.items():
            u &= bdd.var(v) if value else ~bdd.var(v)
        return u


class AtPoint:
    """The chain at one point: ``there`` (the criteria at the point, functions of the
    outputs), ``states`` (``S_0 … S_n``, each a :class:`Fixed`) and ``bests`` (whether each
    criterion finds a solution there), as :meth:`synth.filter.points.Points.chain` gives
    them as single BDDs."""

    def __init__(self, points: Points, point: Mapping[str, bool], like: AtPoint | None = None,
                 base: Function | None = None) -> None:
        self.points = points
        self.engine = points.engine
        self.bdd = points.bdd
        self.false = points.bdd.false
        self.point = point
        self.there = points.there(point)
        last: dict[str, int] = {v: -1 for v in points.anchors}
        for j, g in enumerate(self.there):
            for v in points.reads(g):
                last[v] = j
        self.last_read = last
        """Per output (internal name): the last criterion reading it at the point (-1: none)."""
        if like is not None and (like.points is not points or like.last_read != last):
            like = None  # another chain, or the outputs read last elsewhere: the horizons would differ
        base = points.base_at(point) if base is None else base  # S_0 at the point, when the caller has it
        self.states, self.bests = self._chain(Fixed({}, base), like)
        self._free: list[Function | None] | None = None
        self._projected: dict[int, Function] = {}
        self.runs: dict[tuple[int, Function], tuple[list[Fixed], list[str], bool]] = {}
        """:meth:`differ`'s runs: per criterion and other criterion at the point, each step's
        ``z``, the answer, and whether it was reached by this chain alone (for ``like``)."""
        self.agreed = 0
        """Races :meth:`race` ended because ``Z`` and the chain agreed (for tests and benchmarks)."""

    def _chain(self, s: Fixed, like: AtPoint | None) -> tuple[list[Fixed], list[bool]]:
        """``S_0 … S_n`` and the verdicts from ``s`` (``S_0``). With ``like`` (the chain at
        another point, whose outputs are read last at the same steps): wherever this chain's
        ``S_j`` is ``like``'s as a relation (the same outputs fixed to the same values, the same
        rest) and criterion ``j`` is the same there, ``S_{j+1}`` is ``like``'s (the same
        object: its ``added`` is relative to an equal ``S_j``), no narrowing run; the witnesses
        are made sparse a few variables at a time, so most steps are met again."""
        states, bests = [s], []
        if like is None:
            for g in self.there:
                s, best = self.narrow(s, g)
                states.append(s)
                bests.append(best)
            return states, bests
        theirs, their_there, their_bests = like.states, like.there, like.bests
        same = _equal(s, theirs[0])
        for j, g in enumerate(self.there):
            if same and g == their_there[j]:
                s, best = theirs[j + 1], their_bests[j]
            else:
                s, best = self.narrow(s, g)
                same = _equal(s, theirs[j + 1])
            states.append(s)
            bests.append(best)
        return states, bests

    # ---- relations
    def _literal(self, v: str, value: bool) -> Function:
        x = self.bdd.var(v)
        return x if value else ~x

    def _cofactor(self, u: Function, v: str, value: bool) -> Function:
        """``u`` with output ``v`` at ``value`` (CUDD's cofactor on the literal)."""
        return self.points.cofactor(u, v, value)

    def _restricted(self, s: Fixed, g: Function) -> Function:
        """``g`` with the outputs ``s`` fixes set to their values (``g``: a criterion at the point)."""
        values = [(v, s.fixed[v]) for v in self.points.reads(g) if v in s.fixed]
        if not values:
            return g
        cube = self.bdd.true
        for v, value in values:
            cube &= self._literal(v, value)
        return self.engine.and_exists(g, cube, [v for v, _ in values])

    def _fixing(self, s: Fixed, v: str, value: bool, rest: Function) -> Fixed:
        return Fixed({**s.fixed, v: value}, rest, max(s.horizon, self.last_read[v]), v)

    def narrow(self, s: Fixed, g: Function) -> tuple[Fixed, bool]:
        """``Max(g)`` on ``s`` (:func:`synth.filter.points.narrow`): ``s ∧ g`` where it is
        not empty, else ``s ∧ ¬g``; and whether it was not."""
        false = self.false
        shape = self.points.shape(g)
        if shape is None:  # another function: its outputs s fixes set, it may be constant or a literal then
            g = self._restricted(s, g)
            shape = self.points.shape(g)
        elif shape is not True and shape is not False and shape[0] in s.fixed:  # a literal on an output s fixes
            shape = s.fixed[shape[0]] == shape[1]
        if shape is False:  # constant: s as it is
            return s, False
        if shape is True:
            return s, s.rest != false
        if shape is not None:  # a literal: a cofactor of the rest
            v, value = shape
            kept = self.points.cofactor(s.rest, v, value)
            if kept != false:
                return self._fixing(s, v, value, kept), True
            return self._fixing(s, v, not value, self.points.cofactor(s.rest, v, not value)), False
        kept = s.rest & g
        if kept != false:
            return Fixed(s.fixed, kept, s.horizon), True
        return Fixed(s.fixed, s.rest & ~g, s.horizon), False

    def conjoined(self, s: Fixed, g: Function) -> Fixed:
        """``s ∧ g``, ``g`` a function of the outputs at the point."""
        g = self._restricted(s, g) if g.var is not None else g
        if g.var is not None and g.low.var is None and g.high.var is None:
            v = g.var
            value = g == self.bdd.var(v)
            return self._fixing(s, v, value, self._cofactor(s.rest, v, value))
        return Fixed(s.fixed, s.rest & g, s.horizon)

    def same(self, a: Fixed, b: Fixed) -> bool:
        """Whether ``a`` and ``b`` are the same relation. Where one fixes an output the other
        does not, the other must force it to that value (its rest false at the other one)."""
        if a is b:
            return True
        if a.fixed == b.fixed:
            return bool(a.rest == b.rest)
        return self._same_apart(a, b, a.fixed.items() ^ b.fixed.items())

    def _same_apart(self, a: Fixed, b: Fixed, apart: Iterable[tuple[str, bool]]) -> bool:
        """:meth:`same` given the outputs fixed by one and not the other or to other values,
        ``apart`` (each with its value in the one that fixes it), ``a.fixed`` and ``b.fixed``
        not equal."""
        false = self.bdd.false
        if a.rest == false or b.rest == false:
            return a.rest == false and b.rest == false
        rests = []
        for x, y in ((a, b), (b, a)):
            rest = y.rest
            for v, value in apart:
                if x.fixed.get(v) is not value:
                    continue  # y's own, or a value x does not give v
                if v in y.fixed:
                    return False  # both fix v, to other values
                if self._cofactor(rest, v, not value) != false:
                    return False  # y leaves v free, or forces the other value: another relation
                rest = self._cofactor(rest, v, value)
            rests.append(rest)
        # both now fix the same outputs to the same values: the same relation iff the same rest
        return bool(rests[0] == rests[1])

    def can(self, s: Fixed, v: str, value: bool) -> bool:
        """Whether ``s`` holds a vector with output ``v`` at ``value``."""
        false = self.bdd.false
        if s.rest == false:
            return False
        if v in s.fixed:
            return s.fixed[v] == value
        return (s.rest & self._literal(v, value)) != false

    # ---- the races
    def dropped(self, i: int) -> Fixed:
        """``S_i ∧ ¬g_i``: what criterion ``i`` drops at the point (the race's ``Z``)."""
        return self.conjoined(self.states[i], ~self.there[i])

    def _free_after(self) -> list[Function | None]:
        """Per step j: the cube of the outputs no criterion from j on reads (None: none)."""
        if self._free is None:
            freed: dict[int, list[str]] = {}
            for v, j in self.last_read.items():
                freed.setdefault(j + 1, []).append(v)
            bdd, cube = self.bdd, None
            out: list[Function | None] = []
            for j in range(len(self.there) + 1):
                for v in sorted(freed.get(j, ()), key=bdd.level_of_var):
                    cube = bdd.var(v) if cube is None else cube & bdd.var(v)
                out.append(cube)
            self._free = out
        return self._free

    def race(self, i: int, z: Fixed) -> bool:
        """Whether the race of criterion ``i`` shows its effect at the point (``z``: what the
        criterion drops there, :meth:`dropped`, not empty), as
        :func:`synth.filter.points.race_at_point` decides it, with two shortcuts:

        - a criterion constant at the point narrows neither ``Z`` nor the chain: skipped;
        - once ``Z`` and the chain's ``S_j`` have the same projection on the outputs a
          criterion from ``j`` on reads (here: both fix only outputs no criterion from ``j``
          on reads, and their rests are the same once the others are quantified), every
          later criterion finds a solution in ``Z`` exactly where it finds one in ``S_j``:
          the race runs to the end undecided, which shows the effect (the race of a Sim
          criterion on a chain of outputs meets this a step or two after it starts instead
          of running to the end)."""
        false = self.bdd.false
        free = self._free_after()
        for j in range(i + 1, len(self.there)):
            g, best = self.there[j], self.bests[j]
            if g.var is None:  # own: z is not empty (it never is) for true, false for false
                if g != false and not best:
                    return True
                continue
            cube, s = free[j], self.states[j]
            if cube is not None and z.horizon < j and s.horizon < j:
                mine = self._projected.get(j)
                if mine is None:
                    mine = self._projected[j] = self.bdd.apply("exists", cube, s.rest)
                if self.bdd.apply("exists", cube, z.rest) == mine:
                    self.agreed += 1
                    return True
            z, own = self.narrow(z, g)
            if own and not best:
                return True
            if best and not own:
                return False
        return True

    # ---- the keep/force spellings
    def differ(self, i: int, g: Function, outputs: Sequence[str], like: AtPoint | None = None) -> list[str]:
        """The ``outputs`` (the engine's names, in their order) the chain with criterion
        ``i`` replaced by ``g`` drives differently at the point, none where it rejoins the
        chain (:meth:`synth.filter.spelling_chain.SpellingChain.differ` at a point).

        With ``like`` (the chain at another point, which asked the same before: a witness's
        trials ask it of the chain at the point so far), its run is taken where it is this
        one's: its ``z`` at every step while both chains and their criteria agree from the
        start, and its answer once this ``z`` is its ``z`` at a step from which both chains
        and their criteria agree to the end (the answer depends only on ``z`` there and on
        the chain after it)."""
        points, states, there = self.points, self.states, self.there
        g = points.at(g, self.point)
        if g == there[i]:  # the same criterion at the point: the chain itself
            return []
        theirs = None if like is None else like.runs.get((i, g))
        start, agree = i + 1, len(there) + 1  # agree: from where both chains agree to the end
        if theirs is not None:
            assert like is not None
            zs, answer, complete = theirs
            first = _disagreeing(states, there, like, range(len(there) + 1), len(there) + 1)  # both agree before
            agree = _disagreeing(states, there, like, range(len(there), -1, -1), -1) + 1
            if i < first:  # the same z from i + 1 up to the first step they disagree at
                reached = i + len(zs)
                if (complete and reached < first) or agree <= i + 1:
                    self.runs[(i, g)] = theirs
                    return answer
                start = min(first, reached)
        if start > i + 1:
            assert theirs is not None
            z = theirs[0][start - i - 1]
            mine = list(theirs[0][:start - i])
            apart = {v for v in z.fixed.keys() | states[start].fixed.keys()
                     if z.fixed.get(v) != states[start].fixed.get(v)}
        else:
            z, _ = self.narrow(states[i], g)
            mine = [z]
            # the outputs z and the chain fix apart, kept step by step: each narrowing fixes one at
            # most (a shortcut only: a chain that rejoins gives the same relation at the end); where
            # they fix outputs apart, asked at steps i+1, i+2, i+4, … only (each asking costs
            # cofactors), where they fix the same ones, at every step (their rests compared)
            apart = set()
            _moved(apart, z, states[i], states[i + 1], states[i])
        answer, complete = self._run(i, z, start, apart, mine, agree, theirs, outputs)
        self.runs[(i, g)] = (mine, answer, complete)
        return answer

    def _run(self, i: int, z: Fixed, start: int, apart: set[str], mine: list[Fixed], agree: int,
             theirs: tuple[list[Fixed], list[str], bool] | None, outputs: Sequence[str]) -> tuple[list[str], bool]:
        """:meth:`differ` from step ``start`` (``z`` there, ``apart`` the outputs it and the
        chain fix apart), each ``z`` appended to ``mine``; the answer and whether it was
        reached by this chain alone (not taken from ``theirs`` at a step past ``agree``)."""
        states, there = self.states, self.there
        ask = start
        for j in range(start, len(there)):
            s = states[j]
            if theirs is not None and j >= agree and j - i - 1 < len(theirs[0]) and _equal(z, theirs[0][j - i - 1]):
                return theirs[1], False
            if z is s or (not apart and z.rest == s.rest):
                return [], True
            if apart and j == ask:
                if self._same_apart(z, s, _items(apart, z, s)):
                    return [], True
                ask += ask - i
            before, (z, _) = z, self.narrow(z, there[j])
            mine.append(z)
            _moved(apart, z, before, states[j + 1], s)
        last = states[-1]
        if z is last or (self._same_apart(z, last, _items(apart, z, last)) if apart else z.rest == last.rest):
            return [], True
        out = []
        for o in outputs:
            v = self.engine.declare(o)
            if (self.can(z, v, True), self.can(z, v, False)) != (self.can(last, v, True), self.can(last, v, False)):
                out.append(o)
        return out, True


def _disagreeing(states: Sequence[Fixed], there: Sequence[Function], like: AtPoint, steps: Iterable[int],
                 default: int) -> int:
    """The first of ``steps`` where ``states`` and ``like``'s are other relations or the criteria
    there are others (``default``: none)."""
    n = len(there)
    for j in steps:
        if not _equal(states[j], like.states[j]) or (j < n and there[j] != like.there[j]):
            return j
    return default


def _equal(a: Fixed, b: Fixed) -> bool:
    """Whether ``a`` and ``b`` fix the same outputs to the same values and have the same rest."""
    return a is b or (a.rest == b.rest and a.fixed == b.fixed)


def _moved(apart: set[str], z: Fixed, z_before: Fixed, s: Fixed, s_before: Fixed) -> None:
    """``apart`` (the outputs ``z_before`` and ``s_before`` fix apart) made those ``z`` and ``s``
    fix apart, each narrowed from its ``_before`` (fixing one output more at most)."""
    for x, before in ((z, z_before), (s, s_before)):
        v = x.added if x.fixed is not before.fixed else None
        if v is not None:
            if z.fixed.get(v) != s.fixed.get(v):
                apart.add(v)
            else:
                apart.discard(v)


def _items(apart: set[str], a: Fixed, b: Fixed) -> list[tuple[str, bool]]:
    """The fixed items of ``a`` and ``b`` on the outputs ``apart``: their symmetric difference."""
    return [(v, x.fixed[v]) for v in sorted(apart) for x in (a, b) if v in x.fixed]

"""Two spellings of one relief (issue 23): ``keep L`` and ``force o=v, …`` name the same
column of 000's MC0/MC1, so the loop algorithm reads them alike; the algebraic synthesis
does not (004 eq. 24 minimises ``!L`` for ``keep L``, the forced outputs being off their
values for ``force``), and the two can give different filters — on the four-cylinder square
the ``force`` spelling starves the pallets. :func:`spelling_warnings` solves the filter with
each combined constraint's relief written the other way and warns, located at the relief,
where the two filters differ: the care set, or an output's ``∃O.(S∧o)`` or ``∃O.(S∧!o)``
(the outputs it drives differently, on the inputs where it is defined; docs/filter.md).

Points come first (:mod:`synth.filter.points`): at one valuation of what the filter reads,
both chains are small, and a point where they differ is a witness, given in the warning
(made sparse: the variables at 1, the others 0). The reliefs no point shows different are
compared on every input, within a work limit: one chain of narrowings serves them all, as
the criteria differ in one priority only; each other spelling runs from the state before
its criterion, without the "no effect" races, and stops where its state rejoins the chain's.

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> f = parse_filter("inputs i\\noutputs a, b\\nsafety K: i & a & b keep a", "k.filter")
>>> [s.text() for s in other_spellings(f)]
['keep a', 'force b=0']
>>> spelling_warnings(f).reports()
[]
"""

from __future__ import annotations

import dataclasses
import functools
import random
from typing import Sequence

from synth.errors import InputError, Location, Severity
from synth.filter import points
from synth.filter.language import Criterion, Filter, Forcing, Safety, Sense
from synth.filter.language_check import output_polarities
from synth.filter.at_point import AtPoint
from synth.filter.narrowing import decided, layout
from synth.logic.bdd import Function
from synth.logic.expr import And, Expr, Not, Var
from synth.logic.partition import State
from synth.logic.past import pre_name

__all__ = ["REGION_WORK", "SPELLING_WORK", "Spelling", "Spellings", "Witness", "other_spellings", "spelling_warnings"]


@dataclasses.dataclass(frozen=True)
class Spelling:
    """A relief written one way: ``keep L`` or ``force o=v, …``."""

    keep: Expr | None
    force: tuple[Forcing, ...]

    def text(self) -> str:
        if self.keep is not None:
            return f"keep {self.keep.text()}"
        return "force " + ", ".join(f"{f.output}={int(f.value)}" for f in self.force)


def _other(s: Safety) -> Spelling | None:
    """The relief of ``s`` written the other way, when there is one."""
    if s.keep is not None:
        return Spelling(None, s.forced)
    kept = [o for o in s.outputs if o not in {f.output for f in s.forced}]
    if not kept:  # every output forced (to 0): no literal is kept, there is no `keep` spelling
        return None
    polarity = output_polarities(s.expr, set(s.outputs))
    if any(len(polarity[o]) != 1 for o in kept):
        return None
    literals: list[Expr] = [Var(o) if True in polarity[o] else Not(Var(o)) for o in kept]
    return Spelling(literals[0] if len(literals) == 1 else And(tuple(literals)), ())


def other_spellings(f: Filter) -> list[Spelling]:
    """For the first combined constraint with a relief: its spelling, then the other one
    (the doctest's helper; :func:`spelling_warnings` walks them all)."""
    for s in f.combined:
        other = _other(s) if s.has_priority else None
        if other is not None:
            return [Spelling(s.keep, s.force if s.keep is None else ()), other]
    return []


class _Chain:
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
        """While set, the work (:meth:`Engine.work`) past which running the chain gives up."""
        self.coarse = False
        """Whether the regions are taken on ``S_0`` (:meth:`sparse_points`)."""

    def _upto(self, j: int) -> State:
        """The chain's ``S_j``, the chain run that far if it is not yet (the points need it
        only up to the last relief's criterion)."""
        while len(self.states) <= j:
            if self.budget is not None and self.m.engine.work() > self.budget:
                raise _TooWide
            n = len(self.bests)
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

    def sparse_points(self, candidates: Sequence[int], work: int) -> dict[int, Witness]:
        """:meth:`at_points` with the free variables 0, its regions on the chain's ``S_i``
        while running the chain that far costs at most ``work``; past it, on ``S_0``
        (:meth:`_initial_region`, :attr:`coarse`: the chain is not run, and
        :func:`spelling_warnings` compares nothing on every input)."""
        self.budget = self.m.engine.work() + work
        try:
            return self.at_points(candidates, points.POINT_DEFAULTS[:1], 0)
        except _TooWide:
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

    def _differ_at(self, here: AtPoint, n: int) -> list[str]:
        """The outputs alternative ``n`` drives differently at the point ``here`` (the chain
        there), none where it rejoins the chain."""
        alternative = self.alternatives[n]
        assert alternative is not None
        i, g = alternative
        return here.differ(i, g, self.m.outputs)

    def _witness(self, at: points.Points, n: int, point: dict[str, bool]) -> Witness:
        """``point`` made sparse: its variables at 1 set to 0, all of a group at once (the
        whole set, then halves, and so on), wherever alternative ``n`` still differs; the
        outputs it drives differently at the point left."""
        point = dict(point)

        region = self._region(n)

        def differs() -> list[str]:
            return self._differ_at(AtPoint(at, point), n) if at.holds(region, point) else []

        groups = [[v for v in at.others if point[v]]]  # a stack, not a recursive closure (no cycle to collect)
        while groups:
            group = groups.pop()
            for v in group:
                point[v] = False
            if differs():
                continue
            for v in group:
                point[v] = True
            if len(group) > 1:
                groups += [group[len(group) // 2:], group[:len(group) // 2]]
        e = self.m.engine
        value = {x: point[e.declare(x)] for x in e.names if e.declare(x) in point}
        integers: list[tuple[str, int]] = []
        for i in self.m.filter.integer_observers:  # their bits read as the integer (and its ^-1)
            for name, bits in ((i.name, i.bits), (pre_name(i.name), [pre_name(b) for b in i.bits])):
                if all(b in value for b in bits):
                    integers.append((name, i.low + sum(value.pop(b) << k for k, b in enumerate(bits))))
        return Witness(tuple(differs()), tuple(x for x, v in value.items() if v), tuple(integers))

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

    @functools.cached_property
    def _walked(self) -> list[tuple[Function, Function, Function]]:
        """The file's chain run once more on a :class:`~synth.logic.partition.Walk`, so that
        its messages at every step are kept by value (the alternatives of :meth:`differ`
        meet them); what each bag's local relation is made of at its end."""
        w = self.p.walk(self.states[len(self.goods)])
        return [w.around(m) for m in range(len(w.domains))]


class _TooWide(Exception):
    """Running the chain passed :attr:`_Chain.budget`."""


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


SPELLING_WORK = 10_000_000
"""The BDD work (:meth:`Engine.work`) ``filter check`` spends on comparing on every input the
spellings of the reliefs no sparse point showed different, once the first is compared: about
4 CPU s on this project's machine. The chain of 64 outputs needs 2 % of it for its 63
reliefs; the grids of 32 to 64 outputs need none (a point shows each relief)."""

REGION_WORK = 10_000_000
"""The BDD work ``filter check`` spends on running the chain of narrowings up to the last
relief's criterion, for the regions its points are taken in: past it, the regions are
taken on ``S_0`` and no relief is compared on every input (grid_edges of 8 × 5 outputs
and more: 13 M at 8 × 5, over 50 M at 8 × 8; the grid of 64 and grid_edges 8 × 4 need 3.4
M, the chain of 256 0.6 M, the ring of 32 1.2 M)."""


@dataclasses.dataclass(frozen=True)
class Spellings:
    """What :func:`spelling_warnings` found: the warnings, and the reliefs not compared
    because the work limit was reached first (in file order), no point showing them
    different."""

    warnings: list[InputError]
    skipped: tuple[Safety, ...] = ()
    limit: int | None = None

    def reports(self) -> list[InputError]:
        """The warnings, then one located at the first relief not compared, if any."""
        if not self.skipped:
            return self.warnings
        first = self.skipped[0]
        ids = ", ".join(s.id for s in self.skipped[:3]) + (", …" if len(self.skipped) > 3 else "")
        return self.warnings + [InputError(
            f"the keep/force spellings of {len(self.skipped)} relief(s) ({ids}) were not compared: "
            f"over the work limit of the comparison ({self.limit or 0:,} BDD steps)",
            _relief_loc(first), severity=Severity.WARNING,
            notes=("`synth filter check --all-spellings` compares them all, whatever it costs",))]


def _relief_loc(s: Safety) -> Location | None:
    return (s.keep.loc if isinstance(s.keep, Var) and s.keep.loc else (s.force[0].loc if s.force else s.loc)) or s.loc


def spelling_warnings(f: Filter, safeties: Sequence[Safety] | None = None,
                      limit: int | None = SPELLING_WORK, regions: int = REGION_WORK) -> Spellings:
    """A located warning for each relief whose other spelling gives a different algebraic
    filter: another care set, or an output that may be on or may be off on some input.

    With a ``limit``: first the sparse points (:meth:`_Chain.at_points`; the free
    variables 0), a relief one shows different warned with it; the others compared on
    every input while the BDD work spent on them stays under ``limit`` (the first always);
    those left tried at the other points (free variables 1, random), and the rest listed,
    not compared. When the chain up to the last relief costs more than ``regions``, the
    points are taken where the criteria narrow ``S_0`` and none is compared on every input
    (:meth:`_Chain.sparse_points`). ``limit`` None: every relief compared on every input,
    each warning naming every output it drives differently."""
    swapped: list[tuple[Safety, Safety]] = []  # each relief and the same constraint written the other way
    for s in (safeties if safeties is not None else f.combined):
        other = _other(s) if s.has_priority else None
        if other is not None:
            swapped.append((s, dataclasses.replace(s, keep=other.keep, force=other.force)))
    if not swapped:
        return Spellings([])
    chain = _Chain(f, swapped)
    every = range(len(swapped))
    sparse = {} if limit is None else chain.sparse_points(every, regions)
    compared: dict[int, list[str] | None] = {}
    left: list[int] = []
    start = chain.m.engine.work()
    for n in every:
        if n in sparse:
            continue
        if chain.coarse or (compared and limit is not None and chain.m.engine.work() - start > limit):
            left.append(n)
        else:
            compared[n] = chain.differ(n)
    dense = chain.at_points(left, points.POINT_DEFAULTS[1:], points.POINT_ROUNDS) if left else {}
    shown = sparse | dense
    out: list[InputError] = []
    for n, (s, _) in enumerate(swapped):
        outputs = compared.get(n)
        if n in shown:
            differ = shown[n].text()
        elif outputs is not None:
            differ = f"it drives {', '.join(outputs)} differently"
        else:
            continue
        other = _other(s)
        assert other is not None
        written = Spelling(s.keep, s.force if s.keep is None else ())
        loop = Spelling(None, s.forced).text()
        notes = [f"the algebraic filter uses `{written.text()}`, as written; the loop algorithm reads either "
                 f"spelling as `{loop}`"]
        if n in shown:
            notes.append("`synth filter check --all-spellings` compares on every input and names every output "
                         "it drives differently")
        out.append(InputError(
            f"{s.id}'s relief `{written.text()}` written `{other.text()}` gives another algebraic filter ({differ})",
            _relief_loc(s), severity=Severity.WARNING, notes=tuple(notes)))
    skipped = tuple(swapped[n][0] for n in left if n not in dense)
    return Spellings(out, skipped, limit if skipped else None)

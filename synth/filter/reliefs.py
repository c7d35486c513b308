"""Two spellings of one relief (issue 23): ``keep L`` and ``force o=v, …`` name the same
column of 000's MC0/MC1, so the loop algorithm reads them alike; the algebraic synthesis
does not (004 eq. 24 minimises ``!L`` for ``keep L``, the forced outputs being off their
values for ``force``), and the two can give different filters — on the four-cylinder square
the ``force`` spelling starves the pallets. :func:`spelling_warnings` solves the filter with
each combined constraint's relief written the other way and warns, located at the relief,
where the two filters differ: the care set, or an output's ``∃O.(S∧o)`` or ``∃O.(S∧!o)``
(the outputs it drives differently, on the inputs where it is defined; docs/filter.md).
The criteria differ in one priority only, so one chain of narrowings serves them all: each
other spelling runs from the state before its criterion, without the "no effect" races,
and stops where its state rejoins the chain's.

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
from typing import Sequence

from synth.errors import InputError, Location, Severity
from synth.filter.language import Criterion, Filter, Forcing, Safety, Sense
from synth.filter.language_check import output_polarities
from synth.filter.narrowing import decided, layout
from synth.logic.bdd import Function
from synth.logic.expr import And, Expr, Not, Var
from synth.logic.partition import State

__all__ = ["SPELLING_WORK", "Spelling", "Spellings", "other_spellings", "spelling_warnings"]


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

    def __init__(self, f: Filter, swapped: Sequence[tuple[Safety, Filter]]) -> None:
        from synth.filter.model import functions
        from synth.filter.solve import criteria

        self.m = m = functions(f)
        written = criteria(f)
        self.goods = [self._good(c) for c in written]
        self.alternatives: list[tuple[int, Function] | None] = []
        for _, alt in swapped:  # at most one priority criterion differs: its position and its good
            other = criteria(alt)
            i = next((i for i, (a, b) in enumerate(zip(written, other)) if a != b), None)
            good = None if i is None else self._good(other[i])
            self.alternatives.append(None if i is None or good == self.goods[i] else (i, good))
        self.p = layout(m, self.goods + [a[1] for a in self.alternatives if a is not None])
        self.where = [self.p.position(g) for g in self.goods]
        self.states = [self.p.initial]
        for g, k in zip(self.goods, self.where):
            self.states.append(self._step(self.states[-1], k, g))
        self.base = self._outcome(self.states[-1])

    def _good(self, c: Criterion) -> Function:
        u = self.m.engine.expr(c.expr)
        return u if c.sense is Sense.MAX else ~u

    def _step(self, s: State, k: int, g: Function) -> State:
        return self.p.refine(s, k, g.equiv(self.p.project(s, k, g)))

    def _outcome(self, s: State) -> tuple[Function, dict[str, Function], dict[str, Function]]:
        return decided(self.p, s, self.m.outputs)

    def differ(self, n: int) -> list[str] | None:
        """The outputs alternative ``n`` drives differently (another ``∃O.(S∧o)`` or
        ``∃O.(S∧!o)``; every output when only the care set differs), None when the two
        spellings give the same filter."""
        alternative = self.alternatives[n]
        if alternative is None:  # the criteria are the file's: the spelling changes none
            return None
        i, g = alternative
        mark = self.p.mark()
        s = self._step(self.states[i], self.p.position(g), g)
        for j in range(i + 1, len(self.goods) + 1):
            if s.domains == self.states[j].domains:  # the chain rejoined: the same filter from here
                self.p.forget(mark)
                return None
            if j < len(self.goods):
                s = self._step(s, self.where[j], self.goods[j])
        care, ones, zeros = self._outcome(s)
        self.p.forget(mark)
        differ = [o for o in self.m.outputs if ones[o] != self.base[1][o] or zeros[o] != self.base[2][o]]
        if not differ and care == self.base[0]:
            return None
        return differ or list(self.m.outputs)


SPELLING_WORK = 10_000_000
"""The BDD work (:meth:`Engine.work`) ``filter check`` spends on comparing the spellings of
the other reliefs once the first is compared: about 4 CPU s on this project's machine; the
grid of 32 outputs needs half of it for its 52 reliefs, the grid of 64 fifteen times it."""


@dataclasses.dataclass(frozen=True)
class Spellings:
    """What :func:`spelling_warnings` found: the warnings, and the reliefs not compared
    because the work limit was reached first (in file order)."""

    warnings: list[InputError]
    skipped: tuple[Safety, ...] = ()
    limit: int | None = None

    def reports(self) -> list[InputError]:
        """The warnings, then one located at the first relief not compared, if any."""
        if not self.skipped:
            return self.warnings
        first = self.skipped[0]
        return self.warnings + [InputError(
            f"the keep/force spellings of {len(self.skipped)} relief(s) from {first.id} on were not compared: "
            f"over the work limit of the comparison ({self.limit or 0:,} BDD steps)",
            _relief_loc(first), severity=Severity.WARNING,
            notes=("`synth filter check --all-spellings` compares them all, whatever it costs",))]


def _relief_loc(s: Safety) -> Location | None:
    return (s.keep.loc if isinstance(s.keep, Var) and s.keep.loc else (s.force[0].loc if s.force else s.loc)) or s.loc


def spelling_warnings(f: Filter, safeties: Sequence[Safety] | None = None,
                      limit: int | None = SPELLING_WORK) -> Spellings:
    """A located warning for each relief whose other spelling gives a different algebraic
    filter: another care set, or an output that may be on or may be off on other inputs.
    ``limit``: the BDD work for the reliefs after the first (None: no limit); the reliefs
    left when it is spent are listed, not compared."""
    swapped: list[tuple[Safety, Filter]] = []
    for s in (safeties if safeties is not None else f.combined):
        other = _other(s) if s.has_priority else None
        if other is not None:
            t = dataclasses.replace(s, keep=other.keep, force=other.force)
            swapped.append((s, dataclasses.replace(f, safeties=tuple(t if u is s else u for u in f.safeties))))
    if not swapped:
        return Spellings([])
    chain = _Chain(f, swapped)
    out: list[InputError] = []
    start = chain.m.engine.work()
    for n, (s, _) in enumerate(swapped):
        if n and limit is not None and chain.m.engine.work() - start > limit:
            return Spellings(out, tuple(s for s, _ in swapped[n:]), limit)
        differ = chain.differ(n)
        if differ is None:
            continue
        other = _other(s)
        assert other is not None
        written = Spelling(s.keep, s.force if s.keep is None else ())
        loop = Spelling(None, s.forced).text()
        out.append(InputError(
            f"{s.id}'s relief `{written.text()}` written `{other.text()}` gives another algebraic filter "
            f"(it drives {', '.join(differ)} differently)",
            _relief_loc(s), severity=Severity.WARNING,
            notes=(f"the algebraic filter uses `{written.text()}`, as written; the loop algorithm reads either "
                   f"spelling as `{loop}`",)))
    return Spellings(out)

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
compared on every input, within a size limit: one chain of narrowings serves them all, as
the criteria differ in one priority only; each other spelling runs from the state before
its criterion, without the "no effect" races, and stops where its state rejoins the chain's
(:class:`synth.filter.spelling_chain.SpellingChain`).

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
from synth.filter import points
from synth.filter.language import Filter, Forcing, Safety
from synth.filter.language_check import output_polarities
from synth.filter.spelling_chain import SpellingChain, Witness
from synth.logic.expr import And, Expr, Not, Var

__all__ = ["REGION_SIZE", "SPELLING_SIZE", "Spelling", "Spellings", "Witness", "other_spellings", "spelling_warnings"]


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


SPELLING_SIZE = 125_000_000
"""How much ``filter check`` compares on every input, once the first relief is compared, of the
reliefs no sparse point showed different: the sum of their :meth:`SpellingChain.size` (BDD
nodes × variables), a measure of the filter and its chain, not of the work the comparison
does, so that a faster comparison compares the same reliefs. The bundled filters, the chain
of 256 outputs, the ring of 16 and grid_edges 8 × 3 are compared in full (3.0·10^7, 5.1·10^7
and 7.9·10^7 spent before their last relief); it stops the ring of 32 after K19 (1.31·10^8 with it) and grid_edges
8 × 4 after V3_2 (1.44·10^8 with it), where 10^7 lookups of CUDD's computed table, the limit
before, stopped them too."""

REGION_SIZE = 10_000
"""How wide a chain of narrowings ``filter check`` runs up to the last relief's criterion, for
the regions its points are taken in: the BDD nodes of its local relation at each criterion
(a size read on the filter and its chain, not on the work done, as :data:`SPELLING_SIZE`).
Past it, the regions are taken on ``S_0`` and no relief is compared on every input:
grid_edges of 8 × 5 outputs and more (8 × 5 passes it at its 37th criterion, 8 × 8 at its
46th, with 10 916 and 10 999 nodes); below it, grid_edges 8 × 4 (7 090 nodes at most), the
grid of 64 (6 471), the ring of 32 (4 347) and of 48 (6 499), the chain of 256 (259)."""


@dataclasses.dataclass(frozen=True)
class Spellings:
    """What :func:`spelling_warnings` found: the warnings, and the reliefs not compared
    because the size limit was reached first (in file order), no point showing them
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
            f"over the size limit of the comparison ({self.limit or 0:,} BDD nodes × variables)",
            _relief_loc(first), severity=Severity.WARNING,
            notes=("`synth filter check --all-spellings` compares them all, whatever it costs",))]


def _relief_loc(s: Safety) -> Location | None:
    return (s.keep.loc if isinstance(s.keep, Var) and s.keep.loc else (s.force[0].loc if s.force else s.loc)) or s.loc


def spelling_warnings(f: Filter, safeties: Sequence[Safety] | None = None,
                      limit: int | None = SPELLING_SIZE, regions: int = REGION_SIZE) -> Spellings:
    """A located warning for each relief whose other spelling gives a different algebraic
    filter: another care set, or an output that may be on or may be off on some input.

    With a ``limit``: first the sparse points (:meth:`SpellingChain.at_points`; the free
    variables 0), a relief one shows different warned with it; the others compared on
    every input while the sizes of those compared (:meth:`SpellingChain.size`) stay under ``limit``
    (the first always);
    those left tried at the other points (free variables 1, random), and the rest listed,
    not compared. When the chain's local relation at a criterion up to the last relief's
    has more than ``regions`` nodes (-1: always), the points are taken where the criteria
    narrow ``S_0`` and none is compared on every input (:meth:`SpellingChain.sparse_points`).
    ``limit`` None: every relief compared on every input, each warning naming every output it
    drives differently."""
    swapped: list[tuple[Safety, Safety]] = []  # each relief and the same constraint written the other way
    for s in (safeties if safeties is not None else f.combined):
        other = _other(s) if s.has_priority else None
        if other is not None:
            swapped.append((s, dataclasses.replace(s, keep=other.keep, force=other.force)))
    if not swapped:
        return Spellings([])
    chain = SpellingChain(f, swapped)
    every = range(len(swapped))
    sparse = {} if limit is None else chain.sparse_points(every, regions)
    compared: dict[int, list[str] | None] = {}
    left: list[int] = []
    spent = 0
    for n in every:
        if n in sparse:
            continue
        if chain.coarse or (compared and limit is not None and spent > limit):
            left.append(n)
        else:
            compared[n] = chain.differ(n)
            spent += 0 if limit is None else chain.size(n)
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

"""Two spellings of one relief (issue 23): ``keep L`` and ``force o=v, …`` name the same
column of 000's MC0/MC1, so the loop algorithm reads them alike; the algebraic synthesis
does not (004 eq. 24 minimises ``!L`` for ``keep L``, the forced outputs being off their
values for ``force``), and the two can give different filters — on the four-cylinder square
the ``force`` spelling starves the pallets. :func:`spelling_warnings` synthesises the filter
with each combined constraint's relief written the other way and warns, located at the
relief, where the equations differ.

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> f = parse_filter("inputs i\\noutputs a, b\\nsafety K: i & a & b keep a", "k.filter")
>>> [s.text() for s in other_spellings(f)]
['keep a', 'force b=0']
>>> spelling_warnings(f)
[]
"""

from __future__ import annotations

import dataclasses
from typing import Sequence

from synth.errors import InputError, Severity
from synth.filter.language import Filter, Forcing, Safety
from synth.filter.language_check import output_polarities
from synth.logic.expr import And, Expr, Not, Var

__all__ = ["Spelling", "other_spellings", "spelling_warnings"]


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


def _chained(f: Filter) -> tuple[bool, bool, dict[str, str]]:
    from synth.filter.solve import synthesis

    s = synthesis(f)
    return s.functional, s.consistent, dict(s.chained)


def spelling_warnings(f: Filter, safeties: Sequence[Safety] | None = None) -> list[InputError]:
    """A located warning for each relief whose other spelling gives a different algebraic filter."""
    out: list[InputError] = []
    base: tuple[bool, bool, dict[str, str]] | None = None
    for s in (safeties if safeties is not None else f.combined):
        other = _other(s) if s.has_priority else None
        if other is None:
            continue
        if base is None:
            base = _chained(f)
        swapped = dataclasses.replace(s, keep=other.keep, force=other.force)
        alt = _chained(dataclasses.replace(f, safeties=tuple(swapped if t is s else t for t in f.safeties)))
        if alt == base:
            continue
        written = Spelling(s.keep, s.force if s.keep is None else ())
        differ = [o for o in f.outputs if base[2].get(o) != alt[2].get(o)] or list(f.outputs)
        loc = s.keep.loc if isinstance(s.keep, Var) and s.keep.loc else (s.force[0].loc if s.force else s.loc)
        loop = Spelling(None, s.forced).text()
        out.append(InputError(
            f"{s.id}'s relief `{written.text()}` written `{other.text()}` gives another algebraic filter "
            f"(the equations of {', '.join(differ)} differ)",
            loc or s.loc, severity=Severity.WARNING,
            notes=(f"the algebraic filter uses `{written.text()}`, as written; the loop algorithm reads either "
                   f"spelling as `{loop}`",)))
    return out

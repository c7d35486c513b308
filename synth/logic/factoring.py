"""The text of a cover: each cube's literals, an edge recognised where a variable and its
previous value differ (``!x^-1 & x`` is ``↑x``), sorted in the text order, then the cubes
factored greedily (the literal common to most terms taken out first, ties to the first in
the text order).

Example
-------
>>> a, b, c = (0, "a"), (1, "b"), (2, "c")
>>> factored([[a, b], [a, c], [c]], top=True)
'a & (b | c) | c'
>>> [t for _, t in cube_literals({"x^-1": False, "x": True, "y": False}, {"x": 0, "y": 1})]
['↑x', '!y']
"""

from __future__ import annotations

from typing import Mapping, Sequence

from synth.logic.isop import Cube
from synth.logic.past import PRE_SUFFIX

__all__ = ["cube_literals", "factored"]

_Lit = tuple[int, str]  # (sort key, text)


def cube_literals(cube: Cube, order: Mapping[str, int]) -> list[_Lit]:
    lits: list[_Lit] = []
    done: set[str] = set()  # the names an edge took
    cut = len(PRE_SUFFIX)
    for n, v in cube.items():
        if done and n in done:
            continue
        if n.endswith(PRE_SUFFIX):
            now = n[:-cut]
            w = cube.get(now)
            if w is not None and w != v:  # !x^-1 & x is ↑x, x^-1 & !x is ↓x
                done.update((n, now))
                lits.append((order.get(now, 0), ("↓" if v else "↑") + now))
                continue
        else:
            w = cube.get(n + PRE_SUFFIX)
            if w is not None and w != v:
                continue  # printed with its past value above
        lits.append((order.get(n, 0), n if v else "!" + n))
    return sorted(lits)


def factored(terms: Sequence[list[_Lit]], top: bool = False) -> str:
    """Greedy algebraic factoring: take out the literal common to most terms (ties to the
    first), then again from the terms without it; the terms with it factored the same way.

    One pass over the cover: a term is never copied (the literals taken out on the way down
    are skipped where it is printed), and when a literal splits the terms, the counts of the
    smaller side are counted afresh and the other side's are what remains of the counts
    (a chain of nested factors, as on the chain of outputs, costs the terms' length once per
    level, not the whole cover)."""
    if any(not t for t in terms):
        return "1"
    counts: dict[_Lit, int] = {}
    for t in terms:
        for lit in t:
            counts[lit] = counts.get(lit, 0) + 1
    return _factored([(t, frozenset(t)) for t in terms], counts, frozenset(), top)


_Term = tuple[Sequence[_Lit], frozenset[_Lit]]  # a term's literals in order, and as a set


def _counted(terms: list[_Term], removed: frozenset[_Lit]) -> dict[_Lit, int]:
    counts: dict[_Lit, int] = {}
    for t, _ in terms:
        for lit in t:
            if lit not in removed:
                counts[lit] = counts.get(lit, 0) + 1
    return counts


def _without(counts: dict[_Lit, int], part: Mapping[_Lit, int]) -> None:
    """``counts`` less those of ``part`` (a part of its terms), in place."""
    for lit, n in part.items():
        left = counts[lit] - n
        if left:
            counts[lit] = left
        else:
            del counts[lit]


def _factored(terms: list[_Term], counts: dict[_Lit, int], removed: frozenset[_Lit], top: bool) -> str:
    """:func:`factored` of ``terms`` without the literals ``removed`` (taken out above: each
    term has them all), none left empty; ``counts``: their other literals' counts (consumed)."""
    heads: list[str] = []
    while True:
        most = max(counts.values()) if counts else 0
        if most < 2:
            out = " | ".join(" & ".join(lit[1] for lit in t if lit not in removed) for t, _ in terms)
            if not heads:
                return out if top or len(terms) == 1 else f"({out})"
            heads.append(out)
            break
        best = min(lit for lit, n in counts.items() if n == most)  # the first of those common to most terms
        inner = [t for t in terms if best in t[1]]
        rest = [t for t in terms if best not in t[1]]
        depth = len(removed) + 1  # the literals a term of inner has that are not left
        if any(len(t) == depth for t, _ in inner):  # x | x & y: cannot happen in an irredundant cover
            heads.append(best[1])
            if rest:
                _without(counts, _counted(inner, removed))
        else:
            here = removed | {best}
            if not rest:
                del counts[best]
                inner_counts, counts = counts, {}
            elif sum(len(t) for t, _ in inner) - depth * len(inner) <= sum(len(t) for t, _ in rest) - (depth - 1) * len(rest):
                inner_counts = _counted(inner, here)
                _without(counts, inner_counts)
                del counts[best]
            else:
                rest_counts = _counted(rest, removed)
                _without(counts, rest_counts)
                del counts[best]
                inner_counts, counts = counts, rest_counts
            heads.append(f"{best[1]} & {_factored(inner, inner_counts, here, False)}")
        if not rest:
            if len(heads) == 1:
                return heads[0]
            break
        terms = rest
    out = " | ".join(heads)
    return out if top else f"({out})"

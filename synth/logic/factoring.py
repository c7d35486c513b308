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
from synth.logic.past import PRE_SUFFIX, pre_name

__all__ = ["cube_literals", "factored"]

_Lit = tuple[int, str]  # (sort key, text)


def cube_literals(cube: Cube, order: Mapping[str, int]) -> list[_Lit]:
    lits: list[_Lit] = []
    done: set[str] = set()
    for n, v in cube.items():
        if n in done:
            continue
        if n.endswith(PRE_SUFFIX):
            now = n[: -len(PRE_SUFFIX)]
            if now in cube and cube[now] != v:  # !x^-1 & x is ↑x, x^-1 & !x is ↓x
                done.update((n, now))
                lits.append((order.get(now, 0), ("↓" if v else "↑") + now))
                continue
        elif pre_name(n) in cube and cube[pre_name(n)] != v:
            continue  # printed with its past value above
        done.add(n)
        lits.append((order.get(n, 0), n if v else "!" + n))
    return sorted(lits)


def factored(terms: Sequence[list[_Lit]], top: bool = False) -> str:
    """Greedy algebraic factoring: take out the literal common to most terms, then again from
    the terms without it (one pass, the counts updated rather than recounted)."""
    terms = [t for t in terms]
    if any(not t for t in terms):
        return "1"
    counts: dict[_Lit, int] = {}
    for t in terms:
        for lit in t:
            counts[lit] = counts.get(lit, 0) + 1
    heads: list[str] = []
    while True:
        best = min(counts, key=lambda lit: (-counts[lit], lit)) if counts else None
        if best is None or counts[best] < 2:
            out = " | ".join(" & ".join(text for _, text in t) for t in terms)
            if not heads:
                return out if top or len(terms) == 1 else f"({out})"
            heads.append(out)
            break
        inner = [[lit for lit in t if lit != best] for t in terms if best in t]
        rest = [t for t in terms if best not in t]
        if any(not t for t in inner):  # x | x & y: cannot happen in an irredundant cover
            heads.append(best[1])
        else:
            sub = factored(inner)
            heads.append(f"{best[1]} & {sub}" if len(inner) > 1 else best[1] + " & " + sub)
        if not rest:
            if len(heads) == 1:
                return heads[0]
            break
        for t in terms:  # the terms with best leave the counts
            if best in t:
                for lit in t:
                    counts[lit] -= 1
                    if not counts[lit]:
                        del counts[lit]
        terms = rest
    out = " | ".join(heads)
    return out if top else f"({out})"

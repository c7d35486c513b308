"""Sets of input vectors as bit sets, and their readable cover (a small sum of cubes).

Used by the ASS to label a transition with the condition on the other inputs.

Example
-------
>>> c = Cubes(2)                                   # inputs a (bit 0) and b (bit 1)
>>> condition_text(c, c.cube({0: True}), c.cube({0: False}), ["a", "b"], [0, 1])
'a'
"""

from __future__ import annotations

from itertools import product
from typing import Mapping, Sequence

__all__ = ["Cubes", "condition_text", "cube_text"]


class Cubes:
    """Sets of input vectors as Python integers (bit ``v`` set iff vector ``v`` is in the set).

    A vector ``v`` has bit ``i`` set iff input ``i`` is 1. Set operations are integer
    bit operations, so whole sets are handled at once.
    """

    def __init__(self, n: int) -> None:
        self.n = n
        self.size = 1 << n
        self.full = (1 << self.size) - 1
        self.one: list[int] = []
        for i in range(n):
            block = ((1 << (1 << i)) - 1) << (1 << i)  # 2^i zeros then 2^i ones
            period = 1 << (i + 1)
            m = 0
            for start in range(0, self.size, period):
                m |= block << start
            self.one.append(m)
        self.zero = [self.full ^ m for m in self.one]

    def flip(self, s: int, i: int) -> int:
        """Every vector of ``s`` with input ``i`` flipped."""
        d = 1 << i
        return ((s & self.zero[i]) << d) | ((s & self.one[i]) >> d)

    def cube(self, literals: Mapping[int, bool]) -> int:
        """Vectors where input ``i`` equals ``literals[i]`` for every given ``i``."""
        c = self.full
        for i, value in literals.items():
            c &= self.one[i] if value else self.zero[i]
        return c

    def members(self, s: int) -> list[int]:
        out = []
        while s:
            low = s & -s
            out.append(low.bit_length() - 1)
            s ^= low
        return out


def condition_text(cubes: Cubes, on: int, off: int, names: Sequence[str], free: Sequence[int]) -> str:
    """A small DNF over inputs ``free`` true on every vector of ``on`` and false on every
    vector of ``off`` (other vectors: don't care); ``any`` when ``off`` is empty.

    >>> c = Cubes(2)
    >>> on = c.cube({0: True}) & ~c.cube({1: True})       # a & !b
    >>> off = c.cube({0: False})                          # !a
    >>> condition_text(c, on, off, ["a", "b"], [0, 1])
    'a'
    >>> condition_text(c, on, 0, ["a", "b"], [0, 1])
    'any'
    """
    if not off:
        return "any"
    keep = list(free)
    cl_on, cl_off = on, off
    for i in list(keep):  # drop every variable not needed to tell on from off
        t_on = cl_on | cubes.flip(cl_on, i)
        t_off = cl_off | cubes.flip(cl_off, i)
        if not t_on & t_off:
            keep.remove(i)
            cl_on, cl_off = t_on, t_off
    if len(keep) > 8:  # too many variables to minimise: list the vectors
        vecs = sorted({tuple(bool(v >> i & 1) for i in keep) for v in cubes.members(on)}, reverse=True)
        return " | ".join(cube_text(dict(zip(keep, vec)), names) for vec in vecs)
    candidates: list[tuple[dict[int, bool], int]] = []
    for values in product((None, True, False), repeat=len(keep)):
        lits = {i: v for i, v in zip(keep, values) if v is not None}
        c = cubes.cube(lits)
        if not c & off and c & on:
            candidates.append((lits, c))
    primes = [
        (l, c) for l, c in candidates
        if not any(c != d and c & d == c for _, d in candidates)
    ]
    uncovered = on
    chosen: list[dict[int, bool]] = []
    while uncovered:
        lits, c = max(
            primes,
            key=lambda lc: (
                (lc[1] & uncovered).bit_count(),
                -len(lc[0]),
                tuple(2 if lc[0].get(i) is None else int(lc[0][i]) for i in keep),
            ),
        )
        chosen.append(lits)
        uncovered &= ~c
    return " | ".join(cube_text(l, names) for l in chosen)


def cube_text(lits: Mapping[int, bool], names: Sequence[str]) -> str:
    parts = [(names[i] if v else "!" + names[i]) for i, v in sorted(lits.items())]
    return " & ".join(parts) if parts else "1"

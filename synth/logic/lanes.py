"""Covers evaluated on lanes: a sum of cubes compiled once into a Python function of
bit masks.

A value on lanes is a Python int whose bit ``j`` is the value in lane ``j``; ``full`` has
every lane's bit set. A cover (a tuple of cubes, each a tuple of ``(name, value)``
literals) on lanes is the OR over its cubes of the AND of its literals, a literal
``(n, True)`` being ``v[n]`` and ``(n, False)`` being ``full ^ v[n]``; the empty cover is
0 and the empty cube ``full``. :func:`compiled` writes those expressions for a sequence
of covers as the source of one Python function and compiles it once, so that evaluating
them is a run of bitwise operations of the interpreter instead of a loop over literals
and a call per cover (the closed loop of ``synth filter verify`` evaluates every
constraint once per class of states).

Example
-------
>>> f = compiled([((("a", True), ("b", False)), (("c", True),)), ((("c", False),),)])
>>> [bin(x) for x in f({"a": 0b1100, "b": 0b1010, "c": 0b0001}, 0b1111)]
['0b101', '0b1110']
>>> compiled([(), ((),)])({}, 0b11)
(0, 3)
"""

from __future__ import annotations

from functools import lru_cache
from typing import Callable, Collection, Mapping, Sequence

Cover = tuple[tuple[tuple[str, bool], ...], ...]
LaneFunction = Callable[[Mapping[str, int], int], tuple[int, ...]]

__all__ = ["Cover", "LaneFunction", "compiled", "lane_mask"]

def compiled(covers: Sequence[Cover], late: Collection[str] = ()) -> LaneFunction:
    """``covers`` as one function ``f(v, full)`` giving each cover's value on the lanes, in
    order (see the module). A cube is read literal by literal and left as soon as no lane
    is left on (``m = m and m & x``: one test where the rest would be read), its literals
    on the names ``late`` (those that differ from lane to lane, as a rule) last."""
    lines = ["def f(v, full):"]
    for k, cover in enumerate(covers):
        lines.append(f"    o{k} = 0")
        for cube in cover:
            ordered = sorted(cube, key=lambda lit: lit[0] in late)  # stable: the cube's order otherwise
            lits = [f"v[{n!r}]" if value else f"(full ^ v[{n!r}])" for n, value in ordered]
            if not lits:
                lines.append(f"    o{k} = full")
                continue
            lines.append(f"    m = full & {lits[0]}")
            lines += [f"    m = m and m & {x}" for x in lits[1:]]
            lines.append(f"    o{k} |= m")
    lines.append("    return (" + "".join(f"o{k}, " for k in range(len(covers))) + ")")
    scope: dict[str, object] = {}
    exec(compile("\n".join(lines), "<covers on lanes>", "exec"), scope)  # noqa: S102 (our own source)
    function: LaneFunction = scope["f"]  # type: ignore[assignment]
    return function


@lru_cache(maxsize=256)
def lane_mask(i: int, count: int) -> int:
    """The lanes, of ``count``, whose number has bit ``i`` set: the values of the ``i``-th
    free name when lane ``j`` gives it bit ``i`` of ``j``.

    >>> bin(lane_mask(0, 4)), bin(lane_mask(1, 4))
    ('0b1010', '0b1100')
    """
    return sum(1 << j for j in range(count) if (j >> i) & 1)

"""A lower bound on the cubes of every cover of an interval ``[lower, upper]`` (every sum of
cubes ``g`` with ``lower ≤ g ≤ upper``), hence on the Minato–Morreale cover's, which is one
of them: a flat probe (a cover asked for with at most N cubes) refused without building
the cubes when the bound exceeds N (docs/filter.md, "The covers' eliminations").

Let ``N(L, U)`` be the fewest cubes of a cover of ``[L, U]``. ``N(0, U) = 0``; ``N(L, 1) = 1``
for ``L ≠ 0``. For any variable ``v``, a cover's cubes have the literal ``!v`` (``a`` of
them), ``v`` (``b``) or neither (``c``). Those without ``v`` as a literal, restricted to
``v = 0``, cover ``[L0, U0]``: ``a + c ≥ N(L0, U0)``. A point of ``x1 = L1 ∧ ¬U0`` (``v = 1``)
lies in no cube without ``v`` (it would hold the point's twin at ``v = 0``, outside ``U``),
so the cubes with ``v`` cover it: ``b ≥ N(x1, U1)``. Hence

    N(L, U) ≥ N(L0, U0) + N(x1, U1)   and, the same way,   N(L, U) ≥ N(L1, U1) + N(x0, U0),

with ``x0 = L0 ∧ ¬U1``. Any variable will do, so the bound splits on the top variable of
the manager's order (the halves are the nodes' children, nothing is built but the ``x``),
and any lower bound may stand for an ``N`` on the right (``1`` for a non-empty ``x``, for
a pair left unexplored): every value below is a lower bound of ``N(lower, upper)``.

Two passes: :func:`path_bound` follows one branch per level (the one whose ``x`` on the
other side is not empty) and counts the non-empty ``x`` met: on the chain of outputs that
is the exact count, in one pass down the BDD. :func:`cubes_at_least` explores both
bounds at each pair of nodes, the ``x`` recursively, up to a number of pairs, and stops as
soon as the bound exceeds what the caller needs.

Example
-------
>>> import dd.cudd as cudd
>>> from synth.logic.native import native
>>> b = cudd.BDD(); b.declare("x", "y", "z")
>>> parity = b.add_expr(r"x ^ y ^ z")
>>> leq = native(b).leq
>>> path_bound(b, parity, parity, leq), cubes_at_least(b, parity, parity, leq, need=10)
(3, 4)
"""

from __future__ import annotations

from typing import Any, Callable

__all__ = ["PAIRS", "cubes_at_least", "path_bound"]

Function = Any  # a dd.cudd Function
Leq = Callable[[Function, Function], bool]

PAIRS = 1000
"""Pairs of nodes :func:`cubes_at_least` explores at most (past them, a pair counts 1)."""
DEPTH = 400
"""Nested pairs :func:`cubes_at_least` follows at most (deeper, a pair counts 1): far from
Python's recursion limit."""


def _halves(u: Function, level: int) -> tuple[Function, Function]:
    """``u`` at the variable of ``level`` false, then true (``u``'s children if it is its top)."""
    if u.var is None or u.level != level:
        return u, u
    low, high = u.low, u.high
    return (~low, ~high) if u.negated else (low, high)


def _split(bdd: Any, lower: Function, upper: Function) -> tuple[Function, Function, Function, Function]:
    """The halves ``L0, L1, U0, U1`` on the interval's top variable."""
    if lower.var is None:
        level = upper.level
    elif upper.var is None:
        level = lower.level
    else:
        level = min(lower.level, upper.level)
    l0, l1 = _halves(lower, level)
    u0, u1 = _halves(upper, level)
    return l0, l1, u0, u1


def path_bound(bdd: Any, lower: Function, upper: Function, leq: Leq) -> int:
    """``N(lower, upper)`` bounded along one path: at each level, ``N(L_b, U_b) + [x_(1-b) ≠ 0]``
    for the ``b`` whose other ``x`` is not empty (else the low half)."""
    count = 0
    false, true = bdd.false, bdd.true
    while lower != false:
        if upper == true:
            return count + 1
        l0, l1, u0, u1 = _split(bdd, lower, upper)
        if not leq(l0, u1):  # x0 is not empty: a cube with !v
            count += 1
            lower, upper = l1, u1
        else:
            if not leq(l1, u0):  # x1
                count += 1
            lower, upper = l0, u0
    return count


def cubes_at_least(bdd: Any, lower: Function, upper: Function, leq: Leq, need: int, pairs: int = PAIRS) -> int:
    """A lower bound of ``N(lower, upper)``, exploring at most ``pairs`` pairs of nodes; it
    stops as soon as it exceeds ``need``."""
    bound = _Bound(bdd, leq, pairs)
    return bound.at_least(lower, upper, need, 0)


class _Bound:
    def __init__(self, bdd: Any, leq: Leq, pairs: int) -> None:
        self.bdd, self.leq, self.pairs = bdd, leq, pairs
        self.known: dict[tuple[Function, Function], int] = {}

    def at_least(self, lower: Function, upper: Function, need: int, depth: int) -> int:
        bdd = self.bdd
        if lower == bdd.false:
            return 0
        if upper == bdd.true or depth >= DEPTH or len(self.known) >= self.pairs:
            return 1
        key = (lower, upper)
        known = self.known.get(key)
        if known is not None:
            return known
        self.known[key] = 1  # counted among the pairs (and a valid bound meanwhile)
        l0, l1, u0, u1 = _split(bdd, lower, upper)
        x0 = bdd.false if self.leq(l0, u1) else l0 & ~u1
        x1 = bdd.false if self.leq(l1, u0) else l1 & ~u0
        options = [(l1, u1, x0, u0), (l0, u0, x1, u1)]  # N(L_b, U_b) + N(x_(1-b), U_(1-b))
        if x0 == bdd.false:
            options.reverse()
        best = 1
        for half_lower, half_upper, x, x_upper in options:
            side = self.at_least(x, x_upper, need, depth + 1)
            if side <= need:  # else enough already
                side += self.at_least(half_lower, half_upper, need - side, depth + 1)
            best = max(best, side)
            if best > need:
                break
        self.known[key] = best
        return best

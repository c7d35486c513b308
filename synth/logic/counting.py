"""Exact model counts of a BDD over a given set of variables: CUDD's count (a double) where
it is exact, below 2^50, an exact recursion over the BDD in Python integers above (the
symbolic engine counts 10^11 SYNC states and more). One home for the plant encoding, the
Grafcet-step path and the filter's symbolic closed loop.

Example
-------
>>> from synth.logic.bdd import Engine
>>> e = Engine(["a", "b", "c"])
>>> count(e, e.var("a") | e.var("b"), [e.level(n) for n in "abc"])
6
>>> u = e.conjunction(e.var(f"x{i}") for i in range(60))
>>> count(e, ~u, [e.level(f"x{i}") for i in range(60)]) == 2**60 - 1
True
"""

from __future__ import annotations

import heapq
import itertools
from typing import Iterable

from synth.logic.bdd import Engine, Function

__all__ = ["DOUBLE_VARIABLES", "Conjunctions", "count"]


DOUBLE_VARIABLES = 1000
"""Above this many variables a model count may pass a double's range (2^1024): CUDD's
count is not asked, the count is exact from the start."""


def count(engine: Engine, u: Function, levels: Iterable[int]) -> int:
    """The valuations of the variables at ``levels`` that satisfy ``u`` (which depends on
    no other variable), exactly."""
    ordered = sorted(levels)
    if u == engine.false:
        return 0
    if len(ordered) <= DOUBLE_VARIABLES:
        fast = engine.bdd.count(u, nvars=len(ordered))
        if fast < 2**50:
            return int(fast)
    return _exact(engine, u, ordered, {})


def _exact(engine: Engine, u: Function, levels: list[int], memo: dict[Function, int]) -> int:
    """Models of ``u`` over the variables at ``levels`` (sorted), as a Python int."""
    position = {lv: i for i, lv in enumerate(levels)}
    return _models(engine, u, position, len(levels), memo) << _position(engine, u, position, len(levels))


def _position(engine: Engine, f: Function, position: dict[int, int], n: int) -> int:
    """Index in the sorted levels of ``f``'s top variable (``n`` for constants)."""
    return n if f == engine.true or f == engine.false else position[f.level]


def _models(engine: Engine, u: Function, position: dict[int, int], n: int, memo: dict[Function, int]) -> int:
    """Models of ``u`` over the variables from its own top position down: each node's
    count from its children's (an explicit stack: a BDD over thousands of variables is
    deeper than Python's recursion limit); ``memo`` keeps every node's count."""
    true, false = engine.true, engine.false
    memo.setdefault(true, 1)
    memo.setdefault(false, 0)

    def below(f: Function) -> int:
        return n if f == true or f == false else position[f.level]

    stack = [u]
    while stack:
        f = stack[-1]
        if f in memo:
            stack.pop()
            continue
        if f.negated:
            g = ~f
            if g not in memo:
                stack.append(g)
                continue
            memo[f] = (1 << (n - below(f))) - memo[g]
        else:
            lo, hi = f.low, f.high
            if lo not in memo or hi not in memo:
                stack.extend(x for x in (lo, hi) if x not in memo)
                continue
            i = below(f)
            memo[f] = (memo[lo] << (below(lo) - i - 1)) + (memo[hi] << (below(hi) - i - 1))
        stack.pop()
    return memo[u]


class Conjunctions:
    """Exact counts of ``f ∧ g`` for one large ``f`` and many ``g`` whose variables all lie
    low in the order, over the variables at ``levels`` (``f`` and every ``g`` depend on
    those only), without building ``f ∧ g``.

    Every path of ``f`` crosses the level where ``g`` starts once, at the first node of
    ``f`` at or below it: ``|f ∧ g| = Σ_c W(c)·|c ∧ g|`` over those nodes ``c`` (the cut),
    ``W(c)`` the valuations of the variables above that lead to ``c``. The cuts are swept
    top-down once (calls in increasing levels of ``g`` never restart it) and ``|c ∧ g|``
    meets ``f``'s own nodes below ``g``, whose counts are kept: each count costs the cut's
    width times ``g``'s window, not ``f``'s size (SUP's moves counted over a line of 300
    cylinders, each against SUP's states)."""

    def __init__(self, engine: Engine, f: Function, levels: Iterable[int]) -> None:
        self.engine = engine
        self.f = f
        self.true, self.false = engine.true, engine.false
        ordered = sorted(levels)
        self.position = {lv: i for i, lv in enumerate(ordered)}
        self.n = len(ordered)
        self.memo: dict[Function, int] = {}
        self.tick = itertools.count()
        self._restart()

    def _restart(self) -> None:
        self.at = 0  # every cut member lies at or below this position
        self.weight: dict[Function, int] = {}  # member -> valuations of the positions above its own
        self.heap: list[tuple[int, int, Function]] = []
        self._add(self.f, 1, 0)

    def _pos(self, f: Function) -> int:
        return self.n if f == self.true or f == self.false else self.position[f.level]

    def _add(self, c: Function, w: int, entered: int) -> None:
        """An edge into ``c`` with ``w`` valuations of the positions before ``entered``."""
        if c == self.false:
            return
        p = self.n if c == self.true else self.position[c.level]
        w <<= p - entered
        old = self.weight.get(c)
        if old is not None:
            self.weight[c] = old + w
        else:
            self.weight[c] = w
            heapq.heappush(self.heap, (p, next(self.tick), c))

    def _cut(self, t: int) -> None:
        """Move the cut down to position ``t``: expand the members above it, top first."""
        if t < self.at:
            self._restart()
        while self.heap and self.heap[0][0] < t:
            p, _, c = heapq.heappop(self.heap)
            w = self.weight.pop(c)
            lo, hi = c.low, c.high  # children of the regular node: complemented if c is
            if c.negated:
                lo, hi = ~lo, ~hi
            self._add(lo, w, p + 1)
            self._add(hi, w, p + 1)
        self.at = t

    def count(self, g: Function) -> int:
        """``|f ∧ g|`` over the levels, exactly."""
        if g == self.false:
            return 0
        t = self._pos(g)
        self._cut(t)
        total = 0
        for c, w in self.weight.items():
            h = c & g
            if h == self.false:
                continue
            ph = self._pos(h)
            total += (w >> (self._pos(c) - t)) * (_models(self.engine, h, self.position, self.n, self.memo) << (ph - t))
        return total

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

from typing import Iterable

from synth.logic.bdd import Engine, Function

__all__ = ["count"]


def count(engine: Engine, u: Function, levels: Iterable[int]) -> int:
    """The valuations of the variables at ``levels`` that satisfy ``u`` (which depends on
    no other variable), exactly."""
    ordered = sorted(levels)
    if u == engine.false:
        return 0
    fast = engine.bdd.count(u, nvars=len(ordered))
    if fast < 2**50:
        return int(fast)
    return _exact(engine, u, ordered)


def _exact(engine: Engine, u: Function, levels: list[int]) -> int:
    """Models of ``u`` over the variables at ``levels`` (sorted), as a Python int."""
    position = {lv: i for i, lv in enumerate(levels)}
    n = len(levels)
    memo: dict[Function, int] = {}
    true, false = engine.true, engine.false

    def below(f: Function) -> int:
        """Index in ``levels`` of ``f``'s top variable (``n`` for constants)."""
        return n if f == true or f == false else position[f.level]

    def models(f: Function) -> int:  # over levels[below(f):]
        if f == true:
            return 1
        if f == false:
            return 0
        hit = memo.get(f)
        if hit is not None:
            return hit
        if f.negated:
            r = (1 << (n - below(f))) - models(~f)
        else:
            i = below(f)
            lo, hi = f.low, f.high
            r = models(lo) * (1 << (below(lo) - i - 1)) + models(hi) * (1 << (below(hi) - i - 1))
        memo[f] = r
        return r

    return models(u) * (1 << below(u))

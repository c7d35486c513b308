"""The synthesised filter as its chain of narrowings run on truth tables, one per bag of the
partition (:mod:`synth.logic.partition`): a representation of the *same* filter whose size
is the number of bags times ``2^width``, where the outputs' functions of Y can grow
exponentially (``grid_edges`` 8 × 8: 12.8 k table entries; docs/performance.md, "Session 29").

A :class:`Plan` is taken from the partition :func:`synth.filter.narrowing.layout` chooses,
without running the chain: per bag (the output eliminated there, then its frontier) the
conjunction of the constraints' complements and assumptions whose first output it is, and
per criterion ``Max(g)`` (``Min(c)`` read as ``Max(!c)``) its bag. :func:`run` evaluates the
plan in an :class:`Algebra`: each table entry is the bag's relation at one valuation of the
bag's outputs, a boolean at one valuation of Y (:class:`Booleans`, what a PLC block would
compute each cycle) or a function of Y (:class:`Symbolic`, every Y at once). Then, criterion
after criterion, ``b_j = ⋁_v F_{k-1} ∧ D_k ∧ g_j ∧ B_{k+1}`` (``F``/``B`` the forward and
backward messages as tables over the frontiers, recomputed past a narrowed bag when next
asked) and ``D_k := D_k ∧ (g_j ↔ b_j)``: the synthesis's ``S_{j+1} = S_j ∧ (g_j ↔ ∃O.(S_j ∧
g_j))`` (:mod:`synth.filter.narrowing`), with ``S_j`` kept as its tables. At the end each
output's ``∃O.(S ∧ o)`` and ``∃O.(S ∧ !o)`` and the care set ``∃O.S`` are read from the
tables of its bag and the messages around it. In :class:`Symbolic` they are the chain's own
BDDs (``tests/test_filter_local.py``).

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> from synth.filter.model import functions
>>> m = functions(parse_filter("inputs i\\noutputs a, b\\nsafety K: a & b\\nmaximize a\\nmaximize b & i", "x.filter"))
>>> p = plan(m, [m.engine.var("a"), m.engine.var("b") & m.engine.var("i")])
>>> [b.anchors for b in p.bags], p.entries
([('a', 'b'), ('b',)], 6)
>>> run(p, Booleans(m.engine, {"i": True})).ones
{'a': True, 'b': False}
>>> m.engine.text(run(p, Symbolic(m.engine)).ones["b"])
'0'
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Generic, Mapping, Protocol, Sequence, TypeVar

from synth.filter.model import FilterFunctions
from synth.filter.narrowing import layout
from synth.logic.bdd import Engine, Function
from synth.logic.partition import Partition

__all__ = ["Bag", "Plan", "plan", "plan_of", "Algebra", "Booleans", "Symbolic", "Outcome", "run"]

V = TypeVar("V")


@dataclass(frozen=True)
class Bag:
    """One bag of the plan: ``anchors`` (the output eliminated here, then its frontier; bit
    ``i`` of a table's index is the value of ``anchors[i]``), ``before`` (for each index of
    this bag's table, the index of the previous bag's frontier valuation in it: where
    ``F_{k-1}`` and ``B_k`` are read and written) and ``relation`` (the conjunction of the
    constraints' complements and assumptions that belong here, a function of the outputs of
    ``anchors`` and of Y)."""

    anchors: tuple[str, ...]
    before: tuple[int, ...]
    relation: Function


@dataclass(frozen=True)
class Plan:
    """The chain of narrowings as tables: ``bags`` in elimination order and ``steps``, one
    ``(bag, g)`` per criterion read as ``Max(g)``, in the criteria's order."""

    outputs: tuple[str, ...]
    bags: tuple[Bag, ...]
    steps: tuple[tuple[int, Function], ...]

    @property
    def entries(self) -> int:
        """The table entries of the bags' relations, added up (2^|anchors| each)."""
        return sum(1 << len(b.anchors) for b in self.bags)

    @property
    def width(self) -> int:
        """The largest bag (anchors)."""
        return max((len(b.anchors) for b in self.bags), default=0)


def plan(m: FilterFunctions, goods: Sequence[Function], order: Sequence[str] | None = None) -> Plan:
    """The plan of the chain of ``goods`` (each criterion as ``Max(g)``) on the partition
    :func:`~synth.filter.narrowing.layout` gives (``order``: its elimination order)."""
    if not m.outputs:
        raise ValueError("a plan needs at least one output")
    return plan_of(m, layout(m, goods, order), goods)


def plan_of(m: FilterFunctions, p: Partition, goods: Sequence[Function]) -> Plan:
    """The plan of the chain of ``goods`` on the partition ``p`` of ``m``'s constraints."""
    n = len(p.anchors)
    relations = [m.engine.true] * n
    for u in [~c for c in m.constraint.values()] + [m.assumed]:
        k = p.position(u)
        relations[k] = relations[k] & u
    bags = []
    for k, anchor in enumerate(p.anchors):
        anchors = (anchor, *p.frontier(k))
        bit = [anchors.index(a) for a in (p.frontier(k - 1) if k else ())]
        before = tuple(sum(((v >> b) & 1) << i for i, b in enumerate(bit)) for v in range(1 << len(anchors)))
        bags.append(Bag(anchors, before, relations[k]))
    return Plan(tuple(m.outputs), tuple(bags), tuple((p.position(g), g) for g in goods))


class Algebra(Protocol[V]):
    """The values of the tables: booleans at one valuation of Y, or functions of Y."""

    false: V
    true: V

    def both(self, a: V, b: V) -> V: ...

    def either(self, a: V, b: V) -> V: ...

    def same(self, a: V, b: V) -> V: ...

    def certain(self, a: V) -> bool:
        """Whether ``a`` is true for every Y (a search may stop there)."""
        ...

    def table(self, u: Function, anchors: tuple[str, ...]) -> list[V]:
        """``u`` at each valuation of ``anchors`` (bit ``i`` of the index: ``anchors[i]``)."""
        ...


def _tabulate(e: Engine, u: Function, anchors: tuple[str, ...]) -> list[Function]:
    """``u``'s cofactors by every valuation of ``anchors`` (one-variable and-abstracts: dd's
    ``let`` walks every declared variable)."""
    out = [u]
    for i, a in enumerate(anchors):
        x, inner = e.var(a), [e.declare(a)]
        out = [e.and_exists(w, ~x, inner) for w in out] + [e.and_exists(w, x, inner) for w in out]
        assert len(out) == 2 << i
    return out


class Symbolic:
    """Tables of functions of Y: the plan run on every Y at once."""

    def __init__(self, engine: Engine) -> None:
        self.engine = engine
        self.false = engine.false
        self.true = engine.true

    def both(self, a: Function, b: Function) -> Function:
        return a & b

    def either(self, a: Function, b: Function) -> Function:
        return a | b

    def same(self, a: Function, b: Function) -> Function:
        return a.equiv(b)

    def certain(self, a: Function) -> bool:
        return a == self.true

    def table(self, u: Function, anchors: tuple[str, ...]) -> list[Function]:
        return _tabulate(self.engine, u, anchors)


class Booleans:
    """Tables of booleans at one valuation ``point`` of Y (names: values), what the block
    computes in one PLC cycle; a name the point does not give is read false."""

    false = False
    true = True

    def __init__(self, engine: Engine, point: Mapping[str, bool]) -> None:
        self.engine = engine
        self.point = point

    def both(self, a: bool, b: bool) -> bool:
        return a and b

    def either(self, a: bool, b: bool) -> bool:
        return a or b

    def same(self, a: bool, b: bool) -> bool:
        return a == b

    def certain(self, a: bool) -> bool:
        return a

    def table(self, u: Function, anchors: tuple[str, ...]) -> list[bool]:
        e = self.engine
        ys = {n: self.point.get(n, False) for n in e.support(u) if n not in anchors}
        t = e.true
        return [w == t for w in _tabulate(e, e.let(ys, u), anchors)]


@dataclass(frozen=True)
class Outcome(Generic[V]):
    """What the chain leaves: whether a safe vector exists (``care``), and per output
    whether some safe vector has it at 1 (``ones``) or at 0 (``zeros``); ``bests``: each
    criterion's ``b_j``."""

    care: V
    ones: dict[str, V]
    zeros: dict[str, V]
    bests: tuple[V, ...]


def run(p: Plan, alg: Algebra[V]) -> Outcome[V]:
    """The chain of narrowings of ``p`` in the algebra ``alg`` (module docstring)."""
    t = _Tables(p, alg)
    bests: list[V] = []
    for k, g in p.steps:
        wanted = alg.table(g, p.bags[k].anchors)
        before, after, bag = t.forward(k - 1), t.backward(k + 1), p.bags[k]
        best = alg.false
        for v, entry in enumerate(t.domains[k]):
            best = alg.either(best, alg.both(alg.both(entry, wanted[v]), alg.both(before[bag.before[v]], after[v >> 1])))
            if alg.certain(best):
                break
        bests.append(best)
        t.narrow(k, [alg.both(entry, alg.same(w, best)) for entry, w in zip(t.domains[k], wanted)])
    ones: dict[str, V] = {}
    zeros: dict[str, V] = {}
    care = alg.false
    for k, bag in enumerate(p.bags):
        entries = t.around(k)
        ones[bag.anchors[0]] = _any(alg, entries[1::2])
        zeros[bag.anchors[0]] = _any(alg, entries[0::2])
        if k == 0:
            care = _any(alg, entries)
    return Outcome(care, {o: ones[o] for o in p.outputs}, {o: zeros[o] for o in p.outputs}, tuple(bests))


class _Tables(Generic[V]):
    """The bags' tables (``domains``) and the messages between them, each computed when
    first asked after the last narrowing that changes it."""

    def __init__(self, p: Plan, alg: Algebra[V]) -> None:
        self.plan, self.alg = p, alg
        self.domains = [alg.table(b.relation, b.anchors) for b in p.bags]
        self._fwd: dict[int, list[V]] = {}
        self._bwd: dict[int, list[V]] = {}

    def narrow(self, k: int, narrowed: list[V]) -> None:
        """Bag ``k``'s table becomes ``narrowed``; the messages that read it are dropped."""
        if narrowed != self.domains[k]:
            self.domains[k] = narrowed
            for j in [j for j in self._fwd if j >= k]:
                del self._fwd[j]
            for j in [j for j in self._bwd if j <= k]:
                del self._bwd[j]

    def forward(self, k: int) -> list[V]:
        """``F_k``: bags 0..k, their outputs but ``k``'s frontier quantified, over that frontier."""
        alg, j = self.alg, k
        while j >= 0 and j not in self._fwd:
            j -= 1
        found = self._fwd[j] if j >= 0 else [alg.true]
        for i in range(j + 1, k + 1):
            bag, domain = self.plan.bags[i], self.domains[i]
            message = [alg.false] * (len(domain) >> 1)
            for v, entry in enumerate(domain):
                message[v >> 1] = alg.either(message[v >> 1], alg.both(entry, found[bag.before[v]]))
            found = self._fwd[i] = message
        return found

    def backward(self, k: int) -> list[V]:
        """``B_k``: bags k..n-1, over the frontier before ``k``."""
        alg, bags, j = self.alg, self.plan.bags, k
        while j < len(bags) and j not in self._bwd:
            j += 1
        found = self._bwd[j] if j < len(bags) else [alg.true]
        for i in range(j - 1, k - 1, -1):
            bag, domain = bags[i], self.domains[i]
            message = [alg.false] * ((1 << (len(bags[i - 1].anchors) - 1)) if i else 1)
            for v, entry in enumerate(domain):
                w = bag.before[v]
                message[w] = alg.either(message[w], alg.both(entry, found[v >> 1]))
            found = self._bwd[i] = message
        return found

    def around(self, k: int) -> list[V]:
        """Each entry of bag ``k`` with the messages of the bags before and after it."""
        alg, bag = self.alg, self.plan.bags[k]
        before, after = self.forward(k - 1), self.backward(k + 1)
        return [alg.both(alg.both(entry, before[bag.before[v]]), after[v >> 1]) for v, entry in enumerate(self.domains[k])]


def _any(alg: Algebra[V], values: Sequence[V]) -> V:
    out = alg.false
    for x in values:
        out = alg.either(out, x)
    return out

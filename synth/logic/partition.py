"""A relation kept as a conjunction of factors, each on few *anchors* (a filter's outputs)
and any other variables (Y), never built as one BDD: ``∃anchors.(R ∧ g)`` is computed by
eliminating the anchors one at a time in a fixed order (early quantification over a
conjunctive partition), with the messages of that elimination cached and reused.

The anchors' elimination order gives a path decomposition: the *frontier* after anchor k
is the set of later anchors sharing a factor with anchor k or an earlier one, and bag k is
anchor k with its frontier. Every factor belongs to the bag of its first anchor (factors
without anchors to the first bag). The forward message ``F_k`` is the conjunction of the
factors of bags 0..k with anchors 0..k quantified (a function of the frontier and Y), the
backward message ``B_k`` that of bags k..n-1 with every anchor not in the frontier before k
quantified; then ``∃anchors.(R ∧ g) = ∃bag_p.(F_{p-1} ∧ bag p's factors ∧ g ∧ B_{p+1})``
for any ``g`` whose anchors are in bag p.

A :class:`State` is one value of the relation: a fixed base (the partition's factors) and
one *domain* per bag, narrowed by :meth:`Partition.refine`. Messages are cached by the
domains they depend on (all of them up to k, or from k on), so states that share their
first or last domains share those messages.

Example
-------
>>> from synth.logic.bdd import Engine
>>> e = Engine(["y", "a", "b", "c"])
>>> a, b, c, y = (e.var(n) for n in "abcy")
>>> p = Partition(e, ["a", "b", "c"], [~(a & b), ~(b & c)])
>>> s = p.refine(p.initial, 0, a.equiv(y))
>>> e.text(p.project(s, 1, b)), e.text(p.project(s, 0)), p.frontier(0)
('!y', '1', ('b',))
"""

from __future__ import annotations

from typing import Any, Iterable, Sequence

from synth.logic.bdd import Engine, Function

__all__ = ["Partition", "State", "Walk"]


class State:
    """One value of a :class:`Partition`'s relation: its domains (one per bag) and the keys
    of the messages that depend on them, filled in as they are asked for."""

    __slots__ = ("domains", "fkeys", "bkeys")

    def __init__(self, domains: tuple[Function, ...], fkeys: list[int | None], bkeys: list[int | None]) -> None:
        self.domains = domains
        self.fkeys = fkeys
        self.bkeys = bkeys


class Partition:
    """The conjunction of ``factors`` over the ``anchors`` (in elimination order) and other
    variables. ``cliques``: further sets of anchors the states' domains will tie together
    (a criterion on two outputs), so that each such set lies in one bag."""

    def __init__(self, engine: Engine, anchors: Sequence[str], factors: Iterable[Function],
                 cliques: Iterable[Iterable[str]] = ()) -> None:
        self.engine = engine
        self.anchors = tuple(anchors)
        n = len(self.anchors)
        self._inner = [engine.declare(a) for a in self.anchors]
        self._pos = {v: i for i, v in enumerate(self._inner)}
        factors = list(factors)
        groups = [self._positions(u) for u in factors]
        groups += [{self._pos[engine.declare(a)] for a in c if a in self.anchors} for c in cliques]
        later: list[set[int]] = [set() for _ in range(n)]
        for g in groups:
            for i in g:
                later[i] |= {j for j in g if j > i}
        fronts: list[tuple[int, ...]] = []
        current: set[int] = set()
        for k in range(n):
            current = (current | later[k]) - {k}
            fronts.append(tuple(sorted(current)))
        self._fronts = fronts
        self._fwd_vars = [[v] for v in self._inner]
        self._bag_vars = [[self._inner[j] for j in (k, *fronts[k])] for k in range(n)]
        self._bwd_vars = [[self._inner[j] for j in (k, *fronts[k]) if k == 0 or j not in fronts[k - 1]]
                          for k in range(n)]
        if not n:
            raise ValueError("a partition needs at least one anchor")
        base = [engine.true] * n
        for u, g in zip(factors, groups):
            k = min(g, default=0)
            base[k] = base[k] & u
        self._base = base
        self._fkeys: dict[tuple[int, Function], int] = {}
        self._bkeys: dict[tuple[int, Function], int] = {}
        self._fwd: dict[int, Function] = {}
        self._bwd: dict[int, Function] = {}
        self._local: dict[tuple[int, int, int], Function] = {}
        self._blocks: dict[tuple[int, Function], Function] = {}
        self._where: dict[Function, int] = {}
        self._fvalues: dict[tuple[int, Function, Function], Function] = {}  # (k, F_{k-1}, domain k) -> F_k
        self._bvalues: dict[tuple[int, Function, Function], Function] = {}  # (k, B_{k+1}, domain k) -> B_k
        self._lvalues: dict[tuple[int, Function, Function, Function], Function] = {}  # (k, F_{k-1}, domain, B_{k+1})
        self._pvalues: dict[tuple[int, Function, Function | None], Function] = {}  # (k, local, g) -> ∃bag k.(local ∧ g)
        self.initial = State(tuple(engine.true for _ in range(n)), [None] * n, [None] * n)
        self.steps = 0
        """Messages computed so far (forward and backward), for benchmarks."""

    def _positions(self, u: Function) -> set[int]:
        return {self._pos[v] for v in self.engine.bdd.support(u) if v in self._pos}

    def position(self, u: Function) -> int:
        """The bag of ``u`` (that of its first anchor, 0 without any): where a domain
        narrowed by ``u``, or a ``g`` projected with :meth:`project`, belongs (remembered
        per function: dd's support walks every declared variable)."""
        found = self._where.get(u)
        if found is None:
            found = self._where[u] = min(self._positions(u), default=0)
        return found

    def anchor_position(self, anchor: str) -> int:
        """The bag of the anchor ``anchor`` (the position of ``engine.var(anchor)``)."""
        return self._pos[self.engine.declare(anchor)]

    def frontier(self, k: int) -> tuple[str, ...]:
        """The anchors after ``k`` that share a factor with anchor ``k`` or an earlier one."""
        return tuple(self.anchors[j] for j in self._fronts[k])

    @property
    def width(self) -> int:
        """The largest bag (anchors)."""
        return max((len(v) for v in self._bag_vars), default=0)

    # ---- states
    def refine(self, s: State, k: int, u: Function) -> State:
        """``s ∧ u``, ``u`` on the anchors of bag ``k`` (:meth:`position`) and other variables."""
        old = s.domains[k]
        new = old & u
        if new == old:
            return s
        n = len(s.domains)
        unknown: list[int | None] = [None] * (n - k)
        return State(s.domains[:k] + (new,) + s.domains[k + 1:],
                     s.fkeys[:k] + unknown, unknown[:1] * (k + 1) + s.bkeys[k + 1:])

    def _fkey(self, s: State, k: int) -> int:
        """The key of ``F_k`` of ``s`` (domains 0..k); -1 for k = -1."""
        if k < 0:
            return -1
        j = k
        while j >= 0 and s.fkeys[j] is None:
            j -= 1
        key = -1 if j < 0 else s.fkeys[j]
        assert key is not None
        for i in range(j + 1, k + 1):
            key = self._fkeys.setdefault((key, s.domains[i]), len(self._fkeys))
            s.fkeys[i] = key
        return key

    def _bkey(self, s: State, k: int) -> int:
        """The key of ``B_k`` of ``s`` (domains k..n-1); -2 past the last bag."""
        n = len(s.domains)
        if k >= n:
            return -2
        j = k
        while j < n and s.bkeys[j] is None:
            j += 1
        key = -2 if j >= n else s.bkeys[j]
        assert key is not None
        for i in range(j - 1, k - 1, -1):
            key = self._bkeys.setdefault((key, s.domains[i]), len(self._bkeys))
            s.bkeys[i] = key
        return key

    def message_key(self, s: State, k: int, forward: bool) -> int:
        """The cache key of ``F_k`` (``forward``) or ``B_k`` of ``s``: two states whose keys
        are equal have the same message, computed or not."""
        return self._fkey(s, k) if forward else self._bkey(s, k)

    def forward(self, s: State, k: int) -> Function:
        """``F_k``: bags 0..k conjoined, anchors 0..k quantified (true for k = -1)."""
        e = self.engine
        j = k
        while j >= 0 and self._fwd.get(self._fkey(s, j)) is None:
            j -= 1
        msg = e.true if j < 0 else self._fwd[self._fkey(s, j)]
        for i in range(j + 1, k + 1):
            before, msg = msg, e.and_exists(msg, self._block(s, i), self._fwd_vars[i])
            self._fwd[self._fkey(s, i)] = self._fvalues[(i, before, s.domains[i])] = msg
            self.steps += 1
        return msg

    def backward(self, s: State, k: int) -> Function:
        """``B_k``: bags k..n-1 conjoined, their anchors not in the frontier before k
        quantified (true past the last bag)."""
        e, n = self.engine, len(s.domains)
        j = k
        while j < n and self._bwd.get(self._bkey(s, j)) is None:
            j += 1
        msg = e.true if j >= n else self._bwd[self._bkey(s, j)]
        for i in range(j - 1, k - 1, -1):
            after, msg = msg, e.and_exists(msg, self._block(s, i), self._bwd_vars[i])
            self._bwd[self._bkey(s, i)] = self._bvalues[(i, after, s.domains[i])] = msg
            self.steps += 1
        return msg

    def _block(self, s: State, k: int) -> Function:
        """Bag ``k``'s factors and domain."""
        return self._block_of(k, s.domains[k])

    def _block_of(self, k: int, domain: Function) -> Function:
        key = (k, domain)
        found = self._blocks.get(key)
        if found is None:
            found = self._blocks[key] = self._base[k] & domain
        return found

    def local(self, s: State, k: int) -> Function:
        """``F_{k-1} ∧ bag k's factors ∧ B_{k+1}``: ``s`` with every anchor outside bag k
        quantified."""
        key = (self._fkey(s, k - 1), self._fkey(s, k), self._bkey(s, k + 1))
        found = self._local.get(key)
        if found is None:
            before, after = self.forward(s, k - 1), self.backward(s, k + 1)
            found = (before & self._block(s, k)) & after
            self._local[key] = self._lvalues[(k, before, s.domains[k], after)] = found
        return found

    def project(self, s: State, k: int, g: Function | None = None) -> Function:
        """``∃anchors.(s ∧ g)``, ``g`` on the anchors of bag ``k`` and other variables
        (``∃anchors.s`` without ``g``)."""
        local = self.local(s, k)
        if g is None:
            found = self.engine.bdd.exist(self._bag_vars[k], local)
        else:
            found = self.engine.and_exists(local, g, self._bag_vars[k])
        self._pvalues[(k, local, g)] = found
        return found

    def relation(self, s: State) -> Function:
        """The relation as one BDD (as large as it is)."""
        return self.engine.conjunction(b & d for b, d in zip(self._base, s.domains))

    # ---- the caches
    def mark(self) -> tuple[int, ...]:
        """The caches' sizes, to :meth:`forget` what is computed after this."""
        return tuple(len(c) for c in self._caches())

    def forget(self, mark: tuple[int, ...]) -> None:
        """Drop the messages computed since ``mark`` (their keys stay: they are small)."""
        for cache, size in zip(self._caches(), mark):
            while len(cache) > size:
                cache.popitem()

    def _caches(self) -> tuple[dict[Any, Function], ...]:
        return self._fwd, self._bwd, self._local, self._blocks, self._fvalues, self._bvalues, self._lvalues, self._pvalues

    def walk(self, s: State) -> Walk:
        """A :class:`Walk` from ``s``."""
        return Walk(self, s.domains)

    # ---- messages keyed by their values (:class:`Walk`)
    def forward_value(self, k: int, before: Function, domain: Function) -> Function:
        """``F_k`` from ``F_{k-1}`` (``before``) and bag ``k``'s ``domain``, kept by these values."""
        return self._message(self._fvalues, self._fwd_vars[k], k, before, domain)

    def backward_value(self, k: int, after: Function, domain: Function) -> Function:
        """``B_k`` from ``B_{k+1}`` (``after``) and bag ``k``'s ``domain``, kept by these values."""
        return self._message(self._bvalues, self._bwd_vars[k], k, after, domain)

    def _message(self, values: dict[tuple[int, Function, Function], Function], inner: list[str], k: int,
                 other: Function, domain: Function) -> Function:
        key = (k, other, domain)
        found = values.get(key)
        if found is None:
            found = values[key] = self.engine.and_exists(other, self._block_of(k, domain), inner)
            self.steps += 1
        return found

    def local_value(self, k: int, before: Function, domain: Function, after: Function) -> Function:
        """Bag ``k``'s local relation (:meth:`local`) from its messages and domain, kept by these values."""
        key = (k, before, domain, after)
        found = self._lvalues.get(key)
        if found is None:
            found = self._lvalues[key] = (before & self._block_of(k, domain)) & after
        return found

    def project_local(self, k: int, local: Function, g: Function | None) -> Function:
        """``∃bag k.(local ∧ g)`` (``∃bag k.local`` without ``g``), kept by these values."""
        key = (k, local, g)
        found = self._pvalues.get(key)
        if found is None:
            if g is None:
                found = self.engine.bdd.exist(self._bag_vars[k], local)
            else:
                found = self.engine.and_exists(local, g, self._bag_vars[k])
            self._pvalues[key] = found
        return found


class Walk:
    """One value of a :class:`Partition`'s relation changed in place, a bag's domain at a
    time (:meth:`refine`), as a chain of narrowings does; its messages are keyed by their
    *values*: ``F_k`` by ``(F_{k-1}, domain k)``, ``B_k`` by ``(B_{k+1}, domain k)``. Where a
    walk's message equals one computed before (by another walk, or by this one at an
    earlier step), every message after it over the same domains is that one's too, and is
    not computed again: a walk that differs from another at one bag recomputes the
    messages its difference reaches, not every message past that bag (the keys of
    :class:`State` are the domains, so such a state recomputes them all). The same
    functions as :meth:`Partition.project` on the same domains, by other keys.

    >>> from synth.logic.bdd import Engine
    >>> e = Engine(["y", "a", "b", "c"])
    >>> a, b, c, y = (e.var(n) for n in "abcy")
    >>> p = Partition(e, ["a", "b", "c"], [~(a & b), ~(b & c)])
    >>> w = p.walk(p.initial)
    >>> w.refine(0, a.equiv(y)), e.text(w.project(1, b)), w.project(1, b) == p.project(p.refine(p.initial, 0, a.equiv(y)), 1, b)
    (True, '!y', True)
    """

    __slots__ = ("p", "domains", "_f", "_b", "_fvalid", "_bvalid")

    def __init__(self, p: Partition, domains: Sequence[Function]) -> None:
        self.p = p
        self.domains = list(domains)
        n = len(self.domains)
        self._f: list[Function] = [p.engine.true] * n  # F_k, valid for k <= _fvalid
        self._b: list[Function] = [p.engine.true] * n  # B_k, valid for k >= _bvalid
        self._fvalid, self._bvalid = -1, n

    def refine(self, k: int, u: Function) -> bool:
        """The relation ``∧ u`` (``u`` on the anchors of bag ``k`` and other variables); whether
        it changed."""
        old = self.domains[k]
        new = old & u
        if new == old:
            return False
        self.domains[k] = new
        self._fvalid = min(self._fvalid, k - 1)
        self._bvalid = max(self._bvalid, k + 1)
        return True

    def forward(self, k: int) -> Function:
        """``F_k`` (true for k = -1)."""
        if k < 0:
            return self.p.engine.true
        f, d = self._f, self.domains
        for i in range(self._fvalid + 1, k + 1):
            f[i] = self.p.forward_value(i, f[i - 1] if i else self.p.engine.true, d[i])
        self._fvalid = max(self._fvalid, k)
        return f[k]

    def backward(self, k: int) -> Function:
        """``B_k`` (true past the last bag)."""
        n = len(self.domains)
        if k >= n:
            return self.p.engine.true
        b, d = self._b, self.domains
        for i in range(self._bvalid - 1, k - 1, -1):
            b[i] = self.p.backward_value(i, b[i + 1] if i + 1 < n else self.p.engine.true, d[i])
        self._bvalid = min(self._bvalid, k)
        return b[k]

    def around(self, k: int) -> tuple[Function, Function, Function]:
        """``F_{k-1}``, bag ``k``'s domain and ``B_{k+1}``: what bag ``k``'s local relation is made of."""
        return self.forward(k - 1), self.domains[k], self.backward(k + 1)

    def project(self, k: int, g: Function | None = None) -> Function:
        """:meth:`Partition.project` of this relation."""
        before, domain, after = self.around(k)
        return self.p.project_local(k, self.p.local_value(k, before, domain, after), g)

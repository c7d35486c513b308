"""The one BDD layer of synth (the filter and the symbolic engine): BDDs (``dd.cudd`` when importable, else ``dd.autoref``)
over filter names, the shared expression AST translated into them, minimal cubes for
counterexamples, and a BDD printed back as a readable expression in filter syntax
(an irredundant sum of prime implicants, Minato–Morreale ISOP then expansion, with
edges recognised and common literals factored out).

Variables keep the callers' names (``A2``, ``A2^-1``, ``R_A2``); the manager uses
internal names ``v0``, ``v1``, … in a fixed order (no dynamic reordering, so every
printed result is deterministic). Two orders may differ: the manager's *variable order*
(what the BDDs' sizes depend on; :func:`interleaved_order` keeps each output next to the
signals of its constraints) and the *text order* in which covers, cubes and counterexamples
are built and printed, so a text depends on the function and the text order only, never on
the variable order.

Example
-------
>>> from synth.logic.expr import And, Edge, Var
>>> e = Engine(["C6^-1", "C6", "A1"])
>>> u = e.expr(And((Edge(True, "C6"), Var("A1"))))
>>> e.text(u)
'↑C6 & A1'
>>> e.minimal_cube(u | e.var("A1"))
{'A1': True}
"""

from __future__ import annotations

import sys
import weakref
from functools import reduce
from typing import Any, Iterable, Mapping, Sequence

from synth.logic.native import native
from synth.logic.past import pre_name
from synth.logic.expr import And, Const, Edge, Expr, Not, Var
from synth.logic.factoring import cube_literals, factored
from synth.logic.isop import CoverTooLarge, Covers, Cube, expanded



def _dd_backend() -> Any:
    """dd's CUDD manager when its extension is built, the pure-Python one otherwise.

    dd imports networkx at load time only to export BDDs as graphs, which synth never asks
    of it; that import is 0.37 s of a 0.55 s ``synth filter check``. networkx is hidden
    while dd loads (dd then leaves its graph export unavailable), unless it is loaded already.
    """
    hide = "networkx" not in sys.modules
    if hide:
        sys.modules["networkx"] = None  # type: ignore[assignment]  # `import networkx` raises ImportError
    try:
        try:
            from dd import cudd as backend
        except ImportError:  # pragma: no cover - depends on the installation
            from dd import autoref as backend
    finally:
        if hide and sys.modules.get("networkx", ...) is None:
            del sys.modules["networkx"]
    return backend


_backend = _dd_backend()

__all__ = ["Engine", "Function", "Cube", "CoverTooLarge", "cube_text", "cube_literals", "factored", "interleaved_order",
           "BACKEND", "CUDD"]

BACKEND: str = _backend.__name__
CUDD: bool = BACKEND == "dd.cudd"  # whether the fast native operations (and-abstract, node counts) exist
Function = Any  # a dd Function of the active backend


def cube_text(cube: Mapping[str, bool]) -> str:
    """A cube in filter syntax, ``1`` when empty.

    >>> cube_text({"C4": True, "C5": False})
    'C4 & !C5'
    """
    return " & ".join(n if v else "!" + n for n, v in cube.items()) or "1"


def interleaved_order(anchors: Sequence[str], supports: Iterable[Iterable[str]], base: Sequence[str],
                      owner: Mapping[str, str]) -> list[str]:
    """A variable order that keeps each anchor (an output) with the names of the constraints
    it takes part in, so that no relation carries every anchor's constraints across one cut.

    ``supports`` are the constraints' names; ``owner`` maps a name to the anchor it belongs
    to (``R_o`` and ``o^-1`` to ``o``); ``base`` is every name in a reference order (ties and
    leftovers). Anchors sharing a support are neighbours; they are visited breadth-first from
    the first anchor of each connected part, neighbours in ``anchors`` order (Cuthill–McKee),
    and each brings, in ``base`` order, the names it owns and the unowned names of its
    constraints not placed yet, then itself.

    >>> interleaved_order(["p", "q", "r"], [{"p", "a"}, {"p", "r"}, {"q", "b"}],
    ...                   ["R_p", "R_q", "R_r", "a", "b"], {"R_p": "p", "R_q": "q", "R_r": "r"})
    ['R_p', 'a', 'p', 'R_r', 'r', 'R_q', 'b', 'q']
    """
    index = {a: i for i, a in enumerate(anchors)}

    def anchor(n: str) -> str | None:
        a = owner.get(n, n)
        return a if a in index else None

    touching: dict[str, set[str]] = {a: set() for a in anchors}  # anchor -> unowned names of its constraints
    neighbours: dict[str, set[str]] = {a: set() for a in anchors}
    for support in supports:
        names = set(support)
        mine = {a for a in (anchor(n) for n in names) if a is not None}
        for a in mine:
            touching[a] |= {n for n in names if anchor(n) is None}
            neighbours[a] |= mine - {a}
    visited: list[str] = []
    seen: set[str] = set()
    for start in anchors:
        if start in seen:
            continue
        seen.add(start)
        queue = [start]
        while queue:
            a = queue.pop(0)
            visited.append(a)
            for b in sorted(neighbours[a] - seen, key=index.__getitem__):
                seen.add(b)
                queue.append(b)
    order: list[str] = []
    placed: set[str] = set()
    for a in visited:
        group = [n for n in base if n not in placed and n != a and (owner.get(n) == a or n in touching[a])]
        order += group + [a]
        placed.update(group, (a,))
    return order + [n for n in base if n not in placed]


class Engine:
    """A BDD manager whose variables are filter names, in a fixed order (``order`` first,
    any other name is appended when first used). ``text_order`` (default: the variable
    order) is the order covers, cubes and counterexamples are built and printed in."""

    def __init__(self, order: Iterable[str] = (), text_order: Iterable[str] | None = None) -> None:
        self.bdd = _backend.BDD()
        self.cudd = _backend.__name__ == "dd.cudd"
        self.bdd.configure(reordering=False)
        self._inner: dict[str, str] = {}
        self._outer: dict[str, str] = {}
        self._rank: dict[str, int] | None = None if text_order is None else {
            n: i for i, n in enumerate(dict.fromkeys(text_order))}
        self._ranks_by_inner: dict[str, int] = {}
        self._ranks_by_name: dict[str, int] = {}  # the same, by the caller's names (the printed literals' order)
        self._covers: Covers | None = None
        self._cubes: dict[frozenset[str], Function] = {}
        self._native = native(self.bdd) if self.cudd else None
        for n in order:
            self.declare(n)

    # ---- variables
    def declare(self, name: str) -> str:
        """The internal name of ``name``, declared if new."""
        inner = self._inner.get(name)
        if inner is None:
            inner = f"v{len(self._inner)}"
            self.bdd.declare(inner)
            self._inner[name] = inner
            self._outer[inner] = name
        return inner

    def declare_top(self, name: str) -> str:
        """As :meth:`declare`, a new name going to the top of the order (level 0; at the
        bottom without CUDD): tags that select one of many functions stored in one BDD."""
        inner = self._inner.get(name)
        if inner is None:
            inner = f"v{len(self._inner)}"
            if self.cudd:
                self.bdd.insert_var(inner, 0)
            else:  # pragma: no cover - dd without its CUDD extension
                self.bdd.declare(inner)
            self._inner[name] = inner
            self._outer[inner] = name
        return inner

    def name_of(self, inner: str) -> str:
        """The caller's name of the manager's variable ``inner`` (``u.var`` of a node)."""
        return self._outer[inner]

    @property
    def names(self) -> tuple[str, ...]:
        """Every declared name, in the variable order (declaration order: :meth:`declare_top` is
        for tags no caller lists)."""
        return tuple(self._inner)

    @property
    def true(self) -> Function:
        return self.bdd.true

    @property
    def false(self) -> Function:
        return self.bdd.false

    def var(self, name: str) -> Function:
        return self.bdd.var(self.declare(name))

    def level(self, name: str) -> int:
        return self.bdd.level_of_var(self.declare(name))

    def level_of(self, u: Function) -> int:
        """The level of ``u``'s top variable; a constant lies below every variable."""
        return len(self._inner) if u.var is None else int(u.level)

    def rank(self, name: str) -> int:
        """The position of ``name`` in the text order (names it does not list come after,
        in their variable order)."""
        if self._rank is None:
            return self.level(name)
        r = self._rank.get(name)
        return r if r is not None else len(self._rank) + self.level(name)

    @property
    def variable_order(self) -> tuple[str, ...]:
        """Every declared name, in the manager's variable order (top first)."""
        return tuple(self._outer[self.bdd.var_at_level(i)] for i in range(len(self._inner)))

    def _first(self, us: Sequence[Function], cache: dict[Function, str] | None = None) -> str:
        """The internal name of the first variable, in the text order, that one of ``us``
        (not all constant) depends on: the top variable when both orders agree. ``cache``
        keeps each function's first variable (one cover's recursion meets them repeatedly)."""
        if self._rank is None:
            return self.bdd.var_at_level(min(self.bdd.level_of_var(u.var) for u in us if u.var is not None))
        firsts = []
        for u in us:
            first = None if cache is None else cache.get(u)
            if first is None and u.var is not None:
                ranks = self.inner_ranks()
                first = min(self.bdd.support(u), key=ranks.__getitem__)
                if cache is not None:
                    cache[u] = first
            if first is not None:
                firsts.append(first)
        return min(firsts, key=self.inner_ranks().__getitem__)

    def inner_ranks(self) -> dict[str, int]:
        """Internal name -> rank in the text order, rebuilt when variables were declared."""
        if len(self._ranks_by_inner) != len(self._outer):
            self._ranks_by_inner = {i: self.rank(n) for i, n in self._outer.items()}
            self._ranks_by_name = {n: self._ranks_by_inner[i] for i, n in self._outer.items()}
        return self._ranks_by_inner

    # ---- translation
    def expr(self, e: Expr) -> Function:
        """The BDD of an expression; ``↑x`` is ``!x^-1 & x`` and ``↓x`` is ``x^-1 & !x``."""
        if isinstance(e, Var):
            return self.var(e.name)
        if isinstance(e, Const):
            return self.true if e.value else self.false
        if isinstance(e, Edge):
            now, before = self.var(e.name), self.var(pre_name(e.name))
            return (~before & now) if e.rising else (before & ~now)
        if isinstance(e, Not):
            return ~self.expr(e.arg)
        parts = [self.expr(a) for a in e.args]
        if isinstance(e, And):
            return reduce(lambda a, b: a & b, parts, self.true)
        return reduce(lambda a, b: a | b, parts, self.false)

    def conjunction(self, parts: Iterable[Function]) -> Function:
        return reduce(lambda a, b: a & b, parts, self.true)

    def disjunction(self, parts: Iterable[Function]) -> Function:
        return reduce(lambda a, b: a | b, parts, self.false)

    # ---- operations on filter names
    def let(self, values: Mapping[str, bool | str | Function], u: Function) -> Function:
        """``u`` with names replaced by constants, other names, or functions."""
        inner: dict[str, Any] = {}
        for n, v in values.items():
            inner[self.declare(n)] = self.var(v) if isinstance(v, str) else v
        return self.bdd.let(inner, u) if inner else u

    def quantified(self, inner: Iterable[str]) -> Function:
        """The positive cube of the variables ``inner`` (internal names), built once per set
        (dd's ``exist`` and ``forall`` walk every declared variable to build one each call)."""
        key = frozenset(inner)
        hit = self._cubes.get(key)
        if hit is None:
            hit = self._cubes[key] = self.bdd.cube(key)
        return hit

    def exists(self, names: Iterable[str], u: Function) -> Function:
        vs = [self.declare(n) for n in names]
        return self.bdd.apply("exists", self.quantified(vs), u) if vs else u

    def and_exists(self, u: Function, v: Function, inner: Sequence[str]) -> Function:
        """The relational product ``∃inner. u ∧ v`` in one pass (CUDD's and-abstract over a
        cached cube, :mod:`synth.logic.native`), over the manager's variables ``inner``
        (internal names, from :meth:`declare`)."""
        if self._native is not None:
            return self._native.product(u, v, self.quantified(inner))
        if not self.cudd:  # pragma: no cover - dd without its CUDD extension
            return self.bdd.exist(inner, u & v)
        return _backend.and_exists(u, v, inner)  # pragma: no cover - a dd whose layout is not known

    def live_nodes(self, exact: bool = False) -> int:
        """The manager's live BDD nodes. With CUDD, its running count (keys − dead, which
        also counts one node per variable) read through ``statistics``: ``len`` of a dd
        manager walks every node (0.6 s at 1.6·10^6 nodes), ``statistics`` only the
        table's slots (about 30 times less). That running count also holds the nodes
        whose release CUDD has deferred (its "death row"), which depend on the run's
        memory addresses: a few hundred nodes from one run to the next on a large model.
        ``exact`` (a count that is printed) empties the death row first (CUDD's
        ``Cudd_ReadNodeCount``): the same count on every run."""
        if not self.cudd:  # pragma: no cover - dd without its CUDD extension
            return len(self.bdd)
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # dd's note that the key 'mem' is now in bytes
            return int(self.bdd.statistics(exact_node_count=exact)["n_nodes"])

    def work(self) -> int:
        """The BDD work done so far in this manager, deterministic for a given sequence of
        operations: CUDD's computed-table lookups (one per recursive step of an operation
        that is not a terminal case); 0 without CUDD."""
        if not self.cudd:  # pragma: no cover - dd without its CUDD extension
            return 0
        if self._native is not None:
            return self._native.lookups()
        return int(self.bdd.statistics()["cache_lookups"])  # pragma: no cover - a dd whose layout is not known

    def forall(self, names: Iterable[str], u: Function) -> Function:
        vs = [self.declare(n) for n in names]
        return self.bdd.apply("forall", self.quantified(vs), u) if vs else u

    def support(self, u: Function) -> list[str]:
        """The names ``u`` depends on, in variable order."""
        inner = self.bdd.support(u)
        return sorted((self._outer[i] for i in inner), key=self.rank)

    def cube(self, values: Mapping[str, bool]) -> Function:
        return self.conjunction(self.var(n) if v else ~self.var(n) for n, v in values.items())

    def implies(self, a: Function, b: Function) -> bool:
        return (a & ~b) == self.false

    def value(self, u: Function, point: Mapping[str, bool]) -> bool:
        """``u`` at a valuation of (at least) its support."""
        r = self.let({n: point[n] for n in self.support(u)}, u)
        return r == self.true

    # ---- cubes
    def path_cube(self, u: Function) -> Cube | None:
        """One path to 1 of ``u``, preferring the 0 branch; ``None`` when ``u`` is false."""
        if u == self.false:
            return None
        cube: Cube = {}
        while u != self.true:  # cofactors by let: dd.cudd's low/high ignore complement edges
            inner = self._first((u,))
            name = self.name_of(inner)
            low = self.bdd.let({inner: False}, u)
            if low != self.false:
                cube[name], u = False, low
            else:
                cube[name], u = True, self.bdd.let({inner: True}, u)
        return self.ordered(cube)

    def expanded(self, cube: Cube, upper: Function) -> Cube:
        """``cube`` (implying ``upper``) with literals dropped, in text order, while it
        still implies ``upper``: a prime implicant of ``upper``."""
        leq = None if self._native is None else self._native.leq
        kept = expanded(self.bdd, {self.declare(n): v for n, v in cube.items()}, upper, leq)
        return {self._outer[v]: x for v, x in kept.items()}

    def minimal_cube(self, u: Function) -> Cube | None:
        """A prime implicant of ``u`` (a counterexample no literal of which can be dropped)."""
        c = self.path_cube(u)
        return None if c is None else self.expanded(c, u)

    def witness(self, u: Function, care: Function | None = None) -> Cube | None:
        """A prime implicant of ``u`` within ``care``: a cube meeting ``u & care`` whose
        every valuation in ``care`` is in ``u``; ``None`` when ``u & care`` is false."""
        care = self.true if care is None else care
        c = self.path_cube(u & care)
        return None if c is None else self.expanded(c, u | ~care)

    def ordered(self, cube: Mapping[str, bool]) -> Cube:
        return dict(sorted(cube.items(), key=lambda kv: self.rank(kv[0])))

    # ---- covers
    def cover(self, lower: Function, upper: Function | None = None, limit: int | None = None) -> list[Cube]:
        """An irredundant cover of prime implicants of some function between ``lower`` and
        ``upper`` (``upper`` defaults to ``lower``; the gap is the don't-care set), built in
        the text order (:class:`~synth.logic.isop.Covers`). :class:`CoverTooLarge` when the
        Minato–Morreale cover has more than ``limit`` cubes."""
        if self._covers is None:
            engine = weakref.ref(self)  # no cycle: the engine (and the cubes it caches) freed as soon as unused
            self._covers = Covers(self.bdd, lambda inner: engine().inner_ranks()[inner])  # type: ignore[union-attr]
        return [{self._outer[v]: x for v, x in c.items()} for c in self._covers.cover(lower, upper, limit)]

    def text(self, lower: Function, upper: Function | None = None, limit: int | None = None) -> str:
        """``u`` (or some function between ``lower`` and ``upper``) in filter syntax
        (:class:`CoverTooLarge` past ``limit`` cubes, see :meth:`cover`)."""
        if lower == self.false:
            return "0"
        cubes = self.cover(lower, upper, limit)
        if cubes == [{}]:
            return "1"
        self.inner_ranks()  # built once per set of declared variables, not per equation
        return factored([cube_literals(c, self._ranks_by_name) for c in cubes], top=True)

"""The plant's state space on BDDs: one boolean variable per plant variable, in three copies.

A plant state is the valuation of every element variable (``A1``, ``a1_0``, …): the
*current* copy carries a variable's own name, the *next* copy ``name'`` and an *auxiliary*
copy ``name''`` (used to compose relations); the three copies of a variable are adjacent
in the order, so relations that change one element stay small. Elements are ordered from
the constraint graph (:func:`element_order`): the partners of each constraint (an
interlock between two cylinders declared far apart) sit side by side, so a state set
does not carry every constraint across one cut of the order. Each element's reachable local codes form its *domain*; a state set is always a
subset of the product of the domains.

Counts are exact Python integers (CUDD's own count is a double, wrong above 2^53).

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> enc = PlantEncoding(plant(load_rules(_plants("tri_annex.rules"))))
>>> enc.count(enc.domain)
15552
>>> enc.local(enc.pick(enc.state(enc.plant.initial))) == enc.plant.initial
True
"""

from __future__ import annotations

from enum import Enum
from typing import Iterator, Mapping, Sequence

from synth.errors import InputError, LimitExceeded
from synth.logic.bdd import Engine, Function, interleaved_order
from synth.logic.counting import count
from synth.logic.expr import names as expr_names
from synth.plant.composition import Plant
from synth.plant.rules import Constraint

__all__ = ["Copy", "PlantEncoding", "NodeBudget", "live_nodes", "element_order"]


class Copy(Enum):
    """Which copy of the plant variables a BDD speaks about."""

    CURRENT = ""
    NEXT = "'"
    AUX = "''"


def live_nodes(engine: Engine, exact: bool = False) -> int:
    """The manager's live BDD nodes (:meth:`Engine.live_nodes`; ``exact`` for a count that is printed)."""
    return engine.live_nodes(exact)


class NodeBudget:
    """``--max-nodes``: the largest number of live BDD nodes allowed (None: no limit).

    Checked at once, then at most every :attr:`interval` seconds (a reading of the node
    count costs milliseconds on a large manager, and is asked once per situation), so
    the engine stops within that interval of crossing the budget."""

    __slots__ = ("limit", "_next")
    interval = 0.25

    def __init__(self, limit: int | None = None) -> None:
        self.limit = limit
        self._next = 0.0

    def check(self, engine: Engine, where: str) -> None:
        """Stop with :class:`~synth.errors.LimitExceeded` above the budget."""
        if self.limit is None:
            return
        from time import monotonic

        now = monotonic()
        if now < self._next:
            return
        n = live_nodes(engine)
        self._next = monotonic() + self.interval
        if n > self.limit:
            raise LimitExceeded(
                f"the symbolic engine needs more than {self.limit} BDD nodes ({n} while {where}); "
                "raise --max-nodes or use --engine explicit"
            )


def element_order(p: Plant, constraints: Sequence[Constraint] = ()) -> tuple[int, ...]:
    """The elements (indices in declaration order) in the BDD variable order: the elements
    a constraint names are neighbours, visited breadth-first from the first declared
    element of each connected part (:func:`~synth.logic.bdd.interleaved_order`). Elements
    no constraint links keep their declaration order.

    >>> from synth.plant.rules_check import load_rules
    >>> from synth.plant.composition import plant, _plants
    >>> rs = load_rules(_plants("tri.rules"))
    >>> sorted(element_order(plant(rs), rs.constraints)) == list(range(len(rs.elements)))
    True
    """
    label = [str(i) for i in range(len(p.elements))]
    supports = [{label[p.owner[n.name]] for n in expr_names(c.forbidden) if n.name in p.owner} for c in constraints]
    return tuple(int(a) for a in interleaved_order(label, supports, label, {}))


class PlantEncoding:
    """BDD variables, domains and conversions for the states of one plant; ``constraints``
    choose the variable order (:func:`element_order`)."""

    def __init__(self, p: Plant, budget: NodeBudget | None = None, constraints: Sequence[Constraint] = (),
                 anchored: Mapping[int | None, Sequence[str]] | None = None) -> None:
        if p.reads:  # a move would depend on other elements' variables: not encoded here
            readers = ", ".join(e.name for e in p.elements if e.guards is not None and not e.guards.all())
            raise InputError(
                f"the symbolic engine does not support elements that read other elements' variables "
                f"(`reads` in {readers})", p.reads_at, notes=("use --engine explicit",))
        self.plant = p
        self.budget = budget or NodeBudget()
        self.variables: tuple[str, ...] = tuple(v for e in p.elements for v in e.variables)
        self.order: tuple[int, ...] = element_order(p, constraints)
        # ``anchored``: other variables (the Grafcet's steps, :mod:`synth.symbolic.steps.encoding`), in
        # three copies too, declared just before the element they are anchored to (None: first)
        extra = anchored or {}
        order = [v + c.value for v in extra.get(None, ()) for c in Copy]
        for a in self.order:
            order += [v + c.value for v in extra.get(a, ()) for c in Copy]
            order += [v + c.value for v in p.elements[a].variables for c in Copy]
        self.engine = Engine(order)
        self.bdd = self.engine.bdd
        self.element_variables: tuple[tuple[str, ...], ...] = tuple(e.variables for e in p.elements)
        self.domains: tuple[Function, ...] = tuple(
            self.engine.disjunction(self.code(i, int(c)) for c in e.codes) for i, e in enumerate(p.elements)
        )
        self.domain: Function = self.engine.conjunction(self.domains)
        self._renames: dict[tuple, tuple[Function, Function]] = {}
        self._quantified: dict[tuple, Function] = {}
        self._qvars: dict[tuple, list[str]] = {}
        self._inner = {v: self.engine.declare(v) for v in self.variables}
        self._levels: dict[tuple[Copy, ...], list[int]] = {}

    # ---- names and renaming
    @staticmethod
    def name(v: str, copy: Copy) -> str:
        return v + copy.value

    def rename(self, u: Function, source: Copy, target: Copy, names: Sequence[str] | None = None) -> Function:
        """``u`` with the ``source`` copy of ``names`` (default: every variable) renamed to
        ``target``: ``∃source. u ∧ (source = target)``, which is the substitution
        ``u[source := target]`` whatever ``u`` depends on (the source variables are pinned to
        the target's values), with the cube and the equality built once per key (a vector
        compose walks every variable of the manager on each call)."""
        key = (source, target, None if names is None else tuple(names))
        hit = self._renames.get(key)
        if hit is None:
            vs = self.variables if names is None else names
            equal = self.engine.conjunction(self.engine.var(v + source.value).equiv(self.engine.var(v + target.value)) for v in vs)
            hit = self._renames[key] = (self._cube(source, vs), equal)
        cube, equal = hit
        return self.and_exists(u, equal, source, names)

    def exists(self, u: Function, copy: Copy, names: Sequence[str] | None = None) -> Function:
        """``∃`` the ``copy`` of ``names`` (default: every variable) in ``u``."""
        key = (copy, None if names is None else tuple(names))
        cube = self._quantified.get(key)
        if cube is None:
            cube = self._quantified[key] = self._cube(copy, self.variables if names is None else names)
        return self.bdd.apply("exists", cube, u)

    def and_exists(self, u: Function, v: Function, copy: Copy, names: Sequence[str] | None = None) -> Function:
        """``∃`` the ``copy`` of ``names`` (default: every variable) in ``u ∧ v``, in one pass
        (CUDD's relational product: the conjunction is never built)."""
        key = (copy, None if names is None else tuple(names))
        qvars = self._qvars.get(key)
        if qvars is None:
            qvars = self._qvars[key] = [self.engine.declare(n + copy.value) for n in (self.variables if names is None else names)]
        return self.engine.and_exists(u, v, qvars)

    def _cube(self, copy: Copy, names: Sequence[str]) -> Function:
        """The positive cube of the ``copy`` of ``names`` (what ``∃`` quantifies)."""
        return self.bdd.cube({self.engine.declare(v + copy.value) for v in names})

    # ---- states
    def code(self, axis: int, code: int, copy: Copy = Copy.CURRENT) -> Function:
        """The cube of element ``axis``'s local code ``code`` (bit i = its i-th variable)."""
        names = self.element_variables[axis]
        return self.engine.cube({n + copy.value: bool((code >> i) & 1) for i, n in enumerate(names)})

    def local_state(self, axis: int, k: int, copy: Copy = Copy.CURRENT) -> Function:
        return self.code(axis, int(self.plant.elements[axis].codes[k]), copy)

    def state(self, local: Sequence[int], copy: Copy = Copy.CURRENT) -> Function:
        """The cube of one plant state given as local indices."""
        return self.engine.conjunction(self.local_state(a, k, copy) for a, k in enumerate(local))

    def pick(self, u: Function) -> dict[str, bool] | None:
        """One state of ``u`` (a valuation of every current variable), ``None`` if empty:
        the first path to 1 in the BDD order, variables it leaves free false (every
        completion of a path to 1 is in ``u``). Cheap, but which state depends on the
        order: what a report shows comes from :meth:`smallest`."""
        if u == self.engine.false:
            return None
        return {**{v: False for v in self.variables}, **first_path(self.engine, u)}

    def smallest(self, u: Function) -> dict[str, bool] | None:
        """The smallest state of ``u``, ``None`` if empty: variables in declaration order,
        false before true, whatever the BDD order (:meth:`pick` when the two orders agree)."""
        if u == self.engine.false:
            return None
        if self.order == tuple(range(len(self.order))):
            return self.pick(u)
        values: dict[str, bool] = {}
        false = self.engine.false
        f = u
        for v in self.variables:
            low = self.bdd.let({self._inner[v]: False}, f)
            values[v] = low == false
            f = self.bdd.let({self._inner[v]: True}, f) if values[v] else low
        return values

    def one(self, u: Function) -> tuple[int, ...]:
        """The state :meth:`smallest` chooses in ``u``, as local indices (``u`` not empty)."""
        values = self.smallest(u)
        if values is None:
            raise ValueError("no state to pick in an empty set")
        return self.local(values)

    def local(self, values: Mapping[str, bool]) -> tuple[int, ...]:
        """Local indices of the state whose variables have ``values``."""
        out = []
        for e in self.plant.elements:
            code = sum(1 << i for i, v in enumerate(e.variables) if values[v])
            out.append(int(e.codes.searchsorted(code)))
        return tuple(out)

    def states(self, u: Function, limit: int) -> Iterator[tuple[int, ...]]:
        """Every state of ``u`` as local indices, at most ``limit``; in the order of
        :meth:`smallest` (variables in declaration order, false first), whatever the BDD order."""
        care = [self.engine.declare(v) for v in self.variables]
        found: list[tuple[bool, ...]] = []
        for n, inner in enumerate(self.bdd.pick_iter(u, care_vars=care)):
            if n >= limit:
                raise LimitExceeded(f"more than {limit} states to list from a BDD")
            found.append(tuple(bool(inner[c]) for c in care))
        for values in sorted(found):
            yield self.local(dict(zip(self.variables, values)))

    # ---- exact counting
    def count(self, u: Function, copies: Sequence[Copy] = (Copy.CURRENT,)) -> int:
        """The exact number of valuations of the given copies of the variables in ``u``
        (``u`` must depend on those copies only; :func:`synth.logic.counting.count`)."""
        return count(self.engine, u, self.levels(copies))

    def levels(self, copies: Sequence[Copy]) -> list[int]:
        """The sorted BDD levels of the given copies of every plant variable."""
        key = tuple(copies)
        levels = self._levels.get(key)
        if levels is None:
            levels = self._levels[key] = sorted(self.engine.level(v + c.value) for v in self.variables for c in copies)
        return levels

    def check(self, where: str) -> None:
        self.budget.check(self.engine, where)


def first_path(engine: Engine, u: Function) -> dict[str, bool]:
    """The first path to 1 of ``u`` (not false) in the BDD order, low branch first: the
    variables it sets, by caller names (those it leaves free are absent)."""
    out: dict[str, bool] = {}
    f = u
    true, false = engine.true, engine.false
    while f != true:
        lo, hi = f.low, f.high  # children of the regular node: complement them if f is
        if f.negated:
            lo, hi = ~lo, ~hi
        out[engine.name_of(f.var)] = lo == false
        f = hi if lo == false else lo
    return out

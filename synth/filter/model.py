"""A checked filter as Boolean functions: one BDD per constraint, the assumptions A(Y),
the aggregated simple constraints fs0/fs1 (000 eqs. 5-7) and the combined reliefs
fc0/fc1 (000 eqs. 8-10). Shared by the coherence checks and the synthesis.

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> m = functions(parse_filter("inputs i\\noutputs o\\nsafety S: i & o\\nsafety T: !i & !o", "x.filter"))
>>> m.engine.text(m.fs0["o"]), m.engine.text(m.fs1["o"]), [i for i, _ in m.forcing_parts("o", True)]
('i', '!i', ['T'])
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Iterable, Mapping, Sequence

from synth.logic.bdd import Cube, Engine, Function, factored, cube_literals, interleaved_order
from synth.filter.language import Comparison, Criterion, Filter, IntegerObserver, Safety
from synth.logic.past import base_name, is_pre, pre_name
from synth.logic.expr import Compare, Edge, Expr, Var, names

__all__ = ["FilterFunctions", "functions", "variable_order", "bdd_order", "expr_names", "edge_rule", "equation_functions",
           "IntegerEngine", "filter_engine"]

_FLIPPED = {">=": "<=", "<=": ">=", "<": ">", ">": "<", "=": "=", "<>": "<>"}


class IntegerEngine(Engine):
    """An :class:`Engine` that reads comparisons of integer observers (docs/filter.md,
    "Integer observers"): ``cpt`` is the bits ``cpt_b0 …`` of its code ``cpt - low``
    (``cpt^-1`` the bits' past values), a comparison the Boolean function of the bits, and
    a cover is printed with each cube's literals on one integer's bits written as the
    comparison they spell over its legal values, when they spell an interval."""

    def __init__(self, integers: Iterable[IntegerObserver], order: Iterable[str] = (),
                 text_order: Iterable[str] | None = None) -> None:
        super().__init__(order, text_order)
        self.integers = {i.name: i for i in integers}

    def bits(self, operand: str) -> tuple[IntegerObserver, list[str]]:
        """The integer observer of ``cpt`` or ``cpt^-1`` and the names of its bits."""
        obs = self.integers[base_name(operand)]
        return obs, [pre_name(b) if is_pre(operand) else b for b in obs.bits]

    def at_most(self, bits: Sequence[str], code: int) -> Function:
        """``code(bits) <= code`` over every code the bits spell (least significant first)."""
        if code < 0:
            return self.false
        if code >= (1 << len(bits)) - 1:
            return self.true
        u = self.true  # the low k bits spell at most the low k bits of code
        for k, b in enumerate(bits):
            x = self.var(b)
            u = (~x | u) if (code >> k) & 1 else (~x & u)
        return u

    def constant(self, operand: str, op: str, value: int) -> Function:
        """``operand op value`` for a constant ``value``."""
        obs, bits = self.bits(operand)
        c = value - obs.low
        le, lt = self.at_most(bits, c), self.at_most(bits, c - 1)
        return {"<=": le, "<": lt, ">": ~le, ">=": ~lt, "=": le & ~lt, "<>": ~(le & ~lt)}[op]

    def comparison(self, c: Compare) -> Function:
        if not isinstance(c.right, str):
            return self.constant(c.left, c.op, c.right)
        obs, bits = self.bits(c.left)
        out = self.false
        for v in range(obs.low, obs.high + 1):  # left = v and v op right
            out |= self.cube(dict(zip(bits, obs.values(v)))) & self.constant(c.right, _FLIPPED[c.op], v)
        return out

    def domain(self, operand: str) -> Function:
        """The legal codes of ``cpt`` (or ``cpt^-1``): ``code <= high - low``."""
        obs, bits = self.bits(operand)
        return self.at_most(bits, obs.high - obs.low)

    def expr(self, e: Expr) -> Function:
        if isinstance(e, Compare):
            return self.comparison(e)
        return super().expr(e)

    def text(self, lower: Function, upper: Function | None = None, limit: int | None = None) -> str:
        if not self.integers or lower == self.false:
            return super().text(lower, upper, limit)
        cubes = self.cover(lower, upper, limit)
        if cubes == [{}]:
            return "1"
        order = {n: self.rank(n) for n in self.names}
        terms: list[_Term] = [(dict(c), ()) for c in cubes]
        for obs in self.integers.values():
            for operand in (obs.name, pre_name(obs.name)):
                terms = self._merged(terms, operand, order)
        if not terms:
            return "0"
        return factored([sorted([*lits, *cube_literals(rest, order)]) for rest, lits in terms], top=True)

    def _merged(self, terms: list["_Term"], operand: str, order: Mapping[str, int]) -> list["_Term"]:
        """The terms with their literals on ``operand``'s bits written as comparisons:
        terms equal but for those bits are merged, the legal values they allow split into
        maximal intervals (kept as bits when that takes more terms than the cubes)."""
        obs, bits = self.bits(operand)
        groups: dict[tuple, _Group] = {}
        slots: list[list[_Term]] = []  # a term kept as it is, or the place of a group's terms
        for rest, lits in terms:
            fixed = {b: rest[b] for b in bits if b in rest}
            if not fixed:
                slots.append([(rest, lits)])
                continue
            other = {n: v for n, v in rest.items() if n not in fixed}
            key = (tuple(other.items()), lits)
            if key not in groups:
                groups[key] = _Group(other, lits)
                slots.append(groups[key].out)
            g = groups[key]
            g.cubes.append((rest, lits))
            g.allowed.update(v for v in range(obs.low, obs.high + 1)
                             if all(obs.values(v)[bits.index(b)] == x for b, x in fixed.items()))
        at = min(order.get(b, 0) for b in bits)
        for g in groups.values():
            runs = _runs(sorted(g.allowed))
            if len(runs) > len(g.cubes):
                g.out += g.cubes
                continue
            for a, z in runs:
                texts = ([f"{operand} = {a}"] if a == z else
                         [f"{operand} >= {a}"] * (a > obs.low) + [f"{operand} <= {z}"] * (z < obs.high))
                g.out.append((dict(g.other), (*g.lits, *((at, t) for t in texts))))
        return [t for slot in slots for t in slot]


_Term = tuple[Cube, tuple[tuple[int, str], ...]]  # the bits left to print, the comparisons printed


@dataclass
class _Group:
    """Terms equal but for one integer's bits: the legal values they allow together."""

    other: Cube
    lits: tuple[tuple[int, str], ...]
    cubes: list[_Term] = field(default_factory=list)
    allowed: set[int] = field(default_factory=set)
    out: list[_Term] = field(default_factory=list)


def _runs(values: Sequence[int]) -> list[tuple[int, int]]:
    """The maximal intervals of sorted integers: ``[0, 1, 3]`` is ``[(0, 1), (3, 3)]``."""
    runs: list[tuple[int, int]] = []
    for v in values:
        if runs and runs[-1][1] == v - 1:
            runs[-1] = (runs[-1][0], v)
        else:
            runs.append((v, v))
    return runs


def filter_engine(f: Filter, order: Iterable[str] = (), text_order: Iterable[str] | None = None) -> Engine:
    """The engine of a filter's functions: an :class:`IntegerEngine` when it declares integer observers."""
    return IntegerEngine(f.integers, order, text_order) if f.integers else Engine(order, text_order)


def _exprs(f: Filter) -> list[Expr]:
    """The constraints, assumptions, equations and stated criteria of ``f``."""
    exprs = [s.expr for s in f.safeties] + [a.expr for a in f.assumptions] + [q.expr for q in f.equations]
    return exprs + [c.expr for c in f.criteria if isinstance(c, Criterion)]


def variable_order(f: Filter) -> list[str]:
    """The text order: requests, then read-only variables with their past values, then
    past outputs, then the outputs at t. Every equation and counterexample is built and
    printed in this order, whatever the BDDs' variable order (:func:`bdd_order`)."""
    order = list(f.requests)
    for x in (*f.observer_names, *f.inputs):
        order += [pre_name(x), x]
    order += [pre_name(o) for o in f.outputs]
    exprs = _exprs(f)
    mentioned = [n for e in exprs for v in names(e) if isinstance(v, Var)
                 for n in (v.reads if isinstance(v, Comparison) else (v.name,))]
    order += [n for n in mentioned if n not in order and base_name(n) not in f.outputs]
    return order + list(f.outputs)


def expr_names(e: Expr) -> set[str]:
    """The BDD variables of ``e``: its names, ``x^-1`` for an edge of ``x``, the bits of
    the integer observers a (checked) comparison reads."""
    return {n for v in names(e) for n in ((v.name, pre_name(v.name)) if isinstance(v, Edge) else
                                         v.reads if isinstance(v, Comparison) else (v.name,))}


def bdd_order(f: Filter) -> list[str]:
    """The BDDs' variable order: each output next to the signals of its constraints
    (:func:`~synth.logic.bdd.interleaved_order` over the constraints, assumptions, stated
    criteria and equations; ``R_o`` and ``o^-1`` belong to ``o``), so the admissible set
    S(O,Y) never carries every output's constraints across one cut."""
    exprs = _exprs(f)
    supports = [expr_names(e) for e in exprs]
    supports += [{o for o in f.outputs if any(c.output == o for c in s.forced)} | expr_names(s.expr) for s in f.combined]
    owner = {r: o for r, o in zip(f.requests, f.outputs)} | {pre_name(o): o for o in f.outputs}
    return interleaved_order(f.outputs, supports, variable_order(f), owner)


@dataclass
class FilterFunctions:
    """The BDDs of one filter, all in one :class:`Engine`."""

    filter: Filter
    engine: Engine
    constraint: dict[str, Function]  # id -> the constraint (true = violated)
    assumed: Function  # the conjunction of the assumptions
    fs0: dict[str, Function] = field(default_factory=dict)  # o -> Y where a CSs forces o to 0
    fs1: dict[str, Function] = field(default_factory=dict)
    fc0: dict[str, Function] = field(default_factory=dict)  # o -> (O, Y) where a CSc relief forces o to 0
    fc1: dict[str, Function] = field(default_factory=dict)
    forcing: dict[tuple[str, bool], list[tuple[str, Function]]] = field(default_factory=dict)
    reliefs: dict[tuple[str, bool], list[tuple[str, Function]]] = field(default_factory=dict)  # (o, v) -> relief_parts

    @property
    def outputs(self) -> tuple[str, ...]:
        return self.filter.outputs

    @property
    def forbidden(self) -> Function:
        """F(O, Y): some constraint is violated."""
        return self.engine.disjunction(self.constraint.values())

    @functools.cached_property
    def simple_forbidden(self) -> Function:
        """ΣCSs(O, Y) (built once: P3 and P4 read it for every output)."""
        return self.engine.disjunction(self.constraint[s.id] for s in self.filter.simple)

    def forcing_parts(self, output: str, value: bool) -> list[tuple[str, Function]]:
        """(id, where it forces) for each simple constraint forcing ``output`` to ``value``."""
        return self.forcing.get((output, value), [])

    def relief_parts(self, output: str, value: bool) -> list[tuple[str, Function]]:
        """(id, CSc) for each combined constraint whose relief sets ``output`` to ``value``."""
        return self.reliefs.get((output, value), [])


def functions(f: Filter) -> FilterFunctions:
    """The BDDs of a checked filter."""
    e = filter_engine(f, bdd_order(f), text_order=variable_order(f))
    assumed = e.conjunction(e.expr(a.expr) for a in f.assumptions)
    if isinstance(e, IntegerEngine):  # the domain assumption: only legal codes, now and before
        read = {n for x in _exprs(f) for n in expr_names(x)}
        for i in f.integer_observers:
            assumed &= e.domain(i.name)
            if any(pre_name(b) in read for b in i.bits):
                assumed &= e.domain(pre_name(i.name))
    m = FilterFunctions(f, e, {s.id: e.expr(s.expr) for s in f.safeties}, assumed)
    simple: dict[str, list[Safety]] = {}  # each output's simple constraints, in file order
    for s in f.simple:
        simple.setdefault(s.outputs[0], []).append(s)
    for s in f.combined:  # each relief's (output, value) pairs, in file order
        for key in dict.fromkeys((c.output, c.value) for c in s.forced):
            m.reliefs.setdefault(key, []).append((s.id, m.constraint[s.id]))
    for o in f.outputs:
        for value in (False, True):
            parts = []
            for s in simple.get(o, []):
                if s.outputs == (o,):
                    # o·h0 + !o·h1: the constraint forces 0 where h0 = c|o=1, 1 where h1 = c|o=0
                    where = e.let({o: not value}, m.constraint[s.id])
                    if where != e.false:
                        parts.append((s.id, where))
            m.forcing[(o, value)] = parts
        m.fs0[o] = e.disjunction(u for _, u in m.forcing[(o, False)])
        m.fs1[o] = e.disjunction(u for _, u in m.forcing[(o, True)])
        m.fc0[o] = e.disjunction(u for _, u in m.relief_parts(o, False))
        m.fc1[o] = e.disjunction(u for _, u in m.relief_parts(o, True))
    return m



def edge_rule(m: FilterFunctions, output: str) -> bool:
    """Whether the simple constraints on ``output`` force it to 0 only when it was 0 and
    to 1 only when it was 1 (written with its edges, 000 eqs. 12-13), both kinds present:
    then ``fs0·fs1 = 0`` needs no computation."""
    e, before = m.engine, m.engine.var(pre_name(output))
    fs0, fs1 = m.fs0[output], m.fs1[output]
    return fs0 != e.false and fs1 != e.false and e.implies(fs0, ~before) and e.implies(fs1, before)


def equation_functions(m: FilterFunctions) -> dict[str, Function]:
    """The outputs as functions of Y given by the file's ``equation`` lines, substituted
    in dependency order (an equation may use outputs at t computed before it, as 004's
    eq. (30) does). Every output needs an equation; a dependency cycle is an input error."""
    from synth.errors import InputError, Location

    f, e = m.filter, m.engine
    given = {q.output: q for q in f.equations}
    missing = [o for o in f.outputs if o not in given]
    if missing:
        first: Location | None = f.equations[0].loc if f.equations else None
        raise InputError(f"no equation for output {', '.join(missing)}", first,
                         notes=("check verifies equations only for a complete set",))
    raw = {o: e.expr(given[o].expr) for o in f.outputs}
    done: dict[str, Function] = {}
    while len(done) < len(raw):
        ready = [o for o in f.outputs if o not in done and
                 not any(n in raw and n not in done for n in e.support(raw[o]))]
        if not ready:
            waiting = [o for o in f.outputs if o not in done]
            raise InputError(f"the equations of {', '.join(waiting)} depend on each other in a cycle",
                             given[waiting[0]].loc)
        for o in ready:
            done[o] = e.let(done, raw[o])
    return {o: done[o] for o in f.outputs}

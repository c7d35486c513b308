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

from dataclasses import dataclass, field

from synth.logic.bdd import Engine, Function, interleaved_order
from synth.filter.language import Criterion, Filter
from synth.logic.past import base_name, pre_name
from synth.logic.expr import Edge, Expr, Var, names

__all__ = ["FilterFunctions", "functions", "variable_order", "bdd_order", "expr_names", "edge_rule", "equation_functions"]


def variable_order(f: Filter) -> list[str]:
    """The text order: requests, then read-only variables with their past values, then
    past outputs, then the outputs at t. Every equation and counterexample is built and
    printed in this order, whatever the BDDs' variable order (:func:`bdd_order`)."""
    order = list(f.requests)
    for x in (*f.observer_names, *f.inputs):
        order += [pre_name(x), x]
    order += [pre_name(o) for o in f.outputs]
    exprs = [s.expr for s in f.safeties] + [a.expr for a in f.assumptions] + [q.expr for q in f.equations]
    exprs += [c.expr for c in f.criteria if isinstance(c, Criterion)]
    mentioned = [v.name for e in exprs for v in names(e) if isinstance(v, Var)]
    order += [n for n in mentioned if n not in order and base_name(n) not in f.outputs]
    return order + list(f.outputs)


def expr_names(e: Expr) -> set[str]:
    """The BDD variables of ``e``: its names, and ``x^-1`` for an edge of ``x``."""
    return {n for v in names(e) for n in ((v.name, pre_name(v.name)) if isinstance(v, Edge) else (v.name,))}


def bdd_order(f: Filter) -> list[str]:
    """The BDDs' variable order: each output next to the signals of its constraints
    (:func:`~synth.logic.bdd.interleaved_order` over the constraints, assumptions, stated
    criteria and equations; ``R_o`` and ``o^-1`` belong to ``o``), so the admissible set
    S(O,Y) never carries every output's constraints across one cut."""
    exprs = [s.expr for s in f.safeties] + [a.expr for a in f.assumptions] + [q.expr for q in f.equations]
    exprs += [c.expr for c in f.criteria if isinstance(c, Criterion)]
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

    @property
    def outputs(self) -> tuple[str, ...]:
        return self.filter.outputs

    @property
    def forbidden(self) -> Function:
        """F(O, Y): some constraint is violated."""
        return self.engine.disjunction(self.constraint.values())

    @property
    def simple_forbidden(self) -> Function:
        """ΣCSs(O, Y)."""
        return self.engine.disjunction(self.constraint[s.id] for s in self.filter.simple)

    def forcing_parts(self, output: str, value: bool) -> list[tuple[str, Function]]:
        """(id, where it forces) for each simple constraint forcing ``output`` to ``value``."""
        return self.forcing.get((output, value), [])

    def relief_parts(self, output: str, value: bool) -> list[tuple[str, Function]]:
        """(id, CSc) for each combined constraint whose relief sets ``output`` to ``value``."""
        return [
            (s.id, self.constraint[s.id])
            for s in self.filter.combined
            if any(c.output == output and c.value == value for c in s.forced)
        ]


def functions(f: Filter) -> FilterFunctions:
    """The BDDs of a checked filter."""
    e = Engine(bdd_order(f), text_order=variable_order(f))
    m = FilterFunctions(f, e, {s.id: e.expr(s.expr) for s in f.safeties},
                        e.conjunction(e.expr(a.expr) for a in f.assumptions))
    for o in f.outputs:
        for value in (False, True):
            parts = []
            for s in f.simple:
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

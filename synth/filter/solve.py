"""Algebraic synthesis of a filter (004 §2.2, §3.2) in its relational form: the admissible
set ``S(O,Y) = A ∧ ¬F`` is narrowed by each criterion in order —
``Max(c)``: ``S := S ∧ (c ↔ ∃O.(S∧c))``, ``Min(c)``: ``S := S ∧ (c ↔ ∀O.(¬S∨c))`` —
and when S is functional each output is ``∃O.(S ∧ o)``, printed minimised over the
care set (the assumptions where a safe vector exists).

The criteria, in order: the CSc priorities as leading ``Min`` criteria (004 eq. 24),
unless the file states its own ``minimize``/``maximize`` criteria; then the file's
criteria; ``maximize sim`` expands to one ``Max(R_o·o + !R_o·!o)`` per output named. A
file without any ``maximize sim`` line gets one per output at the end, in ``outputs`` order.

Example (004 eqs. 4-13)
-------
>>> from synth.filter.language_check import parse_filter
>>> f = parse_filter('''inputs i1
... outputs O1, O2
... safety K: O1 & O2
... maximize i1 & O1
... minimize O1
... maximize O2''', "x.filter")
>>> s = synthesis(f)
>>> s.functional, s.equations
(True, {'O1': 'i1', 'O2': '!i1'})
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Collection, Mapping, Sequence

from synth.errors import InputError, LimitExceeded
from synth.logic.bdd import CoverTooLarge, Cube, Function, cube_text
from synth.filter.language import Criterion, Filter, Safety, Sense, SimCriterion, request_name
from synth.logic.past import pre_name
from synth.filter import local, narrowing
from synth.filter.model import FilterFunctions, equation_functions, functions
from synth.logic.expr import And, Const, Edge, Expr, Not, Or, Var
from synth.logic.partition import Partition

__all__ = ["IMPLICIT", "FLAT_PROBE", "FLAT_LIMIT", "TABLES_SIZE", "Applied", "Synthesis", "synthesis", "chained_equations", "criteria", "priority_criteria", "priority_criterion", "requested", "sim_expr",
           "differences", "printed"]


IMPLICIT = "implicit"
FLAT_PROBE = 64
"""Cubes: a Y-only (flat) equation is written only when its cover is this small, unless asked."""
FLAT_LIMIT = 4096
"""Cubes: past this, a flat equation asked for (``solve --flat``) is refused (exit 2)."""
TABLES_SIZE = 500
"""Past this size of the outputs the chain of narrowings decides against its elimination order
(:func:`synth.filter.narrowing.against`: per cut, ``2^n − 1`` for the ``n`` outputs carried
back across it, added up), the filter is its chain run on truth tables (:mod:`synth.filter.local`),
no equations: a figure read on the filter and its partition before the chain runs, which no
faster BDD code moves. The symbolic chain's work grows with it (docs/performance.md, "Session
30"): grid_edges 8 × 4 341 (4.6 M CUDD lookups), 10 stations × 4 461 (8.0 M), 12 × 4 581
(12.3 M), 8 × 5 765 (21 M), 8 × 8 4 805; the bundled filters at most 3, the bench's rings, chains and grids at most 31."""


def sim_expr(output: str) -> Expr:
    """``R_o & o | !R_o & !o``, the similarity of 004 eq. (25)."""
    r, o = Var(request_name(output)), Var(output)
    return Or((And((r, o)), And((Not(r), Not(o)))))


def requested(e: Expr, outputs: Collection[str]) -> Expr:
    """``e`` with each output at t replaced by its request (past values kept), e.g.
    ``↑A4`` becomes ``!A4^-1 & R_A4``: the condition under which the request violates ``e``.

    >>> requested(And((Edge(True, "A4"), Var("C"))), ["A4"]).text()
    '!A4^-1 & R_A4 & C'
    """
    if isinstance(e, Var):
        return Var(request_name(e.name), e.loc) if e.name in outputs else e
    if isinstance(e, Edge):
        if e.name not in outputs:
            return e
        before, now = Var(pre_name(e.name)), Var(request_name(e.name))
        return And((Not(before), now)) if e.rising else And((before, Not(now)))
    if isinstance(e, Const):
        return e
    if isinstance(e, Not):
        return Not(requested(e.arg, outputs), e.loc)
    args: list[Expr] = []
    for a in e.args:  # flatten the And an edge became
        r = requested(a, outputs)
        args.extend(r.args if isinstance(r, type(e)) and not isinstance(a, type(e)) else (r,))
    return type(e)(tuple(args), e.loc)


def priority_criteria(f: Filter) -> list[Criterion]:
    """One ``Min`` per CSc with a priority (004 eq. 24): when the requests violate it,
    minimise ``!L`` for ``keep L``, or the forced outputs being off their values."""
    outputs = frozenset(f.outputs)
    return [priority_criterion(s, outputs) for s in f.combined if s.has_priority]


def priority_criterion(s: Safety, outputs: Collection[str]) -> Criterion:
    """The criterion of one CSc with a priority (:func:`priority_criteria`)."""
    when = requested(s.expr, outputs)
    if s.keep is not None:
        bad: Expr = s.keep.arg if isinstance(s.keep, Not) else Not(s.keep)
    else:
        offs = tuple(Not(Var(c.output)) if c.value else Var(c.output) for c in s.forced)
        bad = offs[0] if len(offs) == 1 else Or(offs)
    return Criterion(Sense.MIN, And((when, bad)), s.loc, f"priority of {s.id}")


def criteria(f: Filter, order: Sequence[str] | None = None) -> list[Criterion]:
    """The criteria of ``f`` in the order they are applied. ``order`` reorders the Sim
    criteria: the outputs it names first, the others after them in their own order."""
    stated = [c for c in f.criteria if isinstance(c, Criterion)]
    out: list[Criterion] = [] if stated else priority_criteria(f)
    sims = [o for c in f.criteria if isinstance(c, SimCriterion) for o in c.outputs]
    implicit = not sims
    if implicit:  # no `maximize sim` line: every output, in `outputs` order, after the rest
        sims = list(f.outputs)
    if order is not None:
        unknown = [o for o in order if o not in f.outputs]
        if unknown:
            raise InputError(f"--order: '{unknown[0]}' is not an output of {f.file}", None, expected=f.outputs)
        sims = [o for o in dict.fromkeys(order) if o in sims] + [o for o in sims if o not in order]
    pending = list(sims)
    for c in f.criteria:
        if isinstance(c, SimCriterion):  # the file's sims, in the (re)ordered sequence
            here, pending = pending[: len(c.outputs)], pending[len(c.outputs):]
            out += [Criterion(Sense.MAX, sim_expr(o), c.loc, f"sim {o}") for o in here]
        else:
            out.append(Criterion(c.sense, c.expr, c.loc, f"line {c.loc.line}" if c.loc else "file"))
    origin = f"{IMPLICIT} sim" if implicit else "sim"
    out += [Criterion(Sense.MAX, sim_expr(o), None, f"{origin} {o}") for o in pending]
    return out


@dataclass(frozen=True)
class Applied:
    """A criterion as applied: does it narrow the admissible set where it stands
    (``narrows``), and would the final filter differ without it (``effect``)? None: not
    decided (the filter on tables: the chain is not run symbolically)."""

    criterion: Criterion
    narrows: bool | None
    effect: bool | None

    @property
    def implicit(self) -> bool:
        return self.criterion.origin.startswith(IMPLICIT)

    def text(self) -> str:
        return f"{self.criterion.sense.value} {self.criterion.expr.text()}  ({self.criterion.origin})"

    def warning(self, number: int) -> str:
        why = "it removes no solution" if not self.narrows else "the criteria after it give the same filter without it"
        return f"criterion {number} has no effect ({why}): {self.text()}"


@dataclass
class Synthesis:
    """The outcome of ``solve``: equations in filter syntax, and why it may have failed."""

    functions: FilterFunctions
    chain: narrowing.Narrowing
    care: Function
    applied: list[Applied]
    equations: dict[str, str] = field(default_factory=dict)  # flat: Y only (FLAT_PROBE cubes at most unless asked)
    chained: dict[str, str] = field(default_factory=dict)  # evaluation order; may use earlier outputs
    outputs: dict[str, Function] = field(default_factory=dict)  # the determined outputs as functions of Y
    free: dict[str, Cube] = field(default_factory=dict)  # output -> Y witness with two choices
    inconsistent: Cube | None = None
    inconsistent_text: str = ""
    notes: list[str] = field(default_factory=list)
    plan: local.Plan | None = None  # the filter on tables (past TABLES_SIZE): no equations

    @property
    def admissible(self) -> Function:
        """The final admissible set S(O, Y) as one BDD (built when first asked)."""
        return self.chain.admissible

    @property
    def functional(self) -> bool:
        return not self.free

    @property
    def variable_order(self) -> tuple[str, ...]:
        """The BDDs' variable order the synthesis ran with (model.bdd_order)."""
        return self.functions.engine.variable_order

    @property
    def flat_omitted(self) -> tuple[str, ...]:
        """The determined outputs whose flat equation was not written (larger than FLAT_PROBE cubes)."""
        return tuple(o for o in self.outputs if o not in self.equations)

    @property
    def consistent(self) -> bool:
        return self.inconsistent is None

    @property
    def warnings(self) -> list[str]:
        return [a.warning(i) for i, a in enumerate(self.applied, 1) if a.effect is False and not a.implicit]

    def output(self, o: str) -> Function:
        """The synthesised output ``o`` as a function of Y."""
        if o in self.outputs:
            return self.outputs[o]
        m = self.functions
        return m.engine.exists(m.outputs, self.admissible & m.engine.var(o))


def synthesis(f: Filter | FilterFunctions, order: Sequence[str] | None = None, *, flat: bool = False,
              applied: Sequence[Criterion] | None = None, partitioned: bool = True,
              tables_size: int | None = TABLES_SIZE) -> Synthesis:
    """Solve the filter's constraints with its criteria (the relational semantics of 004).
    ``flat``: write every Y-only equation (:class:`LimitExceeded` past FLAT_LIMIT cubes),
    not only those of at most FLAT_PROBE cubes. ``applied``: the criteria to apply instead
    of :func:`criteria` (a cluster's share of its whole filter's, :mod:`synth.filter.clusters`).
    ``partitioned``: keep each admissible set as a conjunction of factors, one BDD otherwise
    (:mod:`synth.filter.narrowing`; the same result). ``tables_size``: past this size of what
    the partitioned chain decides against its order (:data:`TABLES_SIZE`), the filter is its
    chain on truth tables (:mod:`synth.filter.local`) and no symbolic chain runs, unless
    ``flat`` asks for the equations."""
    m = f if isinstance(f, FilterFunctions) else functions(f)
    e = m.engine
    steps = [(c, e.expr(c.expr)) for c in (criteria(m.filter, order) if applied is None else applied)]

    goods = [u if c.sense is Sense.MAX else ~u for c, u in steps]  # Min(c) is Max(!c)
    if not partitioned:
        chain = narrowing.monolithic(m, goods)
    elif flat or not m.outputs or tables_size is None:
        chain = narrowing.partitioned(m, goods)
    else:
        p = narrowing.layout(m, goods)
        size, widest = narrowing.against(p, goods)
        if size > tables_size:
            why = (f"the chain of narrowings decides outputs against its order (size {size} over the limit of "
                   f"{tables_size}; {widest} outputs carried back across one cut)")
            return _on_tables(m, steps, goods, p, why)
        chain = narrowing.partitioned(m, goods, partition=p)
    verdicts = [Applied(c, narrows, effect) for (c, _), narrows, effect in zip(steps, chain.narrows, chain.effects)]
    result = Synthesis(m, chain, chain.care, verdicts)
    stated = any(isinstance(c, Criterion) for c in m.filter.criteria)
    if stated and any(s.has_priority for s in m.filter.combined):
        result.notes.append("the file states its criteria: the priorities of the combined constraints are not "
                            "translated into criteria")
    for s in m.filter.combined:
        if not s.has_priority:
            result.notes.append(f"{s.id} has no priority: the criteria order decides how it is relieved")
    care = chain.care
    stuck = m.assumed & ~care
    if stuck != e.false:
        result.inconsistent = e.witness(stuck, m.assumed)
        result.inconsistent_text = e.text(stuck, stuck | ~m.assumed)
    printed(result, chain.ones, chain.zeros, flat)
    return result


def _on_tables(m: FilterFunctions, steps: Sequence[tuple[Criterion, Function]], goods: Sequence[Function],
               p: Partition, why: str) -> Synthesis:
    """The filter as its chain of narrowings on truth tables (:mod:`synth.filter.local`): the
    criteria in order, the care set ``∃O.S_0`` (the narrowings keep it), no equations, the
    criteria's verdicts not decided. Functional by construction when every output has its
    Sim criterion (it fixes that output at every Y); otherwise refused."""
    e, file = m.engine, m.filter.file
    sims = {c.origin.rpartition(" ")[2] for c, _ in steps if c.origin.split(" ")[-2:-1] == ["sim"]}
    missing = [o for o in m.outputs if o not in sims]
    if missing:
        raise LimitExceeded(f"{file}: {why}, and {missing[0]} has no similarity criterion: the filter on "
                            "truth tables needs one per output (maximize sim)")
    plan = local.plan_of(m, p, goods)
    care = p.project(p.initial, 0)
    chain = narrowing.Narrowing([], [], care, {}, {}, lambda: _no_relation(file))
    result = Synthesis(m, chain, care, [Applied(c, None, None) for c, _ in steps], plan=plan)
    result.notes.append(f"{why}: the filter is its chain run on truth tables each cycle ({len(plan.bags)} bags, "
                        f"{plan.entries} entries; filter st writes it); no equations, the criteria's effects not decided")
    stuck = m.assumed & ~care
    if stuck != e.false:
        result.inconsistent = e.witness(stuck, m.assumed)
        result.inconsistent_text = e.text(stuck, stuck | ~m.assumed)
    return result


def _no_relation(file: str) -> Function:
    raise LimitExceeded(f"{file}: the filter is its chain on truth tables: its admissible set is not built")


Text = Callable[[Function, Function, "int | None"], str]
"""How an equation is printed: ``Engine.text`` (or a memo of it)."""


def printed(s: Synthesis, ones: Mapping[str, Function], zeros: Mapping[str, Function], flat: bool = False,
            text: Text | None = None) -> None:
    """Fill ``s`` (its care set given) with the outputs ``∃O.(S∧o)`` / ``∃O.(S∧!o)`` decide:
    the free ones with a witness, the others' functions, flat equations and chained ones."""
    m = s.functions
    e = m.engine
    text = e.text if text is None else text
    for o in m.outputs:
        one, zero = ones[o], zeros[o]
        if (one & zero) != e.false:
            free = e.minimal_cube(one & zero)
            assert free is not None  # one & zero is not false
            s.free[o] = free
            continue
        s.outputs[o] = one
        try:
            s.equations[o] = text(one, one | ~s.care, FLAT_LIMIT if flat else FLAT_PROBE)
        except CoverTooLarge as too_large:
            if flat:
                raise LimitExceeded(f"{m.filter.file}: the flat equation of {o} needs more than {too_large.limit} "
                                    "terms; the chained equations (solve without --flat) are the filter") from None
    s.chained = chained_equations(s, text)


def chained_equations(s: Synthesis, text: Text | None = None) -> dict[str, str]:
    """The equations in an evaluation order where each may use the outputs computed before
    it, as 004's (30) does (``A0 = R_A0 & !P01 & (!C0 | A1)``): outputs with the shortest
    flat equations first (those not written last, smallest BDD first); each keeps its flat
    text unless using earlier outputs is shorter."""
    m = s.functions
    e = m.engine
    text = e.text if text is None else text
    width = 1 + max((len(t) for t in s.equations.values()), default=0)
    order = sorted(s.outputs, key=lambda o: (len(s.equations.get(o, "")) or width + len(s.outputs[o]),
                                             m.outputs.index(o)))
    chained: dict[str, str] = {}
    agree = e.true  # the earlier outputs equal their functions
    for o in order:
        f = s.output(o)
        mine = text(f & agree & s.care, f | ~agree | ~s.care, None)
        flat = s.equations.get(o)
        chained[o] = mine if flat is None or len(mine) < len(flat) else flat
        agree &= e.var(o).equiv(f)
    return chained


def differences(s: Synthesis) -> list[str]:
    """How the file's ``equation`` lines differ from the synthesis, on the care set: the
    printed terms that give 1 where the synthesis gives 0, and where no printed term
    gives the synthesis's 1."""
    m = s.functions
    e, f = m.engine, m.filter
    if not f.equations:
        return []
    printed = equation_functions(m)
    lines = []
    for q in f.equations:
        if q.output in s.free:
            continue
        mine, theirs = s.output(q.output), printed[q.output]
        if (~mine.equiv(theirs) & s.care) == e.false:
            continue
        terms = q.expr.args if isinstance(q.expr, Or) else (q.expr,)
        for t in terms:
            extra = e.let(printed, e.expr(t)) & ~mine
            if (cube := e.witness(extra, s.care)) is not None:
                lines.append(f"{q.output}: the printed term {t.text()} gives 1 where the synthesis gives 0, "
                             f"e.g. when {cube_text(cube)}")
        if (cube := e.witness(mine & ~theirs, s.care)) is not None:
            lines.append(f"{q.output}: the synthesis gives 1 where no printed term does, "
                         f"e.g. when {cube_text(cube)}")
    return lines

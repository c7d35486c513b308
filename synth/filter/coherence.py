"""The coherence of a filter's constraints: MSR 2015's structural properties P1–P4
(000 eqs. 11-18) per output, P2's directed graph GO with its cycles, 001's pair
conditions, and the exact global consistency ``∀Y∈A ∃O: ΣCS(O,Y) = 0`` (004).

Every property is read in two domains: literally (every valuation) and under the
declared assumptions A(Y); P3 and P4 also keep only output vectors satisfying every
simple constraint (the vectors the filter works on). A violation carries a minimal
counterexample cube and the constraints involved.

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> f = parse_filter('''outputs o1, o2, o3
... safety K1: o1 & o2 force o2=0
... safety K2: !o2 & o3 force o2=1''', "c.filter")
>>> print(go_graph(functions(f))[1][0].text())
K1 -(o2:=0)-> K2 -(o2:=1)-> K1
"""

from __future__ import annotations

import builtins
from dataclasses import dataclass
from enum import StrEnum
from itertools import combinations, product
from typing import Any, Sequence

from synth.logic.bdd import Cube, Function, cube_text
from synth.filter.language import Filter
from synth.filter.model import FilterFunctions, edge_rule, equation_functions, functions
from synth.filter.solve import differences, synthesis

__all__ = ["Property", "Status", "Finding", "GoEdge", "Cycle", "Coherence", "coherence", "go_graph", "Check", "check"]


class Property(StrEnum):
    P1 = "P1"
    P2 = "P2"
    P3 = "P3"
    P4 = "P4"
    PAIR = "pair"
    CONSISTENCY = "consistency"
    EQUATION = "equation"


class Status(StrEnum):
    HOLDS = "holds"
    ASSUMED = "holds under assumptions"
    EDGE_RULE = "holds by the edge rule"
    VIOLATED = "violated"


@dataclass(frozen=True)
class GoEdge:
    """Relieving ``source`` sets ``output`` to ``value``, which can make ``target`` true."""

    source: str
    output: str
    value: bool
    target: str

    def text(self) -> str:
        return f"{self.source} -({self.output}:={int(self.value)})-> {self.target}"


@dataclass(frozen=True)
class Cycle:
    edges: tuple[GoEdge, ...]

    def text(self) -> str:
        return self.edges[0].source + "".join(f" -({e.output}:={int(e.value)})-> {e.target}" for e in self.edges)


@dataclass(frozen=True)
class Finding:
    """One property on one subject (an output, a constraint, or the whole filter)."""

    property: Property
    subject: str
    status: Status
    counterexample: Cube | None = None
    constraints: tuple[str, ...] = ()
    detail: str = ""

    @builtins.property  # the field ``property`` hides the builtin in this class body
    def holds(self) -> bool:
        return self.status is not Status.VIOLATED

    def text(self) -> str:
        head = f"{self.property.value}" + (f" on {self.subject}" if self.subject else "") + f": {self.status.value}"
        if self.detail:
            head += f": {self.detail}"
        if self.counterexample is not None and self.status is Status.VIOLATED:
            head += f" when {cube_text(self.counterexample)}"
        return head

    def as_dict(self) -> dict[str, Any]:
        cx = None if self.counterexample is None else {n: int(v) for n, v in self.counterexample.items()}
        return {"property": self.property.value, "subject": self.subject, "status": self.status.value,
                "holds": self.holds, "counterexample": cx, "constraints": list(self.constraints),
                "detail": self.detail}


@dataclass(frozen=True)
class Coherence:
    findings: tuple[Finding, ...]
    go: tuple[GoEdge, ...]
    cycles: tuple[Cycle, ...]

    @property
    def holds(self) -> bool:
        return all(f.holds for f in self.findings)

    def as_dict(self) -> dict[str, Any]:
        return {"holds": self.holds, "findings": [f.as_dict() for f in self.findings],
                "go": {"edges": [e.text() for e in self.go], "cycles": [c.text() for c in self.cycles]}}


def _judged(m: FilterFunctions, prop: Property, subject: str, parts: Sequence[tuple[tuple[str, ...], str, Function]],
            domain: Function, edge: bool = False, outside: str = "outside the assumptions") -> Finding:
    """The status of ``OR parts ≡ 0``: literally, then within ``domain``."""
    e = m.engine
    literal = e.disjunction(u for _, _, u in parts)
    for ids, detail, u in parts:
        bad = u & domain
        if bad != e.false:
            cube = e.witness(u, domain)
            return Finding(prop, subject, Status.VIOLATED, cube, ids, detail)
    if edge:
        return Finding(prop, subject, Status.EDGE_RULE)
    if literal == e.false:
        return Finding(prop, subject, Status.HOLDS)
    only = e.minimal_cube(literal)
    assert only is not None  # literal is not false
    return Finding(prop, subject, Status.ASSUMED, detail=f"fails only {outside}, e.g. when {cube_text(only)}")


def _p1(m: FilterFunctions, o: str) -> Finding:
    simple = [((a, b), f"{a} forces 0, {b} forces 1", u & v)
              for a, u in m.forcing_parts(o, False) for b, v in m.forcing_parts(o, True)]
    combined = [((a, b), f"the relief of {a} forces 0, the relief of {b} forces 1", u & v)
                for a, u in m.relief_parts(o, False) for b, v in m.relief_parts(o, True)]
    no_combined = all(u == m.engine.false for _, _, u in combined)
    return _judged(m, Property.P1, o, simple + combined, m.assumed, edge=no_combined and edge_rule(m, o))


def _p34(m: FilterFunctions, o: str, relief: bool) -> Finding:
    prop = Property.P4 if relief else Property.P3
    parts = [((a, b), f"the relief of {a} forces {int(relief)}, {b} forces {int(not relief)}", u & v)
             for a, u in m.relief_parts(o, relief) for b, v in m.forcing_parts(o, not relief)]
    return _judged(m, prop, o, parts, m.assumed & ~m.simple_forbidden)


def _pair(m: FilterFunctions, ident: str) -> Finding:
    """001 eqs. 12-15 for each pair of outputs of a combined constraint: the values the
    simple constraints force never make it true whatever the other outputs."""
    e, s = m.engine, m.filter.safety(ident)
    parts = []
    for k, l in combinations(s.outputs, 2):
        rest = [o for o in m.outputs if o not in (k, l)]
        for a, b in product((False, True), repeat=2):
            unavoidable = e.forall(rest, e.let({k: a, l: b}, m.constraint[ident]))
            for ka, u in m.forcing_parts(k, a):
                for lb, v in m.forcing_parts(l, b):
                    detail = f"{ka} forces {k}={int(a)}, {lb} forces {l}={int(b)}, then {ident} holds"
                    parts.append(((ident, ka, lb), detail, u & v & unavoidable))
    return _judged(m, Property.PAIR, ident, parts, m.assumed)


def _consistency(m: FilterFunctions) -> Finding:
    e = m.engine
    stuck = e.forall(m.outputs, m.forbidden)
    bad = stuck & m.assumed
    if bad == e.false:
        return _judged(m, Property.CONSISTENCY, "", [((), "", stuck)], m.assumed)
    cube = e.witness(stuck, m.assumed)
    assert cube is not None  # stuck & assumed is not false
    where = e.cube(cube) & m.assumed
    core = list(m.constraint)
    for ident in list(core):  # a minimal set of constraints still unsatisfiable on the cube
        rest = e.disjunction(m.constraint[i] for i in core if i != ident)
        if e.implies(where, e.forall(m.outputs, rest)):
            core.remove(ident)
    whole = e.text(bad, bad | ~m.assumed)
    detail = f"no output vector satisfies {', '.join(core)}"
    if whole != cube_text(cube):
        detail += f" (inconsistent wherever {whole})"
    return Finding(Property.CONSISTENCY, "", Status.VIOLATED, cube, tuple(core), detail)


def _equations(m: FilterFunctions) -> list[Finding]:
    e = m.engine
    implemented = equation_functions(m)
    safe = m.assumed & e.exists(m.outputs, ~m.forbidden)
    found = []
    for ident, u in m.constraint.items():
        now = e.let(implemented, u)
        found.append(_judged(m, Property.EQUATION, ident, [((ident,), f"the equations violate {ident}", now)],
                             safe, outside="outside the assumptions or where no output vector is safe"))
    return found


def go_graph(m: FilterFunctions) -> tuple[tuple[GoEdge, ...], tuple[Cycle, ...]]:
    """GO (000 eq. 16, MC = MC0ᵀ·MX0 + MC1ᵀ·MX1) and one shortest cycle per cyclic
    strongly connected component. An edge j → l labelled o:=v exists when CSc_l can
    become true by setting o to v in a valuation (within the assumptions) where CSc_j is
    violated with o = !v: 000's MX read semantically, so that ``↑A4·…`` relieved by A4:=0
    does not point at ``↓A4·…``, which needs A4^-1 = 1."""
    e = m.engine
    combined = m.filter.combined
    touching: dict[str, list[str]] = {}  # output -> the combined constraints that read it at t, in file order
    for t in combined:
        for o in e.support(m.constraint[t.id]):
            touching.setdefault(o, []).append(t.id)
    edges: list[GoEdge] = []
    for s in combined:
        for f in s.forced:
            was = e.let({f.output: not f.value}, m.constraint[s.id]) & m.assumed
            for t_id in touching.get(f.output, []):  # a constraint that does not read o is not set off by o:=v
                c = m.constraint[t_id]
                if (was & e.let({f.output: f.value}, c) & ~e.let({f.output: not f.value}, c)) != e.false:
                    edges.append(GoEdge(s.id, f.output, f.value, t_id))
    ids = [s.id for s in combined]
    succ = {i: [g for g in edges if g.source == i] for i in ids}
    cycles: list[Cycle] = []
    covered: set[str] = set()
    for start in ids:
        if start in covered:
            continue
        back: dict[str, GoEdge | None] = {start: None}  # breadth-first: the shortest way back to start
        frontier, found = [start], None
        while frontier and found is None:
            nxt = []
            for n in frontier:
                for g in succ[n]:
                    if g.target == start:
                        found = (n, g)
                        break
                    if g.target not in back:
                        back[g.target] = g
                        nxt.append(g.target)
                if found:
                    break
            frontier = nxt
        if found is None:
            continue
        path = [found[1]]
        n = found[0]
        while (edge := back[n]) is not None:
            path.append(edge)
            n = edge.source
        cycle = Cycle(tuple(reversed(path)))
        covered.update(g.source for g in cycle.edges)
        cycles.append(cycle)
    return tuple(edges), tuple(cycles)


def coherence(m: FilterFunctions | Any) -> Coherence:
    """Every check of ``synth filter check`` on a filter (or its functions)."""
    if not isinstance(m, FilterFunctions):
        m = functions(m)
    found = [_p1(m, o) for o in m.outputs]
    edges, cycles = go_graph(m)
    if cycles:
        for c in cycles:
            found.append(Finding(Property.P2, "", Status.VIOLATED, None, tuple(g.source for g in c.edges),
                                 f"GO cycle {c.text()}"))
    else:
        found.append(Finding(Property.P2, "", Status.HOLDS, detail="GO is acyclic"))
    found += [_p34(m, o, False) for o in m.outputs]
    found += [_p34(m, o, True) for o in m.outputs]
    found += [_pair(m, s.id) for s in m.filter.combined]
    found.append(_consistency(m))
    if m.filter.equations:
        found += _equations(m)
    return Coherence(tuple(found), edges, cycles)


@dataclass(frozen=True)
class Check:
    """``synth filter check``: the coherence, and how the file's ``equation`` lines differ
    from the synthesis (none without equations)."""

    coherence: Coherence
    differences: tuple[str, ...]

    @property
    def holds(self) -> bool:
        return self.coherence.holds


def check(f: Filter) -> Check:
    """The coherence of ``f`` and, when it states equations, their differences from the synthesis."""
    m = functions(f)
    report = coherence(m)
    return Check(report, tuple(differences(synthesis(m))) if f.equations else ())

"""Independent parts of a filter: outputs that share no constraint — directly, through a
relief, or through an assumption or a stated criterion naming both — form clusters that
can be solved separately and emitted as one block each (``synth filter st --split``).

A cluster's filter keeps the constraints, assumptions and criteria naming its outputs
(``o``, ``o^-1``, ``R_o``), the read-only names they use, and its share of the whole
filter's criteria (so the priorities are translated or not as for the whole file). On the
whole filter's care set, the clusters' outputs are the whole filter's; off it, each block
has its own care set, and in blocking mode each block latches on its own constraints.

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> f = parse_filter("inputs a\\noutputs p, q, r\\nsafety K: p & q keep p\\nsafety S: r & a", "x.filter")
>>> clusters(f)
(('p', 'q'), ('r',))
>>> [s.chained for s in solve_clusters(f)]
[{'p': 'R_p', 'q': 'R_q & !p'}, {'r': 'R_r & !a'}]
"""

from __future__ import annotations

from dataclasses import replace
from typing import Iterable, Sequence

from synth.filter.language import Criterion, Filter, SimCriterion
from synth.filter.model import expr_names
from synth.filter.solve import Synthesis, criteria, synthesis
from synth.logic.past import base_name

__all__ = ["clusters", "cluster_filter", "solve_clusters"]


def _owned(f: Filter, names: Iterable[str]) -> set[str]:
    """The outputs that names belong to (``o``, ``o^-1``, ``R_o``)."""
    requests = dict(zip(f.requests, f.outputs))
    found = set()
    for n in names:
        o = requests.get(n, base_name(n))
        if o in f.outputs:
            found.add(o)
    return found


def _links(f: Filter) -> list[set[str]]:
    """The outputs each constraint (with its relief), assumption and stated criterion links."""
    links = [_owned(f, expr_names(s.expr)) | {c.output for c in s.forced} for s in f.safeties]
    links += [_owned(f, expr_names(a.expr)) for a in f.assumptions]
    return links + [_owned(f, expr_names(c.expr)) for c in f.criteria if isinstance(c, Criterion)]


def clusters(f: Filter) -> tuple[tuple[str, ...], ...]:
    """The outputs in independent groups, each in ``outputs`` order, ordered by first output."""
    root = {o: o for o in f.outputs}

    def find(o: str) -> str:
        while root[o] != o:
            root[o] = root[root[o]]
            o = root[o]
        return o

    for linked in _links(f):
        ordered = sorted(linked, key=f.outputs.index)
        for o in ordered[1:]:
            a, b = find(ordered[0]), find(o)
            if a != b:
                root[max(a, b, key=f.outputs.index)] = min(a, b, key=f.outputs.index)
    groups: dict[str, list[str]] = {}
    for o in f.outputs:
        groups.setdefault(find(o), []).append(o)
    return tuple(tuple(g) for g in groups.values())


def cluster_filter(f: Filter, outputs: Sequence[str]) -> Filter:
    """The part of ``f`` about ``outputs`` (one of its :func:`clusters`)."""
    mine = set(outputs)

    def about(linked: set[str]) -> bool:
        return bool(linked & mine)

    safeties = tuple(s for s in f.safeties if about(_owned(f, expr_names(s.expr))))
    assumptions = tuple(a for a in f.assumptions if about(_owned(f, expr_names(a.expr))) or not _owned(f, expr_names(a.expr)))
    kept = [c for c in f.criteria if isinstance(c, SimCriterion) or about(_owned(f, expr_names(c.expr)))]
    sims = [SimCriterion(tuple(o for o in c.outputs if o in mine), c.loc) if isinstance(c, SimCriterion) else c
            for c in kept]
    used: set[str] = set()
    for e in [s.expr for s in safeties] + [a.expr for a in assumptions] + [c.expr for c in sims if isinstance(c, Criterion)]:
        used |= {base_name(n) for n in expr_names(e)}
    return replace(f, inputs=tuple(i for i in f.inputs if i in used), outputs=tuple(o for o in f.outputs if o in mine),
                   observers=tuple(d for d in f.observers if d.name in used), assumptions=assumptions,
                   safeties=safeties, criteria=tuple(c for c in sims if not isinstance(c, SimCriterion) or c.outputs),
                   equations=())


def solve_clusters(f: Filter, order: Sequence[str] | None = None) -> list[Synthesis]:
    """Each cluster solved alone, with its share of the whole filter's criteria."""
    whole = [(c, _owned(f, expr_names(c.expr))) for c in criteria(f, order)]
    out = []
    for k, group in enumerate(clusters(f)):
        mine = [c for c, linked in whole if (linked <= set(group) if linked else k == 0)]  # Y only: the first
        out.append(synthesis(cluster_filter(f, group), applied=mine))
    return out

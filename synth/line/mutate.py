"""Mutants of a Grafcet and of a filter, generated on the parsed model (frozen data,
:func:`dataclasses.replace`), each with a deterministic id (its operator and what it
changes, in file order), so a CI job can allow known survivors by id.

Grafcet operators: an order dropped, a receptivity negated, a receptivity weakened (one
term of a conjunction dropped), an edge turned into a level, the orders of two successive
steps swapped, a timer shortened (half its duration). Filter operator: a term of an
equation dropped.

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet("grafcet G { initial step 0 step 1: A, B  transition 0 -> 1 when ↑a . b  "
...                   "transition 1 -> 0 when 2s/X1 }")
>>> [m.id for m, _ in grafcet_mutants(g)]  # doctest: +NORMALIZE_WHITESPACE
['drop-order:1:A', 'drop-order:1:B', 'negate:0->1', 'negate:1->0', 'weaken:0->1:1', 'weaken:0->1:2',
 'level:0->1:a', 'swap-orders:0:1', 'shorten-timer:1->0:2s/X1']
>>> dict(grafcet_mutants(g))[Mutant('weaken:0->1:1', Operator.WEAKEN, '')].transitions[0].receptivity.text()
'b'
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from enum import StrEnum
from typing import Callable, Iterator, TypeVar

from synth.errors import Location, SynthError
from synth.grafcet.language import TIMER_RE, Grafcet, Step, Timer, Transition
from synth.logic.expr import And, Edge, Expr, Not, Or, Var, names

TYPE_CHECKING = False
if TYPE_CHECKING:
    from synth.filter.language import Filter

M = TypeVar("M")

__all__ = ["Operator", "Mutant", "grafcet_mutants", "filter_mutants", "grafcet_mutant", "filter_mutant", "shorter"]


class Operator(StrEnum):
    """How a mutant differs from the original."""

    DROP_ORDER = "drop-order"
    NEGATE = "negate"
    WEAKEN = "weaken"
    EDGE_TO_LEVEL = "level"
    SWAP_ORDERS = "swap-orders"
    SHORTEN_TIMER = "shorten-timer"
    DROP_TERM = "drop-term"


@dataclass(frozen=True)
class Mutant:
    """A mutant's id, operator and sentence (where it is: ``loc``, not compared)."""

    id: str
    operator: Operator
    description: str = dataclasses.field(default="", compare=False)
    loc: Location | None = dataclasses.field(default=None, compare=False)


def _replace_nodes(e: Expr, pick: Callable[[Expr], Expr | None]) -> Iterator[Expr]:
    """``e`` with one node replaced, for every node ``pick`` gives a replacement for (pre-order)."""
    new = pick(e)
    if new is not None:
        yield new
    if isinstance(e, Not):
        yield from (dataclasses.replace(e, arg=a) for a in _replace_nodes(e.arg, pick))
    elif isinstance(e, (And, Or)):
        for i, arg in enumerate(e.args):
            for a in _replace_nodes(arg, pick):
                yield dataclasses.replace(e, args=e.args[:i] + (a,) + e.args[i + 1:])


def shorter(timer: str) -> str:
    """A timer atom at half its duration, in milliseconds when not whole seconds.

    >>> shorter("2s/X101"), shorter("3s/X1"), shorter("500ms/X2")
    ('1s/X101', '1500ms/X1', '250ms/X2')
    """
    from synth.grafcet.language import duration_seconds

    m = TIMER_RE.match(timer)
    assert m is not None
    half = duration_seconds(m.group(1), m.group(2)) / 2
    text = f"{half}s" if half.denominator == 1 else f"{half * 1000}ms" if (half * 1000).denominator == 1 \
        else f"{float(half * 1000)}ms"
    return f"{text}/X{m.group(3)}"


def _retimed(g: Grafcet) -> Grafcet:
    """``g`` with its timers those its expressions name (a shortened timer replaces its original)."""
    used = list(dict.fromkeys(n.name for x in g.expressions() for n in names(x) if TIMER_RE.match(n.name)))
    known = {t.id: t for t in g.timers}
    timers = []
    for name in used:
        if name in known:
            timers.append(known[name])
        else:
            from synth.grafcet.language import duration_seconds

            m = TIMER_RE.match(name)
            assert m is not None
            timers.append(Timer(name, m.group(3), duration_seconds(m.group(1), m.group(2))))
    return dataclasses.replace(g, timers=tuple(timers))


def _with_transition(g: Grafcet, old: Transition, new: Transition) -> Grafcet:
    parts = tuple(dataclasses.replace(p, transitions=tuple(new if t is old else t for t in p.transitions))
                  for p in g.grafcets)
    return _retimed(dataclasses.replace(g, grafcets=parts))


def _with_steps(g: Grafcet, changed: dict[int, Step]) -> Grafcet:
    """``g`` with the steps whose ``id()`` is a key of ``changed`` replaced."""
    parts = tuple(dataclasses.replace(p, steps=tuple(changed.get(id(s), s) for s in p.steps)) for p in g.grafcets)
    return dataclasses.replace(g, grafcets=parts)


def _names(g: Grafcet) -> list[str]:
    """Each transition's name, made unique by ``#k`` when several share one."""
    seen: dict[str, int] = {}
    out = []
    for t in g.transitions:
        seen[t.name] = seen.get(t.name, 0) + 1
        out.append(t.name if seen[t.name] == 1 else f"{t.name}#{seen[t.name]}")
    return out


def _level(x: Expr) -> Expr | None:
    if isinstance(x, Edge):
        return Var(x.name) if x.rising else Not(Var(x.name))
    return None


def grafcet_mutants(g: Grafcet) -> list[tuple[Mutant, Grafcet]]:
    """Every mutant of ``g``, operators in the order of :class:`Operator`, each in file order."""
    out: list[tuple[Mutant, Grafcet]] = []
    for s in g.steps:
        for i, a in enumerate(s.actions):
            out.append((Mutant(f"drop-order:{s.name}:{a.order}" + (f"#{i + 1}" if [b.order for b in s.actions].count(a.order) > 1 else ""),
                               Operator.DROP_ORDER, f"step {s.name} without its action {a.text()}", s.loc),
                        _with_steps(g, {id(s): dataclasses.replace(s, actions=s.actions[:i] + s.actions[i + 1:])})))
    labelled = list(zip(_names(g), g.transitions))
    for name, t in labelled:
        out.append((Mutant(f"negate:{name}", Operator.NEGATE, f"transition {name} when !({t.receptivity.text()})", t.loc),
                    _with_transition(g, t, dataclasses.replace(t, receptivity=Not(t.receptivity)))))
    for name, t in labelled:
        r = t.receptivity
        if isinstance(r, And) and len(r.args) > 1:
            for i in range(len(r.args)):
                rest = r.args[:i] + r.args[i + 1:]
                new = rest[0] if len(rest) == 1 else dataclasses.replace(r, args=rest)
                out.append((Mutant(f"weaken:{name}:{i + 1}", Operator.WEAKEN,
                                   f"transition {name} when {new.text()} (without {r.args[i].text()})", t.loc),
                            _with_transition(g, t, dataclasses.replace(t, receptivity=new))))
    for name, t in labelled:
        for new in _replace_nodes(t.receptivity, _level):
            edges = [n.name for n in names(t.receptivity) if isinstance(n, Edge)]
            kept = [n.name for n in names(new) if isinstance(n, Edge)]
            gone = next((e for e in edges if edges.count(e) > kept.count(e)), "?")
            out.append((Mutant(f"level:{name}:{gone}", Operator.EDGE_TO_LEVEL, f"transition {name} when {new.text()}", t.loc),
                        _with_transition(g, t, dataclasses.replace(t, receptivity=new))))
    for p in g.grafcets:
        for first, then in zip(p.steps, p.steps[1:]):
            if first.actions != then.actions:
                out.append((Mutant(f"swap-orders:{first.name}:{then.name}", Operator.SWAP_ORDERS,
                                   f"steps {first.name} and {then.name} with each other's actions", first.loc),
                            _with_steps(g, {id(first): dataclasses.replace(first, actions=then.actions),
                                            id(then): dataclasses.replace(then, actions=first.actions)})))
    for name, t in labelled:
        for timer in dict.fromkeys(n.name for n in names(t.receptivity) if TIMER_RE.match(n.name)):
            def pick(x: Expr, timer: str = timer) -> Expr | None:
                return Var(shorter(timer)) if isinstance(x, Var) and x.name == timer else None

            for new in _replace_nodes(t.receptivity, pick):
                out.append((Mutant(f"shorten-timer:{name}:{timer}", Operator.SHORTEN_TIMER,
                                   f"transition {name} when {new.text()}", t.loc),
                            _with_transition(g, t, dataclasses.replace(t, receptivity=new))))
    return out


def filter_mutants(f: Filter) -> list[tuple[Mutant, Filter]]:
    """A term dropped from each equation whose right side is a conjunction or a disjunction."""
    out: list[tuple[Mutant, Filter]] = []
    for k, eq in enumerate(f.equations):
        e = eq.expr
        if isinstance(e, (And, Or)) and len(e.args) > 1:
            for i in range(len(e.args)):
                rest = e.args[:i] + e.args[i + 1:]
                new = rest[0] if len(rest) == 1 else dataclasses.replace(e, args=rest)
                equations = f.equations[:k] + (dataclasses.replace(eq, expr=new),) + f.equations[k + 1:]
                out.append((Mutant(f"drop-term:{eq.output}:{i + 1}", Operator.DROP_TERM,
                                   f"equation {eq.output} = {new.text()} (without {e.args[i].text()})", eq.loc),
                            dataclasses.replace(f, equations=equations)))
    return out


def _pick(mutants: list[tuple[Mutant, M]], ident: str, what: str) -> M:
    for m, model in mutants:
        if m.id == ident:
            return model
    raise SynthError(f"no mutant {ident!r} of {what}")


def grafcet_mutant(g: Grafcet, ident: str) -> Grafcet:
    """The mutant of ``g`` with id ``ident``."""
    return _pick(grafcet_mutants(g), ident, g.path)


def filter_mutant(f: Filter, ident: str) -> Filter:
    """The mutant of ``f`` with id ``ident``."""
    return _pick(filter_mutants(f), ident, f.file)


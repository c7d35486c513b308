"""``synth filter check --plant P.rules``: the valuations the filter can read on this plant,
whatever the control, as ``assume`` lines; the coherence is then judged on them (issue 23).

P1-P4 are properties of the constraints over every valuation of what the filter reads
(its inputs, observers and past values). Many of those valuations never occur on the
machine (a cylinder at both ends). The plant, driven by *any* control (every order may
change at any time, every sensor reaction may follow), reaches a set of states; projected on
the filter's variables this is a sound over-approximation of what the filter will read,
with or without the filter in the loop. Its complement, written as a cover of cubes, gives
one ``assume !(…)`` per cube: lines a user can paste into the ``.filter`` file.

What is read from a plant state: a filter input or output ``x`` is the plant variable ``x``;
a past output ``o^-1`` is the plant's actuator ``o`` (the order written at the previous
cycle, which the plant holds). Past inputs and observers are left free (no invariant
mentions them).

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.filter.language_check import parse_filter
>>> f = parse_filter("inputs v10, v11\\noutputs AVANCER1\\n"
...                  "safety OUT: v11 & AVANCER1\\nsafety IN: v10 & !AVANCER1", "cyl.filter")
>>> print(invariants(f, _plants("tri.rules")).text(), end="")
invariants of ... under any control: 62208 reachable plant states, 6 of the 8 valuations of v10, v11, AVANCER1^-1:
assume !(v10 & v11)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from synth.errors import InputError, LimitExceeded, close_names
from synth.filter.language import Assumption, Filter
from synth.filter.model import functions
from synth.logic.expr import And, Expr, Not, Var
from synth.logic.past import base_name, pre_name

if TYPE_CHECKING:
    from synth.plant.composition import Plant

__all__ = ["Invariants", "invariants", "assumed"]

PLANT_LIMIT = 50_000_000
"""Plants up to this many states are explored (a bit per state)."""


@dataclass(frozen=True)
class Invariants:
    """The plant's reachable states under any control, seen through the filter's variables."""

    rules: str
    states: int  # reachable plant states
    variables: tuple[str, ...]  # the filter's variables read from a plant state
    valuations: int  # distinct valuations of ``variables`` over the reachable states
    excluded: tuple[Expr, ...]  # one conjunction per cube never read: ``assume !(cube)``

    @property
    def lines(self) -> tuple[str, ...]:
        """The ``assume`` lines, as the ``.filter`` language writes them."""
        return tuple(f"assume {_negated(c)}" for c in self.excluded)

    def text(self) -> str:
        head = (f"invariants of {self.rules} under any control: {self.states} reachable plant states, "
                f"{self.valuations} of the {2 ** len(self.variables)} valuations of "
                f"{', '.join(self.variables) or 'nothing'}")
        return "\n".join([head + (":" if self.lines else ": none excluded"), *self.lines]) + "\n"


def _negated(c: Expr) -> str:
    return f"!{c.text()}" if isinstance(c, Var) else f"!({c.text()})"


def _conjunction(cube: tuple[tuple[str, bool], ...]) -> Expr:
    literals: list[Expr] = [Var(n) if v else Not(Var(n)) for n, v in cube]
    return literals[0] if len(literals) == 1 else And(tuple(literals))


def _reachable(p: Plant) -> np.ndarray:
    """Every plant state reachable from the initial one by any event (any control): a flat
    boolean array, by whole-grid images per local transition until nothing is added."""
    grid = np.zeros(p.shape, dtype=bool)
    grid.flat[p.initial_index] = True
    slices = [(*p.slices(t), p.guard_grid(t)) for t in p.transitions]  # guards: elements that read others
    while True:
        before = int(np.count_nonzero(grid))
        for s, d, g in slices:
            grid[d] |= grid[s] & g
        if int(np.count_nonzero(grid)) == before:
            return grid.ravel()


def invariants(f: Filter, rules_path: str) -> Invariants:
    """The :class:`Invariants` of ``f`` on the plant of ``rules_path``."""
    from synth.plant.composition import plant
    from synth.plant.rules_check import load_rules

    p = plant(load_rules(rules_path))
    for kind, declared in (("input", f.inputs), ("output", f.outputs)):
        for n in declared:
            if n not in p.variables:
                raise InputError(f"the filter's {kind} {n} is not a variable of the plant {rules_path}",
                                 next((d.loc for d in f.declarations if d.name == n), None),
                                 expected=close_names(n, p.variables) or tuple(p.variables))
    if p.size > PLANT_LIMIT:
        raise LimitExceeded(f"the plant of {rules_path} has {p.size} states; the invariants are computed up to "
                            f"{PLANT_LIMIT}")
    m = functions(f)
    e = m.engine
    readable = {*f.inputs, *(pre_name(o) for o in f.outputs)}
    variables = tuple(n for n in e.names if n in readable)
    reach = _reachable(p)
    codes = np.zeros(int(np.count_nonzero(reach)), dtype=np.int64)
    for i, n in enumerate(variables):
        column = np.broadcast_to(p.values(base_name(n)), p.shape).ravel()[reach]
        codes |= column.astype(np.int64) << i
    seen = np.unique(codes)
    read = e.disjunction(e.cube({n: bool((int(c) >> i) & 1) for i, n in enumerate(variables)}) for c in seen)
    excluded = tuple(_conjunction(tuple(cube.items())) for cube in e.cover(~read))
    return Invariants(rules_path, int(np.count_nonzero(reach)), variables, len(seen), excluded)


def assumed(f: Filter, inv: Invariants) -> Filter:
    """``f`` with the invariants' ``assume`` lines added after its own."""
    extra = tuple(Assumption(Not(c)) for c in inv.excluded)
    return dataclasses.replace(f, assumptions=f.assumptions + extra)

"""Element automata: the boolean-state automaton of one plant element (docs/method.md, plant).

Construction (thesis lines 2470-2520), state-based reading of the rules:

1. all 2^n vectors of the element's variables;
2. remove the incoherent ones (and those where a held order has the other value);
3. every state gets one controllable transition per (non-held) order: toggle it;
4. uncontrollable transitions: a rule ``cause [guard] -> consequence`` enables its
   consequence in every state where the cause's order has its post-edge value, the
   guard holds, the consequence can happen and the target is coherent; a precedence
   ``cause: u1 < u2`` adds "u1's effect already holds" to u2's condition. Free inputs
   may change at any time.

Only the states reachable from the initial state are kept.

An element that ``reads`` other elements' variables has them as extra bits while its
masks are computed; its own automaton over-approximates them (a move exists when some
value of the read variables allows it), and ``guards[t]`` keeps, per code of the read
variables (bit j = ``reads[j]``), whether transition ``t`` is enabled: the product
evaluates it with the other elements' actual values.

Example
-------
>>> from synth.plant.rules_check import parse_rules
>>> from synth.plant.library import library_dir
>>> rs = parse_rules(open(library_dir() / "double_acting.rules").read() +
...     "element V1 = double_acting(AVANCER=AVANCER1, RECULER=RECULER1, v0=v10, v1=v11)")
>>> a = element_automaton(rs.elements[0])
>>> a.size, a.count(controllable=True), a.count(controllable=False)
(12, 24, 12)
"""

from __future__ import annotations

from functools import cached_property
from typing import Iterable

import numpy as np

from synth.errors import InputError, Severity
from synth.frozen import frozen
from synth.logic.events import Event
from synth.logic.expr import evaluate
from synth.plant.rules import ElementSpec, VarKind

__all__ = ["ElementAutomaton", "element_automaton"]

MAX_ELEMENT_VARIABLES = 20



def distinct(a: np.ndarray) -> np.ndarray:
    """``np.unique(a)`` for an integer array, by sorting: ``np.unique`` asks whether its
    argument is a masked array, which imports ``numpy.ma`` (25 ms of every start)."""
    a = np.sort(a)
    return a[np.concatenate(([True], a[1:] != a[:-1]))] if a.size else a

@frozen(eq=False)
class ElementAutomaton:
    """States are codes over the element's variables (bit i = ``variables[i]``).

    ``codes[k]`` is the code of local state ``k`` (sorted ascending); transitions are
    parallel arrays ``src``, ``dst`` (local state indices), ``var`` (index of the
    variable that flips), ``controllable``.
    """

    name: str
    variables: tuple[str, ...]
    orders: frozenset[str]
    codes: np.ndarray
    initial: int
    src: np.ndarray
    dst: np.ndarray
    var: np.ndarray
    controllable: np.ndarray
    spec: ElementSpec
    warnings: tuple[InputError, ...] = ()
    reads: tuple[str, ...] = ()
    guards: np.ndarray | None = None  # (transitions × 2^len(reads)) booleans, None without reads

    @property
    def size(self) -> int:
        return int(self.codes.size)

    def count(self, controllable: bool | None = None) -> int:
        if controllable is None:
            return int(self.src.size)
        return int(np.count_nonzero(self.controllable == controllable))

    def value(self, name: str) -> np.ndarray:
        """Boolean array over local states: the value of variable ``name``."""
        i = self.variables.index(name)
        return ((self.codes >> i) & 1).astype(bool)

    def event(self, t: int) -> Event:
        """Transition ``t``'s event, ``↑x`` or ``↓x`` (rising iff the target has x=1)."""
        i = int(self.var[t])
        rising = bool((self.codes[self.dst[t]] >> i) & 1)
        return Event.edge(self.variables[i], rising)

    def guard(self, t: int) -> tuple[bool, ...] | None:
        """Transition ``t``'s condition on the variables it reads, as a truth table over
        their codes (bit j = ``reads[j]``); None when it does not depend on them."""
        if self.guards is None or bool(self.guards[t].all()):
            return None
        return tuple(bool(x) for x in self.guards[t])

    def events(self) -> list[Event]:
        return [self.event(t) for t in range(self.src.size)]

    def true_variables(self, k: int) -> tuple[str, ...]:
        code = int(self.codes[k])
        return tuple(v for i, v in enumerate(self.variables) if (code >> i) & 1)

    def state_label(self, k: int) -> str:
        return "{" + ",".join(self.true_variables(k)) + "}"

    @cached_property
    def _uncontrollable(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The uncontrollable moves as two sparse adjacency lists: (targets by source: indptr,
        targets), (sources by target: indptr, sources), and the moves' sources and targets."""
        u = ~self.controllable
        src, dst = self.src[u].astype(np.int64), self.dst[u].astype(np.int64)
        by_src, by_dst = np.argsort(src, kind="stable"), np.argsort(dst, kind="stable")
        n = self.size
        out_ptr = np.searchsorted(src[by_src], np.arange(n + 1))
        in_ptr = np.searchsorted(dst[by_dst], np.arange(n + 1))
        return out_ptr, dst[by_src], in_ptr, src[by_dst], src, dst

    @staticmethod
    def _closure(start: np.ndarray, ptr: np.ndarray, nbr: np.ndarray) -> np.ndarray:
        """The states reached from ``start`` (a boolean mask) along the adjacency lists: one
        pass per frontier, linear in the moves explored (no dense n x n matrix)."""
        reach = start.astype(bool).copy()
        frontier = np.nonzero(reach)[0]
        while frontier.size:
            lo, hi = ptr[frontier], ptr[frontier + 1]
            counts = hi - lo
            if not counts.sum():
                break
            idx = np.repeat(lo - np.concatenate(([0], np.cumsum(counts)[:-1])), counts) + np.arange(counts.sum())
            found = distinct(nbr[idx])
            frontier = found[~reach[found]]
            reach[frontier] = True
        return reach

    def can_reach(self, mask: np.ndarray) -> np.ndarray:
        """The local states from which a state of ``mask`` is reachable by the element's own
        uncontrollable moves (``mask`` included)."""
        _, _, in_ptr, sources, _, _ = self._uncontrollable
        return self._closure(np.asarray(mask, dtype=bool), in_ptr, sources)

    def reachable_from(self, k: int) -> np.ndarray:
        """The local states the element reaches from ``k`` by its own uncontrollable moves (``k`` included)."""
        found = self._reached.get(k)
        if found is None:
            out_ptr, targets, _, _, _, _ = self._uncontrollable
            start = np.zeros(self.size, dtype=bool)
            start[k] = True
            found = self._reached[k] = self._closure(start, out_ptr, targets)
        return found

    @cached_property
    def _reached(self) -> dict[int, np.ndarray]:
        return {}

    def is_true(self, k: int, name: str) -> bool:
        """Value of variable ``name`` in local state ``k``."""
        return bool((int(self.codes[k]) >> self.variables.index(name)) & 1)

    def flipped(self, k: int, names: Iterable[str]) -> int | None:
        """The local state equal to ``k`` but for ``names`` flipped, if it is a state
        of the element (incoherent codes are not)."""
        code = int(self.codes[k])
        for name in names:
            code ^= 1 << self.variables.index(name)
        j = int(np.searchsorted(self.codes, code))
        return j if j < self.size and int(self.codes[j]) == code else None

    def drift(self, k: int) -> tuple[Event, ...]:
        """Events the element can do from ``k`` on its own (uncontrollable moves only), sorted."""
        reach = self.reachable_from(k)
        return tuple(sorted({self.event(t) for t in range(self.src.size)
                             if not self.controllable[t] and reach[int(self.src[t])]}))

    def produces(self, k: int, event: Event) -> bool:
        """``event`` can occur from ``k`` without any order change (uncontrollable moves)."""
        return event in self.drift(k)


def element_automaton(e: ElementSpec) -> ElementAutomaton:
    """Build the automaton of element ``e`` (see module docstring): vectorised over every
    code of the element's variables and of the variables it reads (at most 2^20 in all),
    then a breadth-first search from the initial state, one frontier at a time."""
    names = tuple(v.name for v in e.variables)
    reads = e.read_names
    n, r = len(names), len(reads)
    if n + r > MAX_ELEMENT_VARIABLES:
        what = f"{n} variables" + (f" and reads {r}" if r else "")
        raise InputError(f"element {e.name} has {what}; at most {MAX_ELEMENT_VARIABLES} are supported", e.loc)
    index = {v: i for i, v in enumerate(names + reads)}
    every = np.arange(1 << (n + r), dtype=np.int64)  # bit i < n: own variable i; bit n + j: reads[j]
    bits = [((every >> i) & 1).astype(bool) for i in range(n + r)]

    def val(name: str) -> np.ndarray:
        return bits[index[name]]

    def everywhere(x: object) -> np.ndarray:
        return np.broadcast_to(np.asarray(x, dtype=bool), every.shape)

    def own(mask: np.ndarray) -> np.ndarray:
        """A mask over own codes: some value of the read variables satisfies ``mask``."""
        return np.asarray(mask.reshape(1 << r, 1 << n).any(axis=0), dtype=bool)

    coherent = np.ones(1 << n, dtype=bool)  # incoherences and held orders speak of own variables only
    for v in e.variables:
        if v.held:
            coherent &= bits[index[v.name]][: 1 << n] == v.initial
    for inc in e.incoherences:
        coherent &= ~everywhere(evaluate(inc, val))[: 1 << n]

    # per variable: the codes where it may flip, and per rule the codes where that rule makes it flip
    rule_masks: dict[int, np.ndarray] = {}
    flips: list[tuple[int, bool, np.ndarray]] = []
    for v in e.variables:
        i = index[v.name]
        if v.kind == VarKind.ORDER:
            if not v.held:
                flips.append((i, True, everywhere(True)))
            continue
        if v.kind is VarKind.FREE:
            flips.append((i, False, everywhere(True)))
            continue
        enabled = np.zeros(every.size, dtype=bool)
        for k, rule in enumerate(e.rules):
            if rule.consequence.name != v.name:
                continue
            mask = (bits[i] != rule.consequence.rising) & (bits[index[rule.cause.name]] == rule.cause.rising)
            if rule.guard is not None:
                mask &= everywhere(evaluate(rule.guard, val))
            for p in e.precedences:
                if p.cause == rule.cause and p.then == rule.consequence:
                    mask &= bits[index[p.first.name]] == p.first.rising
            rule_masks[k] = own(mask)
            enabled |= mask
        flips.append((i, False, enabled))
    local_flips = [(i, ctrl, own(mask)) for i, ctrl, mask in flips]

    init = sum(1 << index[v.name] for v in e.variables if v.initial)
    if not coherent[init]:  # caught with a location by the rules checker; defensive here
        raise InputError(f"the initial state of element {e.name} is incoherent", e.loc)
    seen_mask = np.zeros(1 << n, dtype=bool)
    seen_mask[init] = True
    frontier = np.array([init], dtype=np.int64)
    while frontier.size:
        found = []
        for i, _, mask in local_flips:
            src = frontier[mask[frontier]]
            dst = src ^ (1 << i)
            found.append(dst[coherent[dst]])
        new = distinct(np.concatenate(found)) if found else frontier[:0]
        frontier = new[~seen_mask[new]]
        seen_mask[frontier] = True
    codes = np.nonzero(seen_mask)[0].astype(np.int64)  # the reachable codes, sorted: state k is codes[k]
    parts = []
    tables = []
    for (i, ctrl, mask), (_, _, full) in zip(local_flips, flips):
        src = codes[mask[codes]]
        dst = src ^ (1 << i)
        ok = coherent[dst]
        parts.append((src[ok], dst[ok], np.full(int(ok.sum()), i, dtype=np.int64), np.full(int(ok.sum()), ctrl)))
        if r:
            tables.append(np.broadcast_to(full, every.shape).reshape(1 << r, 1 << n)[:, src[ok]].T)
    src_pos = np.searchsorted(codes, np.concatenate([p[0] for p in parts]))
    dst_pos = np.searchsorted(codes, np.concatenate([p[1] for p in parts]))
    var = np.concatenate([p[2] for p in parts])
    ctrl_arr = np.concatenate([p[3] for p in parts]).astype(bool)
    order = np.lexsort((dst_pos, var, src_pos))  # by source, then variable, then target
    guards = np.concatenate(tables)[order] if r else None
    applied = {k for k, mask in rule_masks.items()
               if (mask[codes] & coherent[codes ^ (1 << index[e.rules[k].consequence.name])]).any()}
    held = {v.name: v.initial for v in e.variables if v.held}  # a rule caused by the other edge never applies, by design
    return ElementAutomaton(
        name=e.name,
        variables=names,
        orders=frozenset(v.name for v in e.variables if v.kind == VarKind.ORDER),
        codes=codes,
        initial=int(np.searchsorted(codes, init)),
        src=src_pos[order].astype(np.int64),
        dst=dst_pos[order].astype(np.int64),
        var=var[order],
        controllable=ctrl_arr[order],
        spec=e,
        warnings=tuple(
            InputError(
                f"rule {rule.text()} of element {e.name} never applies in any reachable state",
                rule.loc,
                notes=("its guard, a precedence or the incoherences rule it out everywhere: the element will never "
                       f"produce {rule.consequence.text()} this way",),
                severity=Severity.WARNING,
            )
            for k, rule in enumerate(e.rules)
            if k not in applied and not (held.get(rule.cause.name) is not None and held[rule.cause.name] != rule.cause.rising)
        ),
        reads=reads,
        guards=guards,
    )

"""One PLC cycle of ``synth filter verify --any-control`` as BDDs, for the symbolic engine
(:mod:`synth.filter.loop.symbolic.rings`): the same cycle as :mod:`synth.filter.loop.verify`
(its docstring gives the semantics), with the filter's outputs, its memory after the
cycle and its flags as functions of the plant state after the plant's events, the
memory before and the free requests, and the ordered write (falls first, then rises,
each in the plant's output order) as functions of that state and the target orders.

Variables, in one manager (the plant's :class:`~synth.symbolic.encoding.PlantEncoding`):

- the plant's variables ``x`` (current copy: a node's state, or the state after the
  plant's events), ``x'`` (next copy; for an order ``z``, ``z'`` is the order the PLC
  writes: the *target*) and ``x''`` (the node's state while the plant's events run);
- the filter memory: ``n^-1`` for every name ``n`` whose past value the filter reads,
  and ``n^-1'`` after the cycle; ``?Blocked`` / ``?Blocked'`` in blocking mode;
- the free inputs of one cycle (existentially quantified): the filter's requests
  ``R_o``, a passed-through order's request ``?R_z``, ``?Ack``;
- the outcome's flags ``?fallback`` and ``?outside``.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.filter.from_rules import skeleton
>>> sk = skeleton(_plants("tri.rules"), _plants("F.filter"))  # the text only: nothing is written
>>> from synth.plant.composition import plant
>>> from synth.plant.rules_check import load_rules
>>> rs = load_rules(_plants("tri.rules"))
>>> c = SymbolicCycle(sk.filter, rs, plant(rs), Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False)
>>> c.outcome != c.engine.false, c.refused != c.engine.true
(True, True)
"""

from __future__ import annotations

import copy
from typing import Callable, Iterable, Mapping

import numpy as np

from synth.errors import InputError, LimitExceeded
from synth.filter.cycle import Algorithm, Cover, FilterCycle, Mode
from synth.filter.language import Filter
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.logic.past import base_name, is_pre, pre_name
from synth.plant.composition import Plant
from synth.plant.rules import RuleSet
from synth.sup.constraints import split_terms
from synth.symbolic.encoding import Copy, PlantEncoding
from synth.symbolic.relation import Move, plant_moves, preimage

__all__ = ["SymbolicCycle", "BLOCKED", "FALLBACK", "OUTSIDE", "next_name"]

BLOCKED = "?Blocked"
FALLBACK = "?fallback"
OUTSIDE = "?outside"
ACK_VAR = "?Ack"


def next_name(n: str) -> str:
    """The name of a memory variable after the cycle."""
    return n + Copy.NEXT.value


def cover_function(cover: Cover, env: Mapping[str, Function], false: Function, true: Function) -> Function:
    """An OR of cubes with every name read from ``env``."""
    out = false
    for cube in cover:
        term = true
        for n, v in cube:
            term = term & (env[n] if v else ~env[n])
        out = out | term
    return out


def check_filter(f: Filter, p: Plant, rules_path: str) -> None:
    """The checks of :class:`~synth.filter.loop.product.Product` that do not need its arrays."""
    for kind, names, have in (("input", f.inputs, p.inputs), ("output", f.outputs, p.outputs)):
        missing = [n for n in names if n not in have]
        if missing:
            raise InputError(f"{f.file}: the filter's {kind} {', '.join(missing)} is not an "
                             f"{kind} of the plant {rules_path}", None)
    for d in f.observers:
        if d.definition is None:
            raise InputError(f"observer {d.name} has no value in verify: define it (`observer {d.name} := "
                             "EXPR`) or make it a step variable of the --grafcet Grafcet", d.loc)


def _without_reads(p: Plant) -> Plant:
    """``p`` for :class:`PlantEncoding`, which refuses elements reading each other's
    variables (the symbolic validation does not support them); here its variables and states
    serve, and :func:`~synth.symbolic.relation.plant_moves` encodes the guards."""
    if not p.reads:
        return p
    q = copy.copy(p)
    q.__dict__["reads"] = False  # the cached property, for this copy only
    return q


class SymbolicCycle:
    """The BDDs of one cycle (module docstring): ``outcome`` relates (post state ``x``,
    memory) to (targets ``z'``, memory after, flags); ``refused``, ``edge_bad`` and
    ``middle_bad`` are over (``x``, targets)."""

    def __init__(self, f: Filter, rs: RuleSet, p: Plant, algorithm: Algorithm, mode: Mode, atomic: bool) -> None:
        check_filter(f, p, rs.path)
        self.plant, self.rules, self.atomic = p, rs, atomic
        self.cycle = cyc = FilterCycle(f, algorithm, mode)
        if cyc.plan is not None:
            raise LimitExceeded(f"{f.file}: the filter is its chain of narrowings on truth tables (too large for "
                                "equations): filter verify runs it on the explicit engine only (--engine explicit)")
        self.enc = enc = PlantEncoding(_without_reads(p), constraints=rs.constraints)
        self.engine = e = enc.engine
        self.orders: tuple[str, ...] = p.outputs
        self.blocking = cyc.mode is Mode.BLOCKING
        self.memory: tuple[str, ...] = tuple(pre_name(n) for n in cyc.used)
        self.state_memory: tuple[str, ...] = self.memory + ((BLOCKED,) if self.blocking else ())
        self.passthrough = tuple(o for o in self.orders if o not in f.outputs)
        self.held = {v.name: v.initial for v in rs.variables if v.held}
        self.free = [r for o, r in zip(cyc.outputs, cyc.requests) if o not in self.held]
        self.free += [f"?R_{o}" for o in self.passthrough if o not in self.held]
        if self.blocking:
            self.free.append(ACK_VAR)
        self._order_variables()
        terms = split_terms(p, rs.constraints)
        self.illegal = self._terms(t.factors for t in terms if t.event is None)
        self.forbid: dict[str, Function] = {}
        for t in terms:
            if t.event is not None:
                self.forbid[t.event] = self.forbid.get(t.event, e.false) | self._terms([t.factors])
        self.moves: tuple[Move, ...] = plant_moves(enc)
        self.uncontrollable = tuple(m for m in self.moves if not m.controllable)
        self.removed = self.backward(self.illegal)
        self._by_constraint = terms
        self.outcome = self._outcome()
        self._write()

    # ------------------------------------------------------------------ variables
    def _order_variables(self) -> None:
        """Declare the memory and request variables next to the plant variable they copy
        (a previous input beside the input; an observer's previous value beside the last
        plant variable its definition reads: :meth:`_observer_places`), then reorder the
        manager once."""
        e, cyc = self.engine, self.cycle
        beside: dict[str, list[str]] = {}
        loose: list[str] = []
        request_of = dict(zip(cyc.requests, cyc.outputs))
        place = self._observer_places()
        for n, m in zip(cyc.used, self.memory):
            base = request_of.get(n, n)
            base = place.get(base, base)
            (beside.setdefault(base, []) if base in self.plant.owner else loose).extend([m, next_name(m)])
        for r in self.free:
            base = request_of.get(r, r[3:] if r.startswith("?R_") else "")
            (beside.setdefault(base, []) if base in self.plant.owner else loose).append(r)
        loose += [BLOCKED, next_name(BLOCKED)] if self.blocking else []
        loose += [FALLBACK, OUTSIDE]
        order: list[str] = []
        for n in e.variable_order:
            order.append(n)
            if n.endswith(Copy.AUX.value):
                order.extend(beside.get(n[: -len(Copy.AUX.value)], ()))
        order.extend(loose)
        for n in order:
            e.declare(n)
        if e.cudd:
            from dd import cudd

            cudd.reorder(e.bdd, {e.declare(n): i for i, n in enumerate(order)})

    def _observer_places(self) -> dict[str, str]:
        """Per observer defined from the plant's variables (directly, through their past
        values or through other observers): the one of them last in the variable order.
        Its memory goes there rather than after every plant variable, so that a ring of
        cylinders keeps each cylinder's observer with the cylinder (the ring of 10: 272 s
        grouped at the end, 12 s placed; docs/performance.md, session 27)."""
        position = {n: i for i, n in enumerate(self.engine.variable_order)}
        defined = dict(self.cycle.defined)

        def reads(n: str, seen: set[str]) -> set[str]:
            n = base_name(n) if is_pre(n) else n
            if n in self.plant.owner:
                return {n}
            if n in seen or n not in defined:
                return set()
            seen.add(n)
            return {v for cube in defined[n] for m, _ in cube for v in reads(m, seen)}

        places = {n: reads(n, set()) for n in defined}
        return {n: max(r, key=position.__getitem__) for n, r in places.items() if r}

    def _terms(self, terms: Iterable[Iterable[tuple[int, np.ndarray]]]) -> Function:
        """The union of product terms, each a tuple of (element, local states it allows)."""
        enc = self.enc
        out = self.engine.false
        for factors in terms:
            term = self.engine.true
            for axis, vec in factors:
                term &= self.engine.disjunction(enc.local_state(axis, int(k)) for k in vec.nonzero()[0])
            out |= term
        return out

    def constraint_terms(self) -> tuple[dict[str, Function], dict[str, dict[str, Function]]]:
        """Per constraint id: its level terms; per output event, per id: its edge terms."""
        level: dict[str, Function] = {}
        edge: dict[str, dict[str, Function]] = {}
        for t in self._by_constraint:
            u = self._terms([t.factors])
            if t.event is None:
                level[t.constraint] = level.get(t.constraint, self.engine.false) | u
            else:
                at = edge.setdefault(t.event, {})
                at[t.constraint] = at.get(t.constraint, self.engine.false) | u
        return level, edge

    def backward(self, target: Function) -> Function:
        """The states from which uncontrollable events lead into ``target`` (SUP's
        *removed* states when ``target`` is the illegal ones)."""
        reach, frontier = target, target
        while frontier != self.engine.false:
            frontier = self.engine.disjunction(preimage(self.enc, frontier, m) for m in self.uncontrollable) & ~reach
            reach |= frontier
        return reach

    # ------------------------------------------------------------------ the filter
    def _outcome(self) -> Function:
        """∃ requests: targets, memory after and flags, as in :meth:`FilterCycle.lanes`."""
        e, cyc = self.engine, self.cycle
        T, F = e.true, e.false

        def ev(cover: Cover, env: Mapping[str, Function]) -> Function:
            return cover_function(cover, env, F, T)

        values: dict[str, Function] = {y: e.var(y) for y in cyc.filter.inputs}
        for o, r in zip(cyc.outputs, cyc.requests):
            values[r] = (T if self.held[o] else F) if o in self.held else e.var(r)
        if self.blocking:
            values["Ack"] = e.var(ACK_VAR)
        for n in cyc.remembered:
            values[pre_name(n)] = e.var(pre_name(n)) if n in cyc.used else F
        for n, cover in cyc.defined:
            values[n] = ev(cover, values)
        requests = [values[r] for r in cyc.requests]
        with_requests = dict(values)
        with_requests.update(zip(cyc.outputs, requests))
        violated = e.disjunction(ev(c, with_requests) for c in cyc.constraint.values())
        g1 = requests
        blocked = F
        if self.blocking:
            blocked = (e.var(BLOCKED) & ~values["Ack"]) | violated
            g1 = [r & ~blocked for r in requests]
        fallback = outside = F
        if cyc.algorithm is Algorithm.ALGEBRAIC:
            with_g1 = dict(values)
            with_g1.update(zip(cyc.requests, g1))
            outside = ~ev(cyc.care, with_g1)
            for o, cover in cyc.equations:
                with_g1[o] = ev(cover, with_g1)
            outputs = [with_g1[o] for o in cyc.outputs]
        else:
            outputs, fallback = self._loop(values, g1, ev)
        with_outputs = dict(values)
        with_outputs.update(zip(cyc.outputs, outputs))
        out_of = dict(zip(cyc.outputs, outputs))
        rel = (e.var(FALLBACK).equiv(fallback)) & (e.var(OUTSIDE).equiv(outside))
        for z in self.orders:
            target = out_of[z] if z in out_of else (
                (T if self.held[z] else F) if z in self.held else e.var(f"?R_{z}"))
            rel &= e.var(z + Copy.NEXT.value).equiv(target)
        for n, m in zip(cyc.used, self.memory):
            rel &= e.var(next_name(m)).equiv(with_outputs[n])
        if self.blocking:
            rel &= e.var(next_name(BLOCKED)).equiv(blocked)
        self.relation: Function = rel  # with the requests: a trace's witness
        return e.exists(self.free, rel)

    def _loop(self, values: dict[str, Function], g1: list[Function],
              ev: Callable[[Cover, Mapping[str, Function]], Function]) -> tuple[list[Function], Function]:
        """The correction loop of :meth:`FilterCycle._loop` (not the literal one), lane by
        lane as functions: ``flag`` is where the loop still iterates."""
        e, cyc = self.engine, self.cycle
        T, F = e.true, e.false
        outs = cyc.outputs
        fs0 = [ev(cyc.fs0[o], values) for o in outs]
        fs1 = [ev(cyc.fs1[o], values) for o in outs]
        fc0, fc1 = [F] * len(outs), [F] * len(outs)
        flag, cpt, ncsc = T, 0, len(cyc.combined)
        si: list[Function] = [F] * len(outs)
        while flag != F and cpt <= ncsc:
            new = [(~fs0[k] & ((~fc0[k] & g1[k]) | fc1[k])) | fs1[k] for k in range(len(outs))]
            si = [(n & flag) | (s & ~flag) for n, s in zip(new, si)]
            at = dict(values)
            at.update(zip(outs, si))
            v = {i: ev(cyc.constraint[i], at) & flag for i in cyc.combined}
            cpt += 1
            for k, o in enumerate(outs):
                for i in cyc.mc0[o]:
                    fc0[k] |= v[i]
                for i in cyc.mc1[o]:
                    fc1[k] |= v[i]
            flag = e.disjunction(v.values())
        if flag != F:
            si = [((~fs0[k] & fs1[k]) & flag) | (si[k] & ~flag) for k in range(len(outs))]
        return si, flag

    # ------------------------------------------------------------------ the write
    def _write(self) -> None:
        """``refused``, ``edge_bad`` and ``middle_bad`` over (``x``, targets ``z'``), as
        :meth:`~synth.filter.loop.explorer.Explorer.write` applies the changed orders."""
        e = self.engine
        F = e.false
        guard = {m.event: m.guard for m in self.moves if m.controllable}
        cur = {z: e.var(z) for z in self.orders}
        refused = edge_bad = middle = F
        for rising in (False, True):
            for z in self.orders:
                t = e.var(z + Copy.NEXT.value)
                attempted = (t & ~cur[z]) if rising else (~t & cur[z])
                if attempted == F:
                    continue
                ev = Event.edge(z, rising)
                here = dict(cur)
                if ev in self.forbid:
                    bad = self.forbid[ev] if self.atomic else e.let(here, self.forbid[ev])
                    edge_bad |= attempted & ~refused & bad
                ok = e.let(here, guard.get(ev, F))
                before = refused
                refused = refused | (attempted & ~ok)
                cur[z] = (cur[z] | t) if rising else (cur[z] & t)
                if not self.atomic:
                    middle |= attempted & ok & ~before & e.let(cur, self.illegal)
        self.refused: Function = refused
        self.edge_bad: Function = edge_bad
        final_illegal = e.let({z: e.var(z + Copy.NEXT.value) for z in self.orders}, self.illegal)
        self.violation: Function = ~refused & final_illegal
        self.middle_bad: Function = middle & ~self.violation & ~self.illegal

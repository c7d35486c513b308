"""The Grafcet's evolution on many situations at once: the same IEC 60848 reading as
:class:`~synth.grafcet.machine.GrafcetMachine`, with situations as rows of bits.

A row holds the active steps (``A``, one column per step in file order) and the
situation's memory (``T``: the elapsed timers, one column per timer of
``grafcet.timers``, then the outputs set by stored actions, one column per order of
:attr:`VectorMachine.stored_names`); the inputs are bit columns
(``I``, ``machine.inputs`` order) and the input event one integer per row (``E``: twice
the input's column, plus one for a rising edge; -1 for none). Receptivities and action
conditions become numpy Boolean expressions over those columns, and the search for
stability runs round after round on every row until none fires; a row still firing after
:data:`ROUNDS` rounds, or one where transitions leaving one step fire together (an OR
divergence's conflict, which the explorer must note with the rounds fired), is left to
the machine itself (``pending``).

Stored actions run as the machine runs them: those on an event before the first round
(on the rows whose event it is), those on deactivation and on activation in each round
(the deactivated steps' first, then the activated ones'; in each phase, sets first, then
resets). What the rows do not carry, the machine alone reads: internal variables,
assignments, ``--semantics sfc``; :func:`unsupported` names the first such feature of
a Grafcet (the explicit engine then explores with the machine, state by state).

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet('''grafcet G { initial step 0  step 1: A  step 2
...   transition 0 -> 1 when ↑a  transition 1 -> 2 when b  transition 2 -> 0 when 1 }''', "demo.g7")
>>> v = VectorMachine(GrafcetMachine(g))
>>> A, T = v.rows([v.machine.initial({"a": False, "b": False})] * 2)
>>> I = np.array([[True, False], [True, True]])
>>> A2, T2, moved, pending = v.react(A, T, I, np.array([1, 1]))
>>> [v.situation(a, t).text() for a, t in zip(A2, T2)], moved.tolist(), pending.tolist()
(['{X1}', '{X0}'], [True, True], [False, False])
>>> v.orders(A2, T2, I)[:, v.order_names.index("A")].tolist()
[True, False]
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from synth.grafcet.language import (CONDITIONAL, CONTINUOUS, ON_ACTIVATION, ON_DEACTIVATION, STORED, Semantics,
                                   StoredWhen, step_key, step_of)
from synth.grafcet.machine import GrafcetMachine
from synth.grafcet.situation import Situation
from synth.logic.expr import And, Compare, Edge, Expr, Not, Or, Var, evaluate, names

__all__ = ["VectorMachine", "unsupported", "ROUNDS"]

ROUNDS = 32
"""Rounds of the search for stability run on the rows; a row still evolving after them is
left to the machine (which finds the transient cycle, or the rest of a long evolution)."""

Columns = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""An expression over the columns: (I, A, T, E, zeros) -> one Boolean per row."""


def _names_outside(e: Expr, inputs: set[str], steps: set[str], timers: set[str]) -> str | None:
    """The first name of ``e`` that is neither a timer, a step variable nor an input."""
    if isinstance(e, Compare):
        return e.left
    if isinstance(e, Var):
        ok = e.name in timers or step_of(e.name, steps) is not None or e.name in inputs
        return None if ok else e.name
    if isinstance(e, Not):
        return _names_outside(e.arg, inputs, steps, timers)
    if isinstance(e, (And, Or)):
        return next((n for n in (_names_outside(a, inputs, steps, timers) for a in e.args) if n), None)
    return None


def unsupported(machine: GrafcetMachine) -> str | None:
    """Why :class:`VectorMachine` cannot run ``machine``'s Grafcet (the first feature it
    does not carry), or None when it can."""
    g = machine.grafcet
    if machine.sfc or g.semantics is not Semantics.GRAFCET:
        return "--semantics sfc (one evolution per scan)"
    if g.internals:
        return "internal variables"
    for s in g.steps:
        for a in s.actions:
            if a.kind not in (CONTINUOUS, CONDITIONAL, STORED):
                return f"{a.kind.value} actions (step {s.name}: {a.text()})"
    steps = {s.name for s in g.steps}
    timers = {t.id for t in g.timers}
    exprs = [t.receptivity for t in g.transitions]
    exprs += [a.condition for s in g.steps for a in s.actions if a.condition is not None]
    for e in exprs:
        name = _names_outside(e, set(machine.inputs), steps, timers)
        if name is not None:
            return f"'{name}' is neither an input, a step nor a timer"
    return None


class VectorMachine:
    """``machine``'s evolution over rows of bits (see module doc); build it only when
    :func:`unsupported` says None."""

    def __init__(self, machine: GrafcetMachine) -> None:
        self.machine = machine
        g = machine.grafcet
        self.step_names = tuple(s.name for s in g.steps)
        self.timer_names = tuple(t.id for t in g.timers)
        self._step = {s: i for i, s in enumerate(self.step_names)}
        self._timer = {t: i for i, t in enumerate(self.timer_names)}
        self._input = {n: i for i, n in enumerate(machine.inputs)}
        self.events: dict[str, int] = {}  # edge text -> E code
        for n, i in self._input.items():
            self.events[Edge(False, n).text()] = 2 * i
            self.events[Edge(True, n).text()] = 2 * i + 1
        trans = machine.transitions
        # which steps each transition leaves and enters, as lists (_Lists): a round marks the
        # steps of its firing pairs only (a product of matrices would multiply integers in
        # a plain loop, floats through a BLAS whose threads spend CPU on a shared machine)
        src = np.zeros((len(trans), len(self.step_names)), dtype=bool)
        dst = np.zeros_like(src)
        for j, t in enumerate(trans):
            src[j, [self._step[s] for s in t.sources]] = 1
            dst[j, [self._step[s] for s in t.targets]] = 1
        # each transition's first source step (a sourceless one reads the column of ones
        # after the steps), and its further sources: which transitions are enabled, read in
        # one gather for all of them
        self._first_source = np.array([self._step[t.sources[0]] if t.sources else len(self.step_names)
                                       for t in trans], dtype=np.int64)
        self._sourceless = any(not t.sources for t in trans)
        # the k-th further source of every transition that has one, one pass per k
        self._more_sources = [(np.array([j for j, t in enumerate(trans) if len(t.sources) > k], dtype=np.int64),
                               np.array([self._step[t.sources[k]] for t in trans if len(t.sources) > k], dtype=np.int64))
                              for k in range(1, max((len(t.sources) for t in trans), default=0))]
        self.stored_names = tuple(sorted({a.order for s in g.steps for a in s.actions if a.kind == STORED}))
        nt = len(self.timer_names)
        self.memory = nt + len(self.stored_names)
        """The columns of ``T``: the timers, then the stored outputs."""
        timers_of = np.zeros((len(self.step_names), self.memory), dtype=bool)
        for timer in g.timers:
            timers_of[self._step[timer.step], self._timer[timer.id]] = 1
        # per phase, the stored outputs each step's actions set and reset (T's columns)
        sets = {when: np.zeros_like(timers_of) for when in (ON_DEACTIVATION, ON_ACTIVATION)}
        resets = {when: np.zeros_like(timers_of) for when in (ON_DEACTIVATION, ON_ACTIVATION)}
        self._on_event: list[tuple[int, int, bool, Columns]] = []  # step, T's column, set, condition
        for s in g.steps:
            for a in s.actions:
                col = nt + self.stored_names.index(a.order) if a.kind == STORED else -1
                if a.kind == STORED and a.when in sets:
                    (sets if a.value else resets)[a.when][self._step[s.name], col] = True
                elif a.kind == STORED and a.condition is not None:
                    self._on_event.append((self._step[s.name], col, a.value, self._compile(a.condition)))
        self._sources_of, self._targets_of = _Lists(src), _Lists(dst)
        self._shared = bool((src.sum(axis=0) > 1).any())  # a step two transitions leave: firing both is a conflict
        self._timer_cols = _Lists(timers_of)
        self._sets = {when: _Lists(m) for when, m in sets.items() if m.any()}
        self._resets = {when: _Lists(m) for when, m in resets.items() if m.any()}
        self._rec = [self._compile(t.receptivity) for t in trans]
        orders: dict[str, None] = {}
        self._actions: list[tuple[int, str, Columns | None]] = []
        for s in g.steps:
            for a in s.actions:
                orders[a.order] = None
                if a.kind in (CONTINUOUS, CONDITIONAL):
                    cond = self._compile(a.condition) if a.kind == CONDITIONAL and a.condition is not None else None
                    self._actions.append((self._step[s.name], a.order, cond))
        self.order_names = tuple(sorted(orders))
        self.conditional = any(cond is not None for _, _, cond in self._actions)
        """Whether some action has a condition (the orders then read the inputs)."""
        self._order = {o: i for i, o in enumerate(self.order_names)}
        self._stored_cols = [(nt + i, self._order[o]) for i, o in enumerate(self.stored_names)]
        self._sorted: tuple[np.ndarray, tuple[str, ...], np.ndarray, tuple[str, ...]] | None = None  # situation()

    # ------------------------------------------------------------------ compilation
    def _compile(self, e: Expr) -> Columns:
        """``e`` on whole columns: the one expression walker (:func:`~synth.logic.expr.evaluate`,
        which takes numpy arrays), its names resolved to columns once here."""
        where: dict[str, tuple[str, int]] = {}
        for n in names(e):
            if isinstance(n, Var):  # Compare is refused by unsupported()
                step = step_of(n.name, set(self._step))
                where[n.name] = (("T", self._timer[n.name]) if n.name in self._timer
                                 else ("A", self._step[step]) if step is not None else ("I", self._input[n.name]))
        events = {n.text(): self.events.get(n.text(), -2) for n in names(e) if isinstance(n, Edge)}

        def fn(I: np.ndarray, A: np.ndarray, T: np.ndarray, E: np.ndarray, Z: np.ndarray) -> np.ndarray:
            table = {"I": I, "A": A, "T": T}

            def value(name: str) -> np.ndarray:
                kind, k = where[name]
                return table[kind][:, k]

            out = evaluate(e, value, lambda x: E == events[x.text()])
            return out if isinstance(out, np.ndarray) else (~Z if out else Z)

        return fn

    # ------------------------------------------------------------------ situations as rows
    def rows(self, sits: list[Situation]) -> tuple[np.ndarray, np.ndarray]:
        """The bits (A, T) of ``sits``."""
        A = np.zeros((len(sits), len(self.step_names)), dtype=bool)
        T = np.zeros((len(sits), self.memory), dtype=bool)
        nt = len(self.timer_names)
        for r, s in enumerate(sits):
            A[r, [self._step[x] for x in s.steps]] = True
            T[r, [self._timer[x] for x in s.elapsed]] = True
            T[r, [nt + self.stored_names.index(o) for o in s.stored]] = True
        return A, T

    def situation(self, a: np.ndarray, t: np.ndarray) -> Situation:
        """The situation of one row, as the machine builds it (steps, stored outputs and
        timers in their sorted orders: the columns read in those orders)."""
        return self.situations(a[None, :], t[None, :])[0]

    def situations(self, A: np.ndarray, T: np.ndarray) -> list[Situation]:
        """:meth:`situation` of each row, the rows' columns read in one pass each."""
        if self._sorted is None:
            steps = sorted(range(len(self.step_names)), key=lambda i: step_key(self.step_names[i]))
            nt = len(self.timer_names)
            timers = sorted(range(nt), key=lambda i: self.timer_names[i])
            self._sorted = (np.array(steps, dtype=np.int64), tuple(self.step_names[i] for i in steps),
                            np.array(timers, dtype=np.int64), tuple(self.timer_names[i] for i in timers))
        steps_at, step_names, timers_at, timer_names = self._sorted
        nt = len(self.timer_names)

        def named(bits: np.ndarray, labels: tuple[str, ...]) -> list[list[str]]:  # each row's true columns, in order
            out: list[list[str]] = [[] for _ in range(len(bits))]
            rows, cols = bits.nonzero()
            for r, c in zip(rows.tolist(), cols.tolist()):
                out[r].append(labels[c])
            return out

        return [Situation(tuple(s), tuple(o), tuple(e), ()) for s, o, e in  # the stored outputs' names are sorted
                zip(named(A[:, steps_at], step_names), named(T[:, nt:], self.stored_names), named(T[:, timers_at], timer_names))]

    # ------------------------------------------------------------------ evolution
    def _fireable(self, A: np.ndarray, T: np.ndarray, I: np.ndarray, E: np.ndarray) -> np.ndarray:
        A, T, I = np.asfortranarray(A), np.asfortranarray(T), np.asfortranarray(I)
        n = len(A)
        Z = np.zeros(n, dtype=bool)
        steps = np.hstack([A, np.ones((n, 1), dtype=bool)]) if self._sourceless else A
        out = np.asfortranarray(steps[:, self._first_source])  # the transitions enabled
        for cols, further in self._more_sources:
            out[:, cols] &= A[:, further]
        for j in np.logical_or.reduce(out, axis=0).nonzero()[0].tolist():
            out[:, j] &= self._rec[j](I, A, T, E, Z)
        return out

    def react(self, A: np.ndarray, T: np.ndarray, I: np.ndarray, E: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The stable situations after the input events ``E`` (inputs ``I`` once they
        happened) from the rows (A, T); the rows where a transition fired or an action on
        the event stored (``moved``); and
        the rows left to the machine (``pending``: a conflict, or still evolving after
        :data:`ROUNDS` rounds), whose bits are meaningless."""
        A, T = A.copy(), T.copy()
        pending = np.zeros(len(A), dtype=bool)
        moved = self._event_actions(A, T, I, E) if self._on_event else np.zeros(len(A), dtype=bool)
        live = np.arange(len(A))
        ev = E
        for _ in range(ROUNDS):
            if not live.size:
                return A, T, moved, pending
            a, t = A[live], T[live]
            fire = self._fireable(a, t, I[live], ev)
            firing = fire.any(axis=1)
            live, a, t = live[firing], a[firing], t[firing]
            moved[live] = True
            row, tr = fire[firing].nonzero()  # the firing pairs, by row
            if self._shared:  # conflict: a step left twice
                deact, conflict = self._sources_of.mark_shared(row, tr, len(live))
            else:
                deact, conflict = self._sources_of.mark(row, tr, len(live)), np.zeros(len(live), dtype=bool)
            act = self._targets_of.mark(row, tr, len(live))
            pending[live[conflict]] = True
            A[live] = (a & ~deact) | act
            left = deact & ~act
            if self.timer_names:
                lrow, lstep = np.nonzero(left)
                t &= ~self._timer_cols.mark(lrow, lstep, len(live))
            if self.stored_names:
                t = self._stored_phase(t, left, ON_DEACTIVATION)
                t = self._stored_phase(t, act & ~a, ON_ACTIVATION)
            T[live] = t
            live = live[~conflict]
            ev = np.empty(len(live), dtype=np.int64)
            ev.fill(-1)
        pending[live] = True
        return A, T, moved, pending

    def _event_actions(self, A: np.ndarray, T: np.ndarray, I: np.ndarray, E: np.ndarray) -> np.ndarray:
        """The stored actions on the input event ``E`` of the active steps (sets, then
        resets), in place in ``T``; the rows they changed."""
        Z = np.zeros(len(A), dtype=bool)
        sets, resets = np.zeros_like(T), np.zeros_like(T)
        for step, col, value, cond in self._on_event:
            (sets if value else resets)[:, col] |= A[:, step] & (E >= 0) & cond(I, A, T, E, Z)
        after = (T | sets) & ~resets
        changed: np.ndarray = (after != T).any(axis=1)
        T[:] = after
        return changed

    def _stored_phase(self, t: np.ndarray, steps: np.ndarray, when: StoredWhen) -> np.ndarray:
        """The memory ``t`` after the stored actions of ``steps`` for ``when`` (the
        machine's ``_apply``: sets, then resets)."""
        row, step = np.nonzero(steps)
        if when in self._sets:
            t = t | self._sets[when].mark(row, step, len(t))
        if when in self._resets:
            t = t & ~self._resets[when].mark(row, step, len(t))
        return t

    def orders(self, A: np.ndarray, T: np.ndarray, I: np.ndarray) -> np.ndarray:
        """The orders each row emits (columns :attr:`order_names`) on the input levels ``I``."""
        out = self.situation_orders(A, T)
        self.add_conditional(out, A, T, I)
        return out

    def situation_orders(self, A: np.ndarray, T: np.ndarray) -> np.ndarray:
        """What of :meth:`orders` the situation alone decides: the continuous actions without
        a condition and the stored outputs (a situation's part, read once per situation)."""
        out = np.zeros((len(A), len(self.order_names)), dtype=bool)
        for step, order, cond in self._actions:
            if cond is None:
                out[:, self._order[order]] |= A[:, step]
        for col_t, col_o in self._stored_cols:
            out[:, col_o] |= T[:, col_t]
        return out

    def add_conditional(self, out: np.ndarray, A: np.ndarray, T: np.ndarray, I: np.ndarray) -> None:
        """The conditional actions' orders on the input levels ``I``, added to ``out`` in place."""
        Z = np.zeros(len(A), dtype=bool)
        E = np.full(len(A), -1)
        for step, order, cond in self._actions:
            if cond is not None:
                out[:, self._order[order]] |= A[:, step] & cond(I, A, T, E, Z)


class _Lists:
    """A Boolean matrix's rows as lists of columns, to mark many rows' columns at once."""

    def __init__(self, matrix: np.ndarray) -> None:
        rows, self.cols = np.nonzero(matrix)
        self.starts = np.searchsorted(rows, np.arange(len(matrix) + 1))
        self.width = matrix.shape[1]

    def _spread(self, row: np.ndarray, item: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(row, column) for each column of each pair's ``item``."""
        counts = self.starts[item + 1] - self.starts[item]
        ends = counts.cumsum()
        at = (self.starts[item] - ends + counts).repeat(counts) + np.arange(int(ends[-1]) if ends.size else 0)
        return row.repeat(counts), self.cols[at]

    def mark(self, row: np.ndarray, item: np.ndarray, n: int) -> np.ndarray:
        """An n-row matrix with the columns of ``item`` set in ``row``, for each pair."""
        return self._marked(*self._spread(row, item), n)

    def mark_shared(self, row: np.ndarray, item: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`mark`, and the rows where two pairs' items share a column."""
        r, c = self._spread(row, item)
        key = r * self.width + c
        key.sort()
        twice = np.zeros(n, dtype=bool)
        twice[key[1:][key[1:] == key[:-1]] // max(self.width, 1)] = True
        return self._marked(r, c, n), twice

    def _marked(self, r: np.ndarray, c: np.ndarray, n: int) -> np.ndarray:
        out = np.zeros((n, self.width), dtype=bool)
        out[r, c] = True
        return out

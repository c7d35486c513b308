"""IEC 60848 evolution of a Grafcet and the automaton of its stable situations (ASS).

:class:`GrafcetMachine` applies the five evolution rules with search for stability:

1. the initial situation is the set of initial steps;
2. a transition is *enabled* when all its source steps are active, *fireable* when it
   is enabled and its receptivity is true;
3. firing deactivates all its source steps and activates all its target steps;
4. all fireable transitions fire simultaneously (across partial grafcets);
5. a step both deactivated and activated stays active.

After an input event (exactly one input changes: ``↑x`` or ``↓x``) or a timer event
(``2s/X101`` elapses), transitions fire round after round *without new input
events* until none is fireable: the result is the next *stable situation*. Edges are
true only in the first round; step variables and timers are re-read every round.
Continuous and conditional actions are emitted in stable situations only; stored
actions (``set``/``reset``) run on every activation/deactivation, transient ones
included. A transient cycle that never stabilises is an :class:`InputError`.

:func:`stable_situation_automaton` explores all stable situations reachable from the
initial one, with every input the Grafcet reads free to change (one at a time) and
every running timer free to elapse.

Example
-------
>>> from synth.grafcet import parse_grafcet
>>> g = parse_grafcet('''
... grafcet G { initial step 0
...   step 1: A
...   step 2
...   transition 0 -> 1 when ↑a
...   transition 1 -> 2 when b
...   transition 2 -> 0 when 1 }''', "demo.g7")
>>> m = GrafcetMachine(g)
>>> s0 = m.initial({"a": False, "b": False})
>>> s0.text()
'{X0}'
>>> s1 = m.react(s0, {"a": False, "b": False}, {"a": True, "b": False})
>>> s1.text(), sorted(m.orders(s1, {"a": True, "b": False}))
('{X1}', ['A'])
>>> m.react(s1, {"a": True, "b": False}, {"a": True, "b": True}).text()  # 1 -> 2 -> 0, 2 transient
'{X0}'
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from itertools import product
from typing import Callable, Mapping, Sequence

from .errors import InputError, LimitExceeded
from .expr import And, Const, Edge, Expr, Not, Var, edge_text, names
from .grafcet import (
    CONDITIONAL,
    CONTINUOUS,
    ON_ACTIVATION,
    ON_DEACTIVATION,
    ON_EVENT,
    STORED,
    Grafcet,
    Transition,
    load_grafcet,
    receptivity_inputs,
    step_key,
)

__all__ = [
    "Situation",
    "GrafcetMachine",
    "ASSState",
    "ASSTransition",
    "ASS",
    "stable_situation_automaton",
    "load_grafcet",
    "receptivity_inputs",
    "parse_event",
    "event_text",
    "Event",
]

# (input name, rising) for an input edge, or a timer id
Event = tuple[str, bool] | str


def _sorted_steps(steps: Sequence[str] | set[str] | frozenset[str]) -> tuple[str, ...]:
    return tuple(sorted(steps, key=step_key))


@dataclass(frozen=True, order=True)
class Situation:
    """A situation of the Grafcet: active steps, stored outputs set, elapsed timers.

    >>> Situation(("1", "101"), ("M",), ("2s/X101",)).text()
    '{X1, X101} stored{M} elapsed{2s/X101}'
    """

    steps: tuple[str, ...]
    stored: tuple[str, ...] = ()
    elapsed: tuple[str, ...] = ()

    def text(self) -> str:
        out = "{" + ", ".join("X" + s for s in self.steps) + "}"
        if self.stored:
            out += " stored{" + ", ".join(self.stored) + "}"
        if self.elapsed:
            out += " elapsed{" + ", ".join(self.elapsed) + "}"
        return out

    @property
    def step_variables(self) -> tuple[str, ...]:
        return tuple("X" + s for s in self.steps)


# --------------------------------------------------------------------------- compiled expressions

_Fn = Callable[[Mapping[str, bool], frozenset[str], frozenset[str], "tuple[str, bool] | None"], bool]


def _code(e: Expr, steps: set[str], timers: set[str]) -> str:
    if isinstance(e, Var):
        if e.name in timers:
            return f"({e.name!r} in T)"
        if e.name.startswith("X") and e.name[1:] in steps:
            return f"({e.name[1:]!r} in A)"
        return f"I[{e.name!r}]"
    if isinstance(e, Const):
        return "True" if e.value else "False"
    if isinstance(e, Edge):
        return f"(E == {(e.name, e.rising)!r})"
    if isinstance(e, Not):
        return f"(not {_code(e.arg, steps, timers)})"
    op = " and " if isinstance(e, And) else " or "
    return "(" + op.join(_code(a, steps, timers) for a in e.args) + ")"


def _compile(e: Expr, steps: set[str], timers: set[str]) -> _Fn:
    """``e`` as a fast function of (inputs I, active steps A, elapsed timers T, event E)."""
    fn: _Fn = eval(f"lambda I, A, T, E: {_code(e, steps, timers)}", {"__builtins__": {}})  # noqa: S307 - names are repr-quoted
    return fn


@dataclass
class _State:
    active: set[str]
    stored: set[str]
    elapsed: set[str]

    def key(self) -> tuple[frozenset[str], frozenset[str], frozenset[str]]:
        return (frozenset(self.active), frozenset(self.stored), frozenset(self.elapsed))


class GrafcetMachine:
    """The IEC 60848 interpreter of a :class:`~synth.grafcet.Grafcet` (see module doc).

    Deterministic: transitions are considered in file order, sets are returned sorted.
    ``settle_initial`` (default True): apply search for stability to the initial
    situation, with the initial input levels (no edge, no elapsed timer).
    """

    def __init__(self, grafcet: Grafcet, *, settle_initial: bool = True) -> None:
        self.grafcet = grafcet
        self.inputs: tuple[str, ...] = grafcet.inputs
        self.outputs: tuple[str, ...] = grafcet.outputs
        self.read_inputs: tuple[str, ...] = grafcet.read_inputs
        self.settle_initial = settle_initial
        self.transitions: tuple[Transition, ...] = grafcet.transitions
        steps = {s.name for s in grafcet.steps}
        timers = {t.id for t in grafcet.timers}
        self._timer_step = {t.id: t.step for t in grafcet.timers}
        self._seconds = {t.id: t.seconds for t in grafcet.timers}
        self._timers_of_step: dict[str, tuple[str, ...]] = {}
        for t in grafcet.timers:
            self._timers_of_step[t.step] = self._timers_of_step.get(t.step, ()) + (t.id,)
        self._rec = [_compile(t.receptivity, steps, timers) for t in self.transitions]
        self._enabled_cache: dict[frozenset[str], tuple[int, ...]] = {}
        self._rec_inputs = [frozenset(receptivity_inputs(t, self.inputs)) for t in self.transitions]
        self._steps = {s.name: s for s in grafcet.steps}
        self._cond: dict[tuple[str, int], _Fn] = {}
        for s in grafcet.steps:
            for i, a in enumerate(s.actions):
                if a.condition is not None:
                    self._cond[(s.name, i)] = _compile(a.condition, steps, timers)
        self._event_inputs: dict[str, frozenset[str]] = {}
        for s in grafcet.steps:
            used: set[str] = set()
            for a in s.actions:
                if a.kind == STORED and a.when == ON_EVENT and a.condition is not None:
                    used.update(n.name for n in names(a.condition))
            self._event_inputs[s.name] = frozenset(used)

    # ------------------------------------------------------------------ public API
    def initial(self, inputs: Mapping[str, bool]) -> Situation:
        """The initial situation: initial steps active (their ``on activation`` stored
        actions run), then, if ``settle_initial``, search for stability on ``inputs``."""
        st = _State(set(self.grafcet.initial_steps), set(), set())
        self._stored_phase(st, st.active, ON_ACTIVATION)
        if self.settle_initial:
            self._settle(st, inputs, None, rounds=[])
        return self._situation(st)

    def react(self, sit: Situation, before: Mapping[str, bool], after: Mapping[str, bool]) -> Situation:
        """The stable situation after one input event (``before`` → ``after``)."""
        return self.react_with_trace(sit, before, after)[0]

    def react_with_trace(
        self, sit: Situation, before: Mapping[str, bool], after: Mapping[str, bool]
    ) -> tuple[Situation, tuple[tuple[Transition, ...], ...]]:
        """:meth:`react`, plus the transitions fired in each round of the search for stability."""
        changed = [n for n in self.inputs if bool(before[n]) != bool(after[n])]
        if len(changed) > 1:
            raise ValueError(f"one input changes per event, not {len(changed)}: {', '.join(changed)}")
        event = (changed[0], bool(after[changed[0]])) if changed else None
        return self.react_event(sit, event, after)

    def react_event(
        self, sit: Situation, event: tuple[str, bool] | None, after: Mapping[str, bool]
    ) -> tuple[Situation, tuple[tuple[Transition, ...], ...]]:
        """The stable situation after input ``event`` (``("dcy", True)`` is ``↑dcy``),
        ``after`` being the input values once it happened; with the rounds fired."""
        st = self._state(sit)
        if event is not None:
            self._event_actions(st, after, event)
        rounds: list[tuple[Transition, ...]] = []
        self._settle(st, after, event, rounds)
        return self._situation(st), tuple(rounds)

    def timers(self, sit: Situation) -> tuple[str, ...]:
        """Timer events that can occur now (sorted): the step is active, the timer has not
        elapsed, and no shorter timer of the same step is still running (timers of one
        step start together, so ``2s/X1`` always elapses before ``5s/X1``)."""
        done = set(sit.elapsed)
        out = []
        for s in sit.steps:
            running = [t for t in self._timers_of_step.get(s, ()) if t not in done]
            if running:
                first = min(self._seconds[t] for t in running)
                out += [t for t in running if self._seconds[t] == first]
        return tuple(sorted(out))

    def fire_timer(self, sit: Situation, timer: str, inputs: Mapping[str, bool]) -> Situation:
        """The stable situation after ``timer`` elapses (inputs unchanged)."""
        return self.fire_timer_with_trace(sit, timer, inputs)[0]

    def fire_timer_with_trace(
        self, sit: Situation, timer: str, inputs: Mapping[str, bool]
    ) -> tuple[Situation, tuple[tuple[Transition, ...], ...]]:
        if timer not in self.timers(sit):
            raise ValueError(f"timer {timer} is not running in {sit.text()}")
        st = self._state(sit)
        st.elapsed.add(timer)
        rounds: list[tuple[Transition, ...]] = []
        self._settle(st, inputs, None, rounds)
        return self._situation(st), tuple(rounds)

    def orders(self, sit: Situation, inputs: Mapping[str, bool]) -> frozenset[str]:
        """Outputs emitted in ``sit``: continuous, conditional (condition true), stored."""
        out = set(sit.stored)
        active = frozenset(sit.steps)
        elapsed = frozenset(sit.elapsed)
        for s in sit.steps:
            for i, a in enumerate(self._steps[s].actions):
                if a.kind == CONTINUOUS:
                    out.add(a.order)
                elif a.kind == CONDITIONAL and self._cond[(s, i)](inputs, active, elapsed, None):
                    out.add(a.order)
        return frozenset(out)

    def awaited(self, sit: Situation) -> list[Transition]:
        """Transitions enabled in ``sit`` (all source steps active), in file order."""
        active = set(sit.steps)
        return [t for t in self.transitions if all(s in active for s in t.sources)]

    def fireable(self, sit: Situation, inputs: Mapping[str, bool]) -> list[Transition]:
        """Enabled transitions whose receptivity holds on the levels ``inputs`` (no edge)."""
        active, elapsed = frozenset(sit.steps), frozenset(sit.elapsed)
        return [
            t for i, t in enumerate(self.transitions)
            if all(s in active for s in t.sources) and self._rec[i](inputs, active, elapsed, None)
        ]

    def relevant_inputs(self, sit: Situation) -> frozenset[str]:
        """Inputs whose change may change ``sit``: read by an enabled transition or by an
        event action of an active step."""
        active = set(sit.steps)
        used: set[str] = set()
        for i, t in enumerate(self.transitions):
            if all(s in active for s in t.sources):
                used |= self._rec_inputs[i]
        for s in sit.steps:
            used |= self._event_inputs[s]
        return frozenset(used)

    # ------------------------------------------------------------------ internals
    def _enabled(self, active: frozenset[str]) -> tuple[int, ...]:
        """Indices of the transitions enabled by ``active`` (cached)."""
        hit = self._enabled_cache.get(active)
        if hit is None:
            hit = tuple(i for i, t in enumerate(self.transitions) if all(s in active for s in t.sources))
            self._enabled_cache[active] = hit
        return hit

    def _state(self, sit: Situation) -> _State:
        return _State(set(sit.steps), set(sit.stored), set(sit.elapsed))

    def _situation(self, st: _State) -> Situation:
        return Situation(_sorted_steps(st.active), tuple(sorted(st.stored)), tuple(sorted(st.elapsed)))

    def _stored_phase(self, st: _State, steps: set[str], when: str) -> None:
        """Stored actions of ``steps`` for ``when``: sets first, then resets (reset wins)."""
        sets: set[str] = set()
        resets: set[str] = set()
        for s in _sorted_steps(steps):
            for a in self._steps[s].actions:
                if a.kind == STORED and a.when == when:
                    (sets if a.value else resets).add(a.order)
        st.stored |= sets
        st.stored -= resets

    def _event_actions(self, st: _State, inputs: Mapping[str, bool], event: tuple[str, bool]) -> None:
        sets: set[str] = set()
        resets: set[str] = set()
        active, elapsed = frozenset(st.active), frozenset(st.elapsed)
        for s in _sorted_steps(st.active):
            for i, a in enumerate(self._steps[s].actions):
                if a.kind == STORED and a.when == ON_EVENT and self._cond[(s, i)](inputs, active, elapsed, event):
                    (sets if a.value else resets).add(a.order)
        st.stored |= sets
        st.stored -= resets

    def _settle(
        self,
        st: _State,
        inputs: Mapping[str, bool],
        event: tuple[str, bool] | None,
        rounds: list[tuple[Transition, ...]],
    ) -> None:
        """Search for stability, in place. Edges (``event``) hold in the first round only."""
        seen: dict[tuple[frozenset[str], frozenset[str], frozenset[str]], int] = {}
        history: list[tuple[Transition, ...]] = []
        first = True
        while True:
            if not first or event is None:
                key = st.key()
                if key in seen:
                    self._never_stable(history[seen[key]:], inputs)
                seen[key] = len(history)
            active, elapsed = frozenset(st.active), frozenset(st.elapsed)
            ev = event if first else None
            rec = self._rec
            fire = tuple(self.transitions[i] for i in self._enabled(active) if rec[i](inputs, active, elapsed, ev))
            first = False
            if not fire:
                return
            history.append(fire)
            rounds.append(fire)
            deact = {s for t in fire for s in t.sources}
            act = {s for t in fire for s in t.targets}
            left = deact - act
            entered = act - st.active
            st.active = (st.active - deact) | act
            for s in left:
                st.elapsed -= set(self._timers_of_step.get(s, ()))
            self._stored_phase(st, left, ON_DEACTIVATION)
            self._stored_phase(st, entered, ON_ACTIVATION)

    def _never_stable(self, cycle: list[tuple[Transition, ...]], inputs: Mapping[str, bool]) -> None:
        steps = _sorted_steps({s for fire in cycle for t in fire for s in (*t.sources, *t.targets)})
        trans = [t for fire in cycle for t in fire]
        first = trans[0]
        values = ", ".join(f"{n}={int(bool(inputs[n]))}" for n in self.read_inputs)
        raise InputError(
            "the Grafcet never stabilises: transient cycle through steps " + ", ".join(steps),
            first.loc,
            notes=(
                "transitions fired again and again: " + ", ".join(dict.fromkeys(t.name for t in trans)),
                f"with inputs {values}" if values else "whatever the inputs",
            ),
        )


# --------------------------------------------------------------------------- events


def parse_event(text: str) -> Event:
    """``"↑dcy"``/``"^dcy"`` → ``("dcy", True)``, ``"↓v10"``/``"_v10"`` → ``("v10", False)``,
    a timer ``"2s/X101"`` stays a string.

    >>> parse_event("^dcy"), parse_event("↓v10"), parse_event("2s/X101")
    (('dcy', True), ('v10', False), '2s/X101')
    """
    t = text.strip()
    if t[:1] in ("↑", "^"):
        return (t[1:].strip(), True)
    if t[:1] in ("↓", "_"):
        return (t[1:].strip(), False)
    return t


def event_text(event: Event) -> str:
    """``("dcy", True)`` → ``"↑dcy"``; a timer id is returned as is."""
    return event if isinstance(event, str) else edge_text(event[1], event[0])


# --------------------------------------------------------------------------- ASS


@dataclass(frozen=True)
class ASSState:
    """A stable situation of the ASS, with the orders it emits.

    ``orders``: every order emitted for some reachable input valuation;
    ``conditional``: those among them emitted only for some valuations.
    """

    id: int
    situation: Situation
    orders: tuple[str, ...]
    conditional: tuple[str, ...] = ()


@dataclass(frozen=True)
class ASSTransition:
    """``source --event [condition]--> target`` (condition on the other inputs, ``any`` if none)."""

    source: int
    event: str
    condition: str
    target: int


@dataclass(frozen=True)
class ASS:
    """The automaton of the stable situations."""

    states: tuple[ASSState, ...]
    transitions: tuple[ASSTransition, ...]
    initial: int = 0
    inputs: tuple[str, ...] = ()
    initial_inputs: tuple[tuple[str, bool], ...] = field(default=())

    def state_of(self, sit: Situation) -> ASSState:
        for s in self.states:
            if s.situation == sit:
                return s
        raise KeyError(sit.text())

    def successors(self, state: int) -> tuple[ASSTransition, ...]:
        return tuple(t for t in self.transitions if t.source == state)


class _Cubes:
    """Sets of input vectors as Python integers (bit ``v`` set iff vector ``v`` is in the set).

    A vector ``v`` has bit ``i`` set iff input ``i`` is 1. Set operations are integer
    bit operations, so whole sets are handled at once.
    """

    def __init__(self, n: int) -> None:
        self.n = n
        self.size = 1 << n
        self.full = (1 << self.size) - 1
        self.one: list[int] = []
        for i in range(n):
            block = ((1 << (1 << i)) - 1) << (1 << i)  # 2^i zeros then 2^i ones
            period = 1 << (i + 1)
            m = 0
            for start in range(0, self.size, period):
                m |= block << start
            self.one.append(m)
        self.zero = [self.full ^ m for m in self.one]

    def flip(self, s: int, i: int) -> int:
        """Every vector of ``s`` with input ``i`` flipped."""
        d = 1 << i
        return ((s & self.zero[i]) << d) | ((s & self.one[i]) >> d)

    def cube(self, literals: Mapping[int, bool]) -> int:
        """Vectors where input ``i`` equals ``literals[i]`` for every given ``i``."""
        c = self.full
        for i, value in literals.items():
            c &= self.one[i] if value else self.zero[i]
        return c

    def members(self, s: int) -> list[int]:
        out = []
        while s:
            low = s & -s
            out.append(low.bit_length() - 1)
            s ^= low
        return out


def _condition_text(cubes: _Cubes, on: int, off: int, names: Sequence[str], free: Sequence[int]) -> str:
    """A small DNF over inputs ``free`` true on every vector of ``on`` and false on every
    vector of ``off`` (other vectors: don't care); ``any`` when ``off`` is empty.

    >>> c = _Cubes(2)
    >>> on = c.cube({0: True}) & ~c.cube({1: True})       # a & !b
    >>> off = c.cube({0: False})                          # !a
    >>> _condition_text(c, on, off, ["a", "b"], [0, 1])
    'a'
    >>> _condition_text(c, on, 0, ["a", "b"], [0, 1])
    'any'
    """
    if not off:
        return "any"
    keep = list(free)
    cl_on, cl_off = on, off
    for i in list(keep):  # drop every variable not needed to tell on from off
        t_on = cl_on | cubes.flip(cl_on, i)
        t_off = cl_off | cubes.flip(cl_off, i)
        if not t_on & t_off:
            keep.remove(i)
            cl_on, cl_off = t_on, t_off
    if len(keep) > 8:  # too many variables to minimise: list the vectors
        vecs = sorted({tuple(bool(v >> i & 1) for i in keep) for v in cubes.members(on)}, reverse=True)
        return " | ".join(_cube_text(dict(zip(keep, vec)), names) for vec in vecs)
    candidates: list[tuple[dict[int, bool], int]] = []
    for values in product((None, True, False), repeat=len(keep)):
        lits = {i: v for i, v in zip(keep, values) if v is not None}
        c = cubes.cube(lits)
        if not c & off and c & on:
            candidates.append((lits, c))
    primes = [
        (l, c) for l, c in candidates
        if not any(c != d and c & d == c for _, d in candidates)
    ]
    uncovered = on
    chosen: list[dict[int, bool]] = []
    while uncovered:
        lits, c = max(
            primes,
            key=lambda lc: (
                (lc[1] & uncovered).bit_count(),
                -len(lc[0]),
                tuple(2 if lc[0].get(i) is None else int(lc[0][i]) for i in keep),
            ),
        )
        chosen.append(lits)
        uncovered &= ~c
    return " | ".join(_cube_text(l, names) for l in chosen)


def _cube_text(lits: Mapping[int, bool], names: Sequence[str]) -> str:
    parts = [(names[i] if v else "!" + names[i]) for i, v in sorted(lits.items())]
    return " & ".join(parts) if parts else "1"


class _Reader:
    """Input values from a vector, remembering which inputs were read (for memoisation)."""

    __slots__ = ("mask", "index", "base", "read")

    def __init__(self, mask: int, index: Mapping[str, int], base: Mapping[str, bool]) -> None:
        self.mask = mask
        self.index = index
        self.base = base
        self.read = 0

    def __getitem__(self, name: str) -> bool:
        i = self.index.get(name)
        if i is None:
            return self.base[name]
        self.read |= 1 << i
        return bool(self.mask >> i & 1)


MAX_INPUTS = 20


def stable_situation_automaton(
    machine: GrafcetMachine,
    *,
    initial_inputs: Mapping[str, bool] | None = None,
    max_states: int = 100_000,
    admissible: Callable[[Mapping[str, bool]], bool] | None = None,
) -> ASS:
    """The ASS of ``machine``, explored from its initial situation.

    The exploration runs over pairs (stable situation, valuation of the inputs the
    Grafcet reads); from each, every read input may flip (one event) and every running
    timer may elapse. Pairs are then projected on situations. ``initial_inputs`` gives
    the initial input values (default: all 0; inputs not read never matter).
    Sets of valuations are handled as bit sets, so a situation is processed at once
    for all the valuations that reach it.

    >>> from synth.grafcet import parse_grafcet
    >>> g = parse_grafcet("grafcet G { initial step 0 step 1: A "
    ...                   "transition 0 -> 1 when ↑a . b  transition 1 -> 0 when !b }")
    >>> ass = stable_situation_automaton(GrafcetMachine(g))
    >>> [(s.id, s.situation.text(), s.orders) for s in ass.states]
    [(0, '{X0}', ()), (1, '{X1}', ('A',))]
    >>> [(t.source, t.event, t.condition, t.target) for t in ass.transitions]
    [(0, '↑a', 'b', 1), (1, '↓b', 'any', 0)]
    """
    base = {n: bool((initial_inputs or {}).get(n, False)) for n in machine.inputs}
    read = machine.read_inputs
    n_in = len(read)
    if n_in > MAX_INPUTS:
        raise LimitExceeded(f"the Grafcet reads {n_in} inputs; the ASS is explored for at most {MAX_INPUTS}")
    index = {n: i for i, n in enumerate(read)}
    cubes = _Cubes(n_in)

    def valuation(v: int) -> dict[str, bool]:
        d = dict(base)
        for n, i in index.items():
            d[n] = bool(v >> i & 1)
        return d

    v0 = sum(1 << i for n, i in index.items() if base[n])
    allowed = -1  # every vector
    if admissible is not None and n_in <= 16:
        allowed = sum(1 << v for v in range(1 << n_in) if admissible(valuation(v))) | (1 << v0)
    s0 = machine.initial(base)
    sits: list[Situation] = [s0]
    sid: dict[Situation, int] = {s0: 0}
    reached: list[int] = [1 << v0]
    pending: list[int] = [1 << v0]
    relevant: list[int] = []
    timers: list[tuple[str, ...]] = []
    labels: list[str] = [edge_text(r, n) for n in read for r in (True, False)]
    # (situation, label) -> [(vectors covered, target)], from memoised runs
    memo: dict[tuple[int, str], list[tuple[int, int]]] = {}
    # (situation, label) -> {target: vectors before the event}
    moves: dict[tuple[int, str], dict[int, int]] = {}
    queue: deque[int] = deque([0])
    queued = {0}

    def known(sit: Situation) -> int:
        k = sid.get(sit)
        if k is None:
            if len(sits) >= max_states:
                raise LimitExceeded(f"more than {max_states} stable situations while building the ASS")
            k = sid[sit] = len(sits)
            sits.append(sit)
            reached.append(0)
            pending.append(0)
        while len(relevant) < len(sits):
            j = len(relevant)
            relevant.append(sum(1 << index[x] for x in machine.relevant_inputs(sits[j]) if x in index))
            timers.append(machine.timers(sits[j]))
        return k

    known(s0)

    def classify(k: int, label: str, event: tuple[str, bool] | str, after: int) -> dict[int, int]:
        """Target situation of each vector of ``after`` (values once the event happened)."""
        entries = memo.setdefault((k, label), [])
        out: dict[int, int] = {}
        rest = after
        for covered, target in entries:
            hit = rest & covered
            if hit:
                out[target] = out.get(target, 0) | hit
                rest &= ~covered
        while rest:
            v = (rest & -rest).bit_length() - 1
            reader = _Reader(v, index, base)
            if isinstance(event, str):
                result = machine.fire_timer_with_trace(sits[k], event, reader)[0]  # type: ignore[arg-type]
            else:
                result = machine.react_event(sits[k], event, reader)[0]  # type: ignore[arg-type]
            target = known(result)
            covered = cubes.cube({i: bool(v >> i & 1) for i in range(n_in) if reader.read >> i & 1})
            entries.append((covered, target))
            out[target] = out.get(target, 0) | (rest & covered)
            rest &= ~covered
        return out

    def add(k: int, vectors: int) -> None:
        new = vectors & ~reached[k]
        if new:
            reached[k] |= new
            pending[k] |= new
            if k not in queued:
                queued.add(k)
                queue.append(k)

    while queue:
        k = queue.popleft()
        queued.discard(k)
        todo, pending[k] = pending[k], 0
        for i, n in enumerate(read):
            for rising in (True, False):
                src = todo & (cubes.zero[i] if rising else cubes.one[i])
                if not src:
                    continue
                after = cubes.flip(src, i) & allowed
                if not after:
                    continue
                if not relevant[k] >> i & 1:
                    add(k, after)
                    continue
                label = labels[2 * i + (0 if rising else 1)]
                for target, vecs in classify(k, label, (n, rising), after).items():
                    add(target, vecs)
                    if target != k:
                        m = moves.setdefault((k, label), {})
                        m[target] = m.get(target, 0) | cubes.flip(vecs, i)
        for t in timers[k]:
            for target, vecs in classify(k, t, t, todo).items():
                add(target, vecs)
                if target != k:
                    m = moves.setdefault((k, t), {})
                    m[target] = m.get(target, 0) | vecs
    # states, with the orders they emit
    states: list[ASSState] = []
    for k, sit in enumerate(sits):
        emitted = {machine.orders(sit, valuation(v)) for v in cubes.members(reached[k])}
        union = frozenset().union(*emitted) if emitted else frozenset()
        always = frozenset.intersection(*emitted) if emitted else frozenset()
        outs = tuple(o for o in machine.outputs if o in union)
        states.append(ASSState(k, sit, outs, tuple(o for o in outs if o not in always)))
    # transitions, with the condition on the other inputs
    rank = {label: r for r, label in enumerate(labels)}
    trans: list[ASSTransition] = []
    for (k, label), by_target in moves.items():
        if label in rank:
            x = rank[label] // 2
            domain = reached[k] & (cubes.zero[x] if rank[label] % 2 == 0 else cubes.one[x])
            free = [i for i in range(n_in) if i != x]
        else:
            domain = reached[k]
            free = list(range(n_in))
        for target in sorted(by_target):
            on = by_target[target] & domain
            trans.append(ASSTransition(k, label, _condition_text(cubes, on, domain & ~on, read, free), target))
    trans.sort(key=lambda t: (t.source, rank.get(t.event, len(rank)), t.event, t.target))
    return ASS(tuple(states), tuple(trans), 0, read, tuple((n, base[n]) for n in read))

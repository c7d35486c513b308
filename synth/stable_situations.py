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
from .expr import And, Const, Edge, Expr, Not, Or, Var, edge_text
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
        self._timers_of_step: dict[str, tuple[str, ...]] = {}
        for t in grafcet.timers:
            self._timers_of_step[t.step] = self._timers_of_step.get(t.step, ()) + (t.id,)
        self._rec = [_compile(t.receptivity, steps, timers) for t in self.transitions]
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
                    used.update(n.name for n in _names(a.condition))
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
        st = self._state(sit)
        if event is not None:
            self._event_actions(st, after, event)
        rounds: list[tuple[Transition, ...]] = []
        self._settle(st, after, event, rounds)
        return self._situation(st), tuple(rounds)

    def timers(self, sit: Situation) -> tuple[str, ...]:
        """Timer events that can occur now: step active, timer not yet elapsed (sorted)."""
        done = set(sit.elapsed)
        return tuple(sorted(t for s in sit.steps for t in self._timers_of_step.get(s, ()) if t not in done))

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
            fire = tuple(
                t for i, t in enumerate(self.transitions)
                if all(s in active for s in t.sources) and self._rec[i](inputs, active, elapsed, ev)
            )
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


def _names(e: Expr) -> list[Var | Edge]:
    from .expr import names

    return list(names(e))


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


def _condition_text(on: set[tuple[bool, ...]], off: set[tuple[bool, ...]], names: Sequence[str]) -> str:
    """A small DNF true on every ``on`` vector and false on every ``off`` one (others: don't care).

    >>> _condition_text({(True, False), (True, True)}, {(False, True)}, ["a", "b"])
    'a'
    >>> _condition_text({(True,)}, set(), ["a"])
    'any'
    """
    if not off:
        return "any"
    keep = list(range(len(names)))
    for i in list(keep):
        trial = [k for k in keep if k != i]
        pon = {tuple(v[k] for k in trial) for v in on}
        poff = {tuple(v[k] for k in trial) for v in off}
        if not pon & poff:
            keep = trial
    pon = {tuple(v[k] for k in keep) for v in on}
    poff = {tuple(v[k] for k in keep) for v in off}
    n = len(keep)
    if n > 10:  # too many variables to minimise: list the vectors
        cubes = sorted(pon, reverse=True)
        return " | ".join(_cube_text(c, [names[k] for k in keep]) for c in cubes)

    def covers(cube: tuple[bool | None, ...], v: tuple[bool, ...]) -> bool:
        return all(c is None or c == x for c, x in zip(cube, v))

    valid = [
        c for c in product((None, True, False), repeat=n)
        if not any(covers(c, v) for v in poff) and any(covers(c, v) for v in pon)
    ]

    def sub(a: tuple[bool | None, ...], b: tuple[bool | None, ...]) -> bool:  # a strictly inside b
        return a != b and all(y is None or x == y for x, y in zip(a, b))

    primes = [c for c in valid if not any(sub(c, d) for d in valid)]
    uncovered = set(pon)
    chosen: list[tuple[bool | None, ...]] = []
    while uncovered:
        best = max(
            primes,
            key=lambda c: (
                sum(covers(c, v) for v in uncovered),
                -sum(x is not None for x in c),
                tuple(0 if x is None else (2 if x else 1) for x in c),
            ),
        )
        chosen.append(best)
        uncovered = {v for v in uncovered if not covers(best, v)}
    kept = [names[k] for k in keep]
    return " | ".join(_cube_text(c, kept) for c in chosen)


def _cube_text(cube: tuple[bool | None, ...], names: Sequence[str]) -> str:
    lits = [(n if v else "!" + n) for n, v in zip(names, cube) if v is not None]
    return " & ".join(lits) if lits else "1"


def stable_situation_automaton(
    machine: GrafcetMachine,
    *,
    initial_inputs: Mapping[str, bool] | None = None,
    max_states: int = 2_000_000,
) -> ASS:
    """The ASS of ``machine``, explored from its initial situation.

    The exploration runs over pairs (stable situation, valuation of the inputs the
    Grafcet reads); from each, every read input may flip (one event) and every running
    timer may elapse. Pairs are then projected on situations. ``initial_inputs`` gives
    the initial input values (default: all 0; inputs not read never matter).
    """
    base = {n: bool((initial_inputs or {}).get(n, False)) for n in machine.inputs}
    names = machine.read_inputs
    index = {n: i for i, n in enumerate(names)}

    def valuation(v: tuple[bool, ...]) -> dict[str, bool]:
        d = dict(base)
        d.update(zip(names, v))
        return d

    v0 = tuple(base[n] for n in names)
    s0 = machine.initial(valuation(v0))
    order: dict[Situation, int] = {s0: 0}
    vectors: dict[Situation, set[tuple[bool, ...]]] = {s0: {v0}}
    # (situation, event) -> {vector before: target situation}
    moves: dict[tuple[Situation, str], dict[tuple[bool, ...], Situation]] = {}
    relevant: dict[Situation, frozenset[str]] = {}
    queue: deque[tuple[Situation, tuple[bool, ...]]] = deque([(s0, v0)])
    seen = {(s0, v0)}
    events: list[tuple[str, bool]] = [(n, r) for n in names for r in (True, False)]
    while queue:
        sit, v = queue.popleft()
        if sit not in relevant:
            relevant[sit] = machine.relevant_inputs(sit)
        rel = relevant[sit]
        succ: list[tuple[str, Situation, tuple[bool, ...]]] = []
        for n, rising in events:
            i = index[n]
            if v[i] == rising:
                continue
            w = v[:i] + (rising,) + v[i + 1:]
            target = machine.react(sit, valuation(v), valuation(w)) if n in rel else sit
            succ.append((edge_text(rising, n), target, w))
        for t in machine.timers(sit):
            succ.append((t, machine.fire_timer(sit, t, valuation(v)), v))
        for label, target, w in succ:
            moves.setdefault((sit, label), {})[v] = target
            if target not in order:
                order[target] = len(order)
                vectors[target] = set()
            if (target, w) not in seen:
                if len(seen) >= max_states:
                    raise LimitExceeded(f"more than {max_states} (situation, inputs) pairs while building the ASS")
                seen.add((target, w))
                vectors[target].add(w)
                queue.append((target, w))
    # states
    states: list[ASSState] = []
    for sit, i in sorted(order.items(), key=lambda kv: kv[1]):
        emitted = [machine.orders(sit, valuation(v)) for v in sorted(vectors[sit])]
        union = frozenset().union(*emitted) if emitted else frozenset()
        always = frozenset.intersection(*emitted) if emitted else frozenset()
        outs = tuple(o for o in machine.outputs if o in union)
        cond = tuple(o for o in outs if o not in always)
        states.append(ASSState(i, sit, outs, cond))
    # transitions, with the condition on the other inputs
    event_rank = {edge_text(r, n): k for k, (n, r) in enumerate(events)}
    trans: list[ASSTransition] = []
    for (sit, label), by_vector in moves.items():
        if label in event_rank:
            name = label[1:]
            others = [k for k, n in enumerate(names) if n != name]
        else:
            others = list(range(len(names)))
        other_names = [names[k] for k in others]
        targets = {t for t in by_vector.values() if t != sit}
        for target in targets:
            on = {tuple(v[k] for k in others) for v, t in by_vector.items() if t == target}
            off = {tuple(v[k] for k in others) for v, t in by_vector.items() if t != target}
            trans.append(ASSTransition(order[sit], label, _condition_text(on, off, other_names), order[target]))
    trans.sort(key=lambda t: (t.source, event_rank.get(t.event, len(event_rank)), t.event, t.target))
    return ASS(tuple(states), tuple(trans), 0, names, tuple((n, base[n]) for n in names))

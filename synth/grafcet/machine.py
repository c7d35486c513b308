"""IEC 60848 evolution of a Grafcet: the machine that ``synth run``, the ASS, validation and
code generation all follow.

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

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
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

from typing import Mapping

from synth.errors import InputError
from synth.logic.events import Event
from synth.logic.expr import Var, names
from synth.grafcet.language import (
    ASSIGN,
    CONDITIONAL,
    CONTINUOUS,
    ON_ACTIVATION,
    ON_DEACTIVATION,
    ON_EVENT,
    STORED,
    Action,
    Grafcet,
    Semantics,
    StoredWhen,
    Transition,
    receptivity_inputs,
    step_of,
    step_variable,
)
from synth.grafcet.situation import CompiledFn, Situation, State, assign, compile_expr, sorted_steps

__all__ = ["Situation", "GrafcetMachine"]


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
        self.sfc = grafcet.semantics is Semantics.SFC  # one evolution (round) per PLC scan
        self.transitions: tuple[Transition, ...] = grafcet.transitions
        steps = {s.name for s in grafcet.steps}
        timers = {t.id for t in grafcet.timers}
        self._seconds = {t.id: t.seconds for t in grafcet.timers}
        self._timers_of_step: dict[str, tuple[str, ...]] = {}
        # timers of one step with equal durations (2s/X1, 2000ms/X1) elapse at the same
        # instant: one event, named after the first of them (grafcet.timers order)
        self._same_instant: dict[str, tuple[str, ...]] = {}
        for t in grafcet.timers:
            self._timers_of_step[t.step] = self._timers_of_step.get(t.step, ()) + (t.id,)
            self._same_instant[t.id] = tuple(
                u.id for u in grafcet.timers if u.step == t.step and u.seconds == t.seconds
            )
        self.internals = {v.name: v for v in grafcet.internals}
        self._initial_data = tuple((v.name, v.initial) for v in grafcet.internals)
        ints = set(self.internals)
        self._rec = [compile_expr(t.receptivity, steps, timers, ints) for t in self.transitions]
        self._enabled_cache: dict[frozenset[str], tuple[int, ...]] = {}
        self._rec_inputs = [frozenset(receptivity_inputs(t, self.inputs)) for t in self.transitions]
        self._rec_steps = [
            frozenset(s for s in (step_of(n.name, steps) for n in names(t.receptivity)
                                  if isinstance(n, Var) and n.name not in timers) if s is not None)
            for t in self.transitions
        ]
        self._index = {t: i for i, t in enumerate(self.transitions)}
        self._steps = {s.name: s for s in grafcet.steps}
        self._cond: dict[tuple[str, int], CompiledFn] = {}
        for s in grafcet.steps:
            for i, a in enumerate(s.actions):
                if a.condition is not None:
                    self._cond[(s.name, i)] = compile_expr(a.condition, steps, timers, ints)
        # the actions of each step for each ``when``, for the steps that have some
        self._phase: dict[StoredWhen, dict[str, tuple[Action, ...]]] = {when: {} for when in StoredWhen}
        for s in grafcet.steps:
            for when in StoredWhen:
                if acts := tuple(a for a in s.actions if a.when == when):
                    self._phase[when][s.name] = acts
        self._event_inputs: dict[str, frozenset[str]] = {}
        for s in grafcet.steps:
            used: set[str] = set()
            for a in s.actions:
                if a.kind in (STORED, ASSIGN) and a.when == ON_EVENT and a.condition is not None:
                    used.update(n.name for n in names(a.condition))
            self._event_inputs[s.name] = frozenset(used)

    # ------------------------------------------------------------------ public API
    def initial(self, inputs: Mapping[str, bool]) -> Situation:
        """The initial situation: initial steps active (their ``on activation`` stored
        actions run), then, if ``settle_initial``, search for stability on ``inputs``."""
        st = State(set(self.grafcet.initial_steps), set(), set(), dict(self._initial_data))
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
        event = Event.edge(changed[0], bool(after[changed[0]])) if changed else None
        return self.react_event(sit, event, after)

    def react_event(
        self, sit: Situation, event: Event | None, after: Mapping[str, bool]
    ) -> tuple[Situation, tuple[tuple[Transition, ...], ...]]:
        """The stable situation after input ``event`` (an edge such as ``↑dcy``),
        ``after`` being the input values once it happened; with the rounds fired."""
        st = self._state(sit)
        if event is not None and not self.sfc:
            self._event_actions(st, after, event)
        rounds: list[tuple[Transition, ...]] = []
        self._settle(st, after, event, rounds)
        if event is not None and self.sfc:  # a PLC runs action bodies after the scan's evolution
            self._event_actions(st, after, event)
        return self._situation(st), tuple(rounds)

    def scan(self, sit: Situation, inputs: Mapping[str, bool]) -> tuple[Situation, tuple[tuple[Transition, ...], ...]]:
        """``--semantics sfc``: the situation after one PLC scan in which no input changed
        (one round of the transitions fireable on the levels ``inputs``), with the round fired."""
        return self.react_event(sit, None, inputs)

    def scans(self, sit: Situation, inputs: Mapping[str, bool]) -> bool:
        """``--semantics sfc``: whether a scan without input change evolves ``sit``."""
        return self.sfc and bool(self.fireable(sit, inputs))

    def timers(self, sit: Situation) -> tuple[Event, ...]:
        """Timer events that can occur now (sorted): the step is active, the timer has not
        elapsed, and no shorter timer of the same step is still running (timers of one
        step start together, so ``2s/X1`` always elapses before ``5s/X1``). Timers of
        equal duration are one event, named by :meth:`timer_event`."""
        done = set(sit.elapsed)
        out = []
        for s in sit.steps:
            running = [t for t in self._timers_of_step.get(s, ()) if t not in done]
            if running:
                first = min(self._seconds[t] for t in running)
                out += [t for t in running if self._seconds[t] == first and self.timer_event(t) == t]
        return tuple(Event.timer(t) for t in sorted(out))

    def timer_event(self, timer: str) -> Event:
        """The event of ``timer``: itself, or the first timer of its step with the same duration.

        >>> from synth.grafcet.language_check import parse_grafcet
        >>> m = GrafcetMachine(parse_grafcet("grafcet G { initial step 0 step 1 step 2 "
        ...     "transition 0 -> 1 when 2s/X0  transition 0 -> 2 when 2000ms/X0 }"))
        >>> m.timer_event("2s/X0"), m.timer_event("2000ms/X0")
        ('2000ms/X0', '2000ms/X0')
        """
        return Event.timer(self._same_instant[timer][0])

    def fire_timer(self, sit: Situation, timer: str, inputs: Mapping[str, bool]) -> Situation:
        """The stable situation after ``timer`` elapses (inputs unchanged)."""
        return self.fire_timer_with_trace(sit, timer, inputs)[0]

    def fire_timer_with_trace(
        self, sit: Situation, timer: str, inputs: Mapping[str, bool]
    ) -> tuple[Situation, tuple[tuple[Transition, ...], ...]]:
        if self.timer_event(timer) not in self.timers(sit):
            raise ValueError(f"timer {timer} is not running in {sit.text()}")
        st = self._state(sit)
        st.elapsed.update(self._same_instant[timer])
        rounds: list[tuple[Transition, ...]] = []
        self._settle(st, inputs, None, rounds)
        return self._situation(st), tuple(rounds)

    def orders(self, sit: Situation, inputs: Mapping[str, bool]) -> frozenset[str]:
        """Outputs emitted in ``sit``: continuous, conditional (condition true), stored."""
        out = set(sit.stored)
        active = frozenset(sit.steps)
        elapsed = frozenset(sit.elapsed)
        data = sit.values
        for s in sit.steps:
            for i, a in enumerate(self._steps[s].actions):
                if a.kind == CONTINUOUS:
                    out.add(a.order)
                elif a.kind == CONDITIONAL and self._cond[(s, i)](inputs, active, elapsed, None, data):
                    out.add(a.order)
        return frozenset(out)

    def awaited(self, sit: Situation) -> list[Transition]:
        """Transitions enabled in ``sit`` (all source steps active), in file order."""
        active = set(sit.steps)
        return [t for t in self.transitions if all(s in active for s in t.sources)]

    def fireable(self, sit: Situation, inputs: Mapping[str, bool]) -> list[Transition]:
        """Enabled transitions whose receptivity holds on the levels ``inputs`` (no edge)."""
        active, elapsed, data = frozenset(sit.steps), frozenset(sit.elapsed), sit.values
        return [
            t for i, t in enumerate(self.transitions)
            if all(s in active for s in t.sources) and self._rec[i](inputs, active, elapsed, None, data)
        ]

    def _elapsed(self, sit: Situation, after_time: bool) -> frozenset[str]:
        """The elapsed timers of ``sit``, with ``after_time`` all of its active steps' (time passes)."""
        if not after_time:
            return frozenset(sit.elapsed)
        return frozenset(sit.elapsed).union(*(self._timers_of_step.get(s, ()) for s in sit.steps))

    def enabling_events(self, sit: Situation, t: Transition, inputs: Mapping[str, bool],
                        after_time: bool = False) -> tuple[Event, ...]:
        """The single input changes that would make ``t`` fireable in ``sit`` (inputs at
        ``inputs``; with ``after_time``, once the timers of its active steps have elapsed),
        in input-name order.

        >>> from synth.grafcet.language_check import parse_grafcet
        >>> m = GrafcetMachine(parse_grafcet("grafcet G { initial step 0 step 1 "
        ...                    "transition 0 -> 1 when ↑a . !b }"))
        >>> s0 = m.initial({"a": False, "b": False})
        >>> m.enabling_events(s0, m.transitions[0], {"a": False, "b": False})
        ('↑a',)
        """
        i = self._index[t]
        active, elapsed = frozenset(sit.steps), self._elapsed(sit, after_time)
        out = []
        for x in sorted(self._rec_inputs[i] & inputs.keys()):
            after = dict(inputs)
            after[x] = not inputs[x]
            event = Event.edge(x, after[x])
            if self._rec[i](after, active, elapsed, event, sit.values):
                out.append(event)
        return tuple(out)

    def first_events(self, sit: Situation, t: Transition, inputs: Mapping[str, bool],
                     limit: int = 12, after_time: bool = False) -> tuple[tuple[Event, ...], Event | None]:
        """When no single input change makes ``t`` fireable: the fewest input changes needed
        first and the one that then fires it (``↑a & b``, ``a`` true, ``b`` false: ``↓a``, ``↑b``,
        then ``↑a``); ``((), None)`` when none does or it reads over ``limit`` inputs.

        >>> from synth.grafcet.language_check import parse_grafcet
        >>> m = GrafcetMachine(parse_grafcet("grafcet G { initial step 0 step 1 transition 0 -> 1 when ↑a & b }"))
        >>> m.first_events(m.initial({"a": True, "b": False}), m.transitions[0], {"a": True, "b": False})
        (('↓a', '↑b'), '↑a')
        """
        from itertools import product

        i = self._index[t]
        active, elapsed = frozenset(sit.steps), self._elapsed(sit, after_time)
        names = sorted(self._rec_inputs[i] & inputs.keys())
        best: tuple[int, tuple[Event, ...], Event] | None = None
        for values in product((False, True), repeat=len(names) if len(names) <= limit else 0):
            before = dict(zip(names, values))
            changes = tuple(Event.edge(x, v) for x, v in before.items() if v != inputs[x])
            if best is not None and len(changes) + 1 >= best[0]:
                continue
            for y in names:
                after = {**inputs, **before, y: not before[y]}
                if self._rec[i](after, active, elapsed, Event.edge(y, after[y]), sit.values):
                    best = (len(changes) + 1, changes, Event.edge(y, after[y]))
                    break
        return ((), None) if best is None else (best[1], best[2])

    def waiting_steps(self, sit: Situation, t: Transition) -> tuple[str, ...]:
        """Step variables read by ``t``'s receptivity whose step is not active in ``sit``."""
        return tuple(sorted(step_variable(s) for s in self._rec_steps[self._index[t]] if s not in sit.steps))

    def receptivity(self, i: int) -> CompiledFn:
        """Transition ``i``'s receptivity, compiled: what every evolution of this machine
        calls (the symbolic step encoding calls it on recorded inputs)."""
        return self._rec[i]

    def condition(self, step: str, i: int) -> CompiledFn:
        """The compiled condition of action ``i`` of ``step`` (a conditional action)."""
        return self._cond[(step, i)]

    def event_inputs(self, step: str) -> frozenset[str]:
        """The inputs read by ``step``'s stored actions and assignments on an event."""
        return self._event_inputs[step]

    def relevant_inputs(self, sit: Situation) -> frozenset[str]:
        """Inputs whose change may change ``sit``: read by an enabled transition or by an
        event action of an active step (with ``--semantics sfc``, where event actions run
        after the scan's evolution, also of the steps an enabled transition activates)."""
        active = set(sit.steps)
        used: set[str] = set()
        for i, t in enumerate(self.transitions):
            if all(s in active for s in t.sources):
                used |= self._rec_inputs[i]
                if self.sfc:
                    for s in t.targets:
                        used |= self._event_inputs[s]
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

    def _state(self, sit: Situation) -> State:
        return State(set(sit.steps), set(sit.stored), set(sit.elapsed), dict(sit.data))

    def _situation(self, st: State) -> Situation:
        return Situation(sorted_steps(st.active), tuple(sorted(st.stored)), tuple(sorted(st.elapsed)),
                         tuple(st.data.items()))

    def _apply(self, st: State, stored: list[Action], assignments: list[Action]) -> None:
        """Stored actions (sets first, then resets: reset wins) and assignments (simultaneous)."""
        st.stored |= {a.order for a in stored if a.value}
        st.stored -= {a.order for a in stored if not a.value}
        if assignments:
            assign(st.data, assignments, self.internals, self._situation(st).text())

    def _stored_phase(self, st: State, steps: set[str], when: StoredWhen) -> None:
        """Stored actions and assignments of ``steps`` for ``when``."""
        phase = self._phase[when]
        acting = [s for s in steps if s in phase]  # most steps have none: no sort, no pass
        if not acting:
            return
        acts = [a for s in sorted_steps(acting) for a in phase[s]]
        self._apply(st, [a for a in acts if a.kind == STORED], [a for a in acts if a.kind == ASSIGN])

    def _event_actions(self, st: State, inputs: Mapping[str, bool], event: Event) -> None:
        active, elapsed, data = frozenset(st.active), frozenset(st.elapsed), st.data
        acts = [a for s in sorted_steps(st.active) for i, a in enumerate(self._steps[s].actions)
                if a.when == ON_EVENT and self._cond[(s, i)](inputs, active, elapsed, event, data)]
        self._apply(st, [a for a in acts if a.kind == STORED], [a for a in acts if a.kind == ASSIGN])

    def _settle(
        self,
        st: State,
        inputs: Mapping[str, bool],
        event: Event | None,
        rounds: list[tuple[Transition, ...]],
    ) -> None:
        """Search for stability, in place. Edges (``event``) hold in the first round only."""
        seen: dict[tuple[frozenset[str], frozenset[str], frozenset[str], tuple[tuple[str, int], ...]], int] = {}
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
            data = st.data
            fire = tuple(self.transitions[i] for i in self._enabled(active) if rec[i](inputs, active, elapsed, ev, data))
            first = False
            if not fire:
                return
            history.append(fire)
            rounds.append(fire)
            self._fire(st, fire)
            if self.sfc:  # IEC 61131-3 SFC: this round is the scan's one evolution
                return

    def _fire(self, st: State, fire: tuple[Transition, ...]) -> None:
        """Rules 3 and 5: fire ``fire`` at once, with the stored actions and assignments."""
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
        steps = sorted_steps({s for fire in cycle for t in fire for s in (*t.sources, *t.targets)})
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

"""The automaton of the stable situations (ASS) of a Grafcet.

:func:`stable_situation_automaton` explores all stable situations reachable from the
initial one, with every input the Grafcet reads free to change (one at a time) and
every running timer free to elapse (see :mod:`synth.grafcet.machine` for the evolution
rules and ``docs/method.md`` for the reading of the thesis).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from functools import partial
from typing import Callable, Mapping, NamedTuple

from synth.errors import LimitExceeded
from synth.logic.cubes import Cubes, condition_text
from synth.logic.events import Event, EventKind
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.grafcet.recorder import InputRecorder

__all__ = ["ASSState", "ASSTransition", "ASS", "stable_situation_automaton", "stable_situations", "MAX_INPUTS"]



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
    event: Event
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
    per_scan: bool = False  # --semantics sfc: the situations after each PLC scan, not stable ones

    def state_of(self, sit: Situation) -> ASSState:
        for s in self.states:
            if s.situation == sit:
                return s
        raise KeyError(sit.text())

    def successors(self, state: int) -> tuple[ASSTransition, ...]:
        return tuple(t for t in self.transitions if t.source == state)


MAX_INPUTS = 20


class _Explored(NamedTuple):
    """What the exploration of :func:`stable_situation_automaton` found."""

    cubes: Cubes
    position: dict[str, int]  # read input -> its bit in a vector
    read: tuple[str, ...]
    base: dict[str, bool]
    sits: list[Situation]
    reached: list[int]  # per situation, the input vectors it is reached with
    moves: dict[tuple[int, Event], dict[int, int]]  # (situation, label) -> {target: vectors before}
    labels: list[Event]

    def valuation(self, v: int) -> dict[str, bool]:
        return _valuation(self.base, self.position, v)


def _valuation(base: dict[str, bool], index: dict[str, int], v: int) -> dict[str, bool]:
    """The inputs' values: ``base``, with the read inputs (bit ``index[n]``) taken from ``v``."""
    d = dict(base)
    for n, i in index.items():
        d[n] = bool(v >> i & 1)
    return d


def stable_situations(machine: GrafcetMachine, *, max_states: int = 100_000,
                      max_reactions: int | None = None) -> tuple[Situation, ...]:
    """The situations of the ASS of ``machine`` (inputs all 0 at first), without its orders nor
    the conditions of its transitions, in an order of their own (what needs only the set of
    situations is spared the covers of every reached input vector). ``max_reactions``: at most
    that many runs of the machine, else :class:`~synth.errors.LimitExceeded`.

    >>> from synth.grafcet.language_check import parse_grafcet
    >>> g = parse_grafcet("grafcet G { initial step 0 step 1: A "
    ...                   "transition 0 -> 1 when ↑a . b  transition 1 -> 0 when !b }")
    >>> [s.text() for s in stable_situations(GrafcetMachine(g))]
    ['{X0}', '{X1}']
    """
    return tuple(_explore(machine, None, max_states, None, closed=True, max_reactions=max_reactions).sits)


def _explore(machine: GrafcetMachine, initial_inputs: Mapping[str, bool] | None, max_states: int,
             admissible: Callable[[Mapping[str, bool]], bool] | None, closed: bool = False,
             max_reactions: int | None = None) -> _Explored:
    """The pairs (stable situation, input vectors) reachable from the initial situation, and
    the moves between situations (see :func:`stable_situation_automaton`). ``closed``: each
    situation taken from the queue first gets every vector the inputs its reactions ignore
    reach (the same pairs in the end, found in fewer passes but in another order, so the
    situations' numbering differs: for :func:`stable_situations` only)."""
    base = {n: bool((initial_inputs or {}).get(n, False)) for n in machine.inputs}
    read = machine.read_inputs
    n_in = len(read)
    if n_in > MAX_INPUTS:
        raise LimitExceeded(f"the Grafcet reads {n_in} inputs; the ASS is explored for at most {MAX_INPUTS}")
    index = {n: i for i, n in enumerate(read)}
    cubes = Cubes(n_in)
    valuation = partial(_valuation, base, index)

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
    by_steps: dict[tuple[str, ...], int] = {}
    cube_of: dict[tuple[tuple[int, bool], ...], int] = {}
    timers: list[tuple[Event, ...]] = []
    labels: list[Event] = [Event.edge(n, r) for n in read for r in (True, False)]
    # (situation, label) -> [(vectors covered, target)], from memoised runs
    memo: dict[tuple[int, Event], list[tuple[int, int]]] = {}
    # (situation, label) -> {target: vectors before the event}
    moves: dict[tuple[int, Event], dict[int, int]] = {}
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
            bits = by_steps.get(sits[j].steps)  # the relevant inputs depend on the active steps alone
            if bits is None:
                bits = by_steps[sits[j].steps] = sum(1 << index[x] for x in machine.relevant_inputs(sits[j]) if x in index)
            relevant.append(bits)
            timers.append(machine.timers(sits[j]))
        return k

    known(s0)
    runs = [0]  # the machine's runs so far

    def classify(k: int, event: Event, after: int) -> dict[int, int]:
        """Target situation of each vector of ``after`` (values once the event happened)."""
        entries = memo.setdefault((k, event), [])
        out: dict[int, int] = {}
        rest = after
        for covered, target in entries:
            hit = rest & covered
            if hit:
                out[target] = out.get(target, 0) | hit
                rest ^= hit
        while rest:
            runs[0] += 1
            if max_reactions is not None and runs[0] > max_reactions:
                raise LimitExceeded(f"more than {max_reactions} reactions while building the ASS")
            v = (rest & -rest).bit_length() - 1
            reader = InputRecorder(partial(valuation, v))
            if event.kind is EventKind.TIMER:
                result = machine.fire_timer_with_trace(sits[k], event, reader)[0]
            elif event.kind is EventKind.SCAN:
                result = machine.scan(sits[k], reader)[0]
            else:
                result = machine.react_event(sits[k], event, reader)[0]
            target = known(result)
            cell = tuple((index[n], x) for n, x in reader.cell().items() if n in index)
            known_cube = cube_of.get(cell)
            if known_cube is None:  # the same few cells come back in situation after situation
                known_cube = cube_of[cell] = cubes.cube(dict(cell))
            covered = known_cube
            entries.append((covered, target))
            hit = rest & covered
            out[target] = out.get(target, 0) | hit
            rest ^= hit
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
        if closed:  # the vectors the inputs k's reactions ignore reach, at once (no admissible: a product)
            more = todo
            for i in range(n_in):
                if not relevant[k] >> i & 1:
                    more |= cubes.flip(more, i)
            todo |= more & ~reached[k]
            reached[k] |= todo
        for i, n in enumerate(read):
            if not relevant[k] >> i & 1:  # both edges at once: k again, with the input flipped
                if not closed:
                    after = cubes.flip(todo, i)
                    add(k, after if allowed == -1 else after & allowed)
                continue
            for rising in (True, False):
                src = todo & (cubes.zero[i] if rising else cubes.one[i])
                if not src:
                    continue
                after = cubes.flip(src, i)
                if allowed != -1:
                    after &= allowed
                    if not after:
                        continue
                label = labels[2 * i + (0 if rising else 1)]
                for target, vecs in classify(k, label, after).items():
                    add(target, vecs)
                    if target != k:
                        m = moves.setdefault((k, label), {})
                        m[target] = m.get(target, 0) | cubes.flip(vecs, i)
        for t in timers[k] + ((Event.scan(),) if machine.sfc else ()):
            for target, vecs in classify(k, t, todo).items():
                add(target, vecs)
                if target != k:
                    m = moves.setdefault((k, t), {})
                    m[target] = m.get(target, 0) | vecs
    return _Explored(cubes, index, read, base, sits, reached, moves, labels)


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

    >>> from synth.grafcet.language_check import parse_grafcet
    >>> g = parse_grafcet("grafcet G { initial step 0 step 1: A "
    ...                   "transition 0 -> 1 when ↑a . b  transition 1 -> 0 when !b }")
    >>> ass = stable_situation_automaton(GrafcetMachine(g))
    >>> [(s.id, s.situation.text(), s.orders) for s in ass.states]
    [(0, '{X0}', ()), (1, '{X1}', ('A',))]
    >>> [(t.source, t.event, t.condition, t.target) for t in ass.transitions]
    [(0, '↑a', 'b', 1), (1, '↓b', 'any', 0)]
    """
    ex = _explore(machine, initial_inputs, max_states, admissible)
    cubes, index, read, sits, reached, moves, labels = ex.cubes, ex.position, ex.read, ex.sits, ex.reached, ex.moves, ex.labels
    valuation, n_in = ex.valuation, len(read)
    # states, with the orders they emit
    states: list[ASSState] = []
    for k, sit in enumerate(sits):
        emitted: set[frozenset[str]] = set()
        rest = reached[k]
        while rest:  # one run per cube of the inputs the orders read, not one per vector
            reader = InputRecorder(partial(valuation, (rest & -rest).bit_length() - 1))
            emitted.add(machine.orders(sit, reader))
            rest &= ~cubes.cube({index[n]: x for n, x in reader.cell().items() if n in index})
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
            trans.append(ASSTransition(k, label, condition_text(cubes, on, domain & ~on, read, free), target))
    trans.sort(key=lambda t: (t.source, rank.get(t.event, len(rank)), t.event, t.target))
    return ASS(tuple(states), tuple(trans), 0, read, tuple((n, ex.base[n]) for n in read), machine.sfc)

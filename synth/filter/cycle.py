"""One PLC cycle of a filter, evaluated in Python: the reference semantics that
``synth filter run`` and ``synth filter verify`` use and that the Structured Text
generator reproduces.

Semantics (docs/filter.md, "One PLC cycle"):

- *observers* declared ``observer P := EXPR`` are computed first, from the inputs, the
  requests and the memory (any other observer is read like an input);
- *memory*: the previous cycle's value ``x^-1`` of every input, observer and output
  of the filter (and of a request, when the file reads ``R_o^-1``), all FALSE
  initially, stored at the end of the cycle (the inputs read, the outputs produced);
  ``↑x`` is ``x & !x^-1`` and ``↓x`` is ``!x & x^-1``;
- :attr:`Mode.SUPERVISOR`: the effective requests are ``g1 = R``.
  :attr:`Mode.BLOCKING` adds the input ``Ack`` and a latch ``Blocked``: at the start of
  the cycle ``IF Ack THEN Blocked := FALSE``; if the raw requests violate a constraint
  (``O := R`` with the current Y and memory) then ``Blocked := TRUE``; ``g1 = R & !Blocked``;
- :attr:`Algorithm.ALGEBRAIC`: ``O`` is given by the block's chained equations
  (:mod:`synth.filter.block`, what ``synth filter st`` emits), assigned in their order,
  each reading the outputs assigned before it; on the care set they are the synthesis,
  off it they are still exactly what the block computes (``outside_care`` says when the
  cycle's Y is not in it, i.e. breaks an assumption or admits no safe vector);
- :attr:`Algorithm.LOOP`: the corrected loop of docs/filter.md (fc0/fc1 accumulate, at
  most Ncsc+1 iterations, ``Fallback`` when a combined constraint is still violated);
  ``literal=True`` runs the published code instead (fc reset at each iteration, final
  test ``Cpt > Ncsc``), to show its two defects.

Every function (constraints, the block's fs0/fs1 and equations, care set) is taken as an
exact cover of cubes of its BDD. A cycle is evaluated on *lanes*: each value is a Python int
whose bit ``j`` is the value in lane ``j``, so :meth:`FilterCycle.lanes` evaluates the
cycle for every valuation of some names at once (``verify --any-control`` uses it for
the 2^|O| request vectors); :meth:`FilterCycle.step` is one lane.

Example (docs/filter.md, "The correction loop", example A)
-------
>>> from synth.filter.language_check import parse_filter
>>> f = parse_filter("outputs o1, o2\\nsafety K: o1 & o2 keep o1", "a.filter")
>>> c = FilterCycle(f, Algorithm.LOOP)
>>> r, memory = c.step(c.initial(), {"R_o1": True, "R_o2": True})
>>> r.outputs, r.iterations, r.fallback, r.corrections
((True, False), ((True, True), (True, False)), False, ('o2',))
>>> FilterCycle(f, Algorithm.LOOP, literal=True).step(c.initial(), {"R_o1": True, "R_o2": True})[0].outputs
(False, False)
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Iterable, Mapping, Sequence

from synth.errors import InputError
from synth.logic.bdd import Cube
from synth.logic.lanes import Cover, compiled, lane_mask
from synth.filter.language import Filter
from synth.logic.past import base_name, is_pre, pre_name
from synth.filter.model import FilterFunctions, functions

TYPE_CHECKING = False
if TYPE_CHECKING:
    from synth.filter.local import Plan
    from synth.filter.solve import Synthesis

__all__ = ["Algorithm", "Mode", "ACK", "Memory", "CycleResult", "Lanes", "FilterCycle", "Cover"]

ACK = "Ack"


class Algorithm(StrEnum):
    """How the outputs are computed: the closed-form equations, or the correction loop."""

    ALGEBRAIC = "algebraic"
    LOOP = "loop"


class Mode(StrEnum):
    """How the requests reach the filter (000:136-158)."""

    SUPERVISOR = "supervisor"  # g1 = R: only the violating orders are corrected
    BLOCKING = "blocking"  # after a violation, g1 = 0 until Ack


@dataclass(frozen=True)
class Memory:
    """What a filter keeps from one cycle to the next: ``previous[i]`` is the value of
    ``FilterCycle.remembered[i]`` at the last cycle; ``blocked`` is the latch of
    :attr:`Mode.BLOCKING`."""

    previous: tuple[bool, ...]
    blocked: bool = False


@dataclass(frozen=True)
class CycleResult:
    """One cycle: the requests and the produced outputs (in ``outputs`` order), the loop's
    SI at each iteration, the fallback, the constraints the raw requests violate, the
    outputs corrected (O ≠ R), whether Y was outside the synthesis care set, the
    constraints the produced outputs still violate, and the Blocked latch after the cycle."""

    requests: tuple[bool, ...]
    outputs: tuple[bool, ...]
    iterations: tuple[tuple[bool, ...], ...]
    fallback: bool
    violated: tuple[str, ...]
    corrections: tuple[str, ...]
    outside_care: bool
    unsafe: tuple[str, ...]
    blocked: bool


@dataclass(frozen=True)
class Lanes:
    """A cycle evaluated on ``count`` lanes at once: every field is a bit mask over the
    lanes (bit j = lane j), per output or per constraint where it says so."""

    count: int
    requests: tuple[int, ...]
    outputs: tuple[int, ...]
    iterations: tuple[tuple[int, ...], ...]  # SI per iteration (lanes that stopped keep their SI)
    rounds: tuple[int, ...]  # rounds[n]: lanes still iterating at iteration n+1
    fallback: int
    violated: dict[str, int]  # constraint id -> lanes where the raw requests violate it
    unsafe: dict[str, int]  # constraint id -> lanes where the outputs violate it
    outside_care: int
    blocked: int  # the latch after the cycle
    previous: tuple[int, ...]  # the memory after the cycle, per remembered name
    names: tuple[str, ...] = ()  # the outputs, in order

    def lane(self, j: int) -> tuple[CycleResult, Memory]:
        """Lane ``j`` as one cycle's result and the memory it leaves."""

        def bit(m: int) -> bool:
            return bool((m >> j) & 1)

        n = sum(1 for r in self.rounds if bit(r))
        outs = tuple(bit(o) for o in self.outputs)
        reqs = tuple(bit(r) for r in self.requests)
        result = CycleResult(
            reqs, outs, tuple(tuple(bit(s) for s in si) for si in self.iterations[:n]), bit(self.fallback),
            tuple(i for i, m in self.violated.items() if bit(m)),
            tuple(o for o, r, v in zip(self.names, reqs, outs) if r != v), bit(self.outside_care),
            tuple(i for i, m in self.unsafe.items() if bit(m)), bit(self.blocked))
        return result, Memory(tuple(bit(p) for p in self.previous), bit(self.blocked))


def _cover(cubes: Iterable[Cube]) -> Cover:
    return tuple(tuple(c.items()) for c in cubes)


class _Compiled:
    """A cycle's covers compiled for lanes (:mod:`synth.logic.lanes`): one function per
    group the cycle evaluates at once, each giving its covers' values in order."""

    def __init__(self, c: "FilterCycle") -> None:
        late = {*c.requests, *c.outputs}  # the names that vary from lane to lane, as a rule
        self.constraint = compiled(tuple(c.constraint.values()), late)
        self.combined = compiled(tuple(c.constraint[i] for i in c.combined), late)
        self.fs = compiled((*c.fs0.values(), *c.fs1.values()), late)
        self.equations = tuple((o, compiled((u,), late)) for o, u in c.equations)
        self.care = compiled((c.care,), late)
        self.defined = tuple((n, compiled((u,), late)) for n, u in c.defined)
        self.previous = tuple(pre_name(n) for n in c.remembered)


class FilterCycle:
    """The cycle evaluator of one filter (see the module docstring)."""

    def __init__(self, f: "Filter | FilterFunctions | Synthesis", algorithm: Algorithm = Algorithm.ALGEBRAIC,
                 mode: Mode = Mode.SUPERVISOR, *, literal: bool = False) -> None:
        from synth.filter.block import algebraic_equations, loop_model
        from synth.filter.solve import Synthesis, synthesis

        solved = f if isinstance(f, Synthesis) else None
        if isinstance(f, Synthesis):
            m = f.functions
        else:
            m = f if isinstance(f, FilterFunctions) else functions(f)
        self.functions, self.filter = m, m.filter
        self.algorithm, self.mode, self.literal = Algorithm(algorithm), Mode(mode), literal
        e, flt = m.engine, m.filter
        self.outputs: tuple[str, ...] = flt.outputs
        self.requests: tuple[str, ...] = flt.requests
        self.constraint: dict[str, Cover] = {i: _cover(e.cover(u)) for i, u in m.constraint.items()}
        self.combined: tuple[str, ...] = tuple(s.id for s in flt.combined)
        loop = loop_model(m)
        self.fs0 = {o: _cover(e.cover(e.expr(x))) for o, x in zip(self.outputs, loop.fs0)}
        self.fs1 = {o: _cover(e.cover(e.expr(x))) for o, x in zip(self.outputs, loop.fs1)}
        # MC0/MC1 as lists: output -> the combined constraints whose relief forces it to 0 / 1
        self.mc0 = {o: tuple(i for i, on in zip(self.combined, row) if on) for o, row in zip(self.outputs, loop.mc0)}
        self.mc1 = {o: tuple(i for i, on in zip(self.combined, row) if on) for o, row in zip(self.outputs, loop.mc1)}
        self.equations: tuple[tuple[str, Cover], ...] = ()  # the block's assignments, in order
        self.plan: "Plan | None" = None  # or the block's chain on truth tables
        self.care: Cover = ((),)
        past: set[str] = set()  # the past values the plan reads
        if self.algorithm is Algorithm.ALGEBRAIC:
            s = solved if solved is not None else synthesis(m)
            if s.free:
                o = next(iter(s.free))
                raise InputError(f"the algebraic filter of {flt.file} is not functional: {o} is free "
                                 f"(solve reports the witness); add criteria or use --algorithm loop", None)
            if s.plan is not None:  # the chain on truth tables (synth.filter.local), as the block runs it
                self.plan = s.plan
                tables = (*(b.relation for b in s.plan.bags), *(g for _, g in s.plan.steps))
                self.care = _cover(e.cover(s.care))
                past = {n for u in tables for n in e.support(u) if is_pre(n)}
            else:
                self.equations = tuple((o, _cover(e.cover(e.expr(x)))) for o, x in algebraic_equations(s))
                self.care = _cover(e.cover(s.care))
        else:
            for c in flt.combined:
                if not c.has_priority:
                    raise InputError(f"{c.id} is a combined constraint without priority: the loop needs "
                                     "`keep L` or `force o=v, ...` to relieve it", c.loc)
        # observers declared ``observer P := EXPR``: computed at the start of every cycle
        self.defined: tuple[tuple[str, Cover], ...] = tuple(
            (d.name, _cover(e.cover(e.expr(d.definition)))) for d in flt.observers if d.definition is not None)
        covers = [*self.constraint.values(), *self.fs0.values(), *self.fs1.values(),
                  *(c for _, c in self.equations), self.care, *(c for _, c in self.defined)]
        used = sorted({n for cover in covers for cube in cover for n, _ in cube if is_pre(n)} | past)
        base = [*flt.inputs, *flt.observer_names, *self.outputs]
        base += [b for b in (base_name(n) for n in used) if b not in base]
        self.remembered: tuple[str, ...] = tuple(base)
        self.used: tuple[str, ...] = tuple(b for b in self.remembered if pre_name(b) in used)
        self._run = _Compiled(self)
        computed = {n for n, _ in self.defined}
        self.reads: tuple[str, ...] = (*flt.inputs, *(n for n in flt.observer_names if n not in computed),
                                       *self.requests) + ((ACK,) if self.mode is Mode.BLOCKING else ())

    # ------------------------------------------------------------------ public API
    def initial(self) -> Memory:
        """Every remembered value FALSE, not blocked."""
        return Memory((False,) * len(self.remembered), False)

    def step(self, memory: Memory, values: Mapping[str, bool]) -> tuple[CycleResult, Memory]:
        """One cycle: ``values`` gives every name of :attr:`reads` (inputs, observers,
        requests ``R_o``, and ``Ack`` in blocking mode); returns its result and the new memory."""
        return self.lanes(memory, values, ()).lane(0)

    def lanes(self, memory: Memory, fixed: Mapping[str, bool], free: Sequence[str], *,
              diagnose: bool = True) -> Lanes:
        """The cycle for every valuation of the names ``free`` (lane j: bit i of j is the
        value of ``free[i]``), the other names of :attr:`reads` given by ``fixed``.

        With ``diagnose=False`` the produced outputs are not checked against the
        constraints: ``unsafe`` is empty, every other field the same (the closed loop reads
        the outputs, the memory, the latch, the fallback, the care set and, as an outcome's
        witness, the constraints the raw requests violate)."""
        if self.literal and free:
            raise ValueError("the literal published loop is evaluated one lane at a time")
        count = 1 << len(free)
        full = (1 << count) - 1
        values: dict[str, int] = {}
        for i, n in enumerate(free):
            values[n] = lane_mask(i, count)
        for n in self.reads:
            if n not in values:
                if n not in fixed:
                    raise KeyError(f"no value for '{n}'")
                values[n] = full if fixed[n] else 0
        run = self._run
        for n, v in zip(run.previous, memory.previous):
            values[n] = full if v else 0
        for n, fn in run.defined:  # from the inputs, the requests and the memory
            values[n] = fn(values, full)[0]
        requests = tuple(values[r] for r in self.requests)
        with_requests = dict(values)
        with_requests.update(zip(self.outputs, requests))
        violated = dict(zip(self.constraint, run.constraint(with_requests, full)))
        blocked = 0
        g1 = requests
        if self.mode is Mode.BLOCKING:
            blocked = (0 if not memory.blocked else full) & (full ^ values[ACK])
            any_violation = 0
            for mask in violated.values():
                any_violation |= mask
            blocked |= any_violation
            g1 = tuple(r & (full ^ blocked) for r in requests)
        iterations: list[tuple[int, ...]] = []
        rounds: list[int] = []
        fallback = 0
        outside = 0
        if self.algorithm is Algorithm.ALGEBRAIC:
            with_g1 = dict(values)
            with_g1.update(zip(self.requests, g1))
            outside = full ^ run.care(with_g1, full)[0]
            for o, fn in run.equations:  # in the block's order: each reads the outputs before it
                with_g1[o] = fn(with_g1, full)[0]
            outputs = tuple(with_g1[o] for o in self.outputs) if self.plan is None else self._tables(with_g1, count)
        else:
            outputs, fallback = self._loop(values, g1, full, iterations, rounds)
        with_outputs = dict(values)
        with_outputs.update(zip(self.outputs, outputs))
        unsafe = dict(zip(self.constraint, run.constraint(with_outputs, full))) if diagnose else {}
        previous = tuple(with_outputs[n] for n in self.remembered)
        return Lanes(count, requests, outputs, tuple(iterations), tuple(rounds), fallback,
                     violated, unsafe, outside, blocked, previous, self.outputs)

    def _tables(self, values: Mapping[str, int], count: int) -> tuple[int, ...]:
        """The outputs of the block on truth tables (:func:`synth.filter.local.run`), lane by lane."""
        from synth.filter.local import Booleans, run

        assert self.plan is not None
        outs = [0] * len(self.outputs)
        for j in range(count):
            ones = run(self.plan, Booleans(self.functions.engine, {n: bool(v >> j & 1) for n, v in values.items()})).ones
            for k, o in enumerate(self.outputs):
                outs[k] |= ones[o] << j
        return tuple(outs)

    # ------------------------------------------------------------------ the loop
    def _loop(self, values: dict[str, int], g1: tuple[int, ...], full: int, iterations: list, rounds: list
              ) -> tuple[tuple[int, ...], int]:
        outs, run = self.outputs, self._run
        fs = run.fs(values, full)
        fs0, fs1 = fs[:len(outs)], fs[len(outs):]
        fc0 = [0] * len(outs)
        fc1 = [0] * len(outs)
        ncsc = len(self.combined)
        flag, cpt = full, 0  # flag: lanes still violated; the WHILE runs where flag is set
        si: list[int] = [0] * len(outs)
        while flag and cpt <= ncsc:
            rounds.append(flag)
            new = [((full ^ fs0[k]) & (((full ^ fc0[k]) & g1[k]) | fc1[k])) | fs1[k] for k in range(len(outs))]
            si = [(n & flag) | (s & (full ^ flag)) for n, s in zip(new, si)]  # stopped lanes keep their SI
            iterations.append(tuple(si))
            at = dict(values)
            at.update(zip(outs, si))
            v = {i: m & flag for i, m in zip(self.combined, run.combined(at, full))}
            flag_now = 0
            for m in v.values():
                flag_now |= m
            cpt += 1
            if self.literal:
                fc0 = [0] * len(outs)
                fc1 = [0] * len(outs)
            for k, o in enumerate(outs):
                for i in self.mc0[o]:
                    fc0[k] |= v[i]
                for i in self.mc1[o]:
                    fc1[k] |= v[i]
            flag = flag_now
        fallback = (full if cpt > ncsc else 0) if self.literal else flag
        if fallback:
            si = [(((full ^ fs0[k]) & fs1[k]) & fallback) | (si[k] & (full ^ fallback)) for k in range(len(outs))]
        return tuple(si), fallback


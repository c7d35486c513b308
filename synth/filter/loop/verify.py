"""``synth filter verify``: the filter in closed loop with synth's plant (docs/filter.md, "The closed loop").

The explored product has one node per (plant state, filter memory, Blocked latch,
Grafcet situation). One **PLC cycle** from a node:

1. the plant makes zero to ``events_per_cycle`` (default 1) uncontrollable events in
   sequence (its asynchronous semantics; with a Grafcet, a running timer may elapse
   instead);
2. the PLC reads Y (the plant's inputs; observers are the Grafcet's step variables);
3. the requests R: the Grafcet reacts and its orders are R (``--grafcet``), or R is any
   of the 2^|O| vectors (``--any-control``); in blocking mode ``Ack`` is free too;
4. the filter computes O (:class:`~synth.filter.cycle.FilterCycle`);
5. the orders that change are applied as the plant's controllable events, **falls
   first, then rises, each in the plant's output order** (an order is released before
   another is taken); with ``atomic=True`` all at once (one step, no intermediate state).

Plant orders the filter does not declare are passed through (O = R for them); an order
the rules ``hold`` is requested at its held value.

Verdicts, over everything reachable:

- (a) *safe*: no node (a plant state once the PLC has written its outputs) violates a
  level constraint of the rules, no output event breaks an edge constraint, and the
  plant accepts every output change. The filter's constraints hold *at the end of
  every cycle*; between the plant's event and the next write the plant may briefly be
  in a violating state the filter could not prevent (the PLC is synchronous, the plant
  asynchronous): such *transient* states — and the intermediate states of an ordered
  write — are counted and shown but fail the verdict only with ``strict=True``. Nodes
  outside SUP (a violation reachable by uncontrollable events alone) are counted, and
  fail the verdict only with ``require_sup=True``;
- (b) *coherent*: the loop never falls back and the algebraic filter never meets a Y
  outside its care set;
- (c) with a Grafcet: the cycles where O ≠ R and the largest Hamming distance.

With ``progress=GOAL`` (an expression over the plant's variables, or an edge ``↑x`` /
``↓x``: x changes between the end of one cycle and the end of the next), also: GOAL stays
reachable from every reachable node, and no *fair* cycle of the product avoids it (every
step of the product is a PLC scan; fair: the plant does not keep an event enabled forever
without making it, nor the Grafcet a running timer) -- :class:`~synth.filter.loop.verification.Progress`.

Every finding comes with a shortest trace (breadth-first, in cycles). The exploration is
explicit (numpy arrays of the reached nodes' integer codes, one level of the
breadth-first search at a time; nothing held per plant state) and stops after
``max_states`` nodes. The parts: the product (:mod:`~synth.filter.loop.product`, the plant
as functions of state codes in :mod:`~synth.filter.loop.columns`), the search (:mod:`~synth.filter.loop.explorer`, one cycle's
outcomes in :mod:`~synth.filter.loop.outcomes`) and what it finds
(:mod:`~synth.filter.loop.verification`); :mod:`synth.output.filter_text` prints it.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.filter.from_rules import skeleton
>>> sk = skeleton(_plants("tri.rules"), _plants("F.filter"))  # the text only: nothing is written
>>> v = verify(sk.filter, _plants("tri.rules"), any_control=True)
>>> v.safe, v.coherent, v.states > 1000
(True, True, True)
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from synth.choices import EngineChoice
from synth.engines import Command, Need, decide, refuse
from synth.errors import InputError, close_names
from synth.filter.loop.control_st import StSource
from synth.filter.cycle import Algorithm, Mode
from synth.filter.loop.explorer import Explorer
from synth.filter.language import Filter
from synth.filter.loop.outcomes import trace_row
from synth.filter.loop.product import Product, rules_of
from synth.filter.loop.verification import (ANY_CONTROL, Control, ControlKind, FindingKind, Progress, ProgressFailure,
                                       TraceRow, Verification)
from synth.logic.events import Event
from synth.logic.expr import Edge, Expr, evaluate, names
from synth.plant.composition import Plant, load_plant, plant

TYPE_CHECKING = False  # typing.TYPE_CHECKING: the Grafcet modules load only with --grafcet
if TYPE_CHECKING:
    from synth.grafcet.language import Grafcet

__all__ = ["verify", "verify_explicit", "plant_of", "Goal", "goal_of", "DEFAULT_MAX_STATES"]

DEFAULT_MAX_STATES = 1_000_000
"""The explicit engine's default ``--max-states``."""

GOAL_FILE = "--progress"
"""The file name of the located errors of a ``--progress`` expression."""


def verify(f: Filter, rules_path: str, grafcet: str | None = None, *, any_control: bool = False,
           algorithm: Algorithm = Algorithm.ALGEBRAIC, mode: Mode = Mode.SUPERVISOR, atomic: bool = False,
           strict: bool = False, require_sup: bool = False, max_states: int | None = DEFAULT_MAX_STATES,
           events_per_cycle: int = 1, progress: str | None = None, control: StSource | None = None,
           engine: EngineChoice = EngineChoice.EXPLICIT, report: Callable[[str], None] | None = None) -> Verification:
    """``synth filter verify``: read each input once, let :func:`synth.engines.decide`
    choose the engine, run it on the loaded models. ``control``: ``--control
    PROG.st[:NAME]``; ``engine``: ``symbolic`` (or ``auto`` on a large plant) runs
    :func:`~synth.filter.loop.symbolic.verify.verify_symbolic` (``--any-control`` only; there
    ``max_states=None`` is no limit, explicitly it is 1000000), otherwise
    :func:`verify_explicit`. ``report`` receives progress lines."""
    if (grafcet is not None) + any_control + (control is not None) != 1:
        raise InputError("verify needs a request source: --grafcet G.g7, --control PROG.st or --any-control "
                         "(one of them)", None)
    if events_per_cycle < 0:
        raise InputError(f"--events-per-cycle is a number of plant events, 0 or more, not {events_per_cycle}", None)
    if max_states is not None and max_states < 1:
        raise InputError(f"--max-states is a number of states, 1 or more, not {max_states}", None)
    options = ({Need.CONTROLLER} if not any_control else set()) | ({Need.PROGRESS} if progress is not None else set())
    refuse(Command.FILTER_VERIFY, engine, options)  # before any input is read
    p = plant_of(f, rules_path)
    chosen = decide(Command.FILTER_VERIFY, engine, options, estimate=p.size, readers=p.readers, reads_at=p.reads_at)
    if chosen.engine is EngineChoice.SYMBOLIC:
        from synth.filter.loop.symbolic.verify import verify_symbolic

        return verify_symbolic(f, p, algorithm=algorithm, mode=mode, atomic=atomic, strict=strict,
                               require_sup=require_sup, max_states=max_states, events_per_cycle=events_per_cycle,
                               report=report)
    g = None
    if grafcet is not None:
        from synth.grafcet.language_check import load_grafcet

        g = load_grafcet(grafcet, inputs=rules_of(p).inputs, outputs=rules_of(p).outputs)
    return verify_explicit(f, p, g, algorithm=algorithm, mode=mode, atomic=atomic, strict=strict,
                           require_sup=require_sup, max_states=max_states, events_per_cycle=events_per_cycle,
                           progress=progress, control=control, report=report)


def plant_of(f: Filter, rules_path: str) -> Plant:
    """The plant of ``rules_path``, read once: from the rule set the filter read for its
    ``use`` when that is the same file (named as ``rules_path`` names it), else from the file."""
    if f.rules is not None and f.plant is not None and Path(f.plant).resolve() == Path(rules_path).resolve():
        return plant(dataclasses.replace(f.rules, path=str(rules_path)))
    return load_plant(rules_path)


def verify_explicit(f: Filter, p: Plant, g: Grafcet | None = None, *, algorithm: Algorithm = Algorithm.ALGEBRAIC,
                    mode: Mode = Mode.SUPERVISOR, atomic: bool = False, strict: bool = False,
                    require_sup: bool = False, max_states: int | None = DEFAULT_MAX_STATES, events_per_cycle: int = 1,
                    progress: str | None = None, control: StSource | None = None,
                    report: Callable[[str], None] | None = None) -> Verification:
    """The explicit engine (see the module docstring) on the plant ``p`` and the requests of
    the Grafcet ``g``, of the ST program ``control``, or of any control (neither); ``report``
    receives progress lines."""
    if max_states is None:
        max_states = DEFAULT_MAX_STATES
    started = time.perf_counter()
    pr = Product(f, p, g, Algorithm(algorithm), Mode(mode), atomic, control)
    goal = goal_of(progress, pr) if progress is not None else None
    ex = Explorer(pr, max_states, events_per_cycle, edges=goal is not None)
    ex.report = report
    ex.run()
    prog = progress_of(ex, goal) if goal is not None and ex.complete else None
    findings = ex.findings()
    if not require_sup:
        findings.pop(FindingKind.OUTSIDE_SUP, None)
    if pr.control is not None:
        source, how = f"PROGRAM {pr.control.program} of {pr.control.file}", Control(
            ControlKind.ST, pr.control.file, pr.control.program)
    elif g is not None:
        source, how = g.path, Control(ControlKind.GRAFCET, g.path)
    else:
        source, how = ANY_CONTROL, Control(ControlKind.ANY)
    return Verification(
        f.file, pr.rules.path, source, pr.cycle.algorithm, pr.cycle.mode,
        atomic, strict, ex.states, ex.plant_states,
        ex.loop_cycles[0], ex.complete,
        time.perf_counter() - started, len(ex.outside_sup), findings, ex.loop_cycles[1], ex.max_distance,
        events_per_cycle, prog, how)


@dataclass(frozen=True)
class Goal:
    """``--progress GOAL``: a condition on the plant's state, or an edge of a plant variable."""

    text: str
    expr: Expr | None = None
    edge: Event | None = None


def goal_of(text: str, pr: Product) -> Goal:
    """The goal of ``--progress`` (located errors in the file ``--progress``)."""
    from synth.filter.language_reader import filter_expression

    e = filter_expression(text, GOAL_FILE)
    known = pr.plant.variables
    for v in names(e):
        if v.name not in known:
            raise InputError(f"unknown variable '{v.name}' in --progress: GOAL names the plant's variables", v.loc,
                             suggestions=close_names(v.name, known))
        if isinstance(v, Edge) and e is not v:
            raise InputError("--progress: an edge is a whole goal (↑x or ↓x), not part of an expression", v.loc)
    if isinstance(e, Edge):
        return Goal(text, edge=Event.edge(e.name, e.rising))
    return Goal(text, expr=e)


# --------------------------------------------------------------------------- progress


def progress_of(ex: Explorer, goal: Goal) -> Progress:
    """Check ``goal`` on the complete product that ``ex`` explored with its edges."""
    pr, size = ex.pr, ex.size
    keys = np.array(ex.order, dtype=np.int64)
    n = keys.size
    codes = keys % size
    sorter = np.argsort(keys)
    parts = [np.concatenate(c) for c in zip(*ex.edge_parts)] if ex.edge_parts else [np.zeros(0, np.int64)] * 5
    src, dst, taken, seq, oid = parts
    s = sorter[np.searchsorted(keys, src, sorter=sorter)]
    d = sorter[np.searchsorted(keys, dst, sorter=sorter)]
    key = s * n + d  # one edge per (source, target): the first one's events, the union of the events taken
    order = np.argsort(key, kind="stable")
    ks = key[order]
    starts = np.flatnonzero(np.concatenate(([True], ks[1:] != ks[:-1]))) if ks.size else np.zeros(0, np.int64)
    first = order[starts]
    s, d, seq, oid = s[first], d[first], seq[first], oid[first]
    taken = np.bitwise_or.reduceat(taken[order], starts) if starts.size else taken.astype(np.uint64)
    if goal.edge is None:
        assert goal.expr is not None
        at = evaluate(goal.expr, lambda v: pr.val[v][codes])
        g_node = np.broadcast_to(np.asarray(at, dtype=bool), (n,)).copy()
        g_edge = np.zeros(s.size, dtype=bool)
    else:
        x, r = pr.val[goal.edge.name], goal.edge.rising
        g_node = np.zeros(n, dtype=bool)
        g_edge = (x[codes[s]] != r) & (x[codes[d]] == r)
    can = g_node.copy()
    can[s[g_edge]] = True
    _backward(can, s, d)
    stuck = np.flatnonzero(~can)
    inner = ~g_edge & ~g_node[s] & ~g_node[d]
    es, ed, et, eseq, eoid = s[inner], d[inner], taken[inner], seq[inner], oid[inner]
    labels = _scc(n, es, ed)
    internal = labels[es] == labels[ed]
    count = int(labels.max()) + 1 if n else 0
    cyclic = np.zeros(count, dtype=bool)
    cyclic[labels[es[internal]]] = True
    always = np.full(count, np.iinfo(np.uint64).max, dtype=np.uint64)
    np.bitwise_and.at(always, labels, _enabled(ex, keys))
    took = np.zeros(count, dtype=np.uint64)
    np.bitwise_or.at(took, labels[es[internal]], et[internal])
    fair = cyclic & ((always & ~took) == 0)
    on_fair = fair[labels]
    if stuck.size:
        rows = ex.trace(int(keys[stuck[0]]))
        rows[-1] = _noted(rows[-1], "GOAL cannot be reached from here")
        return Progress(goal.text, int(stuck.size), int(on_fair.sum()), ProgressFailure.UNREACHABLE, tuple(rows))
    if not on_fair.any():
        return Progress(goal.text, 0, 0)
    entry = int(np.argmax(on_fair))  # the first found
    rows = ex.trace(int(keys[entry]))
    mine = np.flatnonzero(internal & (labels[es] == labels[entry]))
    loop = _cycle(entry, es[mine], ed[mine])
    for j in loop:
        e = mine[j]
        t = int(ed[e])
        rows.append(trace_row(pr, ex.outcomes[int(eoid[e])], ex.events[int(eseq[e])], int(codes[t]),
                              ex.aux_list[int(keys[t]) // size][2]))
    rows[-1] = _noted(rows[-1], f"back to the state of cycle {len(rows) - len(loop) - 1}: a fair cycle avoids GOAL")
    return Progress(goal.text, 0, int(on_fair.sum()), ProgressFailure.AVOIDED, tuple(rows))


def _noted(row: TraceRow, note: str) -> TraceRow:
    return dataclasses.replace(row, note="; ".join(x for x in (row.note, note) if x))


def _enabled(ex: Explorer, keys: np.ndarray) -> np.ndarray:
    """The fairness bits of the events enabled in each node (plant events, running timers)."""
    pr, size = ex.pr, ex.size
    codes = keys % size
    out = np.zeros(keys.size, dtype=np.uint64)
    for e, nxt in pr.moves(codes):
        out |= (nxt >= 0).astype(np.uint64) << np.uint64(ex.fair[e])
    if pr.controlled:
        auxes = keys // size
        for aux in np.unique(auxes).tolist():
            for t in pr.timers(ex.aux_list[aux][2]):
                out[auxes == aux] |= np.uint64(ex.bit(t))
    return out


def _backward(can: np.ndarray, s: np.ndarray, d: np.ndarray) -> None:
    """Extend ``can`` to every node with a path into it."""
    n = can.size
    order = np.argsort(d, kind="stable")
    sources = s[order]
    ptr = np.searchsorted(d[order], np.arange(n + 1))
    frontier = np.flatnonzero(can)
    while frontier.size:
        lo, cnt = ptr[frontier], ptr[frontier + 1] - ptr[frontier]
        idx = np.repeat(lo, cnt) + np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        pred = np.unique(sources[idx])
        frontier = pred[~can[pred]]
        can[frontier] = True


def _scc(n: int, s: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The strongly connected component of each of ``n`` nodes (Tarjan's, iterative)."""
    order = np.argsort(s, kind="stable")
    target = d[order].tolist()
    ptr = np.searchsorted(s[order], np.arange(n + 1)).tolist()
    index, low = [-1] * n, [0] * n
    on = [False] * n
    stack: list[int] = []
    labels = np.full(n, -1, dtype=np.int64)
    counter = count = 0
    for root in range(n):
        if index[root] >= 0:
            continue
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on[root] = True
        work = [(root, ptr[root])]
        while work:
            v, i = work[-1]
            if i < ptr[v + 1]:
                work[-1] = (v, i + 1)
                w = target[i]
                if index[w] < 0:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on[w] = True
                    work.append((w, ptr[w]))
                elif on[w]:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                u = work[-1][0]
                low[u] = min(low[u], low[v])
            if low[v] == index[v]:
                while True:
                    w = stack.pop()
                    on[w] = False
                    labels[w] = count
                    if w == v:
                        break
                count += 1
    return labels


def _cycle(entry: int, s: np.ndarray, d: np.ndarray) -> list[int]:
    """The edges (indices into ``s``/``d``) of a shortest cycle from ``entry`` back to it."""
    out: dict[int, list[int]] = {}
    for j, a in enumerate(s.tolist()):
        out.setdefault(a, []).append(j)
    parent: dict[int, int] = {}
    queue, seen = [entry], {entry}
    for v in queue:
        for j in out.get(v, ()):
            w = int(d[j])
            if w == entry:
                path = [j]
                while v != entry:
                    path.append(parent[v])
                    v = int(s[parent[v]])
                return path[::-1]
            if w not in seen:
                seen.add(w)
                parent[w] = j
                queue.append(w)
    raise AssertionError("a node of a strongly connected component with an internal edge lies on a cycle")

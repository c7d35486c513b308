"""``synth filter verify``: the filter in closed loop with synth's plant (FILTER.md §3.4).

The explored product has one node per (plant state, filter memory, Blocked latch,
Grafcet situation). One **PLC cycle** from a node:

1. the plant makes zero or one uncontrollable event (its asynchronous semantics; with
   a Grafcet, a running timer may elapse instead);
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

Every finding comes with a shortest trace (breadth-first, in cycles). The exploration is
explicit (numpy arrays over the plant's state codes, one level of the breadth-first
search at a time) and stops after ``max_states`` nodes.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.filter.from_rules import skeleton
>>> import tempfile, pathlib
>>> sk = skeleton(_plants("tri.rules"), pathlib.Path(tempfile.mkdtemp()) / "F.filter")
>>> v = verify(sk.filter, _plants("tri.rules"), any_control=True)
>>> v.safe, v.coherent, v.states > 1000
(True, True, True)
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from synth.errors import InputError, LimitExceeded
from synth.filter.cycle import ACK, Algorithm, FilterCycle, Memory, Mode
from synth.filter.language import Filter
from synth.logic.events import Event

__all__ = ["TraceRow", "Finding", "Verification", "verify", "verification_text", "verification_json",
           "PLANT_LIMIT", "FINDINGS"]

PLANT_LIMIT = 20_000_000
"""verify keeps flat arrays over the plant's states; above this many it stops."""

FINDINGS = {
    "violation": "a plant state violates a constraint once the outputs are written",
    "edge": "an output event breaks an edge constraint",
    "refused": "the plant has no controllable event for an output change",
    "fallback": "the loop falls back",
    "outside_care": "Y is outside the care set of the algebraic filter",
    "transient": "a plant state violates a constraint before the PLC writes its outputs",
    "outside_sup": "uncontrollable events alone can lead from a state to a violation (it is not in SUP)",
}


@dataclass(frozen=True)
class TraceRow:
    """One cycle of a trace, as ``synth run`` prints a step: the plant's event, the
    plant state (its true variables), the situation, the requests and the orders."""

    event: str
    state: str
    situation: str
    requests: tuple[str, ...]
    orders: tuple[str, ...]
    note: str = ""
    ran: bool = True  # False: the plant's event only, the PLC has not run yet


@dataclass(frozen=True)
class Finding:
    """The first (shortest) occurrence of one kind of finding, and how many distinct
    plant states show it."""

    kind: str
    constraints: tuple[str, ...]
    trace: tuple[TraceRow, ...]
    count: int


@dataclass(frozen=True)
class Verification:
    """The outcome of :func:`verify`."""

    filter: str
    plant: str
    source: str  # "any control" or the Grafcet's file
    algorithm: Algorithm
    mode: Mode
    atomic: bool
    strict: bool
    states: int  # nodes of the product
    plant_states: int  # distinct plant states among them
    cycles: int  # transitions explored
    complete: bool
    seconds: float
    outside_sup: int
    findings: dict[str, Finding] = field(default_factory=dict)
    corrected: int = 0  # cycles where O != R (with a Grafcet: the transparency)
    max_distance: int = 0

    @property
    def safe(self) -> bool:
        bad = {"violation", "edge", "refused", "outside_sup"} | ({"transient"} if self.strict else set())
        return not any(k in self.findings for k in bad)

    @property
    def coherent(self) -> bool:
        return "fallback" not in self.findings and "outside_care" not in self.findings


# ---------------------------------------------------------------------------- the product


class _Product:
    def __init__(self, f: Filter, rules_path: str, grafcet_path: str | None, algorithm: Algorithm,
                 mode: Mode, atomic: bool) -> None:
        from synth.plant.composition import plant
        from synth.plant.rules_check import load_rules
        from synth.sup.constraints import CompiledConstraints, _product

        rs = load_rules(rules_path)
        p = plant(rs)
        if p.size > PLANT_LIMIT:
            raise LimitExceeded(f"the plant of {rules_path} has {p.size} states; verify keeps arrays over the "
                                f"plant's states and stops above {PLANT_LIMIT}")
        self.plant, self.rules = p, rs
        self.cycle = FilterCycle(f, algorithm, mode)
        self.filter, self.atomic = f, atomic
        for kind, names, have in (("input", f.inputs, p.inputs), ("output", f.outputs, p.outputs)):
            missing = [n for n in names if n not in have]
            if missing:
                raise InputError(f"{f.file}: the filter's {kind} {', '.join(missing)} is not an "
                                 f"{kind} of the plant {rules_path}", None)
        self.machine = None
        self.grafcet = None
        if grafcet_path is not None:
            from synth.grafcet.language_check import load_grafcet
            from synth.grafcet.machine import GrafcetMachine

            self.grafcet = load_grafcet(grafcet_path, inputs=rs.inputs, outputs=rs.outputs)
            self.machine = GrafcetMachine(self.grafcet)
        steps = set() if self.grafcet is None else {f"X{s.name}" for s in self.grafcet.steps}
        for d in f.observers:
            if d.name not in steps:
                raise InputError(f"observer {d.name} has no value in verify: only step variables of the "
                                 "--grafcet Grafcet can be observed", d.loc)
        size, shape = p.size, p.shape
        self.size = size
        self.val = {v: np.broadcast_to(p.values(v), shape).ravel().copy() for v in p.variables}
        self.orders = p.outputs
        self.passthrough = tuple(o for o in p.outputs if o not in f.outputs)
        self.held = {v.name: v.initial for v in rs.variables if v.held}  # requested at their held value
        self.ynames = tuple(dict.fromkeys([*f.inputs, *(self.grafcet.inputs if self.grafcet else ())]))
        if len(self.ynames) > 40:
            raise LimitExceeded(f"{len(self.ynames)} inputs are read; verify codes an input vector in 40 bits")
        self.toggle: dict[str, np.ndarray] = {}
        self.uncontrollable: list[tuple[str, np.ndarray]] = []
        for t, src, dst in p.transition_arrays():
            if t.controllable:
                arr = self.toggle.setdefault(t.event, np.full(size, -1, dtype=np.int64))
            else:
                found = [a for e, a in self.uncontrollable if e == t.event]
                arr = found[0] if found else np.full(size, -1, dtype=np.int64)
                if not found:
                    self.uncontrollable.append((t.event, arr))
            arr[src] = dst
        for z in self.orders:
            for ev in (Event.rise(z), Event.fall(z)):
                self.toggle.setdefault(ev, np.full(size, -1, dtype=np.int64))
        cc = CompiledConstraints(p, rs.constraints)
        self.cc = cc
        illegal = np.zeros(shape, dtype=bool)
        for t in cc.level_terms:
            illegal |= _product(p, t.factors)
        self.illegal = illegal.ravel()
        outside = np.zeros(shape, dtype=bool)
        for factors in cc.level_reach:
            outside |= _product(p, factors)
        self.outside_sup = outside.ravel()
        self.forbid: dict[str, np.ndarray] = {}
        for ev, terms in cc.edge_terms.items():
            g = np.zeros(shape, dtype=bool)
            for t in terms:
                g |= _product(p, t.factors)
            self.forbid[ev] = g.ravel()
        self.used_index = [self.cycle.remembered.index(n) for n in self.cycle.used]

    def label(self, code: int) -> str:
        return self.plant.label(self.plant.local(code))

    def violated(self, code: int) -> tuple[str, ...]:
        return tuple(self.cc.violated(self.plant.local(code)))


@dataclass(frozen=True)
class _Outcome:
    """What one cycle does to the product; the requests are one witness (not compared:
    request vectors that give the same outputs, memory and flags are one outcome)."""

    targets: tuple[bool, ...]  # every plant order, in plant output order
    aux: int
    fallback: bool
    outside_care: bool
    requests: tuple[bool, ...] = field(compare=False)  # every plant order's request
    violated: tuple[str, ...] = field(compare=False)  # filter constraints the requests violate


def verify(f: Filter, rules_path: str, grafcet: str | None = None, *, any_control: bool = False,
           algorithm: Algorithm = Algorithm.ALGEBRAIC, mode: Mode = Mode.SUPERVISOR, atomic: bool = False,
           strict: bool = False, require_sup: bool = False, max_states: int = 1_000_000) -> Verification:
    """Explore the closed loop (see the module docstring)."""
    if (grafcet is None) == (not any_control):
        raise InputError("verify needs a request source: --grafcet G.g7 or --any-control (one of them)", None)
    started = time.perf_counter()
    pr = _Product(f, rules_path, grafcet, Algorithm(algorithm), Mode(mode), atomic)
    ex = _Explorer(pr, max_states)
    ex.run()
    findings = ex.findings()
    if not require_sup:
        findings.pop("outside_sup", None)
    return Verification(
        f.file, rules_path, grafcet if grafcet is not None else "any control", pr.cycle.algorithm, pr.cycle.mode,
        atomic, strict, len(ex.seen_keys), len({k % pr.size for k in ex.seen_keys}), ex.cycles, ex.complete,
        time.perf_counter() - started, len(ex.outside_sup), findings, ex.corrected, ex.max_distance)


_NOTES = {"violation": "", "edge": "output event forbidden", "refused": "output change refused",
          "fallback": "fallback", "outside_care": "outside the care set",
          "transient": "an intermediate state of the write violates a constraint"}


class _Explorer:
    """The breadth-first search over the product, one level at a time.

    A node is the integer ``aux * plant.size + code``: ``code`` the plant state, ``aux``
    an interned (memory of the names whose past value the filter reads, Blocked,
    situation). The cycle's outcomes depend on the node only through a *class* (Y read,
    aux before, situation after the Grafcet's reaction), computed once for every request
    vector at once; the writes are then applied to whole arrays of (state, outcome) pairs.
    """

    def __init__(self, pr: _Product, max_states: int) -> None:
        self.pr, self.max_states = pr, max_states
        self.size = pr.size
        self.aux_of: dict[tuple, int] = {}
        self.aux_list: list[tuple] = []
        self.classes: dict[tuple, int] = {}
        self.outcomes: list[_Outcome] = []
        self.outcome_of: dict[_Outcome, int] = {}
        self.flat: list[int] = []  # the outcomes of every class, class after class
        self.n_out: list[int] = []
        self.arrays = _Grown(len(pr.orders))
        self.events: list[str] = ["-"] + [e for e, _ in pr.uncontrollable]
        self.parent: dict[int, tuple[int, str, int]] = {}  # node -> (parent node, event, outcome)
        self.seen_keys: set[int] = set()
        self.seen_arrays: dict[int, np.ndarray] = {}
        self.first: dict[str, tuple[int, str, int, int, tuple[str, ...]]] = {}  # kind -> (node, event, outcome, code, ids)
        self.counts: dict[str, set[int]] = {k: set() for k in FINDINGS}
        self.outside_sup: set[int] = set()
        self.first_outside_sup: int | None = None
        self.cycles = self.corrected = self.max_distance = 0
        self.complete = True
        p = pr.plant
        init = {v.name: v.initial for v in pr.rules.variables if v.is_input}
        sit0 = pr.machine.initial({n: init[n] for n in pr.grafcet.inputs}) if pr.machine else None
        memory = pr.cycle.initial()
        self.key0 = self.intern((tuple(memory.previous[i] for i in pr.used_index), False, sit0)) * self.size \
            + p.initial_index
        self.admit_one(self.key0)
        if pr.illegal[p.initial_index]:
            self.counts["violation"].add(p.initial_index)

    # ------------------------------------------------------------------ bookkeeping
    def intern(self, a: tuple) -> int:
        k = self.aux_of.get(a)
        if k is None:
            k = self.aux_of[a] = len(self.aux_list)
            self.aux_list.append(a)
        return k

    def seen_array(self, aux: int) -> np.ndarray:
        arr = self.seen_arrays.get(aux)
        if arr is None:
            arr = self.seen_arrays[aux] = np.zeros(self.size, dtype=bool)
        return arr

    def admit_one(self, key: int) -> None:
        code = key % self.size
        self.seen_keys.add(key)
        self.seen_array(key // self.size)[code] = True
        if self.pr.outside_sup[code]:
            self.outside_sup.add(code)
            self.first_outside_sup = key if self.first_outside_sup is None else self.first_outside_sup

    def record(self, kind: str, mask: np.ndarray, where: np.ndarray, node: np.ndarray, event: np.ndarray,
               oid: np.ndarray | None, shown: np.ndarray, ids: Any = ()) -> None:
        """Count the plant states ``where[mask]``; keep the first occurrence (its node, event,
        outcome, the state to show and the constraints, ``ids(i)`` when callable)."""
        if not mask.any():
            return
        self.counts[kind].update(np.unique(where[mask]).tolist())
        if kind not in self.first:
            i = int(np.argmax(mask))
            self.first[kind] = (int(node[i]), self.events[int(event[i])], -1 if oid is None else int(oid[i]),
                                int(shown[i]), ids(i) if callable(ids) else ids)

    # ------------------------------------------------------------------ one cycle's outcomes
    def outcomes_for(self, ybits: int, aux: int, sit: Any) -> int:
        """The class of (Y, aux before, situation after): its distinct outcomes over every
        request vector (and Ack), each with the first request vector giving it."""
        key = (ybits, aux, sit)
        k = self.classes.get(key)
        if k is not None:
            return k
        pr, cyc = self.pr, self.pr.cycle
        mem_used, blocked, _ = self.aux_list[aux]
        values = {n: bool((ybits >> i) & 1) for i, n in enumerate(pr.ynames)}
        fixed = {n: values[n] for n in pr.filter.inputs}
        free: list[str] = []
        passed: dict[str, bool] = {}
        if sit is not None:
            for st in pr.grafcet.steps:
                fixed[f"X{st.name}"] = st.name in sit.steps
            orders = pr.machine.orders(sit, {n: values[n] for n in pr.grafcet.inputs})
            fixed.update({r: pr.held.get(o, o in orders) for o, r in zip(cyc.outputs, cyc.requests)})
            passed = {o: pr.held.get(o, o in orders) for o in pr.passthrough}
        else:
            fixed.update({r: pr.held[o] for o, r in zip(cyc.outputs, cyc.requests) if o in pr.held})
            passed = {o: pr.held[o] for o in pr.passthrough if o in pr.held}
            free = [r for o, r in zip(cyc.outputs, cyc.requests) if o not in pr.held]
            free += [o for o in pr.passthrough if o not in pr.held]
        if cyc.mode is Mode.BLOCKING:
            free.append(ACK)
        previous = [False] * len(cyc.remembered)
        for i, v in zip(pr.used_index, mem_used):
            previous[i] = v
        lanes = cyc.lanes(Memory(tuple(previous), blocked), fixed, free)
        n = lanes.count
        out = {o: _unpack(m, n) for o, m in zip(cyc.outputs, lanes.outputs)}
        for o in pr.passthrough:
            out[o] = np.full(n, passed[o]) if o in passed else _unpack(_lane_bits(free.index(o), n), n)
        columns = [out[o] for o in pr.orders] + [_unpack(lanes.previous[i], n) for i in pr.used_index]
        columns += [_unpack(m, n) for m in (lanes.blocked, lanes.fallback, lanes.outside_care)]
        _, firsts = np.unique(np.stack(columns, axis=1), axis=0, return_index=True)
        found: list[int] = []
        for j in sorted(firsts.tolist()):  # one witness lane per distinct outcome, the first
            result, memory = lanes.lane(j)
            targets = dict(zip(cyc.outputs, result.outputs))
            req = dict(zip(cyc.outputs, result.requests))
            for o in pr.passthrough:
                targets[o] = req[o] = bool(out[o][j])
            mem = tuple(memory.previous[i] for i in pr.used_index)
            oc = _Outcome(tuple(targets[o] for o in pr.orders), self.intern((mem, memory.blocked, sit)),
                          result.fallback, result.outside_care, tuple(req[o] for o in pr.orders), result.violated)
            g = self.outcome_of.get(oc)
            if g is None:
                g = self.outcome_of[oc] = len(self.outcomes)
                self.outcomes.append(oc)
            found.append(g)
        k = self.classes[key] = len(self.n_out)
        self.flat.extend(found)
        self.n_out.append(len(found))
        return k

    # ------------------------------------------------------------------ one level
    def events_from(self, frontier: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Step 1 of a cycle for every node: (state after the plant's event, node, event id),
        the event being none, an uncontrollable event of the plant, or a Grafcet timer."""
        pr, size = self.pr, self.size
        codes_all, auxes_all = frontier % size, frontier // size
        post_l, node_l, event_l = [], [], []

        def add(post: np.ndarray, nodes: np.ndarray, ei: int) -> None:
            post_l.append(post)
            node_l.append(nodes)
            event_l.append(np.full(post.size, ei, dtype=np.int64))

        for aux in np.unique(auxes_all).tolist():
            sel = auxes_all == aux
            codes, nodes = codes_all[sel], frontier[sel]
            add(codes, nodes, 0)
            for ei, (_, nxt) in enumerate(pr.uncontrollable, 1):
                dst = nxt[codes]
                ok = dst >= 0
                if ok.any():
                    add(dst[ok], nodes[ok], ei)
            if pr.machine is not None:
                for tev in pr.machine.timers(self.aux_list[aux][2]):
                    if tev not in self.events:
                        self.events.append(tev)
                    add(codes, nodes, self.events.index(tev))
        return np.concatenate(post_l), np.concatenate(node_l), np.concatenate(event_l)

    def classify(self, post: np.ndarray, node: np.ndarray, event: np.ndarray) -> np.ndarray:
        """Steps 2-3: the class of each (state after the event, node, event)."""
        pr, width = self.pr, len(self.pr.ynames)
        ybits = np.zeros(post.size, dtype=np.int64)
        for i, n in enumerate(pr.ynames):
            ybits |= pr.val[n][post].astype(np.int64) << i
        combo = ((node // self.size) * len(self.events) + event) * (1 << width) + ybits
        uniq, inverse = np.unique(combo, return_inverse=True)
        class_ids = np.empty(uniq.size, dtype=np.int64)
        for u, c in enumerate(uniq.tolist()):
            yb, rest = c % (1 << width), c >> width
            ei, aux = rest % len(self.events), rest // len(self.events)
            sit = self.aux_list[aux][2]
            if pr.machine is not None:
                sit = _react(pr, sit, self.events[ei], yb)
            class_ids[u] = self.outcomes_for(yb, aux, sit)
        return class_ids[inverse]

    def write(self, post: np.ndarray, targets: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str], np.ndarray]:
        """Step 5 for arrays of (state, target orders): the state after the write (-1 when
        refused), refused, edge constraint broken (and by which events), and an
        intermediate state violating a constraint."""
        pr = self.pr
        cur, before = post.copy(), post
        bits = np.stack([pr.val[z][post] for z in pr.orders], axis=1)  # the orders now
        refused = np.zeros(post.size, dtype=bool)
        edge_bad = np.zeros(post.size, dtype=bool)
        edge_events: list[str] = []
        middle_bad = np.zeros(post.size, dtype=bool)
        for rising in (False, True):  # falls first, then rises, each in output order
            for z, name in enumerate(pr.orders):
                idx = np.nonzero((targets[:, z] == rising) & (bits[:, z] != rising) & ~refused)[0]
                if not idx.size:
                    continue
                ev = Event.edge(name, rising)
                c = cur[idx]
                if ev in pr.forbid:
                    hit = pr.forbid[ev][before[idx] if pr.atomic else c]
                    if hit.any():
                        edge_bad[idx[hit]] = True
                        edge_events.append(ev)
                nxt = pr.toggle[ev][c]
                no = nxt < 0
                if no.any():
                    refused[idx[no]] = True
                    cur[idx[no]] = -1
                    idx, nxt = idx[~no], nxt[~no]
                cur[idx] = nxt
                bits[idx, z] = rising
                if not pr.atomic:
                    middle_bad[idx] |= pr.illegal[nxt]
        return cur, refused, edge_bad, edge_events, middle_bad

    def level(self, frontier: np.ndarray) -> np.ndarray:
        """Every cycle from the nodes of ``frontier``; returns the new nodes."""
        pr, size = self.pr, self.size
        post, node, event = self.events_from(frontier)
        # a plant event into a violating state, before the PLC writes (a violation the
        # node already had is reported for the node)
        bad = (event > 0) & pr.illegal[post] & ~pr.illegal[node % size]
        self.record("transient", bad, post, node, event, None, post, lambda i: pr.violated(int(post[i])))
        cls = self.classify(post, node, event)
        n_out = np.array(self.n_out, dtype=np.int64)
        self.cycles += int(n_out[cls].sum())
        # one expansion per distinct (state, class); the first occurrence is the parent
        _, keep = np.unique(post * len(self.n_out) + cls, return_index=True)
        keep.sort()
        post, node, event, cls = post[keep], node[keep], event[keep], cls[keep]
        # one entry per (state, outcome of its class)
        reps = n_out[cls]
        entry = np.repeat(np.arange(post.size), reps)
        within = np.arange(entry.size) - np.repeat(np.cumsum(reps) - reps, reps)
        offsets = np.concatenate(([0], np.cumsum(n_out)))
        oid = np.array(self.flat, dtype=np.int64)[offsets[cls][entry] + within]
        targets, fallback, outside, aux_after, requests = self.arrays.update(self.outcomes)
        post, node, event, targets = post[entry], node[entry], event[entry], targets[oid]
        cur, refused, edge_bad, edge_events, middle_bad = self.write(post, targets)
        ok = cur >= 0
        final = np.where(ok, cur, 0)
        violation = ok & pr.illegal[final]
        middle_bad &= ~violation & ~pr.illegal[post]  # reported as a violation / before the write
        shown = np.where(ok, final, post)

        def edge_ids(i: int) -> tuple[str, ...]:
            return tuple(dict.fromkeys(c for ev in edge_events for c in pr.cc.forbidding(ev, pr.plant.local(int(post[i])))))

        self.record("violation", violation, final, node, event, oid, shown, lambda i: pr.violated(int(final[i])))
        self.record("edge", edge_bad, post, node, event, oid, shown, edge_ids)
        for kind, mask in (("refused", refused), ("fallback", fallback[oid]), ("outside_care", outside[oid]),
                           ("transient", middle_bad)):
            self.record(kind, mask, post, node, event, oid, shown)
        if pr.machine is not None and oid.size:
            dist = (requests[oid] != targets).sum(axis=1)
            self.corrected += int((dist > 0).sum())
            self.max_distance = max(self.max_distance, int(dist.max()))
        return self.admit(aux_after[oid][ok] * size + final[ok], node[ok], event[ok], oid[ok])

    def admit(self, keys: np.ndarray, node: np.ndarray, event: np.ndarray, oid: np.ndarray) -> np.ndarray:
        """The nodes of ``keys`` not seen before (their first occurrence is the parent)."""
        size = self.size
        uk, first = np.unique(keys, return_index=True)
        fresh = np.ones(uk.size, dtype=bool)
        uk_aux = uk // size
        for a in np.unique(uk_aux).tolist():
            sel = uk_aux == a
            fresh[sel] = ~self.seen_array(a)[uk[sel] % size]
        new: list[int] = []
        for k, i in zip(uk[fresh].tolist(), first[fresh].tolist()):
            if len(self.seen_keys) >= self.max_states:
                self.complete = False
                break
            self.admit_one(k)
            self.parent[k] = (int(node[i]), self.events[int(event[i])], int(oid[i]))
            new.append(k)
        return np.array(new, dtype=np.int64)

    def run(self) -> None:
        frontier = np.array([self.key0], dtype=np.int64)
        while frontier.size and self.complete:
            frontier = self.level(frontier)

    # ------------------------------------------------------------------ traces
    def trace(self, key: int) -> list[TraceRow]:
        """The shortest path of cycles from the initial node to ``key``."""
        rows = []
        while key in self.parent:
            pk, ev, g = self.parent[key]
            rows.append(_row(self.pr, self.outcomes[g], ev, key % self.size, self.aux_list[key // self.size][2]))
            key = pk
        rows.append(TraceRow("initial", self.pr.label(key % self.size),
                             _sit_text(self.aux_list[key // self.size][2]), (), ()))
        return rows[::-1]

    def findings(self) -> dict[str, Finding]:
        out: dict[str, Finding] = {}
        if self.pr.illegal[self.key0 % self.size]:
            out["violation"] = Finding("violation", self.pr.violated(self.key0 % self.size),
                                       tuple(self.trace(self.key0)), len(self.counts["violation"]))
        for kind, (node, ev, g, code, ids) in self.first.items():
            if kind in out:
                continue
            rows = self.trace(node)
            if g < 0:  # the plant's event alone
                rows.append(TraceRow(ev, self.pr.label(code), rows[-1].situation, (), (), "before the PLC writes",
                                     False))
            else:
                oc = self.outcomes[g]
                rows.append(_row(self.pr, oc, ev, code, self.aux_list[oc.aux][2], _NOTES[kind]))
            out[kind] = Finding(kind, ids, tuple(rows), len(self.counts[kind]))
        if self.first_outside_sup is not None:
            key = self.first_outside_sup
            rows = self.trace(key)
            ids = tuple(self.pr.cc.threatened(self.pr.plant.local(key % self.size)))
            rows[-1] = dataclasses.replace(rows[-1], note="; ".join(
                n for n in (rows[-1].note, "outside SUP: uncontrollable events can lead to " + ", ".join(ids)) if n))
            out["outside_sup"] = Finding("outside_sup", ids, tuple(rows), len(self.outside_sup))
        return {k: out[k] for k in FINDINGS if k in out}


def _unpack(mask: int, count: int) -> np.ndarray:
    """A lane mask as a bool array (lane j at index j)."""
    raw = np.frombuffer(mask.to_bytes((count + 7) // 8, "little"), dtype=np.uint8)
    return np.unpackbits(raw, bitorder="little")[:count].astype(bool)


def _lane_bits(i: int, count: int) -> int:
    """The lanes where free name ``i`` is true (bit i of the lane number)."""
    return sum(1 << j for j in range(count) if (j >> i) & 1)


class _Grown:
    """Arrays over the outcomes found so far, extended with the new ones only."""

    def __init__(self, width: int) -> None:
        self.targets = np.zeros((0, width), dtype=bool)
        self.fallback = np.zeros(0, dtype=bool)
        self.outside = np.zeros(0, dtype=bool)
        self.aux = np.zeros(0, dtype=np.int64)
        self.requests = np.zeros((0, width), dtype=bool)

    def update(self, outcomes: Sequence[_Outcome]
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        new = outcomes[self.aux.size:]
        if new:
            self.requests = np.concatenate((self.requests, np.array([o.requests for o in new], dtype=bool)
                                            .reshape(len(new), self.requests.shape[1])))
            self.targets = np.concatenate((self.targets, np.array([o.targets for o in new], dtype=bool)
                                           .reshape(len(new), self.targets.shape[1])))
            self.fallback = np.concatenate((self.fallback, np.array([o.fallback for o in new], dtype=bool)))
            self.outside = np.concatenate((self.outside, np.array([o.outside_care for o in new], dtype=bool)))
            self.aux = np.concatenate((self.aux, np.array([o.aux for o in new], dtype=np.int64)))
        return self.targets, self.fallback, self.outside, self.aux, self.requests


def _react(pr: _Product, sit: Any, event: str, ybits: int) -> Any:
    """The Grafcet's stable situation after ``event`` (a plant event, a timer, or none)."""
    values = {n: bool((ybits >> i) & 1) for i, n in enumerate(pr.ynames)}
    inputs = {n: values[n] for n in pr.grafcet.inputs}
    if event == "-":
        return sit
    ev = Event(event)
    if ev.kind.value == "timer":
        return pr.machine.fire_timer(sit, ev, inputs)
    if ev.name not in inputs:
        return sit
    return pr.machine.react_event(sit, ev, inputs)[0]


def _sit_text(sit: Any) -> str:
    return "" if sit is None else sit.text()


def _row(pr: _Product, oc: _Outcome, event: str, code: int, sit: Any, note: str = "") -> TraceRow:
    req = tuple(o for o, v in zip(pr.orders, oc.requests) if v)
    out = tuple(o for o, v in zip(pr.orders, oc.targets) if v)
    extra = []
    if oc.violated:
        extra.append("requests violate " + ", ".join(oc.violated))
    if note:
        extra.append(note)
    return TraceRow(event, pr.label(code), _sit_text(sit), req, out, "; ".join(extra))


# ---------------------------------------------------------------------------- printing


def _names(names: Sequence[str]) -> str:
    return ", ".join(names) if names else "-"


def trace_text(rows: Sequence[TraceRow]) -> str:
    """A trace in the layout of ``synth run``: number, event, plant state (and the
    situation), then the requests and the orders written."""
    w_event = max(len(r.event) for r in rows)
    w_state = max(len(r.state) for r in rows)
    w_sit = max(len(r.situation) for r in rows)
    out = []
    for i, r in enumerate(rows):
        line = f"{i:<3}{r.event:<{w_event}}  {r.state:<{w_state}}"
        if w_sit:
            line += f"  {r.situation:<{w_sit}}"
        if i and r.ran:
            line += f"  requests: {_names(r.requests)}  orders: {_names(r.orders)}"
        if r.note:
            line += f"   {r.note}"
        out.append(line.rstrip() + "\n")
    return "".join(out)


def verification_text(v: Verification) -> str:
    lines = [f"closed loop: {v.filter} on {v.plant}, requests from {v.source} "
             f"({v.algorithm.value}, {v.mode.value}, {'atomic outputs' if v.atomic else 'ordered outputs'})",
             f"explored {v.states} states ({v.plant_states} plant states), {v.cycles} cycles"
             f" in {v.seconds:.2f} s" + ("" if v.complete else " -- STOPPED at the state limit")]
    for kind in ("violation", "edge", "refused", "outside_sup"):
        if kind in v.findings:
            fd = v.findings[kind]
            lines.append(f"unsafe: {FINDINGS[kind]} ({fd.count} plant states)"
                         + (f": {', '.join(fd.constraints)}" if fd.constraints else ""))
    if v.safe:
        lines.append("safe: no constraint is violated once the outputs are written"
                     + ("" if v.complete else " (in the explored part)"))
    if "transient" in v.findings:
        fd = v.findings["transient"]
        lines.append(f"{'unsafe' if v.strict else 'transient'}: {fd.count} plant states violate a constraint "
                     "between the plant's event and the end of the write"
                     + (f" ({', '.join(fd.constraints)})" if fd.constraints else ""))
    if "outside_sup" not in v.findings:
        lines.append(f"outside SUP: {v.outside_sup} explored plant states can reach a violation by "
                     "uncontrollable events alone")
    for kind in ("fallback", "outside_care"):
        if kind in v.findings:
            lines.append(f"incoherent: {FINDINGS[kind]} ({v.findings[kind].count} plant states)")
    if v.coherent:
        lines.append("coherent: " + ("the loop never falls back" if v.algorithm is Algorithm.LOOP
                                     else "Y never leaves the care set"))
    if v.source != "any control":
        lines.append(f"transparency: {v.corrected} of {v.cycles} cycles correct the requests, "
                     f"largest Hamming distance {v.max_distance}")
    for kind in FINDINGS:
        if kind in v.findings:
            lines.append(f"\nshortest trace ({FINDINGS[kind]}):")
            lines.append(trace_text(v.findings[kind].trace).rstrip("\n"))
    return "\n".join(lines) + "\n"


def verification_json(v: Verification) -> dict[str, Any]:
    return {
        "filter": v.filter, "plant": v.plant, "source": v.source, "algorithm": v.algorithm.value,
        "mode": v.mode.value, "atomic_outputs": v.atomic, "strict": v.strict,
        "safe": v.safe, "coherent": v.coherent, "complete": v.complete,
        "states": v.states, "plant_states": v.plant_states, "cycles": v.cycles, "outside_sup": v.outside_sup,
        "corrected": v.corrected, "max_distance": v.max_distance, "seconds": round(v.seconds, 3),
        "findings": {k: {"count": f.count, "constraints": list(f.constraints), "trace": [
            {"event": r.event, "state": r.state, "situation": r.situation, "requests": list(r.requests),
             "orders": list(r.orders), "note": r.note, "plc_ran": r.ran} for r in f.trace]}
                     for k, f in v.findings.items()},
    }

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

Plant orders the filter does not declare are passed through (O = R for them).

Verdicts, over everything reachable:

- (a) *safe*: no node (a plant state once the PLC has written its outputs) violates a
  level constraint of the rules, no output event breaks an edge constraint, and the
  plant accepts every output change. The filter's constraints hold *at the end of
  every cycle*; between the plant's event and the next write the plant may briefly be
  in a violating state the filter could not prevent (the PLC is synchronous, the plant
  asynchronous): such *transient* states — and the intermediate states of an ordered
  write — are counted and shown but fail the verdict only with ``strict=True``. Nodes
  outside SUP (a violation reachable by uncontrollable events alone) are counted;
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

import time
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from synth.errors import InputError, LimitExceeded
from synth.filter.cycle import ACK, Algorithm, FilterCycle, Mode
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
        bad = {"violation", "edge", "refused"} | ({"transient"} if self.strict else set())
        return not any(k in self.findings for k in bad)

    @property
    def coherent(self) -> bool:
        return "fallback" not in self.findings and "outside_care" not in self.findings


# ---------------------------------------------------------------------------- the product


class _Product:
    def __init__(self, f: Filter, rules_path: str, grafcet_path: str | None, algorithm: Algorithm,
                 mode: Mode, atomic: bool) -> None:
        from synth.plant.composition import plant
        from synth.plant.rules import load_rules
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
            from synth.grafcet.language import load_grafcet
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
        self.ynames = tuple(dict.fromkeys([*f.inputs, *(self.grafcet.inputs if self.grafcet else ())]))
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
           strict: bool = False, max_states: int = 1_000_000) -> Verification:
    """Explore the closed loop (see the module docstring)."""
    if (grafcet is None) == (not any_control):
        raise InputError("verify needs a request source: --grafcet G.g7 or --any-control (one of them)", None)
    started = time.perf_counter()
    pr = _Product(f, rules_path, grafcet, Algorithm(algorithm), Mode(mode), atomic)
    p, cyc, size = pr.plant, pr.cycle, pr.size
    blocking = cyc.mode is Mode.BLOCKING

    # ---- interned auxiliary parts of a node: (memory of the used names, Blocked, situation)
    aux_of: dict[tuple, int] = {}
    aux_list: list[tuple] = []

    def intern(a: tuple) -> int:
        k = aux_of.get(a)
        if k is None:
            k = aux_of[a] = len(aux_list)
            aux_list.append(a)
        return k

    init_inputs = {v.name: v.initial for v in pr.rules.variables if v.is_input}
    sit0 = pr.machine.initial({n: init_inputs[n] for n in pr.grafcet.inputs}) if pr.machine else None
    mem0 = cyc.initial()
    aux0 = intern((tuple(mem0.previous[i] for i in pr.used_index), False, sit0))

    # ---- outcomes of one cycle for a class (Y, aux before, situation after)
    classes: dict[tuple, int] = {}
    class_outcomes: list[list[int]] = []
    outcomes: list[_Outcome] = []
    outcome_of: dict[_Outcome, int] = {}
    flat_list: list[int] = []  # the outcomes of every class, class after class
    n_out_list: list[int] = []
    outcome_arrays = _Grown(len(pr.orders))

    def outcomes_for(ybits: int, aux: int, sit: Any) -> int:
        key = (ybits, aux, sit)
        k = classes.get(key)
        if k is not None:
            return k
        mem_used, blocked, _ = aux_list[aux]
        values = {n: bool((ybits >> i) & 1) for i, n in enumerate(pr.ynames)}
        fixed = {n: values[n] for n in pr.filter.inputs}
        if sit is not None:
            for s in pr.grafcet.steps:
                fixed[f"X{s.name}"] = s.name in sit.steps
            orders = pr.machine.orders(sit, {n: values[n] for n in pr.grafcet.inputs})
            fixed.update({r: o in orders for o, r in zip(cyc.outputs, cyc.requests)})
            passed = {o: o in orders for o in pr.passthrough}
            free: list[str] = []
        else:
            free = [*cyc.requests, *pr.passthrough]
            passed = {}
        if blocking:
            free.append(ACK)
        previous = [False] * len(cyc.remembered)
        for i, v in zip(pr.used_index, mem_used):
            previous[i] = v
        from synth.filter.cycle import Memory

        lanes = cyc.lanes(Memory(tuple(previous), blocked), fixed, free)
        n = lanes.count
        out = {o: _unpack(m, n) for o, m in zip(cyc.outputs, lanes.outputs)}
        for o in pr.passthrough:
            out[o] = np.full(n, passed[o]) if sit is not None else _unpack(_lane_bits(free.index(o), n), n)
        columns = [out[o] for o in pr.orders] + [_unpack(lanes.previous[i], n) for i in pr.used_index]
        columns += [_unpack(m, n) for m in (lanes.blocked, lanes.fallback, lanes.outside_care)]
        table = np.stack(columns, axis=1)
        _, firsts = np.unique(table, axis=0, return_index=True)
        found: list[int] = []
        for j in sorted(firsts.tolist()):  # one witness lane per distinct outcome, the first
            result, memory = lanes.lane(j)
            targets = dict(zip(cyc.outputs, result.outputs))
            req = dict(zip(cyc.outputs, result.requests))
            for o in pr.passthrough:
                targets[o] = req[o] = bool(out[o][j])
            mem = tuple(memory.previous[i] for i in pr.used_index)
            oc = _Outcome(tuple(targets[o] for o in pr.orders), intern((mem, memory.blocked, sit)),
                          result.fallback, result.outside_care, tuple(req[o] for o in pr.orders), result.violated)
            g = outcome_of.get(oc)
            if g is None:
                g = outcome_of[oc] = len(outcomes)
                outcomes.append(oc)
            found.append(g)
        k = classes[key] = len(class_outcomes)
        class_outcomes.append(found)
        flat_list.extend(found)
        n_out_list.append(len(found))
        return k

    # ---- breadth-first search, one level at a time
    parent: dict[int, tuple[int, str, int]] = {}  # node key -> (parent key, event, outcome id)
    key0 = aux0 * size + p.initial_index
    seen_keys: set[int] = {key0}
    seen_arrays: dict[int, np.ndarray] = {}

    def seen_array(aux: int) -> np.ndarray:
        arr = seen_arrays.get(aux)
        if arr is None:
            arr = seen_arrays[aux] = np.zeros(size, dtype=bool)
        return arr

    seen_array(aux0)[p.initial_index] = True
    frontier = np.array([key0], dtype=np.int64)
    findings: dict[str, tuple[int, str, int, int, tuple[str, ...]]] = {}  # kind -> (parent key, event, outcome, code, ids)
    counts: dict[str, set[int]] = {k: set() for k in FINDINGS}
    first_node: dict[str, int] = {}
    if pr.illegal[p.initial_index]:
        counts["violation"].add(p.initial_index)
        first_node["violation"] = key0
    cycles = corrected = max_distance = 0
    complete = True
    events = ["-"] + [e for e, _ in pr.uncontrollable]
    outside_sup_codes: set[int] = set()
    if pr.outside_sup[p.initial_index]:
        outside_sup_codes.add(p.initial_index)

    while frontier.size:
        codes_all, auxes_all = frontier % size, frontier // size
        post_l, origin_l, event_l, sits_l = [], [], [], []
        for aux in np.unique(auxes_all):
            sel = auxes_all == aux
            codes, keys = codes_all[sel], frontier[sel]
            sit = aux_list[int(aux)][2]
            post_l.append(codes), origin_l.append(keys), event_l.append(np.zeros(codes.size, dtype=np.int64))
            sits_l.append(np.full(codes.size, -1, dtype=np.int64))
            for ei, (ev, nxt) in enumerate(pr.uncontrollable, 1):
                dst = nxt[codes]
                ok = dst >= 0
                if ok.any():
                    post_l.append(dst[ok]), origin_l.append(keys[ok])
                    event_l.append(np.full(int(ok.sum()), ei, dtype=np.int64))
                    sits_l.append(np.full(int(ok.sum()), -1, dtype=np.int64))
            if pr.machine is not None:
                for tev in pr.machine.timers(sit):
                    if tev not in events:
                        events.append(tev)
                    ei = events.index(tev)
                    post_l.append(codes), origin_l.append(keys)
                    event_l.append(np.full(codes.size, ei, dtype=np.int64))
                    sits_l.append(np.full(codes.size, -1, dtype=np.int64))
        post = np.concatenate(post_l)
        origin = np.concatenate(origin_l)
        event_id = np.concatenate(event_l)
        # transient: the plant's event led into a violating state before the PLC writes
        moved = event_id > 0  # (a violation the node already had is reported for the node)
        bad = moved & pr.illegal[post] & ~pr.illegal[origin % size]
        if bad.any():
            i = int(np.argmax(bad))
            counts["transient"].update(np.unique(post[bad]).tolist())
            if "transient" not in findings:
                findings["transient"] = (int(origin[i]), events[int(event_id[i])], -1, int(post[i]),
                                         pr.violated(int(post[i])))
        ybits = np.zeros(post.size, dtype=np.int64)
        for i, n in enumerate(pr.ynames):
            ybits |= pr.val[n][post].astype(np.int64) << i
        # classes: (Y, aux before, situation after the Grafcet's reaction)
        origin_aux = origin // size
        combo = (origin_aux * len(events) + event_id) * (1 << len(pr.ynames)) + ybits
        uniq, inverse = np.unique(combo, return_inverse=True)
        class_ids = np.empty(uniq.size, dtype=np.int64)
        for u, c in enumerate(uniq.tolist()):
            yb = c % (1 << len(pr.ynames))
            rest = c >> len(pr.ynames)
            ei, aux = rest % len(events), rest // len(events)
            sit = aux_list[aux][2]
            if pr.machine is not None:
                sit = _react(pr, sit, events[ei], yb)
            class_ids[u] = outcomes_for(yb, aux, sit)
        cls = class_ids[inverse]
        n_out = np.array(n_out_list, dtype=np.int64)
        cycles += int(n_out[cls].sum())
        # one expansion per distinct (post state, class); the first occurrence is the parent
        _, keep = np.unique(post * len(n_out_list) + cls, return_index=True)
        keep.sort()
        post, origin, event_id, cls = post[keep], origin[keep], event_id[keep], cls[keep]
        # expand: one entry per (post state, outcome of its class)
        offsets = np.concatenate(([0], np.cumsum(n_out)))
        flat_outcomes = np.array(flat_list, dtype=np.int64)
        reps = n_out[cls]
        entry = np.repeat(np.arange(post.size), reps)
        within = np.arange(entry.size) - np.repeat(np.cumsum(reps) - reps, reps)
        oid = flat_outcomes[offsets[cls][entry] + within]
        all_targets, all_fallback, all_outside, all_aux = outcome_arrays.update(outcomes)
        cur = post[entry].copy()
        before = cur.copy()
        targets = all_targets[oid]
        bits = np.stack([pr.val[z][post] for z in pr.orders], axis=1)[entry]  # the orders now
        refused = np.zeros(entry.size, dtype=bool)
        edge_bad = np.zeros(entry.size, dtype=bool)
        edge_ids: list[str] = []
        middle_bad = np.zeros(entry.size, dtype=bool)
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
                        edge_ids.append(ev)
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
        final_ok = cur >= 0
        origin_e, event_e, post_e = origin[entry], event_id[entry], post[entry]
        final = np.where(final_ok, cur, 0)
        violation = final_ok & pr.illegal[final]
        middle_bad &= ~violation & ~pr.illegal[post_e]  # reported as a violation / before the write
        fallback = all_fallback[oid]
        outside = all_outside[oid]
        for kind, mask, where in (("violation", violation, final), ("edge", edge_bad, post_e),
                                  ("refused", refused, post_e), ("fallback", fallback, post_e),
                                  ("outside_care", outside, post_e), ("transient", middle_bad, post_e)):
            if mask.any():
                counts[kind].update(np.unique(where[mask]).tolist())
                i = int(np.argmax(mask))
                if kind not in findings:
                    ids: tuple[str, ...] = ()
                    if kind == "violation":
                        ids = pr.violated(int(final[i]))
                    elif kind == "edge":
                        ids = tuple(dict.fromkeys(c for ev in edge_ids
                                                  for c in pr.cc.forbidding(ev, p.local(int(post_e[i])))))
                    elif kind == "refused":
                        ids = ()
                    findings[kind] = (int(origin_e[i]), events[int(event_e[i])], int(oid[i]),
                                      int(final[i]) if kind == "violation" else int(post_e[i]), ids)
        if pr.machine is not None:
            req = np.array([o.requests for o in outcomes], dtype=bool).reshape(len(outcomes), len(pr.orders))[oid]
            dist = (req != targets).sum(axis=1)
            corrected += int((dist > 0).sum())
            if dist.size:
                max_distance = max(max_distance, int(dist.max()))
        # new nodes
        aux_after = all_aux[oid]
        keys = aux_after[final_ok] * size + final[final_ok]
        src_entry = np.nonzero(final_ok)[0]
        uk, first = np.unique(keys, return_index=True)
        fresh = np.ones(uk.size, dtype=bool)
        uk_aux = uk // size
        for a in np.unique(uk_aux).tolist():
            sel = uk_aux == a
            fresh[sel] = ~seen_array(a)[uk[sel] % size]
        uk, first = uk[fresh], first[fresh]
        new_keys = []
        for k, fi in zip(uk.tolist(), first.tolist()):
            seen_keys.add(k)
            seen_array(k // size)[k % size] = True
            e_i = int(src_entry[fi])
            parent[k] = (int(origin_e[e_i]), events[int(event_e[e_i])], int(oid[e_i]))
            new_keys.append(k)
            if pr.outside_sup[k % size]:
                outside_sup_codes.add(k % size)
            if len(seen_keys) >= max_states:
                complete = False
                break
        if not complete:
            break
        frontier = np.array(new_keys, dtype=np.int64)

    def trace(key: int) -> list[TraceRow]:
        rows = []
        while key in parent:
            pk, ev, g = parent[key]
            rows.append(_row(pr, outcomes[g], ev, key % size, aux_list[key // size][2]))
            key = pk
        rows.append(TraceRow("initial", pr.label(key % size), _sit_text(aux_list[key // size][2]), (), ()))
        return rows[::-1]

    result: dict[str, Finding] = {}
    for kind, (pk, ev, g, code, ids) in findings.items():
        rows = trace(pk)
        if g < 0:  # the plant's event alone
            rows.append(TraceRow(ev, pr.label(code), rows[-1].situation, (), (), "before the PLC writes"))
        else:
            oc = outcomes[g]
            note = {"violation": "", "edge": "output event forbidden", "refused": "output change refused",
                    "fallback": "fallback", "outside_care": "outside the care set",
                    "transient": "an intermediate state of the write violates a constraint"}[kind]
            sit = aux_list[oc.aux][2]
            shown = code if kind == "violation" else code
            rows.append(_row(pr, oc, ev, shown, sit, note))
            if kind == "transient" and not ids:
                ids = ()
        result[kind] = Finding(kind, ids, tuple(rows), len(counts[kind]))
    if "violation" in first_node and "violation" not in result:
        result["violation"] = Finding("violation", pr.violated(p.initial_index), tuple(trace(key0)),
                                      len(counts["violation"]))
    plant_states = len({k % size for k in seen_keys})
    return Verification(
        f.file, rules_path, grafcet if grafcet is not None else "any control", cyc.algorithm, cyc.mode, atomic,
        strict, len(seen_keys), plant_states, cycles, complete, time.perf_counter() - started,
        len(outside_sup_codes), result, corrected, max_distance)


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

    def update(self, outcomes: Sequence[_Outcome]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        new = outcomes[self.aux.size:]
        if new:
            self.targets = np.concatenate((self.targets, np.array([o.targets for o in new], dtype=bool)
                                           .reshape(len(new), self.targets.shape[1])))
            self.fallback = np.concatenate((self.fallback, np.array([o.fallback for o in new], dtype=bool)))
            self.outside = np.concatenate((self.outside, np.array([o.outside_care for o in new], dtype=bool)))
            self.aux = np.concatenate((self.aux, np.array([o.aux for o in new], dtype=np.int64)))
        return self.targets, self.fallback, self.outside, self.aux


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
        if i or r.requests or r.orders:
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
    for kind in ("violation", "edge", "refused"):
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
             "orders": list(r.orders), "note": r.note} for r in f.trace]} for k, f in v.findings.items()},
    }

"""The breadth-first search of ``synth filter verify`` over the closed loop's product
(:class:`~synth.filter.loop.product.Product`), one level at a time, with the first
(shortest) occurrence of every kind of finding and its trace.

Example
-------
>>> from synth.plant.composition import _plants, load_plant
>>> from synth.filter.from_rules import skeleton
>>> from synth.filter.cycle import Algorithm, Mode
>>> from synth.filter.loop.product import Product
>>> sk = skeleton(_plants("tri.rules"), _plants("F.filter"))  # the text only: nothing is written
>>> pr = Product(sk.filter, load_plant(_plants("tri.rules")), None, Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False)
>>> ex = Explorer(pr, 100)
>>> ex.run()
>>> ex.complete, len(ex.seen_keys)
(False, 100)
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any, Callable

import numpy as np

from synth.filter.loop.control_st import TIMER_PREFIX
from synth.errors import LimitExceeded
from synth.filter.loop.outcomes import (ClassLanes, Outcome, OutcomeArrays, class_lanes, distinct_lanes, react,
                                       situation_text, trace_row)
from synth.filter.loop.product import Product
from synth.filter.loop.writes import merge_events, write
from synth.filter.loop.verification import Finding, FindingKind, TraceRow

__all__ = ["POWER_UP", "Explorer"]

CLASS_BATCH = 512
"""The new classes whose lanes are held before their outcomes are found (all at once)."""

POWER_UP = "power-up"
"""The event of a program's first cycle: its first scan, on the plant's initial state."""


_NOTES = {FindingKind.VIOLATION: "", FindingKind.EDGE: "output event forbidden",
          FindingKind.REFUSED: "output change refused", FindingKind.FALLBACK: "fallback",
          FindingKind.OUTSIDE_CARE: "outside the care set",
          FindingKind.TRANSIENT: "an intermediate state of the write violates a constraint"}


class Explorer:
    """The breadth-first search over the product, one level at a time.

    A node is the integer ``aux * plant.size + code``: ``code`` the plant state, ``aux``
    an interned (memory of the names whose past value the filter reads, Blocked,
    situation). The cycle's outcomes depend on the node only through a *class* (Y read,
    aux before, situation after the Grafcet's reaction), computed once for every request
    vector at once; the writes are then applied to whole arrays of (state, outcome) pairs.
    """

    def __init__(self, pr: Product, max_states: int, events_per_cycle: int = 1, edges: bool = False) -> None:
        self.pr, self.max_states, self.k, self.track = pr, max_states, events_per_cycle, edges
        self.report: Callable[[str], None] | None = None  # progress lines, one per level (the CLI's live line)
        self.size = pr.size
        self.aux_of: dict[tuple, int] = {}
        self.aux_list: list[tuple] = []
        self.classes: dict[tuple, int] = {}
        self.outcomes: list[Outcome] = []
        self.outcome_of: dict[Outcome, int] = {}
        self.outcome_by_key: dict[tuple[int, Any], int] = {}  # (a lane's bits, situation) -> outcome
        self.flat: list[int] = []  # the outcomes of every class, class after class
        self.n_out: list[int] = []
        self.arrays = OutcomeArrays(len(pr.orders))
        # the events of a cycle: its label ("-", "↑a", "↑a, ↓b", a timer) and sequence, interned
        self.events: list[str] = []
        self.seqs: list[tuple[str, ...]] = []
        self.seq_of: dict[tuple[str, ...], int] = {}
        for seq in [(), *((e,) for e in pr.uncontrollable)]:  # ids in the plant's event order
            self.intern_seq(seq)
        # the events the plant (and the Grafcet's timers) may not postpone forever: one bit each
        self.fair: dict[str, int] = {e: i for i, e in enumerate(pr.uncontrollable)}
        self.order: list[int] = []  # the nodes in the order they were found (breadth-first)
        # (source, target, fairness bits of the events taken, events id, outcome): with --progress
        self.edge_parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self.parent: dict[int, tuple[int, str, int]] = {}  # node -> (parent node, event, outcome)
        self.seen_keys: set[int] = set()
        # kind -> (node, event, outcome, code, ids)
        self.first: dict[FindingKind, tuple[int, str, int, int, tuple[str, ...]]] = {}
        self.counts: dict[FindingKind, set[int]] = {k: set() for k in FindingKind}
        self.outside_sup: set[int] = set()
        self.first_outside_sup: int | None = None
        self.cycles = self.corrected = self.max_distance = 0
        self.complete = True
        p = pr.plant
        init = {v.name: v.initial for v in pr.rules.variables if v.is_input}
        sit0 = pr.initial_situation(init)
        memory = pr.cycle.initial()
        self.key0 = self.intern((tuple(memory.previous[i] for i in pr.used_index), False, sit0)) * self.size \
            + p.initial_index
        self.admit_one(self.key0)
        self.note_outside(np.array([self.key0], dtype=np.int64))
        # a program's fresh instance: the PLC before its power-up scan (see run)
        self.prelude: int | None = self.key0 if pr.control is not None else None
        self.prelude_cycles = self.prelude_corrected = 0
        self.powered: set[int] = set()  # the states the power-up scan leads to
        self.reentered = False
        if pr.illegal[p.initial_index]:
            self.counts[FindingKind.VIOLATION].add(p.initial_index)

    # ------------------------------------------------------------------ bookkeeping
    def intern(self, a: tuple) -> int:
        k = self.aux_of.get(a)
        if k is None:
            if (len(self.aux_list) + 1) * self.size >= 2**63:
                raise LimitExceeded(f"{len(self.aux_list) + 1} filter memories and controller states by "
                                    f"{self.size} plant states: a node no longer fits in 63 bits")
            k = self.aux_of[a] = len(self.aux_list)
            self.aux_list.append(a)
        return k

    def intern_seq(self, seq: tuple[str, ...]) -> int:
        k = self.seq_of.get(seq)
        if k is None:
            k = self.seq_of[seq] = len(self.seqs)
            self.seqs.append(seq)
            self.events.append(", ".join(seq) if seq else "-")
        return k

    def bit(self, event: str) -> int:
        """The fairness bit of a plant event or timer (at most 64 of them, for --progress)."""
        b = self.fair.setdefault(event, len(self.fair))
        if b >= 64 and self.track:
            raise LimitExceeded("--progress tracks at most 64 plant events and Grafcet timers in this closed loop")
        return 1 << b if b < 64 else 0

    def admit_one(self, key: int) -> None:
        self.seen_keys.add(key)
        self.order.append(key)

    def note_outside(self, keys: np.ndarray) -> None:
        """Count the plant states outside SUP among the nodes ``keys`` just admitted (in
        their order of admission); keep the first such node."""
        codes = keys % self.size
        out = self.pr.outside_sup[codes]
        if out.any():
            self.outside_sup.update(codes[out].tolist())
            if self.first_outside_sup is None:
                self.first_outside_sup = int(keys[int(np.argmax(out))])

    def record(self, kind: FindingKind, mask: np.ndarray, where: np.ndarray, node: np.ndarray, event: np.ndarray,
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
    def add_classes(self, new: list[tuple[ClassLanes, Any]]) -> None:
        """The outcomes of the classes ``new`` (their lanes, their situation after), in
        order: each class's distinct outcomes over every request vector, each with the first
        request vector giving it (the first lanes of all the classes found at once)."""
        if not new:
            return
        count = new[0][0].lanes.count  # the same free names in every class of a run
        for (cl, sit), (lanes, keys) in zip(new, distinct_lanes([cl.masks for cl, _ in new], count)):
            found: list[int] = []
            for i, j in enumerate(lanes):  # one witness lane per distinct outcome, the first
                g = None if keys is None else self.outcome_by_key.get((keys[i], sit))
                if g is None:
                    g = self.outcome_of_lane(cl, sit, j)
                    if keys is not None:  # the key is the outcome's bits: with sit, the outcome
                        self.outcome_by_key[(keys[i], sit)] = g
                found.append(g)
            self.flat.extend(found)
            self.n_out.append(len(found))

    def outcome_of_lane(self, cl: ClassLanes, sit: Any, j: int) -> int:
        """The outcome of lane ``j`` of a class (``sit``: its situation after), numbered when new."""
        pr, lanes = self.pr, cl.lanes

        def bit(m: int) -> bool:
            return bool((m >> j) & 1)

        oc = Outcome(tuple(bit(cl.out[o]) for o in pr.orders),
                     self.intern((tuple(map(bit, cl.memory_after)), bit(lanes.blocked), sit)),
                     bit(lanes.fallback), bit(lanes.outside_care), (), ())
        g = self.outcome_of.get(oc)  # the witness (requests, violated) is not compared
        if g is None:
            req = dict(zip(pr.cycle.outputs, map(bit, lanes.requests)))
            req.update((o, bit(cl.out[o])) for o in pr.passthrough)
            oc = dataclasses.replace(oc, requests=tuple(req[o] for o in pr.orders),
                                     violated=tuple(i for i, m in lanes.violated.items() if bit(m)))
            g = self.outcome_of[oc] = len(self.outcomes)
            self.outcomes.append(oc)
        return g

    # ------------------------------------------------------------------ one level
    def events_from(self, frontier: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Step 1 of a cycle for every node: (state after the plant's events, node, events id,
        fairness bits of the events taken). The events are none, up to ``events_per_cycle``
        uncontrollable events of the plant in sequence (one entry per state reached, with the
        union of the events of every sequence reaching it, the shortest shown), or a Grafcet
        timer. A plant event into a violating state is a transient finding."""
        pr, size = self.pr, self.size
        codes0 = frontier % size
        fi = np.arange(frontier.size, dtype=np.int64)
        post, seq, mask = codes0, np.zeros(frontier.size, dtype=np.int64), np.zeros(frontier.size, dtype=np.uint64)
        parts = [(fi, post, seq, mask)]
        by_events = pr.machine is not None  # a Grafcet reacts to each event; a program scans once
        for _ in range(self.k):
            found = []
            for ev, dst in pr.moves(post):
                ok = dst >= 0
                if not ok.any():
                    continue
                uniq, inv = np.unique(seq[ok], return_inverse=True)
                ids = np.array([self.intern_seq(self.seqs[u] + (ev,)) for u in uniq.tolist()], dtype=np.int64)
                found.append((fi[ok], dst[ok], ids[inv.ravel()], mask[ok] | np.uint64(self.bit(ev))))
            if not found:
                break
            fi, post, seq, mask = merge_events([np.concatenate(c) for c in zip(*found)], size, frontier, by_events)
            bad = pr.illegal[post] & ~pr.illegal[codes0[fi]]
            self.record(FindingKind.TRANSIENT, bad, post, frontier[fi], seq, None, post,
                        lambda i: pr.violated(int(post[i])))
            parts.append((fi, post, seq, mask))
        fi, post, seq, mask = merge_events([np.concatenate(c) for c in zip(*parts)], size, frontier, by_events)
        if pr.controlled:
            timed = [(fi, post, seq, mask)]
            auxes = frontier // size
            for aux in np.unique(auxes).tolist():
                where = np.nonzero(auxes == aux)[0]
                for tev in pr.timers(self.aux_list[aux][2]):
                    timed.append((where, codes0[where], np.full(where.size, self.intern_seq((tev,)), dtype=np.int64),
                                  np.full(where.size, self.bit(tev), dtype=np.uint64)))
            fi, post, seq, mask = (np.concatenate(c) for c in zip(*timed))
            by_aux = np.argsort(auxes[fi], kind="stable")  # a node's timers after its plant events
            fi, post, seq, mask = fi[by_aux], post[by_aux], seq[by_aux], mask[by_aux]
        return post, frontier[fi], seq, mask

    def classify(self, post: np.ndarray, node: np.ndarray, event: np.ndarray) -> np.ndarray:
        """Steps 2-3: the class of each (state after the event, node, event)."""
        pr, width = self.pr, len(self.pr.ynames)
        ybits = np.zeros(post.size, dtype=np.int64)
        for i, n in enumerate(pr.ynames):
            ybits |= pr.val[n][post].astype(np.int64) << i
        if not pr.controlled:  # the events matter only to a controller
            event = np.zeros_like(event)
        elif pr.control is not None:  # a program scans once after the plant's events: only a timer matters
            timer = np.array([bool(q) and q[0].startswith(TIMER_PREFIX) for q in self.seqs], dtype=bool)
            event = np.where(timer[event], event, 0)
        combo = ((node // self.size) * len(self.events) + event) * (1 << width) + ybits
        uniq, inverse = np.unique(combo, return_inverse=True)
        class_ids = np.empty(uniq.size, dtype=np.int64)
        new: list[tuple[ClassLanes, Any]] = []  # the classes not met before, in order
        for u, c in enumerate(uniq.tolist()):
            yb, rest = c % (1 << width), c >> width
            ei, aux = rest % len(self.events), rest // len(self.events)
            sit = self.aux_list[aux][2]
            if pr.controlled:
                sit = react(pr, sit, self.seqs[ei], yb)
            key = (yb, aux, sit)  # the class: Y read, aux before, situation after
            k = self.classes.get(key)
            if k is None:
                k = self.classes[key] = len(self.n_out) + len(new)
                new.append((class_lanes(pr, yb, self.aux_list[aux], sit), sit))
                if len(new) == CLASS_BATCH:  # a bounded number of lanes held at once
                    self.add_classes(new)
                    new = []
            class_ids[u] = k
        self.add_classes(new)
        return class_ids[inverse]

    def level(self, frontier: np.ndarray) -> np.ndarray:
        """Every cycle from the nodes of ``frontier``; returns the new nodes."""
        pr, size = self.pr, self.size
        post, node, event, taken = self.events_from(frontier)
        cls = self.classify(post, node, event)
        n_out = np.array(self.n_out, dtype=np.int64)
        self.cycles += int(n_out[cls].sum())
        # one expansion per distinct (state, class); the first occurrence is the parent
        _, keep, rep = np.unique(post * len(self.n_out) + cls, return_index=True, return_inverse=True)
        by_position = np.argsort(keep)
        keep = keep[by_position]
        position = np.empty_like(by_position)
        position[by_position] = np.arange(by_position.size)
        rep = position[rep.ravel()]  # the kept entry that stands for each (state, class)
        sources, taken_all, events_all = node, taken, event
        post, node, event, cls = post[keep], node[keep], event[keep], cls[keep]
        # one entry per (state, outcome of its class)
        reps = n_out[cls]
        entry = np.repeat(np.arange(post.size), reps)
        within = np.arange(entry.size) - np.repeat(np.cumsum(reps) - reps, reps)
        offsets = np.concatenate(([0], np.cumsum(n_out)))
        oid = np.array(self.flat, dtype=np.int64)[offsets[cls][entry] + within]
        targets, fallback, outside, aux_after, requests = self.arrays.update(self.outcomes)
        post, node, event, targets = post[entry], node[entry], event[entry], targets[oid]
        cur, refused, edge_bad, edge_events, middle_bad = write(pr, post, targets)
        ok = cur >= 0
        final = np.where(ok, cur, 0)
        violation = ok & pr.illegal[final]
        middle_bad &= ~violation & ~pr.illegal[post]  # reported as a violation / before the write
        shown = np.where(ok, final, post)

        def edge_ids(i: int) -> tuple[str, ...]:
            return tuple(dict.fromkeys(c for ev in edge_events for c in pr.columns.forbidding(ev, int(post[i]))))

        self.record(FindingKind.VIOLATION, violation, final, node, event, oid, shown,
                    lambda i: pr.violated(int(final[i])))
        self.record(FindingKind.EDGE, edge_bad, post, node, event, oid, shown, edge_ids)
        for kind, mask in ((FindingKind.REFUSED, refused), (FindingKind.FALLBACK, fallback[oid]),
                           (FindingKind.OUTSIDE_CARE, outside[oid]), (FindingKind.TRANSIENT, middle_bad)):
            self.record(kind, mask, post, node, event, oid, shown)
        if pr.controlled and oid.size:
            dist = (requests[oid] != targets).sum(axis=1)
            # each kept (state, class) stands for every entry merged into it: count them all, as cycles does
            merged = np.bincount(rep, minlength=keep.size)[entry]
            self.corrected += int(merged[dist > 0].sum())
            self.max_distance = max(self.max_distance, int(dist.max()))
        if self.track:
            self.edges((sources, taken_all, events_all), rep, entry[ok], aux_after[oid][ok] * size + final[ok],
                       oid[ok], keep.size)
        return self.admit(aux_after[oid][ok] * size + final[ok], node[ok], event[ok], oid[ok])

    def edges(self, entries: tuple[np.ndarray, np.ndarray, np.ndarray], rep: np.ndarray, succ_rep: np.ndarray,
              succ_key: np.ndarray, succ_oid: np.ndarray, reps: int) -> None:
        """Every edge of the product (for --progress): each (node, events) entry gets the
        successors (and outcomes) of the entry that stands for its (state, class)."""
        sources, taken, events = entries
        counts = np.bincount(succ_rep, minlength=reps)
        starts = np.cumsum(counts) - counts
        by_rep = np.argsort(succ_rep, kind="stable")
        n = counts[rep]
        pick = np.repeat(starts[rep], n) + np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
        self.edge_parts.append((np.repeat(sources, n), succ_key[by_rep][pick], np.repeat(taken, n),
                                np.repeat(events, n), succ_oid[by_rep][pick]))

    def admit(self, keys: np.ndarray, node: np.ndarray, event: np.ndarray, oid: np.ndarray) -> np.ndarray:
        """The nodes of ``keys`` not seen before (their first occurrence is the parent)."""
        uk, first = np.unique(keys, return_index=True)
        seen = self.seen_keys
        fresh = np.fromiter((k not in seen for k in uk.tolist()), dtype=bool, count=uk.size)
        new: list[int] = []
        if self.prelude is not None and not self.reentered and self.prelude in uk:
            self.reentered = True  # a scan gives the fresh instance back: a state like any other
            new.append(self.prelude)
        admitted = len(new)
        for k, i in zip(uk[fresh].tolist(), first[fresh].tolist()):
            if self.states >= self.max_states:
                self.complete = False
                break
            self.admit_one(k)
            self.parent[k] = (int(node[i]), self.events[int(event[i])], int(oid[i]))
            new.append(k)
        out = np.array(new, dtype=np.int64)
        self.note_outside(out[admitted:])
        return out

    def run(self) -> None:
        frontier = np.array([self.key0], dtype=np.int64)
        if self.prelude is not None:  # the power-up scan reads the plant's initial state: no event before it
            k, self.k = self.k, 0
            frontier = self.level(frontier)
            self.powered = set(frontier.tolist())
            self.k, self.prelude_cycles, self.prelude_corrected = k, self.cycles, self.corrected
        started, levels = time.monotonic(), 0
        while frontier.size and self.complete:
            frontier = self.level(frontier)
            levels += 1
            if self.report is not None:
                rate = self.cycles / max(time.monotonic() - started, 1e-6)
                self.report(f"closed loop: {self.states} states, {self.cycles} cycles ({rate:.0f} cycles/s), "
                            f"level {levels}")

    @property
    def states(self) -> int:
        """The nodes found: the closed loop after a PLC cycle (a program's fresh instance, the
        PLC before its power-up scan, is the traces' first row, not a state unless a scan gives
        it back)."""
        return len(self.seen_keys) - (self.prelude is not None and not self.reentered)

    @property
    def plant_states(self) -> int:
        """The plant states of :attr:`states`."""
        hidden = self.prelude if self.prelude is not None and not self.reentered else None
        return len({k % self.size for k in self.seen_keys if k != hidden})

    @property
    def loop_cycles(self) -> tuple[int, int]:
        """The cycles explored from the states, and those where the filter corrects the
        requests (the power-up cycle is not one of them; its findings are findings)."""
        return self.cycles - self.prelude_cycles, self.corrected - self.prelude_corrected

    # ------------------------------------------------------------------ traces
    def trace(self, key: int) -> list[TraceRow]:
        """The shortest path of cycles from the initial node to ``key``."""
        rows = []
        while key in self.parent:
            pk, ev, g = self.parent[key]
            ev = POWER_UP if key in self.powered else ev
            rows.append(trace_row(self.pr, self.outcomes[g], ev, key % self.size, self.aux_list[key // self.size][2]))
            key = pk
        rows.append(TraceRow("initial", self.pr.label(key % self.size),
                             situation_text(self.aux_list[key // self.size][2]), (), ()))
        return rows[::-1]

    def findings(self) -> dict[FindingKind, Finding]:
        out: dict[FindingKind, Finding] = {}
        if self.pr.illegal[self.key0 % self.size]:
            out[FindingKind.VIOLATION] = Finding(FindingKind.VIOLATION, self.pr.violated(self.key0 % self.size),
                                       tuple(self.trace(self.key0)), len(self.counts[FindingKind.VIOLATION]))
        for kind, (node, ev, g, code, ids) in self.first.items():
            if kind in out:
                continue
            rows = self.trace(node)
            if g < 0:  # the plant's event alone
                rows.append(TraceRow(ev, self.pr.label(code), rows[-1].situation, (), (), "before the PLC writes",
                                     False))
            else:
                oc = self.outcomes[g]
                rows.append(trace_row(self.pr, oc, ev, code, self.aux_list[oc.aux][2], _NOTES[kind]))
            out[kind] = Finding(kind, ids, tuple(rows), len(self.counts[kind]))
        if self.first_outside_sup is not None:
            key = self.first_outside_sup
            rows = self.trace(key)
            ids = self.pr.columns.threatened(key % self.size)
            rows[-1] = dataclasses.replace(rows[-1], note="; ".join(
                n for n in (rows[-1].note, "outside SUP: uncontrollable events can lead to " + ", ".join(ids)) if n))
            out[FindingKind.OUTSIDE_SUP] = Finding(FindingKind.OUTSIDE_SUP, ids, tuple(rows), len(self.outside_sup))
        return {k: out[k] for k in FindingKind if k in out}

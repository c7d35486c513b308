"""Shortest traces of the symbolic closed loop without the explicit engine: a walk back
through the rings of :class:`~synth.filter.loop.symbolic.rings.SymbolicLoop`, one concrete
predecessor per level, for the plants whose explicit arrays do not fit
(:func:`~synth.filter.loop.symbolic.verify.verify_symbolic` uses it when the explicit engine
cannot render the traces within its budget).

Each trace is a shortest one (its length is the explicit engine's), made of real cycles
of the closed loop: the plant's events (a shortest sequence of at most K), the request
vector and the orders written, the note ``requests violate ...`` computed by the
reference cycle (:class:`~synth.filter.cycle.FilterCycle`). Where several shortest traces
exist it may show another one than the explicit engine: the first path to 1 of each
BDD, 0 before 1, in the manager's variable order.

Example
-------
>>> from synth.filter.cycle import Algorithm, Mode
>>> from synth.filter.language_check import load_filter
>>> from synth.plant.composition import _plants, load_plant
>>> loop = SymbolicLoop(load_filter(_plants("../tests/data/filter/two_no_edge.filter")),
...                     load_plant(_plants("../tests/data/filter/two.rules")), Algorithm.ALGEBRAIC, Mode.SUPERVISOR,
...                     False, 1)
>>> loop.run()
>>> ids, rows = Walk(loop).finding(FindingKind.EDGE)
>>> ids, len(rows), rows[-1].note
(('E',), 3, 'requests violate K; output event forbidden')
"""

from __future__ import annotations

from typing import Mapping

from synth.filter.cycle import ACK, Memory
from synth.filter.loop.symbolic.cycle import ACK_VAR, BLOCKED, FALLBACK, OUTSIDE, next_name
from synth.filter.loop.symbolic.rings import SymbolicLoop
from synth.filter.loop.verification import FindingKind, TraceRow
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.logic.past import pre_name
from synth.symbolic.encoding import Copy
from synth.symbolic.relation import image, preimage

__all__ = ["Walk"]

_NOTES = {FindingKind.EDGE: "output event forbidden", FindingKind.REFUSED: "output change refused",
          FindingKind.FALLBACK: "fallback", FindingKind.OUTSIDE_CARE: "outside the care set",
          FindingKind.TRANSIENT: "an intermediate state of the write violates a constraint"}

Point = dict[str, bool]


class Walk:
    """Concrete traces back through the rings of a finished :class:`SymbolicLoop`."""

    def __init__(self, loop: SymbolicLoop) -> None:
        self.loop, self.sc, self.enc, self.e = loop, loop.sc, loop.enc, loop.engine
        self.node_names = list(loop.node_vars)

    # ------------------------------------------------------------------ points
    def pick(self, u: Function, names: list[str]) -> Point:
        """One valuation of ``names`` in ``u`` (a path to 1, the free names false)."""
        cube = self.e.path_cube(u)
        assert cube is not None, "a witness in an empty set"
        return {n: bool(cube.get(n, False)) for n in names}

    def cube(self, point: Mapping[str, bool]) -> Function:
        return self.e.cube(dict(point))

    def label(self, point: Mapping[str, bool]) -> str:
        return self.sc.plant.label(self.enc.local({v: point[v] for v in self.enc.variables}))

    def violated(self, point: Mapping[str, bool], terms: dict[str, Function]) -> tuple[str, ...]:
        c = self.cube({v: point[v] for v in self.enc.variables})
        return tuple(i for i, u in terms.items() if c & u != self.e.false)

    # ------------------------------------------------------------------ the plant's events
    def events(self, node: Point, post: Function) -> tuple[Point, tuple[str, ...]]:
        """A shortest sequence of at most K uncontrollable events from ``node`` into
        ``post`` (a set over x and the memory) and the state it reaches."""
        layers = [self.cube(node)]
        while layers[-1] & post == self.e.false:
            assert len(layers) <= self.loop.k, "no path of the plant's events"
            layers.append(self.e.disjunction(image(self.enc, layers[-1], m) for m in self.sc.uncontrollable))
        here = self.pick(layers[-1] & post, self.node_names)
        at, seq = here, []
        for layer in reversed(layers[:-1]):
            for m in self.sc.uncontrollable:
                before = preimage(self.enc, self.cube(at), m) & layer
                if before != self.e.false:
                    seq.append(m.event)
                    at = self.pick(before, self.node_names)
                    break
        return here, tuple(reversed(seq))

    # ------------------------------------------------------------------ one cycle
    def row(self, node: Point, post: Point, events: tuple[str, ...], choice: Point, shown: Point,
            note: str = "") -> TraceRow:
        """The trace row of one cycle: ``choice`` gives the requests (and Ack)."""
        sc, cyc = self.sc, self.sc.cycle
        requests: dict[str, bool] = {}
        values: dict[str, bool] = {y: post[y] for y in cyc.filter.inputs}
        for o, r in zip(cyc.outputs, cyc.requests):
            requests[o] = values[r] = sc.held[o] if o in sc.held else choice[r]
        for z in sc.passthrough:
            requests[z] = sc.held[z] if z in sc.held else choice[f"?R_{z}"]
        if sc.blocking:
            values[ACK] = choice[ACK_VAR]
        previous = tuple(node[pre_name(n)] if n in cyc.used else False for n in cyc.remembered)
        result, _ = cyc.step(Memory(previous, bool(node.get(BLOCKED, False))), values)
        notes = [f"requests violate {', '.join(result.violated)}"] if result.violated else []
        notes += [note] if note else []
        return TraceRow(", ".join(events) if events else "-", self.label(shown), "",
                        tuple(z for z in sc.orders if requests[z]),
                        tuple(z for z in sc.orders if choice[z + Copy.NEXT.value]), "; ".join(notes))

    def into(self, target: Point) -> Function:
        """The (post state, memory, requests, outcome) whose write leads to node ``target``."""
        e, sc = self.e, self.sc
        fixed: dict[str, bool] = {z + Copy.NEXT.value: target[z] for z in sc.orders}
        fixed.update({next_name(m): target[m] for m in sc.state_memory})
        keep = {v: target[v] for v in self.enc.variables if v not in sc.orders}
        return e.let(fixed, sc.relation & ~sc.refused) & self.cube(keep) & e.cube(fixed)

    def path(self, target: Point, depth: int) -> list[TraceRow]:
        """The rows from the initial node to ``target``, a node of ring ``depth``."""
        e, loop, enc = self.e, self.loop, self.enc
        rows: list[TraceRow] = []
        while depth > 0:
            cycle = self.into(target)
            posts = e.exists(self.choice_names(), cycle)
            reach, layer = posts, posts
            for _ in range(loop.k):
                layer = e.disjunction(preimage(enc, layer, m) for m in self.sc.uncontrollable)
                reach |= layer
            node = self.pick(loop.levels[depth - 1] & reach, self.node_names)
            post, seq = self.events(node, posts & self.memory_cube(node))
            choice = self.pick(cycle & self.cube(post), self.choice_names())
            rows.append(self.row(node, post, seq, choice, target))
            target, depth = node, depth - 1
        rows.append(TraceRow("initial", self.label(target), "", (), ()))
        return rows[::-1]

    def memory_cube(self, node: Point) -> Function:
        return self.cube({m: node[m] for m in self.sc.state_memory})

    def choice_names(self) -> list[str]:
        sc = self.sc
        return [*sc.free, *(z + Copy.NEXT.value for z in sc.orders), *(next_name(m) for m in sc.state_memory),
                FALLBACK, OUTSIDE]

    # ------------------------------------------------------------------ findings
    def finding(self, kind: FindingKind) -> tuple[tuple[str, ...], list[TraceRow]]:
        """The constraints and a shortest trace of the first occurrence of ``kind``."""
        e, sc, loop = self.e, self.sc, self.loop
        d = loop.first_level[kind]
        if kind in (FindingKind.VIOLATION, FindingKind.OUTSIDE_SUP):
            where = sc.illegal if kind is FindingKind.VIOLATION else sc.removed
            node = self.pick(loop.levels[d + 1] & where, self.node_names)
            rows = self.path(node, d + 1)
            if kind is FindingKind.VIOLATION:
                return self.violated(node, self.level_terms()), rows
            threatened = self.violated(node, {i: sc.backward(u) for i, u in self.level_terms().items()})
            last = rows[-1]
            note = "; ".join(x for x in (last.note, "outside SUP: uncontrollable events can lead to "
                                         + ", ".join(threatened)) if x)
            rows[-1] = TraceRow(last.event, last.state, last.situation, last.requests, last.orders, note, last.ran)
            return threatened, rows
        frontier = loop.levels[d]
        if kind is FindingKind.TRANSIENT:  # the plant's events first, as the explicit engine records them
            moved, layer = e.false, frontier & ~sc.illegal
            for _ in range(loop.k):
                layer = e.disjunction(image(self.enc, layer, m) for m in sc.uncontrollable)
                moved |= layer
            if moved & sc.illegal != e.false:
                post_set = moved & sc.illegal
                reach, layer = post_set, post_set
                for _ in range(loop.k):
                    layer = e.disjunction(preimage(self.enc, layer, m) for m in sc.uncontrollable)
                    reach |= layer
                node = self.pick(frontier & ~sc.illegal & reach, self.node_names)
                post, seq = self.events(node, post_set & self.memory_cube(node))
                rows = self.path(node, d)
                rows.append(TraceRow(", ".join(seq), self.label(post), "", (), (), "before the PLC writes", False))
                return self.violated(post, self.level_terms()), rows
        flag = {FindingKind.EDGE: sc.edge_bad, FindingKind.REFUSED: sc.refused, FindingKind.FALLBACK: e.var(FALLBACK),
                FindingKind.OUTSIDE_CARE: e.var(OUTSIDE), FindingKind.TRANSIENT: sc.middle_bad}[kind]
        cycle = sc.relation & flag
        posts = e.exists(self.choice_names(), cycle)
        reach, layer = posts, posts
        for _ in range(loop.k):
            layer = e.disjunction(preimage(self.enc, layer, m) for m in sc.uncontrollable)
            reach |= layer
        node = self.pick(frontier & reach, self.node_names)
        post, seq = self.events(node, posts & self.memory_cube(node))
        choice = self.pick(cycle & self.cube(post), self.choice_names())
        refused = self.cube(post) & self.cube({t: choice[t] for t in self.targets()}) & sc.refused != e.false
        shown = post if refused else {**post, **{z: choice[z + Copy.NEXT.value] for z in sc.orders}}
        rows = self.path(node, d)
        rows.append(self.row(node, post, seq, choice, shown, _NOTES[kind]))
        ids: tuple[str, ...] = ()
        if kind is FindingKind.EDGE:
            ids = self.edge_ids(post, choice)
        return ids, rows

    def targets(self) -> list[str]:
        return [z + Copy.NEXT.value for z in self.sc.orders]

    def level_terms(self) -> dict[str, Function]:
        return self.sc.constraint_terms()[0]

    def edge_ids(self, post: Point, choice: Point) -> tuple[str, ...]:
        """The edge constraints that forbid the write's events, from the state after the plant's events."""
        sc = self.sc
        edges = sc.constraint_terms()[1]
        here = self.cube({v: post[v] for v in self.enc.variables})
        ids: list[str] = []
        for rising in (False, True):
            for z in sc.orders:
                if choice[z + Copy.NEXT.value] == rising and post[z] != rising:
                    for i, u in edges.get(Event.edge(z, rising), {}).items():
                        if here & u != self.e.false and i not in ids:
                            ids.append(i)
        return tuple(ids)


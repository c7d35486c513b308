"""Findings in one pass: the first node and the trace of every finding at once (issue 25).

:meth:`StepReach.first_node <synth.symbolic.steps.reach.StepReach.first_node>` and
:meth:`~synth.symbolic.steps.reach.StepReach.shortest_trace` answer for one target: a
backward layering through the onion rings, then a greedy walk forward. A failing model
has hundreds of findings (``branches_3x6``: 300 prohibited situations), and one
layering each made the findings 80 % of the run. Here the targets are numbered and the
number is written in a few *tag* variables at the top of the BDD order, so one BDD
``L(t, X, x)`` holds every target's layer at once (a tag selects its own), and:

- **one backward layering** from every target at its own depth: a pre-image per ring for
  all the targets (``pre`` does not touch the tags);
- **one forward greedy pass**: per ring and move, one image of the tagged current sets;
  the tags that reach their layer by a move are read from that image, and each tag
  takes its smallest key and every move of it (as :func:`~synth.symbolic.searches.greedy`);
  the tags' paths are read from the chosen tag sets;
- **traces** (event order): the same two passes from the single target nodes, then the
  concrete nodes one ring back at a time for every trace at once (a pre-image per
  event used at that step), the smallest node per tag when a tag has several.

Each tag's result is the per-target search's: layers, choices and picks are the same
sets, only computed together. Tags sit above every other variable, so a tagged BDD is
the targets' BDDs under a small decision tree on the tag bits, sharing their common
parts; reading one target back (:meth:`Tags.split`) walks that tree, no BDD operation.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> from synth.symbolic.steps.sync import step_sync
>>> from synth.symbolic.steps.reach import StepReach
>>> rs, p, g = load_model(_plants("../tests/data/home/production_loop.g7"), _plants("../tests/data/home/cylinder.rules"))
>>> r = StepReach(step_sync(p, rs.constraints, GrafcetMachine(g)))
>>> sets = [r.s.nodes & ~r.s.initial, r.s.initial]
>>> f = Findings(r, sets)
>>> f.firsts == [r.first_node(u) for u in sets]
True
>>> keys = r.listed(r.s.nodes)
>>> f.traces(keys) == [r.shortest_trace(k) for k in keys]
True
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Sequence, TypeVar

from synth.logic.bdd import Engine, Function
from synth.logic.events import Event
from synth.symbolic.interface import Key, PathKey
from synth.symbolic.searches import Order, Path, depth_of, first_from, first_of, path_key
from synth.symbolic.steps.reach import Arc, StepReach

if TYPE_CHECKING:  # pragma: no cover
    from synth.symbolic.ties import Settled

__all__ = ["Tags", "Findings", "Batched"]

T = TypeVar("T")


class Tags:
    """``n`` targets numbered in ``bits`` variables ``#T0``, ``#T1``, … at the top of the
    order (declared once per manager, reused by later batches).

    >>> e = Engine(["x"])
    >>> t = Tags(e, 3)
    >>> f = (t.cube(0) & e.var("x")) | (t.cube(2) & ~e.var("x"))
    >>> t.split(f) == {0: e.var("x"), 2: ~e.var("x")}
    True
    """

    def __init__(self, engine: Engine, n: int) -> None:
        self.engine = engine
        self.bits = max(1, (n - 1).bit_length())
        self.inner = [engine.declare_top(f"#T{i}") for i in range(self.bits)]
        self._cubes: dict[int, Function] = {}

    def cube(self, j: int) -> Function:
        """The tag of target ``j``."""
        hit = self._cubes.get(j)
        if hit is None:
            bdd = self.engine.bdd
            hit = self._cubes[j] = bdd.cube({v: bool(j >> i & 1) for i, v in enumerate(self.inner)})
        return hit

    def split(self, f: Function) -> dict[int, Function]:
        """Per tag present in ``f`` (tags on top of every variable of ``f``), its function."""
        bdd = self.engine.bdd
        false = bdd.false
        levels = sorted((bdd.level_of_var(v), i) for i, v in enumerate(self.inner))
        out: dict[int, Function] = {}
        work = [(f, 0, 0)]  # a loop, not a recursive closure: a closure's cycle would hold BDD nodes
        while work:
            g, depth, value = work.pop()
            if g == false:
                continue
            if depth == len(levels):
                out[value] = g
                continue
            level, bit = levels[depth]
            lo = hi = g
            if g != bdd.true and g.level == level:
                lo, hi = g.low, g.high
                if g.negated:
                    lo, hi = ~lo, ~hi
            work += [(lo, depth + 1, value), (hi, depth + 1, value | 1 << bit)]
        return dict(sorted(out.items()))


class _Batch:
    """The tagged layers and greedy walk of :class:`StepReach`, for many targets."""

    def __init__(self, r: StepReach, targets: Sequence[Function]) -> None:
        self.r = r
        self.s = r.s
        self.false = r.false
        self.tags = Tags(self.s.engine, len(targets))
        bdd = self.s.engine.bdd
        self._next_cube = bdd.cube(set(self.s.next_vars))
        self.depths: list[int] = []
        by_depth: dict[int, Function] = {}
        for j, u in enumerate(targets):
            d = depth_of(r, u)
            if d is None:
                raise ValueError("no candidate is reachable")
            self.depths.append(d)
            by_depth[d] = by_depth.get(d, self.false) | (self.tags.cube(j) & u & self.s.rings[d])
        self.targets = by_depth
        self.every = self.s.engine.disjunction(e for _, e in self.s.links)  # one relation: a pre-image is one product
        self.layers = self._layers(by_depth, max(self.depths, default=0))

    def pre(self, u: Function) -> Function:
        """The nodes with a move into ``u`` (tags kept)."""
        return self.s.engine.and_exists(self.every, self.s.primed(u), self.s.next_vars)

    def _layers(self, by_depth: dict[int, Function], depth: int) -> list[Function]:
        """Per ring k, each tag's ring-k nodes from which its target is reached at its depth."""
        s = self.s
        layers = [self.false] * (depth + 1)
        layers[depth] = by_depth.get(depth, self.false)
        for k in range(depth - 1, -1, -1):
            layers[k] = (self.pre(layers[k + 1]) & s.rings[k]) | by_depth.get(k, self.false)
        return layers

    def greedy(self, order: Callable[[Arc], Order], settled: "Settled | None" = None,
               narrow: Callable[[Function, Function | None, int], Function] | None = None,
               ) -> tuple[list[Function], list[list[tuple[Order, Event, Function]]], list[dict[int, int]]]:
        """Forward through the layers, each tag taking its smallest move (by ``order``):
        the tagged current sets per ring, per step the (order, event, tags) chosen (every
        move of a tag's smallest key, as :func:`~synth.symbolic.searches.greedy`), and
        with ``settled`` each tag's set narrowed at each ring to the node the explicit
        engine enters first, with its rank (:func:`~synth.symbolic.searches.first_of`);
        ``narrow`` (traces) narrows each ring's tagged sets its own way instead (given the
        previous ring's and the ring's number)."""
        s, false, exists = self.s, self.false, self.s.engine.bdd.apply
        current = self.layers[0]
        ranks: list[dict[int, int]] = []
        if settled is not None:
            current = self._first(current, None, settled, ranks)
        elif narrow is not None:
            current = narrow(current, None, 0)
        chosen = [current]
        steps: list[list[tuple[Order, Event, Function]]] = []
        for k in range(1, len(self.layers)):
            layer = self.layers[k]
            target = s.primed(layer)
            options: dict[Order, list[tuple[Event, Function, Function]]] = {}
            for m, e in s.edges:
                v = s.image(current, m, e) & target
                if v != false:
                    options.setdefault(order((m, e)), []).append((m.event, v, exists("exists", self._next_cube, v)))
            taken = nxt = false
            record: list[tuple[Order, Event, Function]] = []
            for key in sorted(options):
                # the tags whose smallest key this is take every move of it that reaches their layer
                mine = s.engine.disjunction(tags for _, _, tags in options[key]) & ~taken
                for event, v, tags in options[key]:
                    sel = tags & mine
                    if sel != false:
                        nxt |= v & sel
                        record.append((key, event, sel))
                taken |= mine
            current = s.unprimed(nxt)
            if settled is not None:
                current = self._first(current, (chosen[-1], record), settled, ranks)
            elif narrow is not None:
                current = narrow(current, chosen[-1], k)
            chosen.append(current)
            steps.append(record)
        return chosen, steps, ranks

    def _first(self, current: Function, via: "tuple[Function, list[tuple[Order, Event, Function]]] | None",
               settled: "Settled", ranks: list[dict[int, int]]) -> Function:
        """Each tag's part of ``current`` narrowed to its first node (as
        :func:`~synth.symbolic.searches.first_of`; ``via``: the previous ring's tagged nodes
        and the moves the tags took), each tag's rank appended to ``ranks``."""
        r, tags = self.r, self.tags
        arcs = {m.event: (m, e) for m, e in self.s.edges}
        before: dict[int, Function] = {}
        moved: dict[int, tuple[Event, ...]] = {}
        if via is not None:
            before = tags.split(via[0])
            for _, event, sel in via[1]:
                for j in tags.split(sel):
                    moved[j] = moved.get(j, ()) + (event,)
        memo: dict[tuple[Function | None, tuple[Event, ...], Function], tuple[Function, int]] = {}
        out, rank = self.false, {}
        for j, u in tags.split(current).items():
            key = (before.get(j), moved.get(j, ()), u)
            hit = memo.get(key)
            if hit is None:
                parent: tuple[Key, list[Arc]] | None = None
                if via is not None:
                    parent = (r.pick(before[j]), [arcs[event] for event in moved[j]])
                hit = memo[key] = first_of(r, u, parent, settled)
            out |= tags.cube(j) & hit[0]
            rank[j] = hit[1]
        ranks.append(rank)
        return out

    def paths(self, steps: list[list[tuple[Order, Event, Function]]]) -> list[list[tuple[Order, Event]]]:
        """Each tag's (order, event) per step, read from the chosen tag sets (the first
        move of the key it took)."""
        out: list[list[tuple[Order, Event]]] = [[] for _ in self.depths]
        for k, record in enumerate(steps):
            for key, event, sel in record:
                for j in self.tags.split(sel):
                    if len(out[j]) == k:
                        out[j].append((key, event))
        return out


class Findings:
    """The first node of every set of ``sets`` (:attr:`firsts`, as
    :meth:`StepReach.first_node`), then the traces to nodes (:meth:`traces`, as
    :meth:`StepReach.shortest_trace`): a node that is the whole target of a set at its
    depth has that set's layers, which its trace reuses."""

    def __init__(self, r: StepReach, sets: Sequence[Function]) -> None:
        self.r = r
        self.firsts: list[tuple[Key, int, PathKey]] = []
        self._whole: dict[Key, int] = {}  # node -> a set whose target at its depth is that node alone
        self._batch: _Batch | None = None
        if not sets:
            return
        b = self._batch = _Batch(r, sets)
        chosen, steps, ranks = b.greedy(r.order, r.settled)
        paths = b.paths(steps)
        ends: dict[int, dict[int, Function]] = {}
        s = r.s
        for j, d in enumerate(b.depths):
            if d not in ends:
                ends[d] = b.tags.split(chosen[d])
            key = r.pick(ends[d][j])
            self.firsts.append((key, d, path_key([k for k, _ in paths[j]], [rk[j] for rk in ranks[:d + 1]])))
            if key not in self._whole and s.count(sets[j] & s.rings[d], s.current_vars) == 1:
                self._whole[key] = j

    def traces(self, keys: Sequence[Key]) -> list[Path]:
        """The trace to every node of ``keys``."""
        found: dict[Key, Path] = {}
        reused = {self._whole[k]: k for k in keys if k in self._whole}
        if reused:
            assert self._batch is not None
            found.update(_traces(self.r, self._batch, reused))
        rest = [k for k in dict.fromkeys(keys) if k not in found]
        if rest:
            found.update(_traces(self.r, _Batch(self.r, [self.r.cube(k) for k in rest]), dict(enumerate(rest))))
        return [found[k] for k in keys]


class Batched:
    """A report's first nodes and traces by :class:`Findings` (the one-target twin:
    :class:`~synth.symbolic.searches.OneByOne`): :meth:`firsts` once, then :meth:`traces`."""

    def __init__(self, r: StepReach) -> None:
        self.r = r
        self._found: Findings | None = None

    def firsts(self, sets: Sequence[Function]) -> list[tuple[Key, int, PathKey]]:
        self._found = Findings(self.r, sets)
        return self._found.firsts

    def traces(self, keys: Sequence[Key]) -> list[Path]:
        assert self._found is not None, "firsts before traces"
        return self._found.traces(keys)


def _traces(r: StepReach, b: _Batch, wanted: dict[int, Key]) -> dict[Key, Path]:
    """The traces of the tags ``wanted`` of ``b`` (each the tag of one node, its target),
    as :func:`~synth.symbolic.searches.shortest_trace`: the greedy walk in event order,
    each tag's ring narrowed to the node the explicit engine numbers first (the first
    nodes of the tags with several, in one batch per ring)."""
    mask = r.s.engine.disjunction(b.tags.cube(j) for j in wanted)
    counted: dict[Function, int] = {}  # traces share their first nodes: each set counted and picked once
    picked: dict[Function, Key] = {}

    def first_each(current: Function, previous: Function | None, k: int) -> Function:
        parts = b.tags.split(current & mask)
        several = {j: u for j, u in parts.items() if _memo(counted, u, r.count) > 1}
        if not several:
            return current & mask
        found: dict[int, Function] = {}
        if previous is not None and r.settled is not None:  # as searches.first_entered, one pre-image for all tags
            parents = b.tags.split(previous)
            feeding = b.tags.split(b.pre(current & mask) & r.s.rings[k - 1])
            for j, u in several.items():
                if feeding[j] == parents[j]:
                    found[j] = first_from(r, u, parents[j], r.settled)
        rest = list(dict.fromkeys(u for j, u in several.items() if j not in found))
        firsts = {u: r.cube(f[0]) for u, f in zip(rest, Findings(r, rest).firsts)} if rest else {}
        return r.s.engine.disjunction(b.tags.cube(j) & found.get(j, firsts.get(u, u)) for j, u in parts.items())

    chosen, steps, _ = b.greedy(r.event, narrow=first_each)
    paths = b.paths(steps)
    rings = [b.tags.split(c) for c in chosen]
    return {k: Path(tuple(_memo(picked, rings[i][j], r.pick) for i in range(b.depths[j] + 1)),
                    tuple(e for _, e in paths[j]))
            for j, k in wanted.items()}


def _memo(memo: dict[Function, T], u: Function, f: Callable[[Function], T]) -> T:
    hit = memo.get(u)
    if hit is None:
        hit = memo[u] = f(u)
    return hit

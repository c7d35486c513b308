"""Differential tests: validation/analysis.py (hand-written Tarjan and breadth-first
searches, kept for start-up cost and speed) against networkx on random graphs.

Every graph function of the analysis is compared: strongly connected components,
coreachability, breadth-first distances and shortest traces, held nodes, the blocking
(terminal) components with their entry states, and the prohibited orders' first states.
networkx is imported here only (synth itself never imports it).
"""

from __future__ import annotations

import random

import pytest

from synth.grafcet.machine import Situation
from synth.logic.events import Event
from synth.validation.analysis import (LAYERS, analyse, coreachable, coreachable_by_layers, held_nodes, shortest_paths,
                                      shortest_paths_by_layers, strongly_connected_components)
from synth.validation.sync import Edge, Node, Prohibition, Sync

nx = pytest.importorskip("networkx")

FAR = 1 << 30
SEEDS = range(150)


def _random_sync(seed: int) -> Sync:
    """A random aggregated automaton: 1-40 nodes, a few situations, edges on a few
    events (self-loops and parallel edges included), some prohibited orders."""
    rnd = random.Random(seed)
    n = rnd.randint(1, 40)
    situations = [Situation((str(k),)) for k in range(rnd.randint(1, 4))]
    orders = [Event.edge(f"Z{k}", rising) for k in range(2) for rising in (True, False)]
    nodes = []
    for _ in range(n):
        proh = tuple(sorted(Prohibition(e, ("C1",)) for e in orders if rnd.random() < 0.06))
        nodes.append(Node(rnd.choice(situations), (0,), frozenset(), (), proh))
    events = [Event.edge(f"e{k}", rising) for k in range(3) for rising in (True, False)]
    density = rnd.choice((0.5, 1.0, 1.5, 2.5))
    edges = {Edge(rnd.randrange(n), rnd.choice(events), rnd.randrange(n)) for _ in range(int(density * n))}
    initial = tuple(sorted(rnd.sample(range(n), rnd.choice((1, 1, 2)) if n > 1 else 1)))
    return Sync(None, None, None, tuple(nodes), tuple(sorted(edges, key=lambda e: (e.source, e.event, e.target))),  # type: ignore[arg-type]
                initial)


def _graph(sync: Sync) -> nx.DiGraph:
    g = nx.DiGraph()
    g.add_nodes_from(range(len(sync.nodes)))
    g.add_edges_from((e.source, e.target) for e in sync.edges)
    return g


def _closure_back(g: nx.DiGraph, targets: set[int]) -> set[int]:
    return set(targets).union(*(nx.ancestors(g, t) for t in targets))


def _distances(g: nx.DiGraph, initial: tuple[int, ...]) -> dict[int, int]:
    lengths = nx.multi_source_dijkstra_path_length(g, set(initial))
    return {i: int(d) for i, d in lengths.items()}


@pytest.mark.parametrize("seed", SEEDS)
def test_strongly_connected_components(seed: int) -> None:
    sync = _random_sync(seed)
    g = _graph(sync)
    succ = {i: sorted(g.successors(i)) for i in g}
    ours = strongly_connected_components(list(range(len(sync.nodes))), succ)
    assert sorted(map(sorted, ours)) == sorted(map(sorted, nx.strongly_connected_components(g)))


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("layers", [False, True])
def test_coreachable_and_held(seed: int, layers: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """One node at a time (small graphs) and a layer at a time (from LAYERS edges on)."""
    if layers:
        import synth.validation.analysis as analysis

        monkeypatch.setattr(analysis, "LAYERS", 0)
    sync = _random_sync(seed)
    g = _graph(sync)
    targets = set(random.Random(-seed).sample(range(len(sync.nodes)), 1))
    assert coreachable(sync, targets) == coreachable_by_layers(sync, targets) == _closure_back(g, targets)
    changers = {e.source for e in sync.edges if sync.nodes[e.source].situation.steps != sync.nodes[e.target].situation.steps}
    assert held_nodes(sync) == set(g) - _closure_back(g, changers)


@pytest.mark.parametrize("seed", SEEDS)
def test_shortest_paths(seed: int) -> None:
    sync = _random_sync(seed)
    g = _graph(sync)
    dist, parent = shortest_paths(sync)
    assert dist == _distances(g, sync.initial)
    for t, (s, event) in parent.items():  # each parent is an edge one step closer
        assert dist[s] + 1 == dist[t]
        assert Edge(s, event, t) in sync.edges


@pytest.mark.parametrize("seed", SEEDS)
def test_analysis(seed: int) -> None:
    sync = _random_sync(seed)
    g = _graph(sync)
    homes = set(sync.initial)
    a = analyse(sync)
    back = _closure_back(g, homes)
    dist = _distances(g, sync.initial)
    assert a.coreachable == back and a.homes == homes

    def first(nodes) -> int:
        return min(nodes, key=lambda i: (dist.get(i, FAR), i))

    # blocking: held nodes with a prohibited order (once per set of steps), then terminal
    # components of the part that cannot reach a home
    held = set(g) - _closure_back(g, {e.source for e in sync.edges
                                      if sync.nodes[e.source].situation.steps != sync.nodes[e.target].situation.steps})
    assert a.held == held
    by_steps: dict[tuple[str, ...], set[int]] = {}
    for i in held:
        if sync.nodes[i].proh:
            by_steps.setdefault(sync.nodes[i].situation.steps, set()).add(i)
    expected = {first(m): tuple(sorted(m)) for m in by_steps.values()}
    stuck = g.subgraph(set(g) - back)
    dag = nx.condensation(stuck)
    for c in dag:
        comp = dag.nodes[c]["members"]
        if dag.out_degree(c) == 0 and not all(sync.nodes[i].situation.steps in by_steps for i in comp):
            expected[first(comp)] = tuple(sorted(comp))
    assert a.components == expected
    assert list(a.blocking) == sorted(expected, key=lambda i: (dist.get(i, FAR), i))
    # traces: shortest, and real paths of the automaton
    for i, tr in a.traces.items():
        assert len(tr.events) == dist.get(i, 0) and tr.nodes[-1] == i
        assert tr.nodes[0] in sync.initial or i not in dist
        assert all(Edge(s, ev, t) in sync.edges for s, ev, t in zip(tr.nodes, tr.events, tr.nodes[1:]))
    for b in a.blocking:  # the point of no return: the first node of the trace that cannot come back
        assert a.no_return[b] == next((n for n in a.traces[b].nodes if n not in back), b)
    # prohibited orders: for each (steps, event), the reachable node met first
    firsts = {}
    for i in sorted(dist, key=lambda i: (dist[i], i)):
        for p in sync.nodes[i].proh:
            firsts.setdefault((sync.nodes[i].situation.steps, p.event), i)
    assert list(a.prohibited) == sorted(set(firsts.values()), key=lambda i: (dist[i], i))


def test_the_random_graphs_are_not_trivial() -> None:
    """The cases above meet blocking components, held prohibited orders, unreachable nodes."""
    blocking = held_proh = unreachable = 0
    for seed in SEEDS:
        sync = _random_sync(seed)
        a = analyse(sync)
        blocking += bool(a.blocking)
        held_proh += any(sync.nodes[i].proh for i in a.held)
        unreachable += len(_distances(_graph(sync), sync.initial)) < len(sync.nodes)
    assert min(blocking, held_proh, unreachable) > 10


@pytest.mark.parametrize("seed", SEEDS)
def test_shortest_paths_parents_as_the_queue_finds_them(seed: int) -> None:
    sync = _random_sync(seed)
    edges = list(sync.edges)
    random.Random(seed).shuffle(edges)  # the engine's edges are in exploration order, not by event
    sync = Sync(None, None, None, sync.nodes, tuple(edges), sync.initial)  # type: ignore[arg-type]
    assert len(sync.edges) < LAYERS  # shortest_paths: one node at a time
    dist, parent = shortest_paths_by_layers(sync)
    ref_dist, ref_parent = shortest_paths(sync)
    assert list(dist.items()) == list(ref_dist.items()) and list(parent.items()) == list(ref_parent.items())

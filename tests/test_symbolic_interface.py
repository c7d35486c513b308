"""One interface for both symbolic SYNC representations (synth/symbolic/interface.py).

The same assertions run against the per-situation representation
(:class:`~synth.symbolic.situations.reach.SituationReach`) and the steps in the BDD
(:class:`~synth.symbolic.steps.reach.StepReach`), each checked against the explicit
engine's SYNC: node sets, rings, moves, fixpoints, held nodes, components, first nodes
and traces. Then: the batched searches of the step path equal the one search on the
bench families; the choice of the path is a function's answer. (That no module of
``synth/symbolic`` reads another object's private member is tests/test_structure.py's scan.)
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

from synth.grafcet.language_check import parse_grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.interface import SymbolicGraph
from synth.symbolic.searches import OneByOne, first_node, shortest_trace, terminal_components
from synth.symbolic.situations.reach import SituationReach
from synth.symbolic.situations.sync import symbolic_sync
from synth.symbolic.steps.batch import Batched
from synth.symbolic.steps.reach import StepReach
from synth.symbolic.steps.sync import step_sync
from synth.symbolic.ties import Settled
from synth.symbolic.validate import PathChoice, SymbolicPath, choose_path
from synth.validation.result import load_model
from synth.validation.validate import validate

from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
from gen_par import write_par  # noqa: E402
from gen_steep import write_steep  # noqa: E402

H = ROOT / "tests" / "data" / "home"
CASES = ["production_loop.g7", "no_restart.g7", "prohibited_initial.g7", "never_leaves.g7"]


def _explicit(grafcet: Path, rules: Path) -> tuple[Any, list[list[int]]]:
    """The explicit engine's validation and its SYNC's breadth-first rings."""
    v = validate(grafcet, rules)
    sync = v.sync
    seen = set(sync.initial)
    rings, ring = [], sorted(sync.initial)
    while ring:
        rings.append(ring)
        nxt = sorted({e.target for i in ring for e in sync.successors(i)} - seen)
        seen |= set(nxt)
        ring = nxt
    return v, rings


class Representation:
    """The assertions; a subclass says how to build the representation (dd's shared backend tests)."""

    @staticmethod
    def build(grafcet: Path, rules: Path) -> SymbolicGraph[Any, Any]:
        raise NotImplementedError

    @pytest.fixture(params=CASES)
    def case(self, request: pytest.FixtureRequest) -> tuple[SymbolicGraph[Any, Any], Any, list[list[int]]]:
        grafcet, rules = H / request.param, H / "cylinder.rules"
        return (self.build(grafcet, rules), *_explicit(grafcet, rules))

    @staticmethod
    def named(g: SymbolicGraph[Any, Any], u: Any) -> set[tuple[tuple[str, ...], tuple[int, ...]]]:
        """The nodes of ``u`` as (active steps, plant state)."""
        return {(g.numbering.situations[s].steps, local) for s, local in g.listed(u, 10_000)}

    @staticmethod
    def explicit(v: Any, nodes: Any) -> set[tuple[tuple[str, ...], tuple[int, ...]]]:
        return {(v.sync.nodes[i].situation.steps, v.sync.nodes[i].plant) for i in nodes}

    def test_nodes_and_rings_are_the_explicit_engines(self, case):
        g, v, rings = case
        assert g.count(g.reached) == v.stats["aggregated_states"] == len(v.sync.nodes)
        assert self.named(g, g.reached) == self.explicit(v, range(len(v.sync.nodes)))
        assert [self.named(g, ring) for ring in g.rings()] == [self.explicit(v, ring) for ring in rings]
        assert self.named(g, g.initial) == self.explicit(v, v.sync.initial)

    def test_set_algebra(self, case):
        g, _, _ = case
        rings = list(g.rings())
        a, b = g.reached, rings[-1]
        assert g.is_empty(g.empty) and not g.is_empty(a)
        assert g.count(g.union(g.minus(a, b), g.meet(a, b))) == g.count(a)
        assert g.is_empty(g.meet(g.minus(a, b), b))
        assert g.count(g.union(rings[0], rings[-1])) == g.count(rings[0]) + g.count(rings[-1]) - g.count(g.meet(rings[0], rings[-1]))

    def test_one_node(self, case):
        g, _, _ = case
        keys = g.listed(g.reached, 10_000)
        for key in keys:
            assert g.pick(g.cube(key)) == key and g.count(g.cube(key)) == 1
            assert g.contains(g.reached, key)
        assert g.pick(g.reached) in keys

    def test_moves_in_the_explicit_order(self, case):
        """Every edge of the explicit SYNC is a move's post-image, and back its pre-image."""
        g, v, _ = case
        edges: set[tuple[Any, str, Any]] = set()
        for key in g.listed(g.reached, 10_000):
            node = g.cube(key)
            keys = [g.order(m) for m in g.moves_from(node) if not g.is_empty(g.post_by(node, m))]
            assert keys == sorted(keys)
            for m in g.moves_from(node):
                post = g.post_by(node, m)
                for target in g.listed(post, 100):
                    assert g.contains(g.pre_by(g.cube(target), m), key)
                    edges.add((self.named(g, node).pop(), str(g.event(m)), self.named(g, g.cube(target)).pop()))
        nodes = v.sync.nodes
        assert edges == {((nodes[e.source].situation.steps, nodes[e.source].plant), str(e.event),
                          (nodes[e.target].situation.steps, nodes[e.target].plant)) for e in v.sync.edges}

    def test_fixpoints_and_held(self, case):
        g, v, _ = case
        assert self.named(g, g.forward(g.initial)) == self.named(g, g.reached)
        back = g.backward(g.initial)
        assert self.named(g, back) == self.explicit(v, v.analysis.coreachable)
        held = g.held()
        assert self.named(g, held) == self.explicit(v, v.analysis.held)
        assert [g.is_held(k) for k in g.listed(g.reached, 10_000)] == [g.contains(held, k) for k in g.listed(g.reached, 10_000)]
        assert self.named(g, g.pre(g.reached, g.reached)) <= self.named(g, g.reached)

    def test_components_first_nodes_and_traces(self, case):
        """Stuck components, each one's first node and its trace: the explicit analysis's."""
        g, v, _ = case
        stuck = g.minus(g.reached, g.backward(g.initial))
        comps = terminal_components(g, stuck)
        assert sorted(len(g.listed(c, 10_000)) for c in comps) == sorted(len(c) for c in v.analysis.components.values())
        found = []
        for c in comps:
            key, depth, _ = first_node(g, c)
            path = shortest_trace(g, key)
            assert len(path.events) == depth and path.nodes[-1] == key and g.contains(g.initial, path.nodes[0])
            found.append((self.named(g, g.cube(key)).pop(), tuple(str(e) for e in path.events)))
        nodes = v.sync.nodes
        assert sorted(found) == sorted(((nodes[b].situation.steps, nodes[b].plant), tuple(str(e) for e in v.analysis.traces[b].events))
                                       for b in v.analysis.blocking)

    def test_never_leaves(self, case):
        g, v, _ = case
        assert g.never_leaves() == v.analysis.never_starts
        assert len(g.one_per_situation()) == len({n.situation for n in v.sync.nodes}) == g.situation_count()


class TestSituations(Representation):
    @staticmethod
    def build(grafcet: Path, rules: Path) -> SymbolicGraph[Any, Any]:
        rs, p, g = load_model(grafcet, rules)
        return SituationReach(symbolic_sync(p, rs.constraints, GrafcetMachine(g)))


class TestSteps(Representation):
    @staticmethod
    def build(grafcet: Path, rules: Path) -> SymbolicGraph[Any, Any]:
        rs, p, g = load_model(grafcet, rules)
        return StepReach(step_sync(p, rs.constraints, GrafcetMachine(g)))


def _family(family: str, n: int, variant: int, tmp_path: Path) -> tuple[StepReach, CompiledConstraints]:
    paths = (write_par if family == "par" else write_steep)(n, tmp_path)
    rs, p, g = load_model(paths[variant], paths[0])
    r = StepReach(step_sync(p, rs.constraints, GrafcetMachine(g)))
    return r, CompiledConstraints(p, rs.constraints)


@pytest.mark.parametrize("family,n", [("par", 3), ("steep", 3), ("par", 4)])
@pytest.mark.parametrize("variant", [1, 2], ids=["passing", "missing"])
def test_batched_is_the_one_search_on_the_bench_families(family, n, variant, tmp_path):
    """The report's searches, batched (steps/batch.py) and one target at a time
    (searches.py), on every ring, every situation and the prohibited sets, ties broken
    as the explicit engine breaks them."""
    r, oracle = _family(family, n, variant, tmp_path)
    r.settled = Settled(r.numbering, oracle)
    s = r.s
    sets = list(r.prohibited().values()) + list(s.rings) + [s.nodes & s.steps.cube(sit) for sit in r.situations_of(s.nodes)]
    sets += terminal_components(r, s.nodes & ~s.backward(s.initial))
    batched, one = Batched(r), OneByOne(r, r.settled)
    firsts = batched.firsts(sets)
    assert firsts == one.firsts(sets) and len(firsts) == len(sets) > 2 * n
    keys = list(dict.fromkeys([k for k, _, _ in firsts] + r.listed(s.nodes)[::7]))
    assert batched.traces(keys) == one.traces(keys)


def test_choosing_the_path():
    """The step path when the step encoding carries the Grafcet, else per situation, with the reason."""
    _, p, g = load_model(H / "production_loop.g7", H / "cylinder.rules")
    assert choose_path(GrafcetMachine(g), p) == PathChoice(SymbolicPath.STEPS, "the step encoding carries the Grafcet")
    _, tri, g = load_model(ROOT / "grafcets" / "tri.g7", ROOT / "plants" / "tri.rules")
    assert choose_path(GrafcetMachine(g), tri) == PathChoice(SymbolicPath.SITUATIONS, "timers")
    stored = parse_grafcet("inputs dcy, v0, v1\noutputs AVANCER, RECULER\n"
                           "grafcet G { initial step 0 step 1: set AVANCER on activation\n"
                           "transition 0 -> 1 when ↑dcy  transition 1 -> 0 when v1 }", "s.g7")
    assert choose_path(GrafcetMachine(stored), p) == PathChoice(SymbolicPath.SITUATIONS, "stored actions")

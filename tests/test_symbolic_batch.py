"""Findings in one pass (synth/symbolic/steps/batch.py, issue 25).

The tagged search must give, target by target, what the one-target search of
:class:`~synth.symbolic.steps.reach.StepReach` gives: the same first node, distance and
path key, the same trace (nodes and events), ties included (``branches_3x2`` meets them).
"""

from __future__ import annotations

import sys

import pytest

from synth.grafcet.machine import GrafcetMachine
from synth.logic.bdd import Engine
from synth.symbolic.steps.batch import Findings, Tags
from synth.symbolic.steps.reach import StepReach
from synth.symbolic.steps.sync import step_sync
from synth.symbolic.ties import Settled
from synth.sup.constraints import CompiledConstraints
from synth.validation.result import load_model

from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
from gen_branches import write_branches  # noqa: E402

H = ROOT / "tests" / "data" / "home"


def _reach(grafcet, rules, ties: bool = False) -> StepReach:
    """The step path's searches; ``ties``: first nodes as the explicit engine numbers them
    (synth/symbolic/ties.py, as ``validate`` runs them)."""
    rs, p, g = load_model(grafcet, rules)
    r = StepReach(step_sync(p, rs.constraints, GrafcetMachine(g)))
    if ties:
        r.settled = Settled(r.s.helper, CompiledConstraints(p, rs.constraints))
    return r


def _sets(r: StepReach) -> list:
    """Every prohibited set, every ring, the stuck nodes' components and every node's
    situation: targets at every distance, single nodes and large sets."""
    s = r.s
    sets = list(r.prohibited().values()) + list(s.rings)
    sets += r.terminal_components(s.nodes & ~s.backward(s.initial))
    sets += [s.nodes & s.steps.cube(sit) for sit in r.situations_of(s.nodes)]
    return sets


def _check(r: StepReach) -> tuple[int, int]:
    sets = _sets(r)
    f = Findings(r, sets)
    assert f.firsts == [r.first_node(u) for u in sets]
    keys = r.listed(r.s.nodes)[::10] + [key for key, _, _ in f.firsts]  # whole targets, and other nodes
    assert f.traces(keys) == [r.shortest_trace(k) for k in keys]
    return len(sets), len(keys)


@pytest.mark.parametrize("ties", [False, True], ids=["smallest", "explicit_order"])
@pytest.mark.parametrize("variant", [0, pytest.param(1, marks=pytest.mark.nightly)], ids=["branches_3x2", "branches_3x2_missing"])
def test_batch_is_the_per_target_search_on_branches(variant, ties, tmp_path):
    rules, passing, missing = write_branches(3, 2, tmp_path)
    r = _reach((passing, missing)[variant], rules, ties)
    n_sets, n_keys = _check(r)
    assert len(r.prohibited()) > 20 and n_sets > 60 and n_keys > 50  # the batch is not trivial
    paths = [path for _, _, path in Findings(r, _sets(r)).firsts]
    if ties:  # each ring's rank: some first node is not the first state its region settles in
        assert all(len(path[0]) == 1 and all(len(k) == 4 for k in path[1:]) for path in paths)
        assert any(k[-1] for path in paths for k in path)
    else:  # the events' keys alone
        assert all(len(k) == 3 for path in paths for k in path)


@pytest.mark.parametrize("grafcet", ["production_loop.g7", "no_restart.g7", "prohibited_initial.g7", "never_leaves.g7"])
def test_batch_is_the_per_target_search_on_home_examples(grafcet):
    _check(_reach(H / grafcet, H / "cylinder.rules"))


def test_single_node_pick_reads_the_path(tmp_path):
    """A one-node set is read off its BDD; a larger one by the step-by-step choice."""
    rules, passing, _ = write_branches(3, 2, tmp_path)
    r = _reach(passing, rules)
    keys = r.listed(r.s.nodes)
    assert [r.pick(r.cube(k)) for k in keys[::5]] == keys[::5]
    ring = r.s.rings[3]
    steps, p = r.s.steps.steps, r.s.plant

    def order(key):  # active steps false first in step order, then the state's variables in declaration order
        sit, valuation = r.situations[key[0]], p.valuation(key[1])
        return tuple(st in sit.steps for st in steps), tuple(bool(valuation[v]) for v in r.s.enc.variables)

    several = r.listed(ring)
    assert len(several) > 1 and r.pick(ring) == min(several, key=order)


@pytest.mark.parametrize("n", [1, 2, 5, 300])
def test_tags_split_back_what_was_tagged(n):
    e = Engine(["a", "b", "c"])
    a, b, c = (e.var(x) for x in "abc")
    funcs = [a, b & ~c, a | c, ~a & b, e.true]
    t = Tags(e, n)
    wanted = {j: funcs[j * 7 % len(funcs)] for j in range(0, n, 3)}
    f = e.disjunction(t.cube(j) & u for j, u in wanted.items())
    assert t.split(f) == wanted
    assert t.bits == max(1, (n - 1).bit_length())
    assert Tags(e, n).split(f) == wanted  # the tag variables are declared once, reused

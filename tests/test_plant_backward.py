"""Backward closures of many state sets at once (synth/plant/closure.py, issue 37): the
same fixpoint as the grid pre-image iterated set by set, on plants whose elements read
each other, for each kind of move, past one 64-bit word of sets, and through the grid
fallback; SUP's "can reach a violation" grids computed once per plant and constraints."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import ROOT
from synth.plant import closure
from synth.plant.closure import backward_closures, backward_grid
from synth.plant.composition import plant
from synth.plant.rules_check import load_rules
from synth.sup.constraints import CompiledConstraints


def _random_grids(p, count: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [rng.random(p.shape) < rng.choice([0.0005, 0.01, 0.1]) for _ in range(count)]


@pytest.mark.parametrize("rules", ["plants/four_cylinders_pallet.rules", "plants/four_cylinders.rules", "plants/tri.rules"])
@pytest.mark.parametrize("controllable", [False, True, None])
def test_closures_equal_the_grid_fixpoint(rules, controllable):
    p = plant(load_rules(ROOT / rules))
    grids = _random_grids(p, 5, 11)
    got = backward_closures(p, grids, controllable)
    want = [backward_grid(p, g, controllable) for g in grids]
    assert len(got) == 5
    for g, a, b in zip(grids, got, want):
        assert a.shape == p.shape and np.array_equal(a, b)
        assert not (g & ~a).any()  # a set is inside its closure


def test_more_sets_than_one_word_and_the_grid_fallback(monkeypatch):
    p = plant(load_rules(ROOT / "plants/four_cylinders_pallet.rules"))
    grids = _random_grids(p, 70, 5)  # two words of 64 bits
    packed = backward_closures(p, grids, False)
    monkeypatch.setattr(closure, "EDGE_LIMIT", 0)
    on_grid = backward_closures(p, grids, False)
    assert len(packed) == len(on_grid) == 70
    assert all(np.array_equal(a, b) for a, b in zip(packed, on_grid))
    assert backward_closures(p, [], False) == []


def test_closure_by_the_definition_on_the_pallet():
    """From a sample of states, a search over ``Plant.successors`` (guards read in the state
    where each move occurs) reaches the set iff the closure holds there."""
    p = plant(load_rules(ROOT / "plants/four_cylinders_pallet.rules"))
    target = np.zeros(p.shape, dtype=bool)
    target[(1,) * p.ndim] = True  # one state
    (reach,) = backward_closures(p, [target], False)
    rng = np.random.default_rng(2)
    hits = 0
    for code in rng.choice(p.size, 300, replace=False):
        local = p.local(int(code))
        seen, todo, found = {local}, [local], bool(target[local])
        while todo and not found:
            for t, nxt in p.successors(todo.pop()):
                if t.controllable or nxt in seen:
                    continue
                seen.add(nxt)
                todo.append(nxt)
                found = found or bool(target[nxt])
        hits += found
        assert bool(reach[local]) == found, local
    assert 0 < hits < 300


def test_reach_grids_are_compiled_once_per_plant_and_read_only():
    rs = load_rules(ROOT / "plants/four_cylinders.rules")
    p = plant(rs)
    first = CompiledConstraints(p, rs.constraints)
    again = CompiledConstraints(p, list(rs.constraints))  # equal content, another sequence
    assert first.reach_grids is not None and again.reach_grids is not None
    assert len(first.reach_grids) == len(first.level_terms) == 8
    assert all(a is b for a, b in zip(first.reach_grids, again.reach_grids))
    with pytest.raises(ValueError):
        first.reach_grids[0][p.initial] = True
    other = CompiledConstraints(plant(rs), rs.constraints)  # another plant: its own grids
    assert other.reach_grids is not None and other.reach_grids[0] is not first.reach_grids[0]
    assert all(np.array_equal(a, b) for a, b in zip(other.reach_grids, first.reach_grids))

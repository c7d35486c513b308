"""The transparency counts of ``synth filter verify`` (cycles, and those that correct the
requests) against an independent count: the same closed loop expanded one node at a time,
so that no two nodes' cycles are ever merged. Cycles and corrections are per node, so the
two sums must be equal; a count taken after the per-level merge of cycles that reach the
same plant state with the same outcomes (the defect of an earlier version: 457 corrections
reported where 556 exist) differs from it."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import ROOT
from synth.filter.cycle import Algorithm, Mode
from synth.filter.language_check import load_filter
from synth.filter.loop.explorer import Explorer
from synth.filter.loop.product import Product, rules_of
from synth.filter.loop.verify import plant_of
from synth.grafcet.language_check import load_grafcet
from test_four_cylinders import GRAFCET_RUNS

FILTER = ROOT / "plants" / "four_cylinders.filter"
GRAFCET = ROOT / "grafcets" / "four_cylinders.g7"
PLANTS = {1: ROOT / "plants" / "four_cylinders.rules", 2: ROOT / "plants" / "four_cylinders_2.rules",
          3: ROOT / "plants" / "four_cylinders_3.rules"}


def _explorer(pallets: int, k: int) -> Explorer:
    f = load_filter(FILTER)
    p = plant_of(f, str(PLANTS[pallets]))
    g = load_grafcet(GRAFCET, inputs=rules_of(p).inputs, outputs=rules_of(p).outputs)
    return Explorer(Product(f, p, g, Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False), 10**6, k)


def _node_by_node(ex: Explorer) -> tuple[int, int, int]:
    """States, cycles and correcting cycles, each node expanded on its own (breadth-first)."""
    assert ex.prelude is None  # a Grafcet: no power-up scan before the first level
    frontier = [ex.key0]
    while frontier:
        new: list[int] = []
        for node in frontier:
            new += ex.level(np.array([node], dtype=np.int64)).tolist()
        frontier = new
    return ex.states, ex.cycles, ex.corrected


@pytest.mark.parametrize("pallets, k, states, cycles, corrected",
                         [(p, k, s, c, r) for p, k, s, _, c, r, _ in GRAFCET_RUNS if (p, k) in {(1, 1), (3, 2)}])
def test_correcting_cycles_equal_a_count_node_by_node(pallets, k, states, cycles, corrected):
    """What ``filter verify`` prints (``tests/test_four_cylinders.py`` checks the CLI prints
    these numbers) equals the count node by node. Counted after the merge, 1 pallet gives
    457 corrections (2 pallets: 666 of 753)."""
    assert _node_by_node(_explorer(pallets, k)) == (states, cycles, corrected)

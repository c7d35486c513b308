"""The elements' uncontrollable closures without dense n x n matrices (issue 23): a plant of
one element with 2^18 states used to ask for 64 GiB in ``filter verify``."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import ROOT
from synth.cli.main import main
from synth.plant.composition import plant
from synth.plant.rules_check import load_rules


def _dense(e) -> np.ndarray:
    """The definition: R[k, j] iff j is reachable from k by uncontrollable moves (k included)."""
    n = e.size
    reach = np.eye(n, dtype=bool)
    step = np.zeros((n, n), dtype=bool)
    u = ~e.controllable
    step[e.src[u], e.dst[u]] = True
    while True:
        nxt = reach | (reach.astype(np.uint8) @ step.astype(np.uint8) > 0)
        if np.array_equal(nxt, reach):
            return reach
        reach = nxt


@pytest.mark.parametrize("rules", ["plants/tri.rules", "plants/tri_annex.rules"])
def test_sparse_closures_equal_the_dense_definition(rules):
    rng = np.random.default_rng(3)
    for e in plant(load_rules(ROOT / rules)).elements:
        dense = _dense(e)
        for k in range(e.size):
            assert np.array_equal(e.reachable_from(k), dense[k])
        for _ in range(20):
            mask = rng.random(e.size) < 0.2
            assert np.array_equal(e.can_reach(mask), (dense & mask).any(axis=1))


def _counter(n: int) -> str:
    sensors = ", ".join(f"s{i} = 0" for i in range(1, n + 1))
    rules = "\n".join(f"    ↑A [!s{i}] -> ↑s{i}" for i in range(1, n + 1))
    return (f"inputs {', '.join(f's{i}' for i in range(1, n + 1))}\noutputs A\nmodel counter {{\n"
            f"    orders A = 0\n    sensors {sensors}\n{rules}\n}}\nelement C = counter()\n"
            f'constraint K "not with the last sensor": A & s{n} = 0\n')


# 17 sensors, 2^18 states: about 1 s (each event's moves read from the element's arrays at once; 20 s
# transition by transition); 2^19 states nightly
@pytest.mark.parametrize("sensors", [17, pytest.param(18, marks=pytest.mark.nightly)])
def test_a_plant_of_262144_states_in_one_element_stops_at_the_budget(sensors, tmp_path, capsys):
    (tmp_path / "big.rules").write_text(_counter(sensors))
    (tmp_path / "big.filter").write_text(f"inputs s1, s{sensors}\noutputs A\nsafety K: A & s{sensors}\n")
    assert main(["filter", "verify", str(tmp_path / "big.filter"), "--plant", str(tmp_path / "big.rules"),
                 "--any-control", "--max-states", "100"]) == 2
    out = capsys.readouterr().out
    assert "explored 100 states" in out and "STOPPED at the state limit" in out and "out of memory" not in out

"""``validate --engine auto`` decided by measured growth (issue 37, build 6): the probe
(synth/probe.py) counts SYNC breadth-first as the explicit engine explores it, and
:func:`synth.engines.decide` chooses on its counts (never on time)."""

from __future__ import annotations

import sys
from typing import Any

import pytest

from synth import engines
from synth.engines import (PROBE_BUDGET, PROBE_LAYER, PROBE_NODES, THRESHOLDS, Command, Decision, EngineChoice,
                           Threshold, decide, measured)
from synth.grafcet.situation import OutOfRange
from synth.probe import Growth, Stop, measure, probe
from synth.validation.result import load_model
from synth.validation.validate import validate_loaded

from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
from gen_branches import with_timers, write_branches  # noqa: E402
from gen_par import write_par  # noqa: E402
from gen_steep import write_steep  # noqa: E402

WRITERS = {"par": lambda n, d: write_par(n, d), "steep": lambda n, d: write_steep(n, d),
           "branches": lambda n, d: write_branches(3, n, d)}


def model(family: str, n: int, folder, missing: bool = False):
    rules, g7, g7_missing = WRITERS[family](n, folder)
    return load_model(g7_missing if missing else g7, rules)


@pytest.mark.parametrize("family, n, missing", [("par", 3, False), ("par", 3, True), ("steep", 3, False),
                                                ("branches", 2, True)])
def test_a_whole_probe_counts_the_explicit_engines_sync_states(family, n, missing, tmp_path):
    rs, p, g = model(family, n, tmp_path, missing)
    whole = probe(p, rs.constraints, g, budget=10**6)
    assert whole.stop is Stop.DONE
    assert whole.states == validate_loaded(rs, p, g).sync.sync_states


def test_the_probe_stops_at_its_budget_or_at_a_wide_layer(tmp_path):
    rs, p, g = model("par", 4, tmp_path)
    assert probe(p, rs.constraints, g, budget=10**6).layers == (1, 16, 5, 18, 42, 71, 87, 78, 50, 64, 52, 18, 42,
                                                                71, 87, 78, 50, 48, 4)
    short = probe(p, rs.constraints, g, budget=100)
    assert (short.stop, short.layers) == (Stop.BUDGET, (1, 16, 5, 18, 42, 21))
    assert short.states == 103 and short.widest == 42
    wide = probe(p, rs.constraints, g, budget=10**6, wide=60)
    assert (wide.stop, wide.layers) == (Stop.WIDE, (1, 16, 5, 18, 42, 61))


def test_an_assignment_out_of_range_stops_the_probe_and_the_explicit_engine_says_where(tmp_path):
    g7 = tmp_path / "counting.g7"
    g7.write_text((ROOT / "grafcets/tri_counting.g7").read_text().replace("boxes : 0..3", "boxes : 0..2"))
    rs, p, g = load_model(g7, ROOT / "plants/tri.rules")
    assert probe(p, rs.constraints, g, budget=10**6).stop is Stop.ERROR
    chosen: list[Decision] = []
    with pytest.raises(OutOfRange) as err:
        engines.validate_models(rs, p, g, decided=chosen.append)
    assert "outside the range 0..2 of 'boxes'" in str(err.value)
    assert [d.engine for d in chosen] == [EngineChoice.EXPLICIT]
    assert chosen[0].reason.startswith("auto: explicit (measured: an internal variable out of range after ")


# the decision on small cases of each kind: (family, n, missing) -> engine, reason
DECISIONS = {
    ("par", 4, False): (EngineChoice.EXPLICIT,
                        "auto: explicit (measured: SYNC has 882 states, its widest breadth-first layer 87, "
                        "not above 250)"),
    ("par", 5, False): (EngineChoice.SYMBOLIC,
                        "auto: symbolic (measured: breadth-first layer 7 of SYNC holds more than 250 states, "
                        "after 756 states)"),
    ("steep", 4, True): (EngineChoice.SYMBOLIC,
                         "auto: symbolic (measured: breadth-first layer 7 of SYNC holds more than 250 states, "
                         "after 660 states)"),
    ("branches", 2, False): (EngineChoice.EXPLICIT,
                             "auto: explicit (measured: 1302 SYNC states in 16 breadth-first layers, none above 250)"),
    ("branches", 3, True): (EngineChoice.SYMBOLIC,
                            "auto: symbolic (measured: breadth-first layer 13 of SYNC holds more than 250 states, "
                            "after 1253 states)"),
}


@pytest.mark.parametrize("case", sorted(DECISIONS), ids=lambda c: f"{c[0]}_{c[1]}{'_missing' if c[2] else ''}")
def test_auto_decides_on_the_probes_counts(case, tmp_path):
    family, n, missing = case
    rs, p, g = model(family, n, tmp_path, missing)
    asked: list[Growth] = []

    def growth(t: Threshold) -> Growth:
        asked.append(probe(p, rs.constraints, g, t.budget, t.layer))
        return asked[-1]

    chosen = decide(Command.VALIDATE, "auto", estimate=p.size * len(g.steps), growth=growth)
    assert (chosen.engine, chosen.reason, chosen.measured) == (*DECISIONS[case], True)
    assert asked[0].states <= PROBE_BUDGET + max(asked[0].layers)  # the budget is checked node by node
    assert (asked[0].stop is Stop.WIDE) == (chosen.engine is EngineChoice.SYMBOLIC)
    assert (max(asked[0].layers) > PROBE_LAYER) == (chosen.engine is EngineChoice.SYMBOLIC)


@pytest.mark.parametrize("family, engine, reason", [
    ("branches", EngineChoice.EXPLICIT, "auto: explicit (measured: breadth-first layer 10 of SYNC holds more than 250 "
                                        "states after 1068 states, not within 800 as exploring per stable situation "
                                        "needs)"),
    ("par", EngineChoice.SYMBOLIC, "auto: symbolic (measured: breadth-first layer 5 of SYNC holds more than 250 "
                                   "states, after 576 states)")])
def test_with_timers_the_wide_layer_must_come_early(family, engine, reason, tmp_path):
    """Timers: the symbolic engine explores one stable situation at a time, and pays per
    situation; it wins on par_5 with timers (its first wide layer after 576 states) but not
    on three timed branches of two cylinders (after 1 068: 1.4 times the explicit time)."""
    rules, g7, _ = WRITERS[family](2 if family == "branches" else 5, tmp_path)
    timed = tmp_path / "timed.g7"
    timed.write_text(with_timers(g7.read_text(encoding="utf-8")), encoding="utf-8")
    rs, p, g = load_model(timed, rules)
    t = THRESHOLDS[Command.VALIDATE]
    counts, done = measure(rs, p, g, (t.nodes, t.budget, t.layer, t.steep))
    assert done is None and counts.stop is Stop.WIDE and counts.per_situation == (engine is EngineChoice.EXPLICIT)
    chosen = measured(counts, t)
    assert (chosen.engine, chosen.reason) == (engine, reason)


def test_auto_runs_the_engine_it_chose_and_says_why_on_stderr(cli, tmp_path):
    rules, _, g7 = write_steep(4, tmp_path)
    code, out, err = cli("validate", g7, "--plant", rules)
    assert code == 1
    assert err.splitlines()[0] == DECISIONS[("steep", 4, True)][1]
    assert err.splitlines()[1].startswith("symbolic engine: ") and len(err.splitlines()) == 2
    assert cli("validate", g7, "--plant", rules, "--engine", "symbolic", "--quiet") == (1, out, "")
    rules, g7, _ = write_par(4, tmp_path)  # the explicit engine: nothing more said, as before
    assert cli("validate", g7, "--plant", rules, "--json") == cli("validate", g7, "--plant", rules, "--json",
                                                                  "--engine", "explicit")


def test_a_small_sync_is_explored_once_by_the_explicit_engine_and_kept(monkeypatch):
    """The box-sorting Grafcet (90 aggregated states): the explicit engine, bounded to
    PROBE_NODES aggregated states, explores SYNC whole; its result is the one returned,
    without a probe or a second exploration."""
    import synth.probe
    import synth.validation.validate as explicit

    runs: list[int] = []
    real = explicit.synchronous_product

    def counted(*args: Any, **kwargs: Any) -> Any:
        runs.append(kwargs["max_states"])
        return real(*args, **kwargs)

    def no_probe(*args: Any, **kwargs: Any) -> Growth:
        raise AssertionError("probed")

    monkeypatch.setattr(explicit, "synchronous_product", counted)
    monkeypatch.setattr(synth.probe, "probe", no_probe)
    rs, p, g = load_model(ROOT / "grafcets/tri.g7", ROOT / "plants/tri.rules")
    chosen: list[Decision] = []
    v = engines.validate_models(rs, p, g, decided=chosen.append)
    assert (runs, v.sync.sync_states, len(v.sync.nodes), v.passed) == ([PROBE_NODES], 150, 90, True)
    assert [(d.engine, d.reason) for d in chosen] == [
        (EngineChoice.EXPLICIT, "auto: explicit (measured: SYNC explored whole within 100 aggregated states, "
                                "150 SYNC states)")]


def test_past_the_bounded_run_the_probe_decides(monkeypatch, tmp_path):
    """par_4 (321 aggregated states): the bounded run stops, the probe explores SYNC whole
    (882 states, no layer above PROBE_LAYER) and the explicit engine runs once more, whole,
    with the user's --max-states."""
    import synth.validation.validate as explicit

    runs: list[int | None] = []
    real = explicit.synchronous_product

    def counted(*args: Any, **kwargs: Any) -> Any:
        runs.append(kwargs["max_states"])
        return real(*args, **kwargs)

    monkeypatch.setattr(explicit, "synchronous_product", counted)
    rs, p, g = model("par", 4, tmp_path)
    chosen: list[Decision] = []
    v = engines.validate_models(rs, p, g, max_states=5000, decided=chosen.append)
    assert (runs, v.sync.sync_states, len(v.sync.nodes)) == ([PROBE_NODES, 5000], 882, 321)
    assert [(d.engine, d.reason) for d in chosen] == [DECISIONS[("par", 4, False)]]

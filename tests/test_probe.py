"""``validate --engine auto`` decided by measured growth (issue 37): the explicit engine's
own run, watched (synth/probe.py), judged at a decision point by the share of the
aggregated states met that still wait; :func:`synth.engines.measured` words the choice
(counts, never time)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

from synth import engines
from synth.engines import THRESHOLDS, Command, Decision, EngineChoice, measured
from synth.errors import LimitExceeded
from synth.grafcet.situation import OutOfRange
from synth.probe import Growth, Points, Stop, measure
from synth.validation.result import load_model
from synth.validation.sync import Exploration
from synth.validation.validate import validate_loaded

from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
from gen_branches import with_timers, write_branches  # noqa: E402
from gen_par import write_par  # noqa: E402
from gen_steep import write_steep  # noqa: E402

WRITERS = {"par": lambda n, d: write_par(n, d), "steep": lambda n, d: write_steep(n, d),
           "branches": lambda n, d: write_branches(3, n, d), "wide": lambda n, d: write_branches(n, 2, d)}
POINTS = THRESHOLDS[Command.VALIDATE].points
assert POINTS is not None


def model(family: str, n: int, folder: Path, variant: str = ""):
    """A bench model; ``variant``: ``missing`` (a retraction order missing), ``timed`` (each
    extension waits 1 s: gen_branches.with_timers), ``internal`` (an internal variable the
    Grafcet never uses: the explicit engine explores state by state)."""
    rules, g7, g7_missing = WRITERS[family](n, folder)
    if variant == "missing":
        return load_model(g7_missing, rules)
    text = g7.read_text(encoding="utf-8")
    text = {"timed": with_timers(text), "internal": text.replace("\ngrafcet ", "\ninternal k : 0..1 = 0\n\ngrafcet ", 1),
            "": text}[variant]
    out = folder / f"{family}_{n}_{variant}.g7"
    out.write_text(text, encoding="utf-8")
    return load_model(out, rules)


def explored(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The explorations of SYNC started from now on (each one's ``max_states`` or 0)."""
    import synth.validation.validate as explicit

    runs: list[int] = []
    real = explicit.explore

    def counted(*args: Any, **kwargs: Any) -> Any:
        how = args[3] if len(args) > 3 else kwargs.get("how")
        runs.append(how.max_states or 0 if how is not None else 0)
        return real(*args, **kwargs)

    monkeypatch.setattr(explicit, "explore", counted)
    return runs


# (family, n, variant) -> how the watched run ended, the engine and the reason
DECISIONS = {
    ("par", 4, ""): (Stop.RAN, EngineChoice.EXPLICIT,
                     "auto: explicit (measured: SYNC explored whole before the decision point, 321 aggregated states, "
                     "882 SYNC states)"),
    ("par", 6, ""): (Stop.NARROW, EngineChoice.EXPLICIT,
                     "auto: explicit (measured: 255 of the 573 aggregated states met wait to be explored, not more "
                     "than 45 %)"),
    ("par", 7, ""): (Stop.STEEP, EngineChoice.SYMBOLIC,
                     "auto: symbolic (measured: 428 of the 815 aggregated states met wait to be explored, more than "
                     "45 %)"),
    ("steep", 4, ""): (Stop.NARROW, EngineChoice.EXPLICIT,
                       "auto: explicit (measured: 160 of the 504 aggregated states met wait to be explored, not more "
                       "than 45 %)"),
    ("steep", 5, "missing"): (Stop.STEEP, EngineChoice.SYMBOLIC,
                              "auto: symbolic (measured: 241 of the 515 aggregated states met wait to be explored, "
                              "more than 45 %)"),
    ("branches", 3, ""): (Stop.NARROW, EngineChoice.EXPLICIT,
                          "auto: explicit (measured: 91 of the 448 aggregated states met wait to be explored, not "
                          "more than 45 %)"),
    ("wide", 4, ""): (Stop.NARROW, EngineChoice.EXPLICIT,
                      "auto: explicit (measured: 139 of the 456 aggregated states met wait to be explored, not more "
                      "than 45 %)"),
    ("par", 5, "timed"): (Stop.STEEP, EngineChoice.SYMBOLIC,
                          "auto: symbolic (measured: 506 of the 717 aggregated states met wait to be explored, more "
                          "than 45 %)"),
    ("branches", 2, "timed"): (Stop.NARROW, EngineChoice.EXPLICIT,
                               "auto: explicit (measured: 156 of the 527 aggregated states met wait to be explored, "
                               "not more than 45 %)"),
    ("par", 5, "internal"): (Stop.NARROW, EngineChoice.EXPLICIT,
                             "auto: explicit (measured: 90 of the 400 aggregated states met wait to be explored, not "
                             "more than 30 %, state by state (internal variables))"),
    ("par", 6, "internal"): (Stop.STEEP, EngineChoice.SYMBOLIC,
                             "auto: symbolic (measured: 211 of the 401 aggregated states met wait to be explored, "
                             "more than 30 %, state by state (internal variables))"),
}


@pytest.mark.parametrize("case", sorted(DECISIONS), ids=lambda c: f"{c[0]}_{c[1]}{'_' + c[2] if c[2] else ''}")
def test_auto_decides_on_the_watched_runs_counts(case, tmp_path, monkeypatch):
    """Each kind of model at the smallest size that shows it; a run judged narrow goes on to
    the end and is the explicit engine's result (SYNC explored once), a steep one stops at
    the decision point."""
    family, n, variant = case
    rs, p, g = model(family, n, tmp_path, variant)
    runs = explored(monkeypatch)
    counts, done = measure(rs, p, g, POINTS)
    stop, engine, reason = DECISIONS[case]
    chosen = measured(counts, THRESHOLDS[Command.VALIDATE])
    assert (counts.stop, chosen.engine, chosen.reason, chosen.measured) == (stop, engine, reason, True)
    assert runs == [0]
    share = POINTS.share if counts.machine is None else POINTS.machine_share
    if stop is Stop.STEEP:
        assert done is None and counts.waiting * 100 > counts.met * share == counts.met * counts.share
    else:
        assert done is not None and done.sync.sync_states > 0
        assert stop is Stop.RAN or counts.waiting * 100 <= counts.met * share


def test_the_run_judged_narrow_is_the_explicit_engines_result(tmp_path, monkeypatch):
    """par_6: judged at 1 119 aggregated states, the run goes on; what it returns is what the
    explicit engine alone finds, node for node and edge for edge."""
    rs, p, g = model("par", 6, tmp_path)
    counts, done = measure(rs, p, g, POINTS)
    alone = validate_loaded(rs, p, g)
    assert counts.stop is Stop.NARROW and done is not None
    assert (done.sync.sync_states, done.sync.nodes, done.sync.edges, done.sync.initial) == \
        (alone.sync.sync_states, alone.sync.nodes, alone.sync.edges, alone.sync.initial) and done.sync.sync_states == 9492
    assert (done.passed, done.analysis) == (alone.passed, alone.analysis)


def test_where_the_symbolic_engine_explores_per_situation_the_share_must_be_higher(tmp_path):
    """par_3 with timers, judged at 200 aggregated states: 99 of 213 wait (46 %), more than
    40 %; the symbolic engine would explore it one stable situation at a time, so the share
    asked is the per-situation one: 70 % keeps the explicit engine (the run went on), 45 %
    does not."""
    rs, p, g = model("par", 3, tmp_path, "timed")
    kept = engines.Threshold(1, "", Points(200, 40, 30, 70))
    assert kept.points is not None
    counts, done = measure(rs, p, g, kept.points)
    assert (counts.stop, counts.per_situation, counts.met, counts.waiting) == (Stop.NARROW, True, 213, 99)
    assert done is not None and done.sync.sync_states == 801
    assert measured(counts, kept).reason == (
        "auto: explicit (measured: 99 of the 213 aggregated states met wait to be explored, more than 40 % but not "
        "more than 70 % as exploring per stable situation needs)")
    counts, done = measure(rs, p, g, Points(200, 40, 30, 45))
    assert (counts.stop, counts.per_situation, done) == (Stop.STEEP, False, None)


def test_a_limit_met_before_the_decision_point_is_judged_there(tmp_path):
    """``--max-states`` below the decision point: the counts where the run stopped decide;
    steep, the symbolic engine runs (it has no such bound), narrow, the explicit engine's
    limit is the error."""
    rs, p, g = model("par", 7, tmp_path)
    counts, done = measure(rs, p, g, POINTS, how=Exploration(300))
    assert (counts.stop, counts.met, counts.waiting, done) == (Stop.STEEP, 148, 106, None)
    rs, p, g = model("branches", 3, tmp_path)
    with pytest.raises(LimitExceeded, match="more than 300 aggregated states"):
        measure(rs, p, g, POINTS, how=Exploration(300))


def test_an_assignment_out_of_range_stops_the_run_and_the_explicit_engine_says_where(tmp_path):
    g7 = tmp_path / "counting.g7"
    g7.write_text((ROOT / "grafcets/tri_counting.g7").read_text().replace("boxes : 0..3", "boxes : 0..2"))
    rs, p, g = load_model(g7, ROOT / "plants/tri.rules")
    assert measure(rs, p, g, POINTS)[0].stop is Stop.ERROR
    chosen: list[Decision] = []
    with pytest.raises(OutOfRange) as err:
        engines.validate_models(rs, p, g, decided=chosen.append)
    assert "outside the range 0..2 of 'boxes'" in str(err.value)
    assert [d.engine for d in chosen] == [EngineChoice.EXPLICIT]
    assert chosen[0].reason.startswith("auto: explicit (measured: an internal variable out of range after ")


def test_a_small_sync_is_explored_once_by_the_explicit_engine_and_kept(monkeypatch):
    """The box-sorting Grafcet (90 aggregated states): the watched run explores SYNC whole;
    its result is the one returned, SYNC explored once."""
    runs = explored(monkeypatch)
    rs, p, g = load_model(ROOT / "grafcets/tri.g7", ROOT / "plants/tri.rules")
    chosen: list[Decision] = []
    v = engines.validate_models(rs, p, g, max_states=5000, decided=chosen.append)
    assert (runs, v.sync.sync_states, len(v.sync.nodes), v.passed) == ([5000], 150, 90, True)
    assert [(d.engine, d.reason) for d in chosen] == [
        (EngineChoice.EXPLICIT, "auto: explicit (measured: SYNC explored whole before the decision point, "
                                "90 aggregated states, 150 SYNC states)")]


def test_auto_runs_the_engine_it_chose_and_says_why_on_stderr(cli, tmp_path):
    rules, _, g7 = write_steep(5, tmp_path)
    code, out, err = cli("validate", g7, "--plant", rules)
    assert code == 1
    assert err.splitlines()[0] == DECISIONS[("steep", 5, "missing")][2]
    assert err.splitlines()[1].startswith("symbolic engine: ") and len(err.splitlines()) == 2
    assert cli("validate", g7, "--plant", rules, "--engine", "symbolic", "--quiet") == (1, out, "")
    rules, g7, _ = write_par(6, tmp_path)  # the explicit engine: nothing more said, as before
    assert cli("validate", g7, "--plant", rules, "--json") == cli("validate", g7, "--plant", rules, "--json",
                                                                  "--engine", "explicit")


def test_the_share_decides_exactly_at_the_decision_point(tmp_path):
    """par_6: 258 of the 1 119 aggregated states met wait at the decision point (23.06 %):
    steep for a share of 23 %, narrow for 24 %; a decision point past SYNC's 2 913 aggregated
    states: explored whole."""
    rs, p, g = model("par", 6, tmp_path)
    at = [measure(rs, p, g, Points(1000, share, 30, 50))[0] for share in (23, 24)]
    assert [(c.stop, c.met, c.waiting) for c in at] == [(Stop.STEEP, 1119, 258), (Stop.NARROW, 1119, 258)]
    whole = measure(rs, p, g, Points(3000, 0, 30, 50))[0]
    assert (whole.stop, whole.met, whole.sync_states) == (Stop.RAN, 2913, 9492)

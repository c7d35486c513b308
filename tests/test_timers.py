"""Durations are numbers: timers of one step with equal durations elapse at the same
instant, as one event, in ``run``, ``ass`` and ``validate`` (IEC 60848 time is real time)."""

from __future__ import annotations

import json

from conftest import ROOT
from synth.cli.main import main
from synth.grafcet.language_check import load_grafcet
from synth.grafcet.machine import GrafcetMachine

D = ROOT / "tests" / "data"


def test_run_accepts_either_spelling_of_one_instant(capsys):
    for spelling in ("700ms/X1", "0.7s/X1"):
        assert main(["run", str(D / "equal_timers_run.g7"), "--events", f"↑a,{spelling},↓a"]) == 0
        lines = capsys.readouterr().out.splitlines()
        assert [line.split()[2] for line in lines] == ["{X0}", "{X1}", "{X2}", "{X0}"]
        assert lines[2].split()[1] == spelling


def test_equal_timers_are_one_event():
    m = GrafcetMachine(load_grafcet(D / "equal_timers_run.g7"))
    s1 = m.react(m.initial({"a": False}), {"a": False}, {"a": True})
    assert m.timers(s1) == ("0.7s/X1",)
    assert m.timer_event("700ms/X1") == "0.7s/X1"
    after = m.fire_timer(s1, "700ms/X1", {"a": True})
    assert after.steps == ("2",)


def test_ass_fires_both_transitions_of_equal_timers(capsys):
    assert main(["ass", str(D / "equal_timers.g7"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [s["situation"] for s in data["states"]] == [["0"], ["1"], ["2", "3"]]
    timer_moves = sorted((t["source"], t["event"], t["condition"], t["target"]) for t in data["transitions"]
                         if "/" in t["event"])
    assert timer_moves == [(1, "2000ms/X1", "!a", 0), (1, "2000ms/X1", "a", 2)]

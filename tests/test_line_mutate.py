"""synth mutate (issue 39, build 3): deterministic mutant ids, equivalent mutants (equal
ASS) not counted, the score and the survivors pinned on small stations, --json, the
allow-list, and the local pool (one process per core, the plant compiled once per worker)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from schemas import assert_valid
from synth.cli.main import main
from synth.grafcet.language_check import load_grafcet
from synth.line.jobs import JobKind
from synth.line.mutate import Operator, grafcet_mutants
from synth.line.run import grafcet_mutant_jobs
from synth.line.runners import RunStats, run_local, run_serial
from synth.line.cache import with_digests

from conftest import ROOT
PRESS = ROOT / "lines" / "example"
CLAMP = [str(PRESS / "grafcets/clamp.g7"), "--plant", str(PRESS / "plants/clamp.rules")]
SURVIVORS = ["negate:2->3", "weaken:0->1:1", "weaken:0->1:2", "level:0->1:dcy"]


def test_every_operator_with_ids_in_file_order() -> None:
    g = load_grafcet(ROOT / "grafcets/tri.g7")
    mutants = grafcet_mutants(g)
    ids = [m.id for m, _ in mutants]
    assert len(ids) == len(set(ids)) == 67
    counts = {op: sum(m.operator is op for m, _ in mutants) for op in Operator}
    # 9 actions, 22 transitions, 21 terms in 9 conjunctions, no edge, 13 pairs of successive steps whose
    # actions differ, 2 timers
    assert counts == {Operator.DROP_ORDER: 9, Operator.NEGATE: 22, Operator.WEAKEN: 21, Operator.EDGE_TO_LEVEL: 0,
                      Operator.SWAP_ORDERS: 13, Operator.SHORTEN_TIMER: 2, Operator.DROP_TERM: 0}
    assert [m.id for m, _ in grafcet_mutants(load_grafcet(ROOT / "grafcets/tri.g7"))] == ids  # deterministic
    timer = dict((m.id, x) for m, x in mutants)["shorten-timer:101->102:2s/X101"]
    assert [t.id for t in timer.timers] == ["1s/X101", "2s/X111"]
    assert [t.receptivity.text() for t in timer.transitions if t.name == "101->102"] == ["1s/X101"]


def test_the_press_pins_its_score_and_survivors(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["mutate", *CLAMP, "--filter", str(PRESS / "plants/clamp.filter"), "--workers", "1", "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert_valid("mutate", data)
    assert (len(data["mutants"]), data["caught"], data["changing"], data["equivalent"], data["score"]) == \
        (19, 15, 19, 0, round(15 / 19, 4))
    assert data["survivors"] == data["unexpected"] == SURVIVORS
    assert [m["id"] for m in data["mutants"] if m["operator"] == "drop-term"] == [
        "drop-term:PRESS:1", "drop-term:PRESS:2", "drop-term:CLAMP:1", "drop-term:CLAMP:2"]
    allow = [a for s in SURVIVORS for a in ("--allow", s)]
    assert main(["mutate", *CLAMP, "--workers", "1", *allow]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[:3] == [f"{CLAMP[0]} against {CLAMP[2]}: 15 mutants, 0 equivalent (equal ASS, not counted), "
                       "15 change behaviour", "mutation score: 11/15 = 73.3%",
                       "surviving mutants (the plant model and its constraints say nothing here):"]
    assert out[4] == f"  weaken:0->1:1 (allowed): transition 0->1 when c0 (without ↑dcy) ({CLAMP[0]}:10:14)"


def test_equivalent_mutants_are_recognised_by_equal_ass_and_not_counted(capsys: pytest.CaptureFixture[str]) -> None:
    home = ROOT / "tests/data/home"
    args = ["mutate", str(home / "production_loop.g7"), "--plant", str(home / "cylinder.rules"), "--home", "X1"]
    assert main([*args, "--workers", "1", "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    status = {m["id"]: m["status"] for m in data["mutants"]}
    assert status == {"drop-order:1:AVANCER": "survived", "drop-order:2:RECULER": "caught", "negate:0->1": "survived",
                      "negate:1->2": "caught", "negate:2->1": "caught", "level:0->1:dcy": "equivalent",
                      "swap-orders:0:1": "survived", "swap-orders:1:2": "survived"}
    assert (data["caught"], data["changing"], data["equivalent"]) == (3, 7, 1)
    assert [m["why"] for m in data["mutants"] if m["id"] == "negate:1->2"] == [
        f"refused: {home / 'production_loop.g7'}:8:16: error: the Grafcet never stabilises: transient cycle through "
        "steps 1, 2"]


def test_a_failing_grafcet_is_not_mutated(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["mutate", str(PRESS / "grafcets/gate.g7"), "--plant", str(PRESS / "plants/gate.rules")]) == 2
    assert "fails validation against" in capsys.readouterr().err


def test_the_local_pool_compiles_the_plant_once_per_worker_and_matches_the_serial_run(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from synth.line import work

    monkeypatch.setattr(work, "_PLANTS", {})  # this process compiled the press's plant in the tests above
    jobs = [with_digests(j) for j in grafcet_mutant_jobs("press", CLAMP[2], CLAMP[0], (("semantics", "grafcet"),))]
    assert len(jobs) == 15 and {j.kind for j in jobs} == {JobKind.MUTANT}
    serial_stats, pool_stats = RunStats(), RunStats()
    serial = run_serial(jobs, stats=serial_stats)
    pooled = run_local(jobs, workers=2, stats=pool_stats)
    assert pooled == serial
    assert list(serial_stats.compiled.values()) == [1]
    assert len(pool_stats.compiled) == 2 and set(pool_stats.compiled.values()) == {1}  # 2 workers, once each


def test_a_job_that_kills_its_worker_is_an_error_and_the_others_finish(monkeypatch: pytest.MonkeyPatch) -> None:
    import os

    from synth.line import work

    jobs = [with_digests(j) for j in grafcet_mutant_jobs("press", CLAMP[2], CLAMP[0], (("semantics", "grafcet"),))][:4]
    real = work._mutant

    def deadly(job, f):  # type: ignore[no-untyped-def]
        if job.mutant == jobs[1].mutant:
            os._exit(9)  # the worker process dies (the pool's workers are forked: they inherit this)
        return real(job, f)

    monkeypatch.setattr(work, "_mutant", deadly)
    results = run_local(jobs, workers=2)
    assert [r["verdict"] for r in results] == ["fail", "error", "fail", "fail"]
    assert results[1]["summary"] == f"press/mutant clamp.g7 {jobs[1].mutant}: its worker process died"
    monkeypatch.setattr(work, "_mutant", real)
    assert [r for i, r in enumerate(results) if i != 1] == [r for i, r in enumerate(run_serial(jobs)) if i != 1]

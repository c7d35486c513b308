"""Home states and the verdicts that depend on them (issue 10): the five situations of
``tests/data/home``, each with its exact verdict, trace and exit code."""

from __future__ import annotations

import json

from conftest import ROOT
from schemas import assert_valid
from synth.cli.main import main

D = ROOT / "tests" / "data" / "home"
CYL = str(D / "cylinder.rules")


def _validate(capsys, g7: str, rules: str = CYL, *flags: str) -> tuple[int, dict]:
    code = main(["validate", str(D / g7), "--plant", rules, "--json", *flags])
    data = json.loads(capsys.readouterr().out)
    assert_valid("validate", data)
    return code, data


MISSING_AVANCER = (
    "missing order AVANCER in step 0: transition 0->1 of G awaits v1, which needs ↑v1; only AVANCER causes ↑v1 "
    "(element V, rule ↑AVANCER [!v0 & !v1] -> ↑v1) and SUP authorises it here"
)


def test_never_leaves_initial_step(capsys):
    code, data = _validate(capsys, "never_leaves.g7")
    assert code == 1 and data["verdict"] == "fail"
    assert data["blocking"] == [] and data["prohibited"] == []
    ns = data["never_starts"]
    assert (ns["verdict"], ns["cause"]) == ("never_starts", "missing_order")
    assert ns["summary"] == "the Grafcet never leaves its initial steps {X0}: " + MISSING_AVANCER


def test_never_leaves_initial_step_with_a_timer(capsys):
    """The same report whether or not the initial step carries a timer (issue 24: the
    initial state after its timer had elapsed was a blocking situation of its own, 1
    against 0 without the timer; waiting in the initial situation is being home)."""
    code, data = _validate(capsys, "never_leaves_timer.g7")
    assert code == 1
    ns = data["never_starts"]
    assert (ns["verdict"], ns["cause"]) == ("never_starts", "missing_order")
    assert ns["summary"] == "the Grafcet never leaves its initial steps {X0}: " + MISSING_AVANCER
    assert data["blocking"] == [] and data["prohibited"] == []


def test_prohibited_order_in_the_initial_step_is_blocking(capsys):
    code, data = _validate(capsys, "prohibited_initial.g7", str(D / "cylinder_no_advance_at_rest.rules"))
    assert code == 1
    (b,) = data["blocking"]
    assert b["trace"] == [] and b["situation"] == ["X0"]
    assert b["proh"] == [{"order": "AVANCER", "event": "↑AVANCER", "constraints": ["C2"]}]
    assert b["diagnosis"]["verdict"] == "prohibited_order"
    assert data["never_starts"]["cause"] == "prohibited_order"


def test_cycle_home_but_plant_not_restartable(capsys):
    code, data = _validate(capsys, "no_restart.g7")
    assert code == 1
    (b,) = data["blocking"]
    assert b["situation"] == ["X0"] and b["trace"] == ["↑dcy", "↓v0", "↑v1"]
    assert b["E"] == {"dcy": 1, "v0": 0, "v1": 1}
    assert b["no_return"] == {"situation": ["X1"], "after": ["↑dcy"]}
    assert b["diagnosis"]["verdict"] == "missing_order"
    assert b["diagnosis"]["summary"].startswith("missing order RECULER in step 0: transition 0->1 of G awaits dcy & v0")


def test_production_loop_is_a_livelock_until_its_home_is_declared(capsys):
    code, data = _validate(capsys, "production_loop.g7")
    assert code == 1
    (b,) = data["blocking"]
    assert b["trace"] == ["↑dcy"]
    d = b["diagnosis"]
    assert d["verdict"] == "livelock"
    assert d["summary"] == (
        "the Grafcet keeps running through {X1} → {X2} and never returns to a home state: transition 1->2 of G "
        "awaits v1, and ↑v1 occurs with the orders as they are (element V); if this loop is the intended cycle, "
        'declare its home with --home "X1"'
    )
    assert d["awaited"][0]["causes"][0]["producible_now"] is True
    code, data = _validate(capsys, "production_loop.g7", CYL, "--home", "X1")
    assert code == 0 and data["verdict"] == "pass" and data["homes"] == ["X1"]


def test_home_conditions_read_plant_values_too(capsys):
    code, data = _validate(capsys, "production_loop.g7", CYL, "--home", "X2 & v1")
    assert code == 0


def test_home_text_and_exit_codes(capsys):
    assert main(["validate", str(D / "production_loop.g7"), "--plant", CYL, "--home", "X1"]) == 0
    out = capsys.readouterr().out
    assert "home states: the initial state and where X1 holds" in out


def test_home_errors_are_located(capsys):
    code = main(["validate", str(D / "production_loop.g7"), "--plant", CYL, "--home", "X1 & v2"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.splitlines()[:3] == [
        "--home:1:6: error: unknown name 'v2' in --home",
        "  1 | X1 & v2",
        "    |      ^~",
    ]
    assert "did you mean X2 or v1 or v0?" in err
    code = main(["validate", str(D / "production_loop.g7"), "--plant", CYL, "--home", "X1 &"])
    assert code == 2 and capsys.readouterr().err.startswith("--home:1:5: error: syntax error: unexpected end of file")
    code = main(["validate", str(D / "production_loop.g7"), "--plant", CYL, "--home", "↑dcy"])
    assert code == 2 and "an edge is not a state: ↑dcy" in capsys.readouterr().err

"""End to end: synth validate on the box-sorting example (issue: SYNC, aggregation, diagnosis)."""

from __future__ import annotations

import json
import shutil

import pytest

from synth.plant.composition import plant
from synth.grafcet.language_check import load_grafcet
from synth.plant.rules_check import load_rules
from synth.grafcet.machine import GrafcetMachine
from synth.sup.supervisor import supremal_controllable
from synth.validation.sync import synchronous_product

from conftest import ROOT
from schemas import assert_valid

G = ROOT / "grafcets"
P = ROOT / "plants"
MISSING_TRACE = ["↑dcy", "↑cp12", "2s/X101", "↓v10", "↑v11"]


def _json(cli, *args):
    code, out, err = cli("validate", *args, "--json")
    assert "Traceback" not in err
    data = json.loads(out)
    assert_valid("validate", data)
    return code, data


def test_tri_passes(cli):
    code, data = _json(cli, G / "tri.g7", "--plant", P / "tri.rules")
    assert code == 0
    assert data["verdict"] == "pass"
    assert data["blocking"] == [] and data["prohibited"] == []
    assert data["unreached_steps"] == []
    assert data["stats"]["aggregated_states"] > 20


def test_tri_text_exit_0(cli):
    code, out, _ = cli("validate", G / "tri.g7", "--plant", P / "tri.rules")
    assert code == 0
    assert out.startswith("PASS: 0 blocking situation(s), 0 situation(s) with prohibited orders")


def test_missing_order(cli):
    code, data = _json(cli, G / "tri_missing_order.g7", "--plant", P / "tri.rules")
    assert code == 1
    assert data["verdict"] == "fail"
    assert len(data["blocking"]) == 1
    b = data["blocking"][0]
    assert b["trace"] == MISSING_TRACE
    assert b["situation"] == ["X1", "X103", "X200", "X300"]
    assert {k for k, v in b["E"].items() if v} == {"dcy", "v11", "v20", "v30", "v40", "cp12"}
    assert {k for k, v in b["Z"].items() if v} == {"TAPIS"}
    assert b["ord"] == ["TAPIS"] and b["proh"] == []
    assert data["unreached_steps"] == ["X104", "X105", "X106", "X301", "X302"]
    assert b["no_return"] == {"situation": ["X1", "X101", "X200", "X300"], "after": ["↑dcy", "↑cp12"]}
    d = b["diagnosis"]
    assert d["verdict"] == "missing_order"
    assert d["summary"] == (
        "missing order AVANCER2 in step 103: transition 103->104 of G2 awaits v21 & v11, which needs ↑v21; "
        "only AVANCER2 causes ↑v21 (element V2, rule ↑AVANCER2 [!v20 & !v21] -> ↑v21) and SUP authorises it here"
    )
    cause = next(c for a in d["awaited"] for c in a["causes"])
    assert cause == {
        "event": "↑v21", "element": "V2", "orders": ["↑AVANCER2"],
        "rules": ["↑AVANCER2 [!v20 & !v21] -> ↑v21", "↓AVANCER2 [!v20 & !v21] -> ↑v21"],
        "emitted": False, "authorised": True, "constraints": [], "producible_now": False, "free": False,
    }


def test_missing_order_terminal_text(cli):
    code, out, _ = cli("validate", G / "tri_missing_order.g7", "--plant", P / "tri.rules")
    assert code == 1
    lines = out.splitlines()
    assert lines[1] == "note: 5 step(s) never active in any reachable stable situation: X104, X105, X106, X301, X302"
    assert lines[3] == "Blocking 1: situation {X1, X103, X200, X300}"
    assert lines[4] == "  E: dcy v11 v20 v30 v40 cp12"
    assert lines[5] == "  Z: TAPIS"
    assert lines[7] == "  trace: ↑dcy ↑cp12 2s/X101 ↓v10 ↑v11"
    assert lines[9].startswith("  diagnosis [missing_order]: missing order AVANCER2 in step 103")


def test_wrong_v1_caught_before_synthesis(cli):
    code, out, err = cli("validate", G / "tri.g7", "--plant", P / "tri_wrong_v1.rules")
    assert code == 2 and out == ""
    first = err.splitlines()[0]
    assert "tri_wrong_v1.rules:17:34: error: rule of element V1 produces ↑v21, but v21 is a sensor of element V2" in first


def test_expert_missing_rule(cli):
    code, data = _json(cli, G / "tri.g7", "--plant", P / "tri_missing_rule.rules", "--expert")
    assert code == 1
    assert data["mode"] == "expert"
    b = data["blocking"][0]
    assert b["trace"] == MISSING_TRACE
    assert b["situation"] == ["X1", "X103", "X200", "X300"]
    assert b["ord"] == ["AVANCER2", "TAPIS"] and b["proh"] == []
    assert {k for k, v in b["Z"].items() if v} == {"AVANCER2", "TAPIS"}
    d = b["diagnosis"]
    assert d["verdict"] == "element_model"
    assert d["summary"].startswith(
        "element V2 cannot produce the awaited ↑v21: AVANCER2 is emitted and authorised, V2 is in {AVANCER2,v20}, "
        "and no rule of V2 produces ↑v21 there"
    )


def test_overstrict_constraint(cli):
    code, data = _json(cli, G / "tri.g7", "--plant", P / "tri_overstrict.rules", "--expert")
    assert code == 1
    b = data["blocking"][0]
    assert b["situation"] == ["X1", "X104", "X200", "X301"]
    assert b["proh"] == [{"order": "AVANCER4", "event": "↑AVANCER4", "constraints": ["C2_9"]}]
    d = b["diagnosis"]
    assert d["verdict"] == "prohibited_order"
    assert 'C2_9 "V4 must not advance while V1 is out (v11)"' in d["summary"]
    assert "over-strict" in d["summary"]
    assert data["prohibited"][0]["order"] == "AVANCER4"


def test_report_html_and_svg(cli, tmp_path):
    if shutil.which("dot") is None:
        pytest.fail("Graphviz's dot is required (CI installs it)")
    out_dir = tmp_path / "rep"
    code, out, _ = cli("validate", G / "tri_missing_order.g7", "--plant", P / "tri.rules", "--report", out_dir)
    assert code == 1
    assert f"report: {out_dir / 'index.html'}" in out
    html = (out_dir / "index.html").read_text()
    assert html.startswith("<!DOCTYPE html>")
    assert html.count("<svg") >= 3  # trace, element V2, SUP neighbourhood (+ aggregated automaton)
    assert "Sit={X1, X103, X200, X300}" in html  # the blocking state drawn like figure 2.10
    assert "missing order AVANCER2 in step 103" in html
    assert "<summary>Element V2: in {" in html  # the element automaton, folded under its state
    assert "↑AVANCER2 ✗" not in html  # SUP authorises AVANCER2 there
    assert list(out_dir.iterdir()) == [out_dir / "index.html"]  # no temporary left behind


def test_cor(cli, tmp_path):
    cor = tmp_path / "cor.json"
    code, _, _ = cli("validate", G / "tri_missing_order.g7", "--plant", P / "tri.rules", "--cor", cor)
    assert code == 1
    data = json.loads(cor.read_text())
    assert data["removed_states"] > 0
    assert all(s["situation"] != ["X1", "X103", "X200", "X300"] for s in data["states"])
    assert data["states"][0]["situation"] == ["X0", "X100", "X200", "X300"]
    assert (tmp_path / "cor.dot").read_text().startswith('digraph "COR"')


def test_deterministic_json(cli):
    a = cli("validate", G / "tri_missing_order.g7", "--plant", P / "tri.rules", "--json")[1]
    b = cli("validate", G / "tri_missing_order.g7", "--plant", P / "tri.rules", "--json")[1]
    assert a == b


class _GridOracle:
    """SUP membership read from the full SUP grid: the plain path the on-the-fly one must match."""

    def __init__(self, sup, lazy):
        self.sup, self.lazy = sup, lazy
        self.constraints = lazy.constraints

    def kept(self, local):
        return bool(self.sup.reachable[local]) or not bool(self.sup.removed[local])

    def move(self, t, local):
        target = list(local)
        target[t.axis] = t.dst
        ok = not self.sup.removed[tuple(target)]
        if t.controllable and t.event in self.sup.forbid:
            ok = ok and not self.sup.forbid[t.event][local]
        return ok, ([] if ok else self.lazy.move(t, local)[1])

    def verdicts(self, ts, local):
        return [self.move(t, local) for t in ts]

    def __getattr__(self, name):
        return getattr(self.lazy, name)


@pytest.mark.parametrize("g,r", [("tri.g7", "tri.rules"), ("tri_missing_order.g7", "tri.rules"),
                                 ("tri.g7", "tri_overstrict.rules")])
def test_on_the_fly_sync_equals_grid_sync(g, r, monkeypatch):
    rs = load_rules(P / r)
    p = plant(rs)
    machine = GrafcetMachine(load_grafcet(G / g, inputs=p.inputs, outputs=p.outputs))
    lazy = synchronous_product(p, rs.constraints, machine)
    sup = supremal_controllable(p, rs.constraints)
    import synth.validation.sync as sync_mod

    real = sync_mod.CompiledConstraints
    monkeypatch.setattr(sync_mod, "CompiledConstraints", lambda p_, c_: _GridOracle(sup, real(p_, c_)))
    plain = synchronous_product(p, rs.constraints, machine)
    assert [(n.situation, n.plant, n.proh) for n in plain.nodes] == [(n.situation, n.plant, n.proh) for n in lazy.nodes]
    assert plain.edges == lazy.edges
    # every SYNC plant state lies in SUP's reachable part
    assert all(sup.reachable[n.plant] for n in lazy.nodes)


def test_max_states_stops_with_a_message(cli):
    code, out, err = cli("validate", G / "tri.g7", "--plant", P / "tri.rules", "--max-states", "5")
    assert code == 2 and out == ""
    assert err.strip() == "stopped: more than 5 aggregated states; raise --max-states or simplify the model"


def test_empty_sup_fails_validation(cli, tmp_path):
    rules = tmp_path / "tri_empty.rules"
    text = (P / "tri.rules").read_text().replace('use "lib/', f'use "{P}/lib/')
    rules.write_text(text + 'constraint K "V1 never at rest": v10 = 0\n')
    code, data = _json(cli, G / "tri.g7", "--plant", rules)
    assert code == 1
    assert data["sup_empty"] is True and data["verdict"] == "fail"
    code, out, _ = cli("sup", rules)
    assert code == 0
    assert "SUP is empty" in out
    assert '{v10,v20,v30,v40} is illegal: it violates K "V1 never at rest"' in out


def _small(tmp_path, rules: str, g7: str):
    (tmp_path / "p.rules").write_text(rules)
    (tmp_path / "g.g7").write_text(g7)
    return tmp_path / "g.g7", tmp_path / "p.rules"


TWO = (
    "element EA { order A = 0  sensor a = 0  ↑A -> ↑a  ↓A -> ↓a }\n"
    "element EB { order B = 0  sensor b = 0  ↑B -> ↑b  ↓B -> ↓b }\n"
    'constraint C1 "not both": A & B = 0\n'
)


def test_initial_region_settling_in_two_states(cli, tmp_path):
    """SUP lets the initial situation set A or B, not both: two initial aggregated states,
    each with its own prohibition; traces start from either. Where A was set, the
    prohibited B holds the Grafcet in step 0 for ever: blocking at the initial state."""
    g, r = _small(tmp_path, TWO, "grafcet G { initial step 0: A, B   step 1   transition 0 -> 1 when b }\n")
    code, data = _json(cli, g, "--plant", r)
    assert code == 1
    assert sorted((p["order"], p["trace"]) for p in data["prohibited"]) == [("A", []), ("B", [])]
    held, dead = data["blocking"]
    assert (held["trace"], held["Z"], held["diagnosis"]["verdict"]) == ([], {"A": 1, "B": 0}, "prohibited_order")
    assert dead["trace"] == ["↑b", "↓b"]
    assert dead["diagnosis"]["verdict"] == "dead_end"


def test_trap_on_operator_inputs(cli, tmp_path):
    g, r = _small(
        tmp_path,
        "free dcy = 0\nelement EA { order A = 0  sensor a = 0  ↑A -> ↑a  ↓A -> ↓a }\n",
        "grafcet G { initial step 0  step 1  step 2: A\n"
        " transition 0 -> 1 when dcy  transition 1 -> 2 when !dcy  transition 2 -> 1 when dcy }\n",
    )
    code, data = _json(cli, g, "--plant", r)
    assert code == 1
    (b,) = data["blocking"]
    assert b["diagnosis"]["verdict"] == "trap"
    assert b["diagnosis"]["summary"].startswith(
        "the Grafcet keeps evolving on operator inputs (↓dcy) between {X1}, {X2} but can never return"
    )


def test_unwritable_report_is_bad_input(cli):
    code, _, err = cli("validate", G / "tri.g7", "--plant", P / "tri.rules", "--report", "/proc/synth-no/dir")
    assert code == 2
    assert err.startswith("error: cannot write")


def test_cor_must_not_end_in_dot(cli, tmp_path):
    code, _, err = cli("validate", G / "tri.g7", "--plant", P / "tri.rules", "--cor", tmp_path / "c.dot")
    assert code == 2 and "must not end in .dot" in err


def test_report_sections_for_prohibitions_with_the_same_trace(cli, tmp_path):
    g, r = _small(
        tmp_path,
        "free go = 0\n" + TWO,
        "grafcet G { initial step 0  step 1: A, B  transition 0 -> 1 when ↑go  transition 1 -> 0 when ↓go }\n",
    )
    code, out, _ = cli("validate", g, "--plant", r, "--report", tmp_path / "rep")
    assert code == 1
    html = (tmp_path / "rep" / "index.html").read_text()
    first, second = html.split("<h2>Prohibited orders 1")[1].split("<h2>Prohibited orders 2")
    assert "SUP forbids ↑B there" in first and "SUP forbids ↑A there" not in first
    assert "SUP forbids ↑A there" in second and "SUP forbids ↑B there" not in second


def test_or_divergence_conflict_is_reported(cli):
    code, data = _json(cli, ROOT / "tests" / "data" / "or_conflict.g7", "--plant", P / "tri.rules")
    assert data["conflicts"] == [
        {"step": "X100", "transitions": ["100->101", "100->111"], "event": "↑cp12",
         "situation": ["X1", "X100"], "trace": ["↑dcy", "↑cp12"]}
    ]
    code, data = _json(cli, G / "tri.g7", "--plant", P / "tri.rules")
    assert data["conflicts"] == []


def test_unproducible_event(cli, tmp_path):
    g, r = _small(
        tmp_path,
        "free go = 0\nelement E { order A = 0  sensor s = 0  ↑A -> ↑s }\n"
        "element F { order B = 0  sensor t = 0 }\n",
        "grafcet G { initial step 0  step 1: B  transition 0 -> 1 when ↑go  transition 1 -> 0 when t }\n",
    )
    code, data = _json(cli, g, "--plant", r)
    assert code == 1
    (b,) = data["blocking"]
    assert b["trace"] == ["↑go"]
    assert b["diagnosis"]["verdict"] == "unproducible_event"
    assert b["diagnosis"]["summary"] == (
        "awaited event ↑t can never occur: transition 1->0 of G awaits t and element F has no rule producing ↑t"
    )

"""The parts of `synth filter verify` after the split of closed_loop (issue 20): the
product's grids come from sup.Supervisor and agree with the per-state closed forms of
CompiledConstraints; the finding kinds print as before; the filter computes and the
output layer prints (from-rules writes nothing, check and run are one call each)."""

from __future__ import annotations

import json

from conftest import ROOT
from synth.filter.coherence import check
from synth.filter.cycle import Algorithm, Mode
from synth.filter.from_rules import Classification, skeleton
from synth.filter.language_check import load_filter
from synth.filter.loop.product import Product
from synth.filter.run import run_trace
from synth.filter.loop.verification import FindingKind
from synth.logic.events import Event
from synth.output.filter_text import FINDINGS, check_text, run_json, skeleton_text, verification_json
from synth.plant.composition import load_plant, plant
from synth.plant.rules_check import load_rules
from synth.sup.constraints import CompiledConstraints

DATA = ROOT / "tests" / "data" / "filter"
TRI = ROOT / "plants" / "tri.rules"


def _product(rules, tmp_path, grafcet=None):
    sk = skeleton(rules, tmp_path / "F.filter")
    return Product(sk.filter, load_plant(rules), grafcet, Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False)


def test_grids_agree_with_the_closed_forms_state_by_state(tmp_path):
    """illegal, outside SUP and the forbidden edges of every state, from the Supervisor's
    grids, equal CompiledConstraints' answers for that one state."""
    seen = set()
    for rules in (DATA / "two.rules", TRI):
        pr = _product(rules, tmp_path)
        rs = load_rules(rules)
        cc = CompiledConstraints(plant(rs), rs.constraints)
        seen |= {"edge"} if pr.forbid else set()
        seen |= {"weakly"} if (pr.outside_sup & ~pr.illegal).any() else set()
        for code in range(pr.size):
            local = pr.plant.local(code)
            assert pr.illegal[code] == bool(cc.violated(local)), (rules, code)
            assert pr.outside_sup[code] == (not cc.kept(local)), (rules, code)
            for ev, grid in pr.forbid.items():
                assert grid[code] == bool(cc.forbidding(ev, local)), (rules, code, ev)
    assert seen == {"edge", "weakly"}  # not vacuous
    # every order has both edges in the toggle table (-1 where the plant has no such move)
    assert all(Event.edge(z, r) in pr.toggle for z in pr.orders for r in (False, True))


def test_finding_kinds_print_as_before():
    assert [str(k) for k in FindingKind] == ["violation", "edge", "refused", "fallback", "outside_care",
                                             "transient", "outside_sup"]
    assert set(FINDINGS) == set(FindingKind)


def test_verification_json_keys_are_plain_strings(tmp_path):
    from synth.filter.loop.verify import verify

    out = tmp_path / "F.filter"
    sk = skeleton(DATA / "two.rules", out)
    v = verify(sk.filter, str(DATA / "two.rules"), any_control=True, require_sup=True)
    data = json.loads(json.dumps(verification_json(v)))
    assert list(data["findings"]) == [str(k) for k in v.findings] and v.findings


def test_from_rules_classification_and_text(tmp_path):
    out = tmp_path / "F.filter"
    sk = skeleton(TRI, out)
    assert not out.exists()  # the filter computes; the CLI writes
    assert {c.kind for c in sk.constraints} == {Classification.SIMPLE, Classification.COMBINED}
    assert skeleton_text(sk).splitlines()[:3] == ["C2_1: CSc (no priority) on AVANCER1, RECULER1",
                                                  "C2_2: CSc (no priority) on AVANCER2, RECULER2",
                                                  "C2_3: CSs on AVANCER3"]


def test_check_and_run_are_one_call_each(cli):
    tri = ROOT / "plants" / "tri.filter"
    c = check(load_filter(tri))
    code, text, _ = cli("filter", "check", tri)
    assert (code, text) == (0 if c.holds else 1, check_text(c))
    loop_c = ROOT / "plants" / "loop_c.filter"
    r = run_trace(load_filter(loop_c), str(DATA / "loop_c.csv"), Algorithm.LOOP)
    code, text, _ = cli("filter", "run", loop_c, "--trace", DATA / "loop_c.csv", "--algorithm", "loop", "--json")
    assert code == (0 if r.coherent else 1)
    assert json.loads(text) == json.loads(json.dumps(run_json(str(loop_c), r)))
